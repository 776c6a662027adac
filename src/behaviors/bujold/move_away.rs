//! `bujold.move_away` and `bujold.give_up`: back off from the entrance, front first,
//! `distance_m` (or for `timeout_s`). Moving away ends with event `done` (retry the
//! approach); giving up ends the docking failed, with the reason the phase that gave up
//! left in memory (a timeout when none did): every failure close to the dock first
//! moves away from the entrance, then stops.

use super::memory::Memory;
use super::params::MoveAwayParams;
use crate::geometry::Pose2;
use crate::schemas::{Behavior, FailureReason, Inputs, Outcome, Step};

/// See the module docs.
pub struct MoveAway {
    name: String,
    params: MoveAwayParams,
    give_up: bool,
    started: f64,
    mark: Pose2,
}

impl MoveAway {
    /// A leaf named `name`; `give_up` ends the docking failed instead of retrying.
    pub fn new(name: &str, params: MoveAwayParams, give_up: bool) -> Self {
        Self {
            name: name.into(),
            params,
            give_up,
            started: 0.0,
            mark: Pose2::default(),
        }
    }
}

impl Behavior<Memory> for MoveAway {
    fn name(&self) -> &str {
        &self.name
    }

    fn enter(&mut self, m: &mut Memory, inputs: &Inputs<'_>) {
        self.started = inputs.now;
        self.mark = m.odo;
    }

    fn tick(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) -> Option<Step> {
        let p = self.params;
        let phase = if self.give_up { "give_up" } else { "move_away" };
        if m.travelled(&self.mark) < p.distance_m && m.now - self.started <= p.timeout_s {
            return Some(m.drive_away(p.speed_mps, phase));
        }
        Some(if self.give_up {
            let reason = m.failing.unwrap_or(FailureReason::Timeout);
            m.hold(phase).finishing(Outcome::Failed(reason))
        } else {
            m.hold(phase).with_event("done")
        })
    }
}
