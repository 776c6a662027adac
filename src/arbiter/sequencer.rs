//! Sequencing: a state machine whose states are behaviors, with typed transitions,
//! per-state timeouts and latched states.
//!
//! Each tick the sequencer may first ask its [`Selector`] which state should run (the
//! reactive re-selection RAPOSA's seven states need); a *latched* state is exempt from
//! re-selection until it ends (RAPOSA's states 6 and 7 must finish their manoeuvre).
//!
//! A state ends in one of two ways, and the transition table says where each leads:
//! * with a named **event** ([`Status::Event`]: `"acquired"`, `"lost"`, `"at_dock"`...):
//!   this tick's output is still commanded and the next state is entered for the next
//!   tick. An event the table leads to [`Next::Finish`] ends the sequence and is reported
//!   upward as the sequence's own event, so a nested sequence (RAPOSA's region-II
//!   manoeuvre) can hand control back to its parent by name; an event with no entry in
//!   the table ends the sequence as failed to control;
//! * with an **outcome** ([`Status::Done`]): `on_success` / `on_failure` decide, or an
//!   event entry named `"docked"`, `"completed"` or `"failed"` when one is declared.
//!
//! A state may have a **timeout**: once it has run longer, the sequencer ends it with the
//! event `"timeout"` before ticking it (stopping the base that tick); with no entry for
//! `"timeout"` the sequence ends with [`FailureReason::Timeout`].
//!
//! Entering a state calls its [`Behavior::enter`] with the tree's memory and the inputs of
//! the tick the transition happened in, so it can note where and when it began. A
//! sequencer that has
//! finished is inactive (`None`) until it is started again ([`Behavior::start`],
//! [`Behavior::enter`] or [`Behavior::reset`]).

use super::decision::{Decision, Strategy};
use crate::schemas::{Behavior, FailureReason, Feedback, Inputs, MotorOutput, Outcome, Status, Step};

/// The transition target that ends a sequence (see [`Next::Finish`]), as profiles and
/// traces name it.
pub const FINISH: &str = "finish";

/// The `to` of a recorded transition that left the sequence.
const LEAVE: usize = usize::MAX;

/// Where to go when a state ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Next {
    /// Enter the state with this index.
    Goto(usize),
    /// End the sequence: with the state's outcome, or passing its event up.
    Finish,
}

