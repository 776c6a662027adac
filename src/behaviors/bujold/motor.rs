//! The motor side Bujold's phase schemas share: the approach motor schema the profile
//! selects, the posture each phase drives in, and the simple raised motions (hold, turn
//! in place, drive away) that several phases step with.

use super::memory::Memory;
use crate::behaviors::common::motion::Motion;
use crate::geometry::{Pose2, wrap_angle};
use crate::perception::two_block_pose::FiducialView;
use crate::schemas::{
    Auxiliary, DriveCommand, MotionVector, MotorOutput, MotorSchema, Posture, PotentialField, RatioSteering, Step,
};

/// The approach motor schema the profile selects (`robot.approach`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ApproachMotor {
    /// Ratio steering: also realises the field's heading error on a turn-or-drive base.
    pub steering: RatioSteering,
    /// The potential field, when selected.
    pub field: Option<PotentialField>,
}

impl ApproachMotor {
    /// The field's desired velocity for a view, body frame (`None` without a field):
    /// Arkin's motion vector, for a vector-sum arbiter to combine with others.
    pub fn vector(&self, view: &FiducialView) -> Option<MotionVector> {
        self.vector_at(&view.dock_pose())
    }

    /// The field's desired velocity for a robot at `pose` in the dock frame, body frame.
    pub fn vector_at(&self, pose: &Pose2) -> Option<MotionVector> {
        let dd = self.steering.geometry.drive_dir;
        // `body_vector` is in the frame of the leading end; back to the body frame.
        self.field.as_ref().map(|pf| pf.body_vector(pose, dd).scale(dd))
    }

    /// The approach command for a view (raised).
    pub fn act(&self, view: &FiducialView) -> MotorOutput {
        let out = match &self.field {
            None => self.steering.act(view),
            // The field gives a heading error; the ratio-steering schema realises it with
            // the same dead band, understeer and turn-or-drive alternation.
            Some(pf) if self.steering.restricted => {
                let error = pf
                    .body_vector(&view.dock_pose(), self.steering.geometry.drive_dir)
                    .angle();
                self.steering
                    .steer(error, self.steering.speed_for(view.total_px as f64))
            }
            Some(pf) => MotorOutput::drive(DriveCommand::Twist(
                pf.twist(&view.dock_pose(), self.steering.geometry.drive_dir),
            )),
        };
        out.with_aux(raised())
    }
}

impl Memory {
    /// Stand still, raised.
    pub fn hold(&self, phase: &'static str) -> Step {
        Step::running(MotorOutput::stop().with_aux(raised()), self.feedback(phase))
    }

    /// Turn in place toward a heading error `err` (rad), raised: twice the error per
    /// second, capped at the turn rate (the odometry manoeuvres' turns).
    pub fn turn_by(&self, err: f64, phase: &'static str) -> Step {
        let rate = self.approach.steering.turn_rate;
        let omega = (2.0 * err).clamp(-rate, rate);
        Step::running(
            MotorOutput::drive(DriveCommand::Turn { omega }).with_aux(raised()),
            self.feedback(phase),
        )
    }

    /// Drive straight away from the dock (front first), raised, at `speed`.
    pub fn drive_away(&self, speed: f64, phase: &'static str) -> Step {
        let v = -self.geometry.drive_dir * speed;
        Step::running(
            MotorOutput::drive(DriveCommand::Straight { v }).with_aux(raised()),
            self.feedback(phase),
        )
    }
}

/// The manoeuvre legs' motions, raised; turns within a heading tolerance (3° when the
/// leg names none).
impl Motion for Memory {
    fn now(&self) -> f64 {
        self.now
    }

    fn odo(&self) -> Pose2 {
        self.odo
    }

    fn hold(&mut self, phase: &'static str) -> Step {
        Memory::hold(self, phase)
    }

    fn turn_toward(&mut self, heading: f64, tolerance: Option<f64>, phase: &'static str) -> Option<Step> {
        let err = wrap_angle(heading - self.odo.theta);
        let tolerance = tolerance.unwrap_or(3f64.to_radians());
        (err.abs() >= tolerance).then(|| self.turn_by(err, phase))
    }

    fn straight(&mut self, v: f64, phase: &'static str) -> Step {
        Step::running(
            MotorOutput::drive(DriveCommand::Straight { v }).with_aux(raised()),
            self.feedback(phase),
        )
    }

    fn back_off(&mut self, speed: f64, phase: &'static str) -> Step {
        self.drive_away(speed, phase)
    }
}

/// Lowered posture (backing in, leaving the pouch).
pub fn lowered() -> Auxiliary {
    Auxiliary::with(Posture::Lowered)
}

/// Raised posture (everywhere else).
pub fn raised() -> Auxiliary {
    Auxiliary::with(Posture::Raised)
}
