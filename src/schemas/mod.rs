//! Schema theory: percepts, perceptual and motor schemas, motor outputs, behaviors.
//!
//! A [`PerceptualSchema`] turns [`Inputs`] into a typed [`Percept`]; a [`MotorSchema`]
//! turns the percept into a [`MotorOutput`]; a [`Behavior`] pairs them with an activation
//! condition and reports [`Feedback`] and a typed [`Outcome`]. Motion vectors compose by
//! Arkin's gain-weighted sum ([`MotionVector::weighted_sum`]).
//!
//! The perceptual schemas of the shipped robots ([`TwoBlockSchema`], [`PyramidSchema`],
//! the AutoKrawler's [`KrawlerSchema`]) run perception's trackers on one camera of the
//! inputs; perception itself knows nothing of schemas. Their motor schemas ([`RatioSteering`], [`PotentialField`],
//! [`ServoLaw`], [`PointController`], [`SearchRotation`], [`DeadReckoning`],
//! [`AvoidObstacles`]) implement [`MotorSchema`] over typed percepts
//! ([`motor_schemas`]); the robots' leaves pair them with their percepts and memory, as
//! a [`SchemaBehavior`] pairs a perceptual and a motor schema with a releaser.

pub mod avoid;
pub mod behavior;
pub mod devices;
pub mod goto_point;
pub mod inputs;
pub mod krawler;
pub mod mission;
pub mod motor_output;
pub mod motor_schemas;
pub mod observation;
pub mod percept;
pub mod potential_field;
pub mod pyramid;
pub mod ratio_steering;
pub mod search;
pub mod traits;
pub mod two_block;
pub mod vector;
pub mod visual_servo;

pub use avoid::AvoidObstacles;
pub use behavior::{Behavior, FailureReason, Feedback, Outcome, Presence, SchemaBehavior, Status, Step};
pub use devices::{
    ARM_KIND, ArmPosition, BUILTIN_ACTUATOR_KINDS, BUILTIN_SENSOR_KINDS, COMMAND_VALUES, Command, DOCK_CONTACT_KIND,
    DeviceCommand, DeviceKinds, DeviceReading, DockContact, GUIDES_KIND, INLINE_DEVICES, LIGHTS_KIND, Lights,
    POSTURE_KIND, TETHER_KIND,
};
pub use goto_point::PointController;
pub use inputs::{
    CameraInput, CameraInputs, INLINE_CAMERAS, Inputs, OdometryReading, SensorInput, SensorInputs, TetherReading,
};
pub use krawler::{KrawlerObservation, KrawlerPercept, KrawlerSchema};
pub use mission::{Agent, AgentStats, Mission, MissionError};
pub use motor_output::{Auxiliary, DriveCommand, Guides, MotorOutput, Posture, TetherCommand};
pub use motor_schemas::{DockPose, Elapsed, GuideView, PointGoal, Travelled};
pub use observation::{ColourRanges, Observation, ObservedPercept};
pub use percept::{Percept, Stamped};
pub use potential_field::PotentialField;
pub use pyramid::PyramidSchema;
pub use ratio_steering::RatioSteering;
pub use search::{DeadReckoning, SearchRotation};
pub use traits::{MotorSchema, PerceptualSchema};
pub use two_block::TwoBlockSchema;
pub use vector::MotionVector;
pub use visual_servo::ServoLaw;
