//! The blind part of the region-II manoeuvre (seed 001 §II.E), by odometry in the frame
//! state 7 left in [`Memory::map`] (the ball frame): `raposa.rotate_odo` finishes the
//! rotation −β (event `rotated`), `raposa.travel` drives to the target with the inverse
//! (x_ref, y_ref) controller (event `arrived`), `raposa.rotate_phi` turns to face where
//! the ball should be (event `facing`, with the detector's tracking forgotten). Entering
//! any of them tells the perception the robot looks away on purpose.

use super::memory::Memory;
use crate::schemas::{Behavior, Inputs, Step};

/// Which part of the manoeuvre a [`Manoeuvre`] leaf runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Part {
    /// The rest of −β.
    RotateOdo,
    /// Travel d.
    Travel,
    /// Rotate φ, facing the ball.
    RotatePhi,
}

/// See the module docs.
pub struct Manoeuvre {
    name: String,
    part: Part,
    /// Where the ball should be, odometry frame (rotate φ).
    ball: (f64, f64),
}

impl Manoeuvre {
    /// A leaf named `name` running `part`.
    pub fn new(name: &str, part: Part) -> Self {
        Self {
            name: name.into(),
            part,
            ball: (0.0, 0.0),
        }
    }
}

impl Behavior<Memory> for Manoeuvre {
    fn name(&self) -> &str {
        &self.name
    }

    fn enter(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) {
        // The blind part of region II looks away from the pyramid on purpose.
        m.blind = true;
        self.ball = m.map.to_world(0.0, 0.0);
    }

    fn tick(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) -> Option<Step> {
        let Some(pl) = m.plan else {
            return Some(m.hold("state_2"));
        };
        let (odo, map) = (m.odo, m.map);
        Some(match self.part {
            Part::RotateOdo => match m.ctrl.rotate(&odo, map.theta + pl.travel_heading) {
                Some(t) => m.turn(t.omega, "state_2_rotate"),
                None => m.hold("state_2_rotate").with_event("rotated"),
            },
            Part::Travel => match m.ctrl.travel(&odo, map.to_world(pl.target.0, pl.target.1), pl.reverse) {
                Some(t) => m.drive(t, "state_2_travel"),
                None => m.hold("state_2_travel").with_event("arrived"),
            },
            Part::RotatePhi => {
                // Face the ball from where the robot actually is: the camera looks back.
                let (bx, by) = self.ball;
                let heading = (by - odo.y).atan2(bx - odo.x) + std::f64::consts::PI;
                match m.ctrl.rotate(&odo, heading) {
                    Some(t) => m.turn(t.omega, "state_2_rotate_phi"),
                    None => {
                        m.source.reset();
                        m.hold("state_2_rotate_phi").with_event("facing")
                    }
                }
            }
        })
    }
}
