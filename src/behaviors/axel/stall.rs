//! `axel.stall`: the reel's stall guard. Axel had no tension sensor and inferred the pull
//! from the reel motor's current (seed 000 §IV-A), so this leaf reads the current, never
//! tension: once it has stayed at or above `current_a` for `for_s` the arm is caught (on
//! the cone's face, or pushed misaligned against its throat, §V-C, §V-F) or the tether is
//! fouled, and reeling on would only load the motor. Under a priority arbiter it subsumes
//! the docking then, stopping wheels and reel with `stuck_contact`; otherwise it is not
//! released.

use super::memory::Memory;
use crate::schemas::{Auxiliary, Behavior, FailureReason, Inputs, MotorOutput, Outcome, Step, TetherCommand};
use serde::Deserialize;

/// `axel.stall`'s params.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct StallParams {
    /// The reel's current that counts as a stall, A (pure reeling against the cone drew
    /// 1.5–2.0 A, vision-guided docking 0.5–1.0 A, seed 000 §V-C).
    pub current_a: f64,
    /// For this long, s.
    pub for_s: f64,
}

impl Default for StallParams {
    fn default() -> Self {
        Self {
            current_a: 1.8,
            for_s: 2.0,
        }
    }
}

/// See the module docs.
pub struct Stall {
    params: StallParams,
    since: Option<f64>,
}

impl Stall {
    /// A guard with `params`.
    pub fn new(params: StallParams) -> Self {
        Self { params, since: None }
    }
}

impl Behavior<Memory> for Stall {
    fn reset(&mut self) {
        self.since = None;
    }

    fn tick(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) -> Option<Step> {
        let high = m.reel.is_some_and(|r| r.motor_current_a >= self.params.current_a);
        if !high {
            self.since = None;
            return None;
        }
        let since = *self.since.get_or_insert(m.now);
        (m.now - since >= self.params.for_s).then(|| {
            let out = MotorOutput::stop().with_aux(Auxiliary::with(TetherCommand {
                reel_rate: 0.0,
                free_wheel: false,
            }));
            Step::done(Outcome::Failed(FailureReason::StuckContact), out, m.feedback("stalled"))
        })
    }
}
