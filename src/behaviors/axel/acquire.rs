//! `axel.acquire`: find the module. The module may start outside the cameras' view, so
//! the rover turns in place in steps, stopping to look after each (sense-plan-act), until
//! a trusted pose arrives (event `acquired`). It turns toward the side the module was last
//! seen on, counter-clockwise when it was never seen. After `behavior.search_timeout_s`
//! without a trusted pose the docking fails: `target_lost` if the module was seen this
//! docking, `target_never_detected` otherwise.

use super::cycle::{Cycle, CycleParams, Decision};
use super::memory::{Memory, Trust};
use crate::arbiter::Blackboard;
use crate::kinematics::two_arc::Polar;
use crate::schemas::{Behavior, FailureReason, Inputs, Outcome, Step};
use serde::Deserialize;

/// `axel.acquire`'s params.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AcquireParams {
    /// Each turn between looks, degrees (below the cameras' 90° view, so views overlap).
    pub turn_deg: f64,
    /// The sense-plan-act timing.
    pub cycle: CycleParams,
    /// What a pose must be to count as found.
    pub trust: Trust,
}

impl Default for AcquireParams {
    fn default() -> Self {
        Self {
            turn_deg: 30.0,
            cycle: CycleParams::default(),
            trust: Trust::default(),
        }
    }
}

/// See the module docs.
pub struct Acquire {
    name: String,
    mem: Blackboard<Memory>,
    params: AcquireParams,
    timeout_s: f64,
    cycle: Cycle,
    since: f64,
}

impl Acquire {
    /// A leaf named `name` giving up after `timeout_s`.
    pub fn new(name: &str, mem: Blackboard<Memory>, params: AcquireParams, timeout_s: f64) -> Self {
        Self {
            name: name.into(),
            mem,
            params,
            timeout_s,
            cycle: Cycle::new(params.cycle, params.trust),
            since: 0.0,
        }
    }
}

impl Behavior for Acquire {
    fn name(&self) -> &str {
        &self.name
    }

    fn enter(&mut self, inputs: &Inputs<'_>) {
        self.since = inputs.now;
        self.cycle.restart(inputs.now);
    }

    fn tick(&mut self, _inputs: &Inputs<'_>) -> Option<Step> {
        let mut m = self.mem.lock();
        if m.now - self.since > self.timeout_s {
            let why = if m.seen {
                FailureReason::TargetLost
            } else {
                FailureReason::TargetNeverDetected
            };
            return Some(m.hold("acquire").finishing(Outcome::Failed(why)));
        }
        let turn = self.params.turn_deg.to_radians();
        Some(self.cycle.tick(&mut m, "acquire", |m, seen| match seen {
            Some(s) => {
                m.seen = true;
                m.search_sign = Polar::from_pose(&s.pose).bearing().signum();
                Decision::Event("acquired")
            }
            None => Decision::Turn(turn * m.search_sign),
        }))
    }
}
