//! The two slow searches (seed 001 §II.E: "rotate slowly until it finds it again",
//! alternating sides and doubling the sweep below 360°): `raposa.search` (state 5, nothing
//! seen) and `raposa.look` (after the region-II manoeuvre, which ends facing where the
//! pyramid should be).

use super::memory::Memory;
use super::params::{LookParams, SearchParams};
use crate::schemas::{Behavior, FailureReason, Inputs, Outcome, SearchRotation, Step};

/// `raposa.search`, state 5: after `grace_frames` frames with nothing seen, the doubling
/// search, first away from the side of the last turn; the docking fails (target lost)
/// after the profile's `behavior.search_timeout_s` of searching. The selector leaves it as
/// soon as anything is seen; the search clock restarts once the ellipse is seen.
pub struct Search {
    name: String,
    params: SearchParams,
    timeout: f64,
}

impl Search {
    /// A leaf named `name`, giving up after `timeout` s.
    pub fn new(name: &str, params: SearchParams, timeout: f64) -> Self {
        Self {
            name: name.into(),
            params,
            timeout,
        }
    }
}

impl Behavior<Memory> for Search {
    fn name(&self) -> &str {
        &self.name
    }

    fn enter(&mut self, _mem: &mut Memory, _inputs: &Inputs<'_>) {}

    fn tick(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) -> Option<Step> {
        m.unseen += 1;
        if m.unseen <= self.params.grace_frames {
            return Some(m.hold("state_5"));
        }
        let now = m.now;
        let start = *m.search_start.get_or_insert(now);
        if now - start > self.timeout {
            return Some(m.hold("state_5").finishing(Outcome::Failed(FailureReason::TargetLost)));
        }
        let search = SearchRotation {
            rate: m.gains.search_rate_dps.to_radians() * -m.last_turn,
            first_sweep: m.gains.search_sweep_deg.to_radians(),
            doubling: true,
        };
        Some(m.command(search.command(now - start), "state_5"))
    }
}

/// `raposa.look`: stand still `settle_s`, then the doubling search, first opposite to the
/// manoeuvre's last turn; the docking fails (target lost) after the profile's
/// `behavior.search_timeout_s`. The selector leaves it, with the angle threshold widened
/// (settling), as soon as the ellipse is seen.
pub struct Look {
    name: String,
    params: LookParams,
    timeout: f64,
    start: f64,
    first_dir: f64,
}

impl Look {
    /// A leaf named `name`, giving up after `timeout` s.
    pub fn new(name: &str, params: LookParams, timeout: f64) -> Self {
        Self {
            name: name.into(),
            params,
            timeout,
            start: 0.0,
            first_dir: 1.0,
        }
    }
}

impl Behavior<Memory> for Look {
    fn name(&self) -> &str {
        &self.name
    }

    fn enter(&mut self, m: &mut Memory, inputs: &Inputs<'_>) {
        m.blind = false;
        self.start = inputs.now;
        self.first_dir = -m.last_turn;
    }

    fn tick(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) -> Option<Step> {
        let t = m.now - self.start;
        if t < self.params.settle_s {
            return Some(m.hold("state_2_look")); // let the image settle after stopping
        }
        if t > self.timeout {
            return Some(
                m.hold("state_2_look")
                    .finishing(Outcome::Failed(FailureReason::TargetLost)),
            );
        }
        let search = SearchRotation {
            rate: m.gains.search_rate_dps.to_radians() * self.first_dir,
            first_sweep: m.gains.search_sweep_deg.to_radians(),
            doubling: true,
        };
        Some(m.command(search.command(t - self.params.settle_s), "state_2_look"))
    }
}
