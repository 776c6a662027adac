//! `raposa.final`, state 6 (latched; seed 001 §II.E), selected once the ball is within
//! `final_distance_m` (the area threshold). On entry the arm goes to −K_arm·y_dev and the
//! lights turn on; the first tick still runs the state-1 law, then the robot drives at the
//! slow constant `final_speed_mps`, steering on the ellipse when seen, for
//! `final_time_s`. With the node's `posture` param it also commands that posture (a robot
//! that lowers itself into its dock). Without the dock switch by then (it subsumes this
//! phase) the lights go off, the posture is raised again, and the attempt counts as a
//! retry: event `retry` (back away and try again), or the docking fails with retries
//! exhausted after the profile's `behavior.max_retries`.

use super::memory::Memory;
use super::params::FinalParams;
use crate::schemas::{ArmPosition, Behavior, FailureReason, Inputs, Lights, Outcome, Posture, Step};

/// See the module docs.
pub struct FinalApproach {
    params: FinalParams,
    start: f64,
    first: bool,
}

impl FinalApproach {
    /// The leaf with the node's params; it fails once the docking's retries
    /// ([`Memory::retries`]) are spent.
    pub fn new(params: FinalParams) -> Self {
        Self {
            params,
            start: 0.0,
            first: true,
        }
    }
}

impl Behavior<Memory> for FinalApproach {
    fn enter(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) {
        let dev = m.percept.view.map_or(0.0, |v| v.dev_px[1]);
        m.aux.set(ArmPosition(m.law.arm(dev)));
        m.aux.set(Lights(true));
        if let Some(p) = self.params.posture {
            m.aux.set(p);
        }
        self.start = m.now;
        self.first = true;
    }

    fn tick(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) -> Option<Step> {
        if std::mem::take(&mut self.first) {
            // The end of state 1: its law still runs on the tick state 6 is selected.
            return Some(m.approach(false, "state_6"));
        }
        if m.now - self.start < m.gains.final_time_s {
            let omega = m.percept.view.map_or(0.0, |v| m.law.turn(v.dev_px[0]));
            return Some(m.drive(m.law.twist(m.gains.final_speed_mps, omega), "state_6"));
        }
        // Time is up without the dock switch: stop, and retry from further out.
        m.aux.set(Lights(false));
        if self.params.posture.is_some() {
            m.aux.set(Posture::Raised);
        }
        if !m.retries.spend() {
            return Some(
                m.hold("state_6")
                    .finishing(Outcome::Failed(FailureReason::RetriesExhausted)),
            );
        }
        Some(m.hold("state_6").with_event("retry"))
    }
}
