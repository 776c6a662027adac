//! The papers' behaviors, as compositions of schemas, and the agents that run them.
//!
//! An [`Agent`](crate::schemas::Agent) is everything one robot runs for a docking
//! experiment: optionally a departure mission (undock, imprint the fiducial on the way
//! out) and the docking mission. Every robot's agent is a [`Composed`]: its shared memory
//! (the perceptual schemas, run once per tick) and the tree its profile's
//! `[behavior.tree]` declares, built by a [`registry::Registry`] of named schemas from
//! `common` (any robot), `bujold`, `raposa`, `axel` and `krawler`. It is itself a
//! [`Behavior`](crate::schemas::Behavior), so the reactive loop, the threaded runtime and
//! the simulator all drive it the same way. `examples/compose.rs` composes a user's robot
//! from its own schemas and the crate's.
//!
//! Which robot a profile builds is its `[robot] kind`, looked up in a [`Catalog`]: each
//! [`RobotKind`] brings its typed tuning, its memory and its leaves ([`bujold::Bujold`],
//! [`raposa::Raposa`], [`axel::Axel`], [`krawler::Krawler`] are the shipped ones), and a
//! user's crate registers its own beside them (`examples/plugin_robot.rs`).

pub mod agent;
pub mod axel;
pub mod bujold;
pub mod catalog;
pub mod common;
pub mod composed;
pub mod krawler;
pub mod leaf_args;
pub mod raposa;
pub mod registry;

pub use agent::{BuildError, agent_for};
pub use catalog::{Catalog, RobotKind};
pub use composed::{Composed, SharedMemory};
