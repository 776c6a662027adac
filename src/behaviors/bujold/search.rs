//! `bujold.search`: rotate in place until the fiducial is acquired (seed 004 §V: "with no
//! fiducial in view, rotate until it is acquired"), toward the side it was last seen.
//!
//! Events: `acquired` (commanding the approach motor schema at once, so acquisition costs
//! no standstill tick), `jammed` when the turn has not changed the view for
//! `jammed_after_s` (beside the gate a corner catches the body: the tracks spin, the view
//! does not move) and unjams are left. After the profile's `behavior.search_timeout_s` it
//! fails: target lost if it was ever seen this docking, never detected otherwise.

use super::memory::{Memory, raised};
use super::params::SearchParams;
use crate::schemas::{Behavior, FailureReason, Inputs, MotorOutput, Outcome, SearchRotation, Step};

/// See the module docs.
pub struct Search {
    name: String,
    params: SearchParams,
    rotation: SearchRotation,
    timeout_s: f64,
    started: f64,
    /// Since when the view has been still while turning.
    still_since: Option<f64>,
}

impl Search {
    /// A leaf named `name` turning at `rotation`'s rate, giving up after `timeout_s`.
    pub fn new(name: &str, params: SearchParams, rotation: SearchRotation, timeout_s: f64) -> Self {
        Self {
            name: name.into(),
            params,
            rotation,
            timeout_s,
            started: 0.0,
            still_since: None,
        }
    }

    /// True when the turn has not changed the view for `jammed_after_s` (and unjams are
    /// left). `change` is this tick's frame-change cue.
    fn jammed(&mut self, change: Option<f32>, now: f64, unjams: u32) -> bool {
        match change {
            Some(c) if c < self.params.still_levels => {
                let since = *self.still_since.get_or_insert(now);
                now - since >= self.params.jammed_after_s && unjams < self.params.max_unjams
            }
            _ => {
                self.still_since = None;
                false
            }
        }
    }
}

impl Behavior<Memory> for Search {
    fn name(&self) -> &str {
        &self.name
    }

    fn enter(&mut self, _mem: &mut Memory, inputs: &Inputs<'_>) {
        self.started = inputs.now;
        self.still_since = None;
    }

    fn tick(&mut self, m: &mut Memory, inputs: &Inputs<'_>) -> Option<Step> {
        let change = m.observe_change(inputs);
        let now = m.now;
        let in_phase = now - self.started;
        if let Some(v) = m.view {
            return Some(Step::event("acquired", m.approach.act(&v), m.feedback("search")));
        }
        if in_phase > self.timeout_s {
            let reason = if m.ever_seen {
                FailureReason::TargetLost
            } else {
                FailureReason::TargetNeverDetected
            };
            return Some(m.hold("search").finishing(Outcome::Failed(reason)));
        }
        if self.jammed(change, now, m.unjams) {
            m.unjams += 1;
            m.last_side = -m.last_side;
            tracing::debug!(target: "marsupial::behavior", now, unjams = m.unjams, "search turn jammed");
            return Some(m.hold("search").with_event("jammed"));
        }
        let mut s = self.rotation;
        s.rate *= m.last_side;
        Some(Step::running(
            MotorOutput::drive(s.command(in_phase)).with_aux(raised()),
            m.feedback("search"),
        ))
    }
}
