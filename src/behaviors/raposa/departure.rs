//! The departure (seed 001's robot leaves the pyramid to explore; the imprint is seed
//! 004's method, seed 001's future work): `raposa.depart` drives straight out, body
//! forward, until the camera is the profile's `perception.pyramid.imprint_distance_m` from
//! the ball (event `stopped`), `raposa.imprint` stands still with the pyramid straight
//! behind and imprints its colours. The perception does not run meanwhile (the departure
//! mission turns it off); only the imprint reads frames.

use super::memory::Memory;
use crate::arbiter::Blackboard;
use crate::schemas::{Behavior, FailureReason, Inputs, MotorOutput, Outcome, Step};

/// `raposa.depart`: see the module docs.
pub struct Depart {
    name: String,
    mem: Blackboard<Memory>,
    /// Where to stop, odometry frame (odometry starts at the docked pose).
    target: (f64, f64),
}

impl Depart {
    /// A leaf named `name`.
    pub fn new(name: &str, mem: Blackboard<Memory>) -> Self {
        // Docked, the camera is `socket_inset` from the ball, and the body's forward
        // direction leads away from it.
        let travel = {
            let m = mem.lock();
            (m.schema.imprint_distance() - m.socket_inset).max(0.0)
        };
        Self {
            name: name.into(),
            mem,
            target: (travel, 0.0),
        }
    }
}

impl Behavior for Depart {
    fn name(&self) -> &str {
        &self.name
    }

    fn enter(&mut self, _inputs: &Inputs<'_>) {}

    fn tick(&mut self, _inputs: &Inputs<'_>) -> Option<Step> {
        let m = self.mem.lock();
        Some(match m.ctrl.travel(&m.odo, self.target, false) {
            Some(t) => m.drive(t, "depart"),
            None => m.hold_event("stopped", "depart"),
        })
    }
}

/// `raposa.imprint`: stand still for the perception's `imprint_frames` frames (the first
/// frame after stopping is skipped: it may still be blurred by the motion), then learn the
/// colours. The departure ends completed when the imprint succeeded, failed (target never
/// detected) otherwise, as Bujold's does.
pub struct Imprint {
    name: String,
    mem: Blackboard<Memory>,
    frames: u32,
}

impl Imprint {
    /// A leaf named `name`.
    pub fn new(name: &str, mem: Blackboard<Memory>) -> Self {
        Self {
            name: name.into(),
            mem,
            frames: 0,
        }
    }
}

impl Behavior for Imprint {
    fn name(&self) -> &str {
        &self.name
    }

    fn enter(&mut self, _inputs: &Inputs<'_>) {
        self.frames = 0;
    }

    fn tick(&mut self, inputs: &Inputs<'_>) -> Option<Step> {
        let mut m = self.mem.lock();
        if self.frames > 0
            && let Some(cam) = inputs.camera(0)
        {
            let _ = m.schema.imprint_frame(&cam.image);
        }
        if self.frames >= m.schema.imprint_frames_wanted() {
            let now = m.now;
            m.imprinted = m.schema.finish_imprint(now);
            let outcome = if m.imprinted {
                Outcome::Completed
            } else {
                Outcome::Failed(FailureReason::TargetNeverDetected)
            };
            let out = MotorOutput::stop().with_aux(m.aux);
            return Some(Step::done(outcome, out, m.feedback("imprint")));
        }
        self.frames += 1;
        Some(m.hold("imprint"))
    }
}
