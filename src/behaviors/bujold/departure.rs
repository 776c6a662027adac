//! The departure phases (seed 004 §IV.C): `undock` out of the pouch lowered, `drive_out`
//! raised with the camera on the flap, stopping at the imprint distance to `imprint` the
//! blocks' colours, then on out. `imprint` is the common leaf
//! ([`crate::behaviors::common::docking::Imprint`]), registered as `bujold.imprint`.

use super::memory::{Memory, lowered};
use super::params::{DriveOutParams, UndockParams};
use crate::schemas::{Behavior, DriveCommand, FailureReason, Inputs, MotorOutput, Outcome, Step};

/// `bujold.undock`: drive out of the pouch front first, lowered, until clear of it;
/// event `out`.
pub struct Undock {
    params: UndockParams,
    depth: f64,
}

impl Undock {
    /// The leaf; `depth` is the pouch's depth, m.
    pub fn new(params: UndockParams, depth: f64) -> Self {
        Self { params, depth }
    }
}

impl Behavior<Memory> for Undock {
    fn enter(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) {
        // Departure distances are measured from where it began.
        m.departure_mark = m.odo;
    }

    fn tick(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) -> Option<Step> {
        let out = MotorOutput {
            drive: DriveCommand::Straight {
                v: -m.geometry.drive_dir * self.params.speed_mps,
            },
            aux: lowered(),
        };
        let feedback = m.feedback("undock");
        Some(
            if m.travelled(&m.departure_mark) >= self.depth + self.params.beyond_depth_m {
                Step::event("out", out, feedback)
            } else {
                Step::running(out, feedback)
            },
        )
    }
}

/// `bujold.drive_out`: drive away from the dock, raised; event `imprint` at the imprint
/// distance (once), then done at the departure distance: completed when the imprint
/// succeeded, failed (target never detected) otherwise.
pub struct DriveOut {
    params: DriveOutParams,
    /// Travel from the departure's start at which to imprint, m.
    imprint_at: f64,
}

impl DriveOut {
    /// The leaf, imprinting `imprint_at` m from where the departure began.
    pub fn new(params: DriveOutParams, imprint_at: f64) -> Self {
        Self { params, imprint_at }
    }
}

impl Behavior<Memory> for DriveOut {
    fn enter(&mut self, _mem: &mut Memory, _inputs: &Inputs<'_>) {}

    fn tick(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) -> Option<Step> {
        let out = m.travelled(&m.departure_mark);
        Some(if !m.imprinted && out >= self.imprint_at {
            m.hold("drive_out").with_event("imprint")
        } else if out >= self.params.distance_m {
            let outcome = if m.imprinted {
                Outcome::Completed
            } else {
                Outcome::Failed(FailureReason::TargetNeverDetected)
            };
            m.hold("drive_out").finishing(outcome)
        } else {
            m.drive_away(self.params.speed_mps, "drive_out")
        })
    }
}
