//! The papers' behaviors, as compositions of schemas, and the agents that run them.
//!
//! An [`Agent`] is everything one robot runs for a docking experiment: optionally a
//! departure phase (undock, imprint the fiducial on the way out) and the docking phase.
//! It is itself a [`Behavior`](crate::schemas::Behavior) whose tick dispatches on the current phase, so the reactive
//! loop, the threaded runtime and the simulator all drive it the same way.

pub mod agent;
pub mod bujold;
pub mod common;
pub mod composed;
pub mod raposa;
pub mod registry;

pub use agent::{BuildError, agent_for};
pub use composed::{Composed, SharedMemory};
