//! Coordination and the reactive loop.
//!
//! Three strategies, each itself a [`Behavior`](crate::schemas::Behavior) so they nest:
//! [`Priority`] (subsumption), [`VectorSum`] (Arkin's gain-weighted sum) and
//! [`Sequencer`] (a state machine with latched states). Each records its per-tick
//! [`Decision`] and emits it through `tracing` (target `marsupial::arbiter`).
//! [`ReactiveLoop`] is the pure tick; [`runtime::run`] is the threaded wrapper.

pub mod decision;
pub mod lockstep;
pub mod priority;
pub mod reactive_loop;
mod repeats;
pub mod runtime;
pub mod sequencer;
pub mod trace;
pub mod vector_sum;

pub use decision::{Candidate, Decision, Strategy};
pub use lockstep::Lockstep;
pub use priority::Priority;
pub use reactive_loop::{
    InputKind, LoopConfig, LoopCore, LoopStatus, ReactiveLoop, Staleness, StopReason, TickOutput, safe_stop_command,
};
pub use sequencer::{Next, Selector, Sequencer};
pub use trace::{NodeTrace, Transition};
pub use vector_sum::VectorSum;
