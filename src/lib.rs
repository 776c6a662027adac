//! # marsupial
//!
//! Reactive, behavior-based robots that dock by vision.
//!
//! * [`perception`]: pure image functions over borrowed views and reusable buffers.
//! * [`schemas`]: perceptual schemas (sensor data → [`schemas::Percept`],
//!   [`schemas::PerceptualSchema`]), motor schemas (percept → [`schemas::MotorOutput`],
//!   [`schemas::MotorSchema`], which every shipped one implements) and
//!   [`schemas::Behavior`]s pairing them; the one device model ([`schemas::devices`]):
//!   the tether, dock switch, arm, lights, guides and posture are device kinds like a
//!   user's, with typed readings and commands.
//! * [`arbiter`]: coordination ([`arbiter::Priority`], [`arbiter::VectorSum`],
//!   [`arbiter::Sequencer`]) and the [`arbiter::ReactiveLoop`], whose tick is a pure
//!   function of its state and timestamped inputs; [`arbiter::runtime`] runs it on
//!   threads against a [`robot::Robot`]. Arbiters and leaves are generic over the memory
//!   `M` a robot's nodes share ([`schemas::Behavior<M>`]): a [`behaviors::Composed`] owns
//!   it and hands it down the tree by `&mut` each tick, with no lock.
//! * [`kinematics`]: differential, skid-steer (effective track), turn-or-drive and
//!   double-Ackermann models, command realisation and odometry.
//! * [`profile`]: one TOML file per platform, validated with precise errors.
//!
//! Above the core, by feature (each layer builds without the ones beside it):
//!
//! * `msgs` (feature `image-io`, so `ros2`, `sim` or `cli`): ROS 2 messages in CDR and
//!   camera pixels (YUV, Bayer, JPEG …) to frames, for the bridge, replay and `detect`;
//! * `ros2` (feature `ros2`): the behaviors as a ROS 2 node over Zenoh, no simulator;
//! * `sim` (feature `sim`): the simulator, scenarios and campaigns writing run records;
//!   `replay`: a profile's perception or behavior on real logs (ROS 2 bags and Foxglove
//!   files in MCAP), for `marsupial replay`; `report`: a campaign's tables and plots;
//! * `cli` (feature `cli`): the `marsupial` tool's commands; the campaign ones with `sim`.
//!
//! ## How the parts fit
//!
//! ```
//! use marsupial::arbiter::{Priority, ReactiveLoop};
//! use marsupial::profile::Profile;
//! use marsupial::schemas::{Behavior, Feedback, Inputs, MotorOutput, Step};
//!
//! /// A behavior that always drives forward slowly. It reads no tree memory, so it is a
//! /// `Behavior<M>` for every memory `M`: the loop's root is a `Behavior` (memory `()`).
//! struct Creep;
//! impl<M: ?Sized> Behavior<M> for Creep {
//!     fn name(&self) -> &str { "creep" }
//!     fn tick(&mut self, _mem: &mut M, inputs: &Inputs<'_>) -> Option<Step> {
//!         Some(Step::running(MotorOutput::twist(0.05, 0.0), Feedback::new("creep", inputs.now)))
//!     }
//! }
//!
//! let profile = Profile::load("profiles/axel.toml".as_ref()).unwrap();
//! let mut config = profile.loop_config();
//! config.staleness = Default::default(); // no sensors in this doc example
//! let root = Priority::new("root", vec![Box::new(Creep)]);
//! let mut lp = ReactiveLoop::new(Box::new(root), config);
//! let out = lp.tick(&Inputs::empty(0.0));
//! assert!(out.command.drive.to_twist().v > 0.0);
//! ```
#![deny(missing_docs)]

pub mod arbiter;
pub mod behaviors;
#[cfg(feature = "cli")]
pub mod cli;
pub mod config;
pub mod geometry;
#[cfg(feature = "image-io")]
pub mod image_io;
pub mod kinematics;
#[cfg(feature = "image-io")]
pub mod msgs;
mod panics;
pub mod perception;
pub mod profile;
#[cfg(feature = "sim")]
pub mod replay;
#[cfg(feature = "sim")]
pub mod report;
pub mod robot;
#[cfg(feature = "ros2")]
pub mod ros2;
pub mod schemas;
#[cfg(feature = "sim")]
pub mod sim;
