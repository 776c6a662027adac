//! Behaviors: a perceptual and a motor schema paired with an activation condition, plus
//! the feedback and typed outcome every behavior reports (after Nav2's docking server).

use super::inputs::Inputs;
use super::motor_output::MotorOutput;
use super::percept::Percept;
use super::traits::{MotorSchema, PerceptualSchema};
use serde::{Deserialize, Serialize};
use std::fmt;

/// Why a behavior gave up.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FailureReason {
    /// The target was never seen (search exhausted).
    TargetNeverDetected,
    /// The target was seen, then lost for longer than allowed.
    TargetLost,
    /// The controller could not bring the robot within tolerance.
    FailedToControl,
    /// The robot is stuck or in unplanned contact (e.g. on the dock entrance edge).
    StuckContact,
    /// A phase or the whole behavior ran out of time.
    Timeout,
    /// Every allowed retry was used.
    RetriesExhausted,
}

impl FailureReason {
    /// Every reason, in a fixed order (for tables and counters).
    pub const ALL: [FailureReason; 6] = [
        FailureReason::TargetNeverDetected,
        FailureReason::TargetLost,
        FailureReason::FailedToControl,
        FailureReason::StuckContact,
        FailureReason::Timeout,
        FailureReason::RetriesExhausted,
    ];

    /// Snake-case name, as used in JSON output.
    pub fn as_str(&self) -> &'static str {
        match self {
            FailureReason::TargetNeverDetected => "target_never_detected",
            FailureReason::TargetLost => "target_lost",
            FailureReason::FailedToControl => "failed_to_control",
            FailureReason::StuckContact => "stuck_contact",
            FailureReason::Timeout => "timeout",
            FailureReason::RetriesExhausted => "retries_exhausted",
        }
    }
}

impl fmt::Display for FailureReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// How a behavior ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    /// Docked (the behavior's success criterion held).
    Docked,
    /// A non-docking behavior (undock, imprint, search) reached its goal.
    Completed,
    /// Gave up.
    Failed(FailureReason),
}

impl Outcome {
    /// True for `Docked` and `Completed`.
    pub fn is_success(&self) -> bool {
        !matches!(self, Outcome::Failed(_))
    }
}

/// Progress report of a running behavior.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Feedback {
    /// Current phase name (e.g. `"search"`, `"approach"`, `"state_7"`).
    pub phase: &'static str,
    /// Seconds since the behavior started.
    pub elapsed: f64,
    /// Retries used so far.
    pub retries: u32,
}

impl Feedback {
    /// Feedback for a phase with no retries.
    pub fn new(phase: &'static str, elapsed: f64) -> Self {
        Self {
            phase,
            elapsed,
            retries: 0,
        }
    }
}

/// Whether a behavior is still running.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Status {
    /// Keep ticking.
    Running,
    /// This state of a sequence is over and names why (`"acquired"`, `"lost"`,
    /// `"at_dock"`...): the enclosing [`Sequencer`](crate::arbiter::Sequencer) takes the
    /// transition its table declares for the event after this tick, and this tick's
    /// output is still commanded. Outside a sequencer an event reads as `Running`.
    Event(&'static str),
    /// Finished; the output of this tick is its last.
    Done(Outcome),
}

/// What an active behavior proposes for one tick.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Step {
    /// The proposed motor output.
    pub output: MotorOutput,
    /// Progress report.
    pub feedback: Feedback,
    /// Running or done.
    pub status: Status,
}

impl Step {
    /// A running step.
    pub fn running(output: MotorOutput, feedback: Feedback) -> Self {
        Self {
            output,
            feedback,
            status: Status::Running,
        }
    }

    /// A step that commands `output` this tick and ends the current sequencer state with
    /// `event` (see [`Status::Event`]).
    pub fn event(event: &'static str, output: MotorOutput, feedback: Feedback) -> Self {
        Self {
            output,
            feedback,
            status: Status::Event(event),
        }
    }

