//! Odometry motion: the inverse (x_ref, y_ref) point controller and rotation to a heading
//! (RAPOSA's region-II travel and turns, seed 001 §II.E).
//!
//! The point controller steers the direction of travel at the reference point while
//! driving: v = k_ρ·ρ·cos e, ω = k_θ·e (ρ the distance, e the heading error of the
//! travel direction, which is the body's front or, with `reverse`, its back). Both are
//! saturated and **scaled together**: when either exceeds its limit both shrink by the
//! same factor, so the path's curvature is kept. Driving in two dimensions, rather than
//! turning and then driving straight, corrects heading errors picked up on the way.

use crate::geometry::{Pose2, Twist, wrap_angle};

/// Limits and gains of the point controller and the rotations.
///
/// # Example
///
/// From the origin facing +x, the point (1, 1) is 45° to the left at √2 m: unsaturated,
/// v = 0.4·√2·cos 45° = 0.4 m/s and ω = 1.5·π/4 rad/s, both then scaled by 0.08/0.4 so
/// that the speed limit holds and the path's curvature is kept.
///
/// ```
/// use marsupial::geometry::Pose2;
/// use marsupial::schemas::PointController;
/// use std::f64::consts::FRAC_PI_4;
///
/// let c = PointController {
///     k_rho: 0.4,
///     k_heading: 1.5,
///     max_speed: 0.08,
///     max_turn: 0.35,
///     position_tolerance: 0.03,
///     rotation_tolerance: 2f64.to_radians(),
/// };
/// let origin = Pose2::new(0.0, 0.0, 0.0);
/// let t = c.travel(&origin, (1.0, 1.0), false).unwrap();
/// assert!((t.v - 0.08).abs() < 1e-12);
/// assert!((t.omega - 1.5 * FRAC_PI_4 * 0.08 / 0.4).abs() < 1e-12);
/// // Back first: the same point is behind the robot's rear, so it turns before driving.
/// let t = c.travel(&origin, (1.0, 1.0), true).unwrap();
/// assert_eq!(t.v, 0.0);
/// assert!(c.travel(&origin, (0.02, 0.0), false).is_none(), "within 3 cm: done");
///
/// // Turning in place to 1 rad: counter-clockwise, capped at 0.35 rad/s, no speed.
/// let t = c.rotate(&origin, 1.0).unwrap();
/// assert!(t.v == 0.0 && (t.omega - 0.35).abs() < 1e-12);
/// assert!(c.rotate(&origin, 0.01).is_none());
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointController {
    /// Speed per metre of remaining distance, 1/s.
    pub k_rho: f64,
    /// Yaw rate per radian of heading error, 1/s.
    pub k_heading: f64,
    /// Largest speed, m/s.
    pub max_speed: f64,
    /// Largest yaw rate, rad/s.
    pub max_turn: f64,
    /// Done within this distance, m.
    pub position_tolerance: f64,
    /// Rotations are done within this angle, rad.
    pub rotation_tolerance: f64,
}

impl PointController {
    /// Twist driving `pose` toward `(x, y)`, front first or (`reverse`) back first;
    /// `None` once within tolerance.
    pub fn travel(&self, pose: &Pose2, target: (f64, f64), reverse: bool) -> Option<Twist> {
        let (dx, dy) = (target.0 - pose.x, target.1 - pose.y);
        let rho = dx.hypot(dy);
        if rho <= self.position_tolerance {
            return None;
        }
        let travel_dir = if reverse {
            pose.theta + std::f64::consts::PI
        } else {
            pose.theta
        };
        let e = wrap_angle(dy.atan2(dx) - travel_dir);
        // Do not drive while facing away: turn first when the error exceeds 60°.
        let v = if e.abs() < 60f64.to_radians() {
            self.k_rho * rho * e.cos()
        } else {
            0.0
        };
        let v = if reverse { -v } else { v };
        Some(self.scaled(v, self.k_heading * e))
    }

    /// Twist turning `pose` to `heading` in place; `None` once within tolerance.
    pub fn rotate(&self, pose: &Pose2, heading: f64) -> Option<Twist> {
        let e = wrap_angle(heading - pose.theta);
        if e.abs() <= self.rotation_tolerance {
            return None;
        }
        // At least a fifth of the rate, so the last degrees do not crawl.
        let w = (self.k_heading * e).abs().max(self.max_turn / 5.0) * e.signum();
        Some(self.scaled(0.0, w))
    }

    /// Saturates v and ω by one common factor.
    pub fn scaled(&self, v: f64, omega: f64) -> Twist {
        let s = (v.abs() / self.max_speed).max(omega.abs() / self.max_turn).max(1.0);
        Twist::new(v / s, omega / s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::integrate_twist;

    fn c() -> PointController {
        PointController {
            k_rho: 0.4,
            k_heading: 1.5,
            max_speed: 0.08,
            max_turn: 0.35,
            position_tolerance: 0.03,
            rotation_tolerance: 2f64.to_radians(),
        }
    }

    #[test]
    fn saturation_scales_both_and_keeps_curvature() {
        let t = c().scaled(0.4, 0.7);
        assert!((t.v - 0.08).abs() < 1e-12);
        assert!((t.omega / t.v - 0.7 / 0.4).abs() < 1e-12);
        let t = c().scaled(0.01, 0.02);
        assert_eq!((t.v, t.omega), (0.01, 0.02));
    }

    #[test]
    fn reaches_points_front_or_back_first() {
        for (target, reverse) in [((1.0, 0.5), false), ((-0.8, 0.6), true), ((0.2, -1.0), false)] {
            let mut p = Pose2::new(0.0, 0.0, 0.0);
            let mut steps = 0;
            while let Some(t) = c().travel(&p, target, reverse) {
                p = integrate_twist(&p, &t, 0.1);
                steps += 1;
                assert!(steps < 2000, "no convergence to {target:?}");
            }
            assert!((p.x - target.0).hypot(p.y - target.1) <= 0.03);
        }
    }

    #[test]
    fn rotates_to_heading_either_way() {
        for h in [1.2, -2.5, 3.1] {
            let mut p = Pose2::new(0.0, 0.0, 0.0);
            let mut steps = 0;
            while let Some(t) = c().rotate(&p, h) {
                assert_eq!(t.v, 0.0);
                p = integrate_twist(&p, &t, 0.1);
                steps += 1;
                assert!(steps < 500);
            }
            assert!(wrap_angle(p.theta - h).abs() <= 2f64.to_radians());
        }
    }
}
