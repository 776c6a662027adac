//! Sequencing: a state machine whose states are behaviors, with latched states.
//!
//! Each tick the sequencer may first ask its [`Selector`] which state should run (the
//! reactive re-selection RAPOSA's seven states need); a *latched* state is exempt from
//! re-selection until it reports `Done` (RAPOSA's states 6 and 7 must finish their
//! manoeuvre). When the running state ends, the transition table picks the next state or
//! finishes the whole sequence with that state's outcome.

use super::decision::{Decision, Strategy};
use crate::schemas::{Behavior, Feedback, Inputs, MotorOutput, Status, Step};

/// Where to go when a state ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Next {
    /// Enter the state with this index.
    Goto(usize),
    /// End the sequence with the state's outcome.
    Finish,
}

/// Chooses the state to run from the inputs (and the current state).
pub trait Selector: Send {
    /// Returns the state to run this tick, or `None` to keep the current one.
    fn select(&mut self, inputs: &Inputs<'_>, current: usize) -> Option<usize>;
}

impl<F> Selector for F
where
    F: FnMut(&Inputs<'_>, usize) -> Option<usize> + Send,
{
    fn select(&mut self, inputs: &Inputs<'_>, current: usize) -> Option<usize> {
        self(inputs, current)
    }
}

struct State {
    behavior: Box<dyn Behavior>,
    latched: bool,
    on_success: Next,
    on_failure: Next,
}

/// A sequencer over behavior states.
pub struct Sequencer {
    name: String,
    states: Vec<State>,
    current: usize,
    selector: Option<Box<dyn Selector>>,
    transitions: u64,
    decision: Decision,
}

impl Sequencer {
    /// An empty sequencer; add states with [`Sequencer::state`].
    pub fn new(name: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            states: Vec::new(),
            current: 0,
            selector: None,
            transitions: 0,
            decision: Decision::new(Strategy::Sequencer),
        }
    }

    /// Appends a state and returns its index. By default success moves to the next state
    /// (or finishes after the last) and failure finishes the sequence.
    pub fn state(&mut self, behavior: Box<dyn Behavior>, latched: bool) -> usize {
        let i = self.states.len();
        self.states.push(State {
            behavior,
            latched,
            on_success: Next::Goto(i + 1),
            on_failure: Next::Finish,
        });
        i
    }

    /// Sets the transitions of state `i`; out-of-range indices are ignored.
    pub fn transitions(&mut self, i: usize, on_success: Next, on_failure: Next) -> &mut Self {
        if let Some(s) = self.states.get_mut(i) {
            s.on_success = on_success;
            s.on_failure = on_failure;
        }
        self
    }

    /// Installs a reactive selector.
    pub fn with_selector(mut self, selector: impl Selector + 'static) -> Self {
        self.selector = Some(Box::new(selector));
        self
    }

    /// Index of the running state.
    pub fn current(&self) -> usize {
        self.current
    }

    /// Number of state changes so far.
    pub fn transition_count(&self) -> u64 {
        self.transitions
    }

    /// The last tick's decision.
    pub fn decision(&self) -> &Decision {
        &self.decision
    }

    fn enter(&mut self, i: usize, now: f64) {
        if i != self.current {
            tracing::debug!(
                target: "marsupial::arbiter",
                arbiter = %self.name,
                from = self.states.get(self.current).map(|s| s.behavior.name()).unwrap_or("-"),
                to = self.states.get(i).map(|s| s.behavior.name()).unwrap_or("-"),
                now,
                "sequencer transition"
            );
            self.transitions += 1;
        }
        self.current = i;
        if let Some(s) = self.states.get_mut(i) {
            s.behavior.reset();
        }
    }

    fn resolve(&self, next: Next) -> Option<usize> {
        match next {
            Next::Goto(j) if j < self.states.len() => Some(j),
            _ => None,
        }
    }
}

impl Behavior for Sequencer {
    fn name(&self) -> &str {
        &self.name
    }

    fn tick(&mut self, inputs: &Inputs<'_>) -> Option<Step> {
        self.decision.clear();
        if self.states.is_empty() {
            return None;
        }
        let latched = self.states[self.current].latched;
        if !latched {
            let cur = self.current;
            if let Some(sel) = self.selector.as_mut()
                && let Some(j) = sel.select(inputs, cur)
                && j < self.states.len()
                && j != cur
            {
                self.enter(j, inputs.now);
            }
        }
        let cur = self.current;
        let step = self.states[cur].behavior.tick(inputs);
        self.decision.push(cur, step.as_ref());
        self.decision.winner = Some(cur);
        let step = match step {
            None => Step::running(MotorOutput::stop(), Feedback::new("idle", 0.0)),
            Some(s) => s,
        };
        let result = match step.status {
            Status::Running => step,
            Status::Done(outcome) => {
                let next = if outcome.is_success() {
                    self.states[cur].on_success
                } else {
                    self.states[cur].on_failure
                };
                match self.resolve(next) {
                    Some(j) => {
                        self.enter(j, inputs.now);
                        Step {
                            status: Status::Running,
                            ..step
                        }
                    }
                    // `Finish`, or a `Goto` past the last state: the sequence ends with
                    // this state's outcome.
                    None => Step {
                        status: Status::Done(outcome),
                        ..step
                    },
                }
            }
        };
        self.decision.output = Some(result.output);
        let states = &self.states;
        self.decision
            .trace(&self.name, &|i| states[i].behavior.name().to_string());
        Some(result)
    }

    fn reset(&mut self) {
        self.current = 0;
        self.transitions = 0;
        if let Some(s) = self.states.first_mut() {
            s.behavior.reset();
        }
    }
}