    /// A final step: stops the base (every exit path commands zero velocity) and reports
    /// the outcome. Auxiliary commands in `aux_output` are kept.
    pub fn done(outcome: Outcome, aux_output: MotorOutput, feedback: Feedback) -> Self {
        Self {
            output: MotorOutput::stop().with_aux(aux_output.aux),
            feedback,
            status: Status::Done(outcome),
        }
    }

    /// This step, ending the current sequencer state with `event` (see [`Step::event`]).
    pub fn with_event(self, event: &'static str) -> Self {
        Self {
            status: Status::Event(event),
            ..self
        }
    }

    /// This step as a final one with `outcome` (see [`Step::done`]: the base stops, the
    /// auxiliary commands and feedback are kept).
    pub fn finishing(self, outcome: Outcome) -> Self {
        Self::done(outcome, self.output, self.feedback)
    }
}

/// A behavior: ticked by the arbiter; returns `None` when its activation condition does
/// not hold this tick (it is not "released"), or a [`Step`] with its proposal.
///
/// `M` is the memory the node reads and writes: the robot's shared memory, handed down
/// the tree by `&mut` for the tick (the arbiters pass theirs to each child in turn; see
/// [`Composed`](crate::behaviors::Composed), which owns it). A node with no memory is a
/// `Behavior` (`M = ()`): that is what the reactive loop, the runtime, an
/// [`Agent`](crate::schemas::Agent) and the simulator run, ticking it with `&mut ()`. A
/// leaf that reads no memory can implement `Behavior<M>` for every `M`
/// (`impl<M: ?Sized> Behavior<M> for MyLeaf`), so it fits in any robot's tree.
///
/// Implementations must be deterministic functions of their state, the memory and the
/// inputs.
pub trait Behavior<M: ?Sized = ()>: Send {
    /// A short name for logs and decisions: sequencers find their states by it, and
    /// decision traces name children by it.
    ///
    /// A tree built by a [`Registry`](crate::behaviors::registry::Registry) names each
    /// leaf by its node (whatever the leaf would say), so a leaf written for a profile's
    /// tree need not implement this. The default is the type's own name: the last
    /// segment of its path in [`std::any::type_name`] (`Align`; a generic type keeps its
    /// arguments as `type_name` writes them). A behavior used
    /// outside a registry-built tree (put straight into a
    /// [`Sequencer`](crate::arbiter::Sequencer) or [`Priority`](crate::arbiter::Priority)
    /// by hand, as the examples and tests may) should override it when something finds
    /// it by name or reads a trace of it.
    fn name(&self) -> &str {
        short_type_name(std::any::type_name::<Self>())
    }
    /// Runs one tick with the tree's memory.
    fn tick(&mut self, mem: &mut M, inputs: &Inputs<'_>) -> Option<Step>;
    /// Returns to the initial state.
    fn reset(&mut self) {}
    /// Called when a sequencer enters this behavior as its state, with the tree's memory
    /// and the inputs of the tick the transition happened in (so a state can note where
    /// and when it began: its odometry mark, its start time). The default resets.
    fn enter(&mut self, mem: &mut M, inputs: &Inputs<'_>) {
        let _ = (mem, inputs);
        self.reset();
    }
    /// Starts this behavior at the state named `state` (of a sequencer in it), entered at
    /// the next tick; returns false when no state has that name. This is how a mission
    /// (departure, docking) is started in a composed tree. The default has no states.
    fn start(&mut self, state: &str) -> bool {
        let _ = state;
        false
    }
    /// Appends this tick's decisions of the arbiters in this behavior (see
    /// [`crate::arbiter::trace`]); a leaf has none.
    fn explain(&self, out: &mut Vec<crate::arbiter::NodeTrace>) {
        let _ = out;
    }
}

impl<M: ?Sized, B: Behavior<M> + ?Sized> Behavior<M> for Box<B> {
    fn name(&self) -> &str {
        (**self).name()
    }
    fn tick(&mut self, mem: &mut M, inputs: &Inputs<'_>) -> Option<Step> {
        (**self).tick(mem, inputs)
    }
    fn reset(&mut self) {
        (**self).reset()
    }
    fn enter(&mut self, mem: &mut M, inputs: &Inputs<'_>) {
        (**self).enter(mem, inputs)
    }
    fn start(&mut self, state: &str) -> bool {
        (**self).start(state)
    }
    fn explain(&self, out: &mut Vec<crate::arbiter::NodeTrace>) {
        (**self).explain(out)
    }
}

/// The last segment of a type's own path (`a::b::Search<a::c::Memory>` is
/// `Search<a::c::Memory>`): the default [`Behavior::name`].
fn short_type_name(full: &'static str) -> &'static str {
    // A generic type keeps its arguments' full paths; its own path ends before the `<`.
    let head = full.find('<').unwrap_or(full.len());
    let start = full[..head].rfind("::").map_or(0, |i| i + 2);
    &full[start..]
}

/// The basic schema-theoretic behavior: perceive, test the releaser on the percept, act.
///
/// It never ends by itself (status is always `Running`); wrap it in a sequencer or write a
/// dedicated behavior when an outcome is needed. It reads no tree memory, so it is a
/// `Behavior<M>` for every `M`.
pub struct SchemaBehavior<P, M, C> {
    name: String,
    perceptual: P,
    motor: M,
    releaser: C,
    started: Option<f64>,
}

impl<P, M, C> SchemaBehavior<P, M, C>
where
    P: PerceptualSchema,
    M: MotorSchema<Percept = P::Percept>,
    C: Fn(&P::Percept) -> bool + Send,
{
    /// Pairs `perceptual` and `motor`; the behavior is active when `releaser(percept)`.
    pub fn new(name: impl Into<String>, perceptual: P, motor: M, releaser: C) -> Self {
        Self {
            name: name.into(),
            perceptual,
            motor,
            releaser,
            started: None,
        }
    }

    /// The perceptual schema (to inspect or retune it).
    pub fn perceptual_mut(&mut self) -> &mut P {
        &mut self.perceptual
    }
}

impl<P, M, C, Mem: ?Sized> Behavior<Mem> for SchemaBehavior<P, M, C>
where
    P: PerceptualSchema,
    M: MotorSchema<Percept = P::Percept>,
    C: Fn(&P::Percept) -> bool + Send,
{
    fn name(&self) -> &str {
        &self.name
    }

    fn tick(&mut self, _mem: &mut Mem, inputs: &Inputs<'_>) -> Option<Step> {
        let percept = self.perceptual.perceive(inputs);
        if !(self.releaser)(&percept) {
            return None;
        }
        let started = *self.started.get_or_insert(inputs.now);
        let output = self.motor.act(&percept);
        Some(Step::running(output, Feedback::new("active", inputs.now - started)))
    }

    fn reset(&mut self) {
        self.started = None;
        self.perceptual.reset();
    }
}

/// A percept that is just "found or not" at a time: handy for releasers and tests.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Presence {
    /// Capture time.
    pub stamp: f64,
    /// Found flag.
    pub found: bool,
}

impl Percept for Presence {
    fn stamp(&self) -> f64 {
        self.stamp
    }
    fn found(&self) -> bool {
        self.found
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Plain;
    impl Behavior for Plain {
        fn tick(&mut self, _mem: &mut (), _inputs: &Inputs<'_>) -> Option<Step> {
            None
        }
    }

    struct Generic<T>(T);
    impl<T: Send> Behavior for Generic<T> {
        fn tick(&mut self, _mem: &mut (), _inputs: &Inputs<'_>) -> Option<Step> {
            None
        }
    }

    #[test]
    fn the_default_name_is_the_types_own() {
        assert_eq!(Plain.name(), "Plain");
        assert_eq!(Box::new(Plain).name(), "Plain", "a box says what it holds");
        assert_eq!(
            Generic(Presence {
                stamp: 0.0,
                found: false
            })
            .name(),
            "Generic<marsupial::schemas::behavior::Presence>"
        );
        assert_eq!(short_type_name("a::b::C<d::E<f::G>>"), "C<d::E<f::G>>");
        assert_eq!(short_type_name("C"), "C");
    }
}
