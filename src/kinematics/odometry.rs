//! Odometry: integrating wheel travel into a pose, exactly along arcs.

use super::DriveModel;
use crate::geometry::{Pose2, Twist, integrate_body_velocity, integrate_twist};

/// Dead-reckoned pose from wheel travel.
///
/// Each update assumes the wheel speeds were constant over the step, so the robot moved
/// along a circular arc; the arc is integrated in closed form (no Euler drift).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Odometry {
    model: DriveModel,
    pose: Pose2,
    twist: Twist,
}

impl Odometry {
    /// Starts at `pose`.
    pub fn new(model: DriveModel, pose: Pose2) -> Self {
        Self {
            model,
            pose,
            twist: Twist::ZERO,
        }
    }

    /// Current pose estimate.
    pub fn pose(&self) -> Pose2 {
        self.pose
    }

    /// Body twist of the last update.
    pub fn twist(&self) -> Twist {
        self.twist
    }

    /// Moves the origin: the pose becomes `pose` (RAPOSA resets it after state 7).
    pub fn reset(&mut self, pose: Pose2) {
        self.pose = pose;
    }

    /// Integrates left/right wheel travel (m) accumulated over `dt` seconds.
    /// Non-finite or non-positive `dt` and non-finite travel are ignored (returns false).
    pub fn update_wheels(&mut self, d_left: f64, d_right: f64, dt: f64) -> bool {
        if !(dt > 0.0 && dt.is_finite() && d_left.is_finite() && d_right.is_finite()) {
            return false;
        }
        let t = self.model.twist_from_wheels(d_left / dt, d_right / dt);
        self.pose = integrate_twist(&self.pose, &t, dt);
        self.twist = t;
        true
    }

    /// Integrates a double-Ackermann step: travel `ds` (m) at axle angles (rad) over `dt`.
    /// For other models the steering angles are ignored and `ds` is a straight step.
    pub fn update_steered(&mut self, ds: f64, steer_front: f64, steer_rear: f64, dt: f64) -> bool {
        if !(dt > 0.0 && dt.is_finite() && ds.is_finite() && steer_front.is_finite() && steer_rear.is_finite()) {
            return false;
        }
        match self.model {
            DriveModel::DoubleAckermann(a) => {
                let b = a.body_velocity(ds / dt, steer_front, steer_rear);
                self.pose = integrate_body_velocity(&self.pose, b.vx, b.vy, b.omega, dt);
                self.twist = Twist::new(b.vx, b.omega);
            }
            _ => {
                self.twist = Twist::new(ds / dt, 0.0);
                self.pose = integrate_twist(&self.pose, &self.twist, dt);
            }
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::{DoubleAckermann, SkidSteer};
    use std::f64::consts::PI;

    #[test]
    fn straight_line() {
        let mut o = Odometry::new(
            DriveModel::Differential(crate::kinematics::Differential { track: 0.3 }),
            Pose2::default(),
        );
        for _ in 0..100 {
            o.update_wheels(0.01, 0.01, 0.1);
        }
        assert!((o.pose().x - 1.0).abs() < 1e-9 && o.pose().y.abs() < 1e-12);
    }

    #[test]
    fn skid_steer_circle_closes() {
        // Right track travels more: CCW circle. Radius R = d/2·(dr+dl)/(dr−dl).
        let s = SkidSteer::new(0.3, 0.4, 0.6).unwrap();
        let mut o = Odometry::new(DriveModel::SkidSteer(s), Pose2::default());
        let (dl, dr) = (0.01, 0.02);
        let dth = (dr - dl) / 0.4;
        let n = (2.0 * PI / dth).round() as usize;
        let r = 0.4 / 2.0 * (dr + dl) / (dr - dl);
        // Quarter of the way: closed-form position on the circle.
        let quarter = n / 4;
        for _ in 0..quarter {
            o.update_wheels(dl, dr, 0.05);
        }
        let th = quarter as f64 * dth;
        assert!((o.pose().x - r * th.sin()).abs() < 1e-9, "{:?}", o.pose());
        assert!((o.pose().y - r * (1.0 - th.cos())).abs() < 1e-9);
    }

    #[test]
    fn ackermann_circle_radius() {
        let a = DoubleAckermann {
            wheelbase: 0.6,
            track: 0.5,
            max_steer: 0.6,
        };
        let mut o = Odometry::new(DriveModel::DoubleAckermann(a), Pose2::default());
        let l = 0.3f64;
        let r = 0.3 / l.tan();
        let steps = 1000;
        let ds = PI * r / steps as f64; // half circle
        for _ in 0..steps {
            o.update_steered(ds, l, -l, 0.01);
        }
        assert!(
            o.pose().x.abs() < 1e-9 && (o.pose().y - 2.0 * r).abs() < 1e-9,
            "{:?}",
            o.pose()
        );
    }

    #[test]
    fn ignores_garbage() {
        let mut o = Odometry::new(
            DriveModel::Differential(crate::kinematics::Differential { track: 0.3 }),
            Pose2::default(),
        );
        assert!(!o.update_wheels(f64::NAN, 0.0, 0.1));
        assert!(!o.update_wheels(0.1, 0.1, 0.0));
        assert_eq!(o.pose(), Pose2::default());
    }
}
