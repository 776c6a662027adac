//! The two schema traits of Arkin's schema theory.

use super::inputs::Inputs;
use super::motor_output::MotorOutput;
use super::percept::Percept;

/// Turns sensor data into a typed percept. May keep adaptive state (colour statistics,
/// tracking windows), hence `&mut self`; must not read clocks or random sources: time
/// comes in with [`Inputs::now`].
pub trait PerceptualSchema: Send {
    /// The percept type produced.
    type Percept: Percept;
    /// Computes this tick's percept.
    fn perceive(&mut self, inputs: &Inputs<'_>) -> Self::Percept;
    /// Forgets adaptive state (called when the owning behavior restarts).
    fn reset(&mut self) {}
}

/// Turns a percept into a motor output. Pure: same percept, same output.
///
/// Every motor schema the crate ships implements it, each over its own typed percept
/// ([`RatioSteering`](super::RatioSteering) over a fiducial view,
/// [`PotentialField`](super::PotentialField) over a [`DockPose`](super::DockPose), the
/// search sweep over [`Elapsed`](super::Elapsed) time, obstacle avoidance over range
/// returns...; see [`super::motor_schemas`]), so one signature drives them all.
pub trait MotorSchema: Send {
    /// The percept type consumed (unsized for a slice of returns).
    type Percept: ?Sized;
    /// Computes the proposed output.
    fn act(&self, percept: &Self::Percept) -> MotorOutput;
}
