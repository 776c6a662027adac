//! The departure (seed 001's robot leaves the pyramid to explore; the imprint is seed
//! 004's method, seed 001's future work): `raposa.depart` drives straight out, body
//! forward, until the camera is the profile's `perception.pyramid.imprint_distance_m` from
//! the ball (for a two-block flap, `perception.imprint.at_distance_m` from the flap; event
//! `stopped`). Then `raposa.imprint`, the common leaf
//! [`crate::behaviors::common::docking::Imprint`], stands still with the target straight
//! behind and imprints its colours, skipping the first frame after stopping (it may still
//! be blurred); its outcome is the departure's. The perception does not run meanwhile
//! (the departure mission turns it off); only the imprint reads frames.

use super::memory::Memory;
use crate::geometry::Pose2;
use crate::schemas::{Behavior, Inputs, Step};

/// `raposa.depart`: see the module docs.
pub struct Depart {
    /// Where to stop, straight ahead of where the departure began: m along the body.
    travel: f64,
    /// Odometry where the departure began (odometry is not reset between missions: on
    /// a real robot, or an endurance outing, it reads wherever the last mission left it).
    from: Pose2,
}

impl Depart {
    /// The leaf, its travel read from `mem` (the robot's memory at build time).
    pub fn new(mem: &Memory) -> Self {
        // Docked, the camera is `docked_distance` from the target (the ball at the socket,
        // or the flap over the pouch the robot sits in), and the body's forward direction
        // leads away from it.
        let travel = (mem.source.imprint_distance() - mem.docked_distance).max(0.0);
        Self {
            travel,
            from: Pose2::default(),
        }
    }
}

impl Behavior<Memory> for Depart {
    fn enter(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) {
        self.from = m.odo;
    }

    fn tick(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) -> Option<Step> {
        let target = self.from.to_world(self.travel, 0.0);
        Some(match m.ctrl.travel(&m.odo, target, false) {
            Some(t) => m.drive(t, "depart"),
            None => m.hold("depart").with_event("stopped"),
        })
    }
}
