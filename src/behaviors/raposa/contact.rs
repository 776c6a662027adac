//! `raposa.dock_switch`: the pyramid is in the socket. Released only when the dock switch
//! reads closed; then the guides close and the docking has succeeded, whatever phase was
//! running: under a priority node it subsumes them.

use super::memory::Memory;
use crate::arbiter::Blackboard;
use crate::schemas::{Behavior, Guides, Inputs, MotorOutput, Outcome, Step};

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
            let mut m = self.mem.lock();
            m.aux.guides = Some(Guides::Closed);
            Step::done(
                Outcome::Docked,
                MotorOutput::stop().with_aux(m.aux),
                m.feedback("docked"),
            )
        })
    }
}
