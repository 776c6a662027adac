//! `bujold.dock_switch`: the pressure plates inside the mother (seed 004 §VI.B: success
//! is contact with them). Released only when the switch reads closed; then the docking
//! has succeeded, whatever phase was running: under a priority node it subsumes them.

use super::memory::{Memory, lowered};
use crate::arbiter::Blackboard;
use crate::schemas::{Behavior, Inputs, MotorOutput, Outcome, Step};

/// See the module docs.
pub struct DockSwitch {
    name: String,
    mem: Blackboard<Memory>,
}

impl DockSwitch {
    /// A leaf named `name`.
    pub fn new(name: &str, mem: Blackboard<Memory>) -> Self {
        Self { name: name.into(), mem }
    }
}

impl Behavior for DockSwitch {
    fn name(&self) -> &str {
        &self.name
    }

    fn tick(&mut self, inputs: &Inputs<'_>) -> Option<Step> {
        inputs.docked_contact().then(|| {
            let m = self.mem.lock();
            Step::done(
                Outcome::Docked,
                MotorOutput::stop().with_aux(lowered()),
                m.feedback("docked"),
            )
        })
    }
}
