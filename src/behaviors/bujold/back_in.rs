//! `bujold.back_in`: the final zone (seed 004 §V: "lower and back in by dead
//! reckoning"). Lowered, blind, by odometry: the entrance is about the decided camera
//! distance less the camera-to-rear arm away, then the pouch, then `margin_m` before the
//! miss is declared (event `missed`). Blind, it still watches odometry's yaw: a straight
//! back-in that turns by more than `max_yaw_drift_deg` (a track slipping or stalled) would
//! reach the entrance askew and catch its edge, so it stops with the event `veered`
//! (Bujold's profile retries from there: move away, approach again). The dock switch, not
//! this schema, ends it docked.

use super::memory::{Memory, lowered};
use super::params::BackInParams;
use crate::geometry::{Pose2, wrap_angle};
use crate::schemas::{Behavior, DeadReckoning, FailureReason, Inputs, MotorOutput, Step};

/// See the module docs.
pub struct BackIn {
    params: BackInParams,
    depth: f64,
    mark: Pose2,
}

impl BackIn {
    /// The leaf; `depth` is the pouch's depth, m.
    pub fn new(params: BackInParams, depth: f64) -> Self {
        Self {
            params,
            depth,
            mark: Pose2::default(),
        }
    }
}

impl Behavior<Memory> for BackIn {
    fn enter(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) {
        self.mark = m.odo;
    }

    fn tick(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) -> Option<Step> {
        let p = self.params;
        if wrap_angle(m.odo.theta - self.mark.theta).abs() > p.max_yaw_drift_deg.to_radians() {
            m.failing = Some(FailureReason::FailedToControl);
            return Some(Step::event("veered", MotorOutput::stop(), m.feedback("back_in")));
        }
        let est = m.samples_distance.max(p.min_distance_m);
        let dr = DeadReckoning {
            speed: m.geometry.drive_dir * p.speed_mps,
            distance: (est - m.rear_behind_camera).max(0.0) + self.depth + p.margin_m,
        };
        Some(match dr.command(m.travelled(&self.mark)) {
            Some(cmd) => Step::running(
                MotorOutput {
                    drive: cmd,
                    aux: lowered(),
                },
                m.feedback("back_in"),
            ),
            None => {
                m.failing = Some(FailureReason::FailedToControl);
                Step::event("missed", MotorOutput::stop(), m.feedback("back_in"))
            }
        })
    }
}
