//! The AutoKrawler's motion leaves: `krawler.traverse` drives at a set speed and turn
//! rate and writes the wheel rotation rate it commands into the memory (what the slip
//! monitor compares the camera's rotation with); `krawler.halt` stops and ends the
//! mission as stuck (after a slip the wheels do not move the rover as told).

use super::KrawlerMemory;
use crate::geometry::Twist;
use crate::schemas::{Behavior, DriveCommand, FailureReason, Feedback, Inputs, MotorOutput, Outcome, Step};
use serde::Deserialize;

/// `krawler.traverse`'s `params`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TraverseParams {
    /// Forward speed, m/s (negative reverses).
    pub speed_mps: f64,
    /// Turn rate, degrees/s (default 0: straight).
    #[serde(default)]
    pub turn_rate_dps: f64,
    /// Completes the mission after this long, s (default: drives until stopped).
    #[serde(default)]
    pub duration_s: Option<f64>,
}

/// `krawler.traverse` (see the module docs).
pub struct Traverse {
    params: TraverseParams,
    started: Option<f64>,
}

impl Traverse {
    /// The leaf with `params`.
    ///
    /// # Errors
    /// Names the field of a speed, rate or duration that is not a finite number (or a
    /// duration that is not positive).
    pub fn new(params: TraverseParams) -> Result<Self, String> {
        if !params.speed_mps.is_finite() {
            return Err(format!(
                "params.speed_mps: expected a number of m/s, got {}",
                params.speed_mps
            ));
        }
        if !params.turn_rate_dps.is_finite() {
            return Err(format!(
                "params.turn_rate_dps: expected a number of degrees/s, got {}",
                params.turn_rate_dps
            ));
        }
        if let Some(d) = params.duration_s
            && !(d.is_finite() && d > 0.0)
        {
            return Err(format!("params.duration_s: expected a positive number of s, got {d}"));
        }
        Ok(Self { params, started: None })
    }
}

impl Behavior<KrawlerMemory> for Traverse {
    fn reset(&mut self) {
        self.started = None;
    }

    fn tick(&mut self, m: &mut KrawlerMemory, inputs: &Inputs<'_>) -> Option<Step> {
        let started = *self.started.get_or_insert(inputs.now);
        let elapsed = inputs.now - started;
        let feedback = Feedback::new("traverse", elapsed);
        if self.params.duration_s.is_some_and(|d| elapsed >= d) {
            m.commanded_rate = 0.0;
            return Some(Step::done(Outcome::Completed, MotorOutput::stop(), feedback));
        }
        let p = &self.params;
        m.commanded_rate = p.speed_mps / m.wheel_radius;
        let drive = if p.turn_rate_dps == 0.0 {
            DriveCommand::Straight { v: p.speed_mps }
        } else {
            DriveCommand::Twist(Twist::new(p.speed_mps, p.turn_rate_dps.to_radians()))
        };
        Some(Step::running(MotorOutput::drive(drive), feedback))
    }
}

/// `krawler.halt` (see the module docs).
#[derive(Debug, Clone, Copy, Default)]
pub struct Halt;

impl Behavior<KrawlerMemory> for Halt {
    fn tick(&mut self, m: &mut KrawlerMemory, inputs: &Inputs<'_>) -> Option<Step> {
        m.commanded_rate = 0.0;
        Some(Step::done(
            Outcome::Failed(FailureReason::StuckContact),
            MotorOutput::stop(),
            Feedback::new("halt", inputs.now),
        ))
    }
}