/// Chooses the state to run from the tree's memory `M`, the inputs and the current state.
pub trait Selector<M: ?Sized = ()>: Send {
    /// Returns the state to run this tick, or `None` to keep the current one.
    fn select(&mut self, mem: &mut M, inputs: &Inputs<'_>, current: usize) -> Option<usize>;

    /// The state the sequence starts in when it is entered (as a state of an enclosing
    /// sequencer, or by [`Behavior::enter`]); `None`, the default: its first. A
    /// manoeuvre whose first leg depends on the plan (Bujold's repositioning drives out
    /// of the gate first only when it must) picks it here, in the tick it is entered.
    fn entry(&mut self, _mem: &mut M, _inputs: &Inputs<'_>) -> Option<usize> {
        None
    }
}

impl<M: ?Sized, F> Selector<M> for F
where
    F: FnMut(&mut M, &Inputs<'_>, usize) -> Option<usize> + Send,
{
    fn select(&mut self, mem: &mut M, inputs: &Inputs<'_>, current: usize) -> Option<usize> {
        self(mem, inputs, current)
    }
}

struct State<M: ?Sized> {
    behavior: Box<dyn Behavior<M>>,
    latched: bool,
    on_success: Next,
    on_failure: Next,
    /// Named events and where they lead (a handful per state: a linear scan is fastest).
    on_event: Vec<(String, Next)>,
    /// Longest time in the state, s.
    timeout: Option<f64>,
}

impl<M: ?Sized> State<M> {
    fn event(&self, name: &str) -> Option<Next> {
        self.on_event.iter().find(|(e, _)| e == name).map(|(_, n)| *n)
    }
}

/// A sequencer over behavior states; `M` is the tree's memory, passed to the state it runs
/// (and to its selector).
pub struct Sequencer<M: ?Sized = ()> {
    name: String,
    states: Vec<State<M>>,
    current: usize,
    /// The current state is entered at the next tick (after a start or a reset).
    pending_entry: bool,
    /// When the current state was entered, loop time.
    entered_at: f64,
    /// The current state was started by its own [`Behavior::start`]: only the clock of
    /// its timeout starts at the next tick.
    pending_clock: bool,
    /// The sequence has ended; inactive until started again.
    finished: bool,
    selector: Option<Box<dyn Selector<M>>>,
    transitions: u64,
    /// Why the last transition fired (`"acquired"`, `"timeout"`, `"selected"`...).
    last_event: Option<&'static str>,
    /// This tick's transitions (from, to, why), for traces.
    tick_transitions: smallvec::SmallVec<[(usize, usize, &'static str); 4]>,
    /// The state that ran this tick.
    ran: Option<usize>,
    decision: Decision,
}

impl<M: ?Sized> Sequencer<M> {
    /// An empty sequencer; add states with [`Sequencer::state`]. It starts at state 0.
    pub fn new(name: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            states: Vec::new(),
            current: 0,
            pending_entry: true,
            entered_at: 0.0,
            pending_clock: false,
            finished: false,
            selector: None,
            transitions: 0,
            last_event: None,
            tick_transitions: smallvec::SmallVec::new(),
            ran: None,
            decision: Decision::new(Strategy::Sequencer),
        }
    }

    /// Appends a state and returns its index. By default success moves to the next state
    /// (or finishes after the last) and failure finishes the sequence.
    pub fn state(&mut self, behavior: Box<dyn Behavior<M>>, latched: bool) -> usize {
        let i = self.states.len();
        self.states.push(State {
            behavior,
            latched,
            on_success: Next::Goto(i + 1),
            on_failure: Next::Finish,
            on_event: Vec::new(),
            timeout: None,
        });
        i
    }

    /// Sets the outcome transitions of state `i`; out-of-range indices are ignored.
    pub fn transitions(&mut self, i: usize, on_success: Next, on_failure: Next) -> &mut Self {
        if let Some(s) = self.states.get_mut(i) {
            s.on_success = on_success;
            s.on_failure = on_failure;
        }
        self
    }

    /// Declares where the event `event` of state `i` leads (replacing an earlier entry);
    /// out-of-range indices are ignored.
    pub fn on_event(&mut self, i: usize, event: impl Into<String>, next: Next) -> &mut Self {
        if let Some(s) = self.states.get_mut(i) {
            let event = event.into();
            s.on_event.retain(|(e, _)| *e != event);
            s.on_event.push((event, next));
        }
        self
    }

    /// Limits the time state `i` may run (s); see the module docs. Out-of-range indices
    /// are ignored.
    pub fn timeout(&mut self, i: usize, seconds: f64) -> &mut Self {
        if let Some(s) = self.states.get_mut(i) {
            s.timeout = Some(seconds);
        }
        self
    }

    /// Installs a reactive selector.
    pub fn with_selector(mut self, selector: impl Selector<M> + 'static) -> Self {
        self.selector = Some(Box::new(selector));
        self
    }

    /// Installs (or replaces) a reactive selector built elsewhere (by a registry).
    pub fn set_selector(&mut self, selector: Box<dyn Selector<M>>) {
        self.selector = Some(selector);
    }

    /// Index of the running state.
    pub fn current(&self) -> usize {
        self.current
    }

    /// Name of the running state.
    pub fn current_name(&self) -> &str {
        self.states.get(self.current).map_or("", |s| s.behavior.name())
    }

    /// Index of the state named `name`.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.states.iter().position(|s| s.behavior.name() == name)
    }

    /// True once the sequence has ended (until it is started again).
    pub fn is_finished(&self) -> bool {
        self.finished
    }

    /// Number of state changes so far.
    pub fn transition_count(&self) -> u64 {
        self.transitions
    }

    /// Why the last transition fired: the event's name, `"selected"` for a selector's
    /// switch, `"started"` for [`Behavior::start`].
    pub fn last_event(&self) -> Option<&'static str> {
        self.last_event
    }

    /// The last tick's decision.
    pub fn decision(&self) -> &Decision {
        &self.decision
    }

    /// Makes state `i` current and enters it at the next tick.
    pub fn start_at(&mut self, i: usize) {
        if i < self.states.len() {
            self.current = i;
            self.pending_entry = true;
            self.finished = false;
            self.last_event = Some("started");
        }
    }

    fn enter(&mut self, i: usize, mem: &mut M, inputs: &Inputs<'_>, why: &'static str) {
        if i != self.current {
            tracing::debug!(
                target: "marsupial::arbiter",
                arbiter = %self.name,
                from = self.states.get(self.current).map(|s| s.behavior.name()).unwrap_or("-"),
                to = self.states.get(i).map(|s| s.behavior.name()).unwrap_or("-"),
                event = why,
                now = inputs.now,
                "sequencer transition"
            );
            self.transitions += 1;
        }
        self.tick_transitions.push((self.current, i, why));
        self.current = i;
        self.last_event = Some(why);
        self.entered_at = inputs.now;
        self.pending_entry = false;
        if let Some(s) = self.states.get_mut(i) {
            s.behavior.enter(mem, inputs);
        }
    }

    fn resolve(&self, next: Next) -> Option<usize> {
        match next {
            Next::Goto(j) if j < self.states.len() => Some(j),
            _ => None,
        }
    }

    /// Where state `cur` goes when it ends with `status` (not `Running`); `None` for an
    /// event its table does not declare.
    fn next_for(&self, cur: usize, status: Status) -> Option<Next> {
        let s = &self.states[cur];
        match status {
            Status::Event(e) => s.event(e),
            Status::Done(outcome) => {
                let named = match outcome {
                    Outcome::Docked => "docked",
                    Outcome::Completed => "completed",
                    Outcome::Failed(_) => "failed",
                };
                Some(s.event(named).unwrap_or(if outcome.is_success() {
                    s.on_success
                } else {
                    s.on_failure
                }))
            }
            Status::Running => Some(Next::Goto(cur)),
        }
    }

    /// Ends state `cur` with `status`, returning the sequence's step for this tick.
    fn finish_state(&mut self, cur: usize, step: Step, mem: &mut M, inputs: &Inputs<'_>) -> Step {
        let next = self.next_for(cur, step.status);
        match next.and_then(|n| self.resolve(n)) {
            Some(j) => {
                let why = match step.status {
                    Status::Event(e) => e,
                    Status::Done(Outcome::Docked) => "docked",
                    Status::Done(Outcome::Completed) => "completed",
                    _ => "failed",
                };
                self.enter(j, mem, inputs, why);
                Step {
                    status: Status::Running,
                    ..step
                }
            }
            // The sequence ends: with the state's outcome; with its event, for the
            // enclosing sequencer to route, when the table says `Finish` for it; as
            // failing to control for an event the table does not declare.
            None => {
                self.finished = true;
                let status = match (step.status, next) {
                    (Status::Done(o), _) => Status::Done(o),
                    (Status::Event(e), Some(_)) => Status::Event(e),
                    _ => Status::Done(Outcome::Failed(FailureReason::FailedToControl)),
                };
                if let Status::Event(e) = status {
                    self.tick_transitions.push((cur, LEAVE, e));
                }
                Step { status, ..step }
            }
        }
    }
}

impl<M: ?Sized> Behavior<M> for Sequencer<M> {
    fn name(&self) -> &str {
        &self.name
    }

