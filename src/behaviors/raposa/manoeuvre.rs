//! The blind part of the region-II manoeuvre (seed 001 §II.E), by odometry in the frame
//! state 7 left in [`Memory::map`] (the ball frame), as three states of the profile's
//! `region_2` sequence: `raposa.rotate_odo` finishes the rotation −β (event `rotated`)
//! and `raposa.rotate_phi` turns to face where the ball should be (event `facing`, with
//! the detector's tracking forgotten), both the common
//! [`TurnTo`](crate::behaviors::common::motion::TurnTo) leg (registered in
//! [`super::register`]); `raposa.travel` ([`Travel`]) drives to the target with the
//! inverse (x_ref, y_ref) controller (event `arrived`). Entering any of them tells the
//! perception the robot looks away on purpose ([`look_away`]).

use super::memory::Memory;
use crate::behaviors::common::motion::Aim;
use crate::schemas::{Behavior, Inputs, Step};

/// The blind part of region II looks away from the pyramid on purpose.
pub fn look_away(m: &mut Memory) {
    m.blind = true;
}

/// The heading of the rest of −β, by odometry (none before a plan).
pub fn rotate_odo(m: &Memory) -> Aim {
    m.plan
        .map_or(Aim::Hold, |pl| Aim::Heading(m.map.theta + pl.travel_heading))
}

/// The heading that faces the ball from where the robot actually is (the camera looks
/// back), the ball where state 7's frame puts it.
pub fn rotate_phi(m: &Memory) -> Aim {
    if m.plan.is_none() {
        return Aim::Hold;
    }
    let (bx, by) = m.map.to_world(0.0, 0.0);
    Aim::Heading((by - m.odo.y).atan2(bx - m.odo.x) + std::f64::consts::PI)
}

/// `raposa.travel`: see the module docs.
#[derive(Debug, Clone, Copy, Default)]
pub struct Travel;

impl Behavior<Memory> for Travel {
    fn enter(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) {
        look_away(m);
    }

    fn tick(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) -> Option<Step> {
        let Some(pl) = m.plan else {
            return Some(m.hold("state_2"));
        };
        let (odo, map) = (m.odo, m.map);
        Some(
            match m.ctrl.travel(&odo, map.to_world(pl.target.0, pl.target.1), pl.reverse) {
                Some(t) => m.drive(t, "state_2_travel"),
                None => m.hold("state_2_travel").with_event("arrived"),
            },
        )
    }
}
