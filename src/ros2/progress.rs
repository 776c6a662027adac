//! Following a goal's run: the `DockRobot` feedback it publishes (Nav2's state for the
//! running phase, the docking time, the retries), the `max_staging_time` limit, and the
//! result made from the runtime's report.

use super::goals::{Shared, status};
use super::messages::GoalId;
use super::nav2::{self, error, state};
use super::nav2_msgs::{DockFeedback, GoalResult, encode_feedback};
use crate::arbiter::reactive_loop::LoopStatus;
use crate::arbiter::runtime::{RuntimeEvent, RuntimeReport, StopHandle};
use crate::schemas::Outcome;

/// Follows a goal's run: publishes a docking's feedback (on each change of Nav2 state and
/// twice a second), and stops the run when staging took longer than allowed.
pub(crate) struct Progress {
    id: GoalId,
    dock: bool,
    stop: StopHandle,
    /// The state last published and when.
    last: Option<(u16, f64)>,
    /// The state of the phase last seen, and when it was seen.
    state: (u16, f64),
    retries: u16,
    /// Time spent in `NAV_TO_STAGING_POSE`, and the limit.
    staging_s: f64,
    max_staging_s: Option<f64>,
    staged_out: bool,
    buf: Vec<u8>,
}

impl Progress {
    pub(crate) fn new(id: GoalId, dock: bool, stop: StopHandle, max_staging_s: Option<f64>) -> Self {
        Self {
            id,
            dock,
            stop,
            last: None,
            state: (state::NONE, 0.0),
            retries: 0,
            staging_s: 0.0,
            max_staging_s,
            staged_out: false,
            buf: Vec::with_capacity(64),
        }
    }

    fn publish(&mut self, sh: &Shared, s: u16, t: f64) {
        self.last = Some((s, t));
        let f = DockFeedback {
            state: s,
            docking_time_ns: (t * 1e9) as i64,
            num_retries: self.retries,
        };
        encode_feedback(&mut self.buf, &self.id, &f);
        let _ = sh.feedback.put(&self.buf);
    }

    pub(crate) fn observe(&mut self, sh: &Shared, t: f64, status: &LoopStatus) {
        let (phase_state, retries) = match status {
            LoopStatus::Running { feedback } => (nav2::state_of(feedback.phase), feedback.retries),
            LoopStatus::SafeStop { .. } | LoopStatus::Idle => (state::NONE, u32::from(self.retries)),
            LoopStatus::Finished { .. } => return,
        };
        let (prev, since) = self.state;
        if prev == state::NAV_TO_STAGING_POSE {
            self.staging_s += t - since;
        }
        // The last docking state, kept through safe stops, decides a failure's code.
        if phase_state != state::NONE || prev == state::NONE {
            self.state = (phase_state, t);
        } else {
            self.state.1 = t;
        }
        if let Some(max) = self.max_staging_s
            && self.staging_s > max
            && !self.staged_out
        {
            self.staged_out = true;
            self.stop.stop();
        }
        if !self.dock {
            return;
        }
        let retries = retries.min(u32::from(u16::MAX)) as u16;
        if retries > self.retries {
            self.retries = retries;
            self.publish(sh, state::RETRY, t);
            return;
        }
        if self.last.is_some_and(|(s, at)| s == phase_state && t - at < 0.5) {
            return;
        }
        self.publish(sh, phase_state, t);
    }
}

/// The result of a goal's run: the typed outcome as text, with Nav2's error code for it.
pub(crate) fn result_of(report: &RuntimeReport, stopped: bool, progress: &Progress, dock: bool) -> GoalResult {
    let refused = report.events.iter().find_map(|e| match e {
        RuntimeEvent::MissionRefused { error, .. } => Some(error.to_string()),
        _ => None,
    });
    let last = progress.state.0;
    let (status, error_code, msg) = match (&report.outcome, &report.aborted, refused) {
        (_, _, Some(why)) => (status::ABORTED, error::DOCK_NOT_VALID, format!("refused: {why}")),
        (_, Some(reason), _) => (status::ABORTED, error::UNKNOWN, format!("aborted: {reason}")),
        (Some(Outcome::Docked), _, _) => (status::SUCCEEDED, error::NONE, "docked".to_owned()),
        (Some(Outcome::Completed), _, _) => (status::SUCCEEDED, error::NONE, "completed".to_owned()),
        (Some(Outcome::Failed(r)), _, _) => (status::ABORTED, nav2::error_code(*r, last, dock), r.as_str().to_owned()),
        (None, None, None) if progress.staged_out => (
            status::ABORTED,
            error::FAILED_TO_STAGE,
            format!(
                "staging took longer than max_staging_time ({:.1} s)",
                progress.max_staging_s.unwrap_or_default()
            ),
        ),
        (None, None, None) if stopped => (status::CANCELED, error::NONE, "canceled".to_owned()),
        (None, None, None) => (status::ABORTED, error::TIMEOUT, "timeout".to_owned()),
    };
    GoalResult {
        status,
        success: status == status::SUCCEEDED,
        error_code,
        num_retries: progress.retries,
        error_msg: msg,
    }
}

#[cfg(test)]
#[path = "goals_tests.rs"]
mod tests;
