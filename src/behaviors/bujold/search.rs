//! `bujold.search`: the common [`Search`](crate::behaviors::common::search::Search)
//! turning one way at the base's turn rate (seed 004 §V: "with no fiducial in view,
//! rotate until it is acquired"), toward the side it was last seen.
//!
//! Events: `acquired` (commanding the approach motor schema at once, so acquisition costs
//! no standstill tick), `jammed` when the turn has not changed the view for
//! `jammed_after_s` ([`JamWatch`]: beside the gate a corner catches the body, the tracks
//! spin, the view does not move) and unjams are left. After the profile's
//! `behavior.search_timeout_s` it fails: target lost if it was ever seen this docking,
//! never detected otherwise.

use super::memory::{Memory, raised};
use super::params::SearchParams;
use crate::behaviors::common::search::{SearchWatch, Searching};
use crate::schemas::{DriveCommand, FailureReason, Inputs, MotorOutput, Step};

impl Searching for Memory {
    fn acquired(&mut self, phase: &'static str) -> Option<Step> {
        let v = self.view?;
        Some(Step::event("acquired", self.approach.act(&v), self.feedback(phase)))
    }

    fn search_side(&self) -> f64 {
        self.last_side
    }

    fn lost_reason(&self) -> FailureReason {
        if self.ever_seen {
            FailureReason::TargetLost
        } else {
            FailureReason::TargetNeverDetected
        }
    }

    fn search_turn(&mut self, turn: DriveCommand, phase: &'static str) -> Step {
        Step::running(MotorOutput::drive(turn).with_aux(raised()), self.feedback(phase))
    }
}

/// Stops the search turn when the view has been still for `jammed_after_s` while
/// turning (and unjams are left): event `jammed`, and the next search turns the other
/// way. Keeps the frame-change cue running every tick.
pub struct JamWatch {
    params: SearchParams,
    /// This tick's frame-change cue.
    change: Option<f32>,
    /// Since when the view has been still while turning.
    still_since: Option<f64>,
}

impl JamWatch {
    /// A watch with the node's params.
    pub fn new(params: SearchParams) -> Self {
        Self {
            params,
            change: None,
            still_since: None,
        }
    }
}

impl SearchWatch<Memory> for JamWatch {
    fn enter(&mut self) {
        self.still_since = None;
    }

    fn observe(&mut self, m: &mut Memory, inputs: &Inputs<'_>) {
        self.change = m.observe_change(inputs);
    }

    fn stop(&mut self, m: &mut Memory) -> Option<Step> {
        let now = m.now;
        let jammed = match self.change {
            Some(c) if c < self.params.still_levels => {
                let since = *self.still_since.get_or_insert(now);
                now - since >= self.params.jammed_after_s && m.unjams < self.params.max_unjams
            }
            _ => {
                self.still_since = None;
                false
            }
        };
        if !jammed {
            return None;
        }
        m.unjams += 1;
        m.last_side = -m.last_side;
        tracing::debug!(target: "marsupial::behavior", now, unjams = m.unjams, "search turn jammed");
        Some(m.hold("search").with_event("jammed"))
    }
}
