//! The shipped motor schemas as [`MotorSchema`]s: each turns its own typed percept into a
//! [`MotorOutput`] through the one trait, so a tree, a [`SchemaBehavior`](super::SchemaBehavior)
//! or a test drives any of them the same way. The schemas keep their finer methods
//! (a steering error, a field vector, a sweep's turn) because the leaves compose those
//! (a field steered by the ratio law, a sweep with a posture); `act` is the whole
//! schema, percept in, output out.

use super::avoid::AvoidObstacles;
use super::devices::ArmPosition;
use super::goto_point::PointController;
use super::motor_output::{Auxiliary, DriveCommand, MotorOutput};
use super::potential_field::PotentialField;
use super::ratio_steering::RatioSteering;
use super::search::{DeadReckoning, SearchRotation};
use super::traits::MotorSchema;
use super::visual_servo::ServoLaw;
use crate::geometry::Pose2;
use crate::perception::FiducialView;

/// How long an open-loop schema has run, s: what [`SearchRotation`] perceives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Elapsed(pub f64);

/// How far the robot has driven since the schema began, m: what [`DeadReckoning`]
/// perceives (from odometry).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Travelled(pub f64);

/// The robot's pose in the dock frame and the end it leads with (+1 front, −1 rear):
/// what [`PotentialField`] perceives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DockPose {
    /// Pose in the dock frame (origin at the entrance, +x out along the axis).
    pub pose: Pose2,
    /// +1 when the robot moves front first, −1 rear first.
    pub drive_dir: f64,
}

/// RAPOSA's guide ellipse as the servo law reads it: what [`ServoLaw`] perceives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GuideView {
    /// Camera-to-ball distance, m.
    pub distance_m: f64,
    /// √(A₁/A): the ellipse's area at 1 m over its area now, square-rooted.
    pub area_root: f64,
    /// Ellipse centre right of the image centre, px.
    pub x_dev_px: f64,
    /// Ellipse centre below the image centre, px.
    pub y_dev_px: f64,
}

/// Where the robot is and the point it should reach: what [`PointController`] perceives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointGoal {
    /// The robot's pose (any frame the target shares).
    pub pose: Pose2,
    /// The point to reach, (x, y) m.
    pub target: (f64, f64),
    /// Travel rear first.
    pub reverse: bool,
}

/// The heading law on the fiducial's view: turn or drive toward the aim point.
impl MotorSchema for RatioSteering {
    type Percept = FiducialView;
    fn act(&self, view: &FiducialView) -> MotorOutput {
        let e = self.error(view);
        let angle = (e * self.image_width / 2.0 / self.geometry.fx).atan();
        self.steer(angle, self.speed_for(view.total_px as f64))
    }
}

/// The sweep's turn after so long searching.
impl MotorSchema for SearchRotation {
    type Percept = Elapsed;
    fn act(&self, elapsed: &Elapsed) -> MotorOutput {
        MotorOutput::drive(self.command(elapsed.0))
    }
}

/// Drive on until the distance is covered, then stop.
impl MotorSchema for DeadReckoning {
    type Percept = Travelled;
    fn act(&self, travelled: &Travelled) -> MotorOutput {
        self.command(travelled.0)
            .map_or_else(MotorOutput::stop, MotorOutput::drive)
    }
}

/// The field's twist at the robot's pose (for a base that turns and drives at once).
impl MotorSchema for PotentialField {
    type Percept = DockPose;
    fn act(&self, p: &DockPose) -> MotorOutput {
        MotorOutput::drive(DriveCommand::Twist(self.twist(&p.pose, p.drive_dir)))
    }
}

/// Region I's servo: speed and turn from the ellipse, and the arm angle for its height.
impl MotorSchema for ServoLaw {
    type Percept = GuideView;
    fn act(&self, g: &GuideView) -> MotorOutput {
        let twist = self.twist(self.speed(g.distance_m, g.area_root), self.turn(g.x_dev_px));
        let aux = Auxiliary::with(ArmPosition(self.arm(g.y_dev_px)));
        MotorOutput::drive(DriveCommand::Twist(twist)).with_aux(aux)
    }
}

/// Travel to the point; stop once within tolerance.
impl MotorSchema for PointController {
    type Percept = PointGoal;
    fn act(&self, g: &PointGoal) -> MotorOutput {
        self.travel(&g.pose, g.target, g.reverse)
            .map_or_else(MotorOutput::stop, |t| MotorOutput::drive(DriveCommand::Twist(t)))
    }
}

/// Repulsion from the returns, as (beam direction in the body frame, rad; range, m);
/// stop when nothing is inside the sphere of influence (the behavior is then not
/// released). The side is chosen afresh from these returns (a leaf keeps it between ticks).
impl MotorSchema for AvoidObstacles {
    type Percept = [(f64, f64)];
    fn act(&self, beams: &[(f64, f64)]) -> MotorOutput {
        let side = self.side(beams.iter().copied());
        self.vector(beams.iter().copied(), side)
            .map_or_else(MotorOutput::stop, |v| MotorOutput::drive(DriveCommand::Vector(v)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn open_loop_schemas_act_through_the_trait() {
        let s = SearchRotation {
            rate: 0.5,
            first_sweep: 0.5,
            doubling: true,
        };
        assert_eq!(s.act(&Elapsed(1.5)).drive, DriveCommand::Turn { omega: -0.5 });
        let d = DeadReckoning {
            speed: -0.03,
            distance: 0.5,
        };
        assert_eq!(d.act(&Travelled(0.2)).drive, DriveCommand::Straight { v: -0.03 });
        assert!(d.act(&Travelled(0.5)).drive.is_stop());
    }

    #[test]
    fn the_servo_law_proposes_the_arm_with_the_twist() {
        let law = ServoLaw {
            k_lin: 0.045,
            k_ang: 0.004,
            k_arm: 0.003,
            far_speed: 0.05,
            far_distance: 1.0,
            camera_backward: true,
        };
        let g = GuideView {
            distance_m: 2.0,
            area_root: 2.0,
            x_dev_px: 10.0,
            y_dev_px: 20.0,
        };
        let out = law.act(&g);
        let t = out.drive.to_twist();
        assert!((t.v + 0.05).abs() < 1e-12 && (t.omega + 0.04).abs() < 1e-12);
        assert!((out.aux.get::<ArmPosition>().unwrap().0 + 0.06).abs() < 1e-12);
    }
}