    fn tick(&mut self, mem: &mut M, inputs: &Inputs<'_>) -> Option<Step> {
        self.decision.clear();
        self.tick_transitions.clear();
        self.ran = None;
        if self.states.is_empty() || self.finished {
            return None;
        }
        if self.pending_entry {
            let cur = self.current;
            self.enter(cur, mem, inputs, self.last_event.unwrap_or("started"));
        } else if self.pending_clock {
            self.entered_at = inputs.now;
        }
        self.pending_clock = false;
        if !self.states[self.current].latched {
            let cur = self.current;
            if let Some(sel) = self.selector.as_mut()
                && let Some(j) = sel.select(mem, inputs, cur)
                && j < self.states.len()
                && j != cur
            {
                self.enter(j, mem, inputs, "selected");
            }
        }
        let cur = self.current;
        if let Some(limit) = self.states[cur].timeout
            && inputs.now - self.entered_at > limit
        {
            // The state overran: stop the base this tick and take its "timeout" exit.
            let feedback = Feedback::new("timeout", inputs.now - self.entered_at);
            let step = match self.states[cur].event("timeout") {
                Some(_) => Step::event("timeout", MotorOutput::stop(), feedback),
                None => Step::done(Outcome::Failed(FailureReason::Timeout), MotorOutput::stop(), feedback),
            };
            self.decision.push(cur, None);
            self.decision.winner = Some(cur);
            let result = self.finish_state(cur, step, mem, inputs);
            self.decision.output = Some(result.output);
            return Some(result);
        }
        let step = self.states[cur].behavior.tick(mem, inputs);
        self.ran = Some(cur);
        self.decision.push(cur, step.as_ref());
        self.decision.winner = Some(cur);
        let step = match step {
            None => Step::running(MotorOutput::stop(), Feedback::new("idle", 0.0)),
            Some(s) => s,
        };
        let result = match step.status {
            Status::Running => step,
            _ => self.finish_state(cur, step, mem, inputs),
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
        self.finished = false;
        self.pending_entry = true;
        self.last_event = None;
        if let Some(s) = self.states.first_mut() {
            s.behavior.reset();
        }
    }

    fn enter(&mut self, mem: &mut M, inputs: &Inputs<'_>) {
        self.reset();
        let first = self
            .selector
            .as_mut()
            .and_then(|s| s.entry(mem, inputs))
            .filter(|&i| i < self.states.len())
            .unwrap_or(0);
        self.enter(first, mem, inputs, "started");
    }

    fn explain(&self, out: &mut Vec<super::NodeTrace>) {
        let name = |i: usize| self.states.get(i).map_or("-", |s| s.behavior.name());
        let mut t = super::trace::node_trace(&self.name, &self.decision, &name);
        t.transitions = self
            .tick_transitions
            .iter()
            .map(|&(from, to, event)| super::Transition {
                from: name(from).to_string(),
                to: if to == LEAVE {
                    FINISH.to_string()
                } else {
                    name(to).to_string()
                },
                event: event.to_string(),
            })
            .collect();
        out.push(t);
        if let Some(r) = self.ran {
            self.states[r].behavior.explain(out);
        }
    }

    fn start(&mut self, state: &str) -> bool {
        if let Some(i) = self.index_of(state) {
            self.start_at(i);
            return true;
        }
        // A nested sequence that has the state: make it current here too, entered by
        // the child's own start (not reset by our entry).
        for i in 0..self.states.len() {
            if self.states[i].behavior.start(state) {
                self.current = i;
                self.pending_entry = false;
                self.pending_clock = true;
                self.finished = false;
                self.last_event = Some("started");
                return true;
            }
        }
        false
    }
}
