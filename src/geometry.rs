//! Planar geometry shared by kinematics, odometry and the motor schemas.
//!
//! Conventions used across the crate: SI units (metres, seconds, radians) unless a name
//! says otherwise (`_deg`, `_px`). A body frame has +x forward, +y to the left, angles
//! counter-clockwise positive. A world or dock frame follows the same right-handed rule.

use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Wraps an angle into (−π, π].
///
/// ```
/// use marsupial::geometry::wrap_angle;
/// assert!((wrap_angle(3.0 * std::f64::consts::PI) - std::f64::consts::PI).abs() < 1e-12);
/// assert!((wrap_angle(-0.5) + 0.5).abs() < 1e-12);
/// ```
pub fn wrap_angle(a: f64) -> f64 {
    if !a.is_finite() {
        return a;
    }
    let mut r = a.rem_euclid(2.0 * PI); // [0, 2π)
    if r > PI {
        r -= 2.0 * PI;
    }
    r
}

/// A pose in the plane: position (m) and heading (rad, CCW from +x).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Pose2 {
    /// x position, metres.
    pub x: f64,
    /// y position, metres.
    pub y: f64,
    /// Heading, radians, counter-clockwise from +x, kept in (−π, π].
    pub theta: f64,
}

impl Pose2 {
    /// Builds a pose, wrapping the heading into (−π, π].
    pub fn new(x: f64, y: f64, theta: f64) -> Self {
        Self {
            x,
            y,
            theta: wrap_angle(theta),
        }
    }

    /// Expresses `p` (a point in this pose's parent frame) in this pose's body frame.
    pub fn to_local(&self, px: f64, py: f64) -> (f64, f64) {
        let (s, c) = self.theta.sin_cos();
        let dx = px - self.x;
        let dy = py - self.y;
        (c * dx + s * dy, -s * dx + c * dy)
    }

    /// Maps a point from this pose's body frame into its parent frame.
    pub fn to_world(&self, lx: f64, ly: f64) -> (f64, f64) {
        let (s, c) = self.theta.sin_cos();
        (self.x + c * lx - s * ly, self.y + s * lx + c * ly)
    }

    /// Composes two poses: `self ⊕ other` (other expressed in self's frame).
    pub fn compose(&self, other: &Pose2) -> Pose2 {
        let (x, y) = self.to_world(other.x, other.y);
        Pose2::new(x, y, self.theta + other.theta)
    }

    /// The pose of `other` expressed in this pose's frame (`self⁻¹ ⊕ other`).
    pub fn relative(&self, other: &Pose2) -> Pose2 {
        let (x, y) = self.to_local(other.x, other.y);
        Pose2::new(x, y, other.theta - self.theta)
    }

    /// True when every component is finite.
    pub fn is_finite(&self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.theta.is_finite()
    }

    /// Distance between the two poses' positions, m (headings ignored).
    ///
    /// ```
    /// use marsupial::geometry::Pose2;
    /// assert_eq!(Pose2::new(1.0, 1.0, 0.3).distance(&Pose2::new(4.0, 5.0, -1.0)), 5.0);
    /// ```
    pub fn distance(&self, other: &Pose2) -> f64 {
        (self.x - other.x).hypot(self.y - other.y)
    }
}

/// A body-frame velocity: forward speed `v` (m/s) and yaw rate `omega` (rad/s, CCW positive).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Twist {
    /// Forward speed along body +x, m/s (negative = reversing).
    pub v: f64,
    /// Yaw rate, rad/s, counter-clockwise positive.
    pub omega: f64,
}

impl Twist {
    /// Zero velocity.
    pub const ZERO: Twist = Twist { v: 0.0, omega: 0.0 };

    /// Builds a twist.
    pub fn new(v: f64, omega: f64) -> Self {
        Self { v, omega }
    }

    /// True when both components are finite.
    pub fn is_finite(&self) -> bool {
        self.v.is_finite() && self.omega.is_finite()
    }
}

/// Integrates a constant body twist over `dt` seconds, exactly along the arc.
///
/// For |ω·dt| ≤ 1e-9 the straight-line limit is used, so the result is continuous in ω.
pub fn integrate_twist(pose: &Pose2, twist: &Twist, dt: f64) -> Pose2 {
    integrate_body_velocity(pose, twist.v, 0.0, twist.omega, dt)
}

/// Integrates a constant body velocity (vx forward, vy left, ω) over `dt`, exactly.
///
/// The lateral term lets slip models and double-Ackermann crab steering use the same
/// integrator as the unicycle.
pub fn integrate_body_velocity(pose: &Pose2, vx: f64, vy: f64, omega: f64, dt: f64) -> Pose2 {
    let dth = omega * dt;
    // Displacement in the start body frame along a circular arc with constant body velocity.
    let (dx, dy) = if dth.abs() <= 1e-9 {
        (vx * dt, vy * dt)
    } else {
        let s = dth.sin();
        let c1 = 1.0 - dth.cos();
        // ∫0^dt R(ωt)·(vx, vy) dt
        ((vx * s - vy * c1) / omega, (vx * c1 + vy * s) / omega)
    };
    let (x, y) = pose.to_world(dx, dy);
    Pose2::new(x, y, pose.theta + dth)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_keeps_range() {
        for k in -20..20 {
            let a = k as f64 * 0.7;
            let w = wrap_angle(a);
            assert!(w > -PI - 1e-12 && w <= PI + 1e-12);
            assert!(((a - w) / (2.0 * PI)).fract().abs() < 1e-9 || ((a - w) / (2.0 * PI)).fract().abs() > 1.0 - 1e-9);
        }
        assert_eq!(wrap_angle(PI), PI);
        assert_eq!(wrap_angle(-PI), PI);
    }

    #[test]
    fn local_world_roundtrip() {
        let p = Pose2::new(1.0, -2.0, 0.7);
        let (lx, ly) = p.to_local(3.0, 4.0);
        let (wx, wy) = p.to_world(lx, ly);
        assert!((wx - 3.0).abs() < 1e-12 && (wy - 4.0).abs() < 1e-12);
        let q = Pose2::new(0.3, 0.2, -1.1);
        let r = p.relative(&p.compose(&q));
        assert!((r.x - q.x).abs() < 1e-12 && (r.y - q.y).abs() < 1e-12 && (r.theta - q.theta).abs() < 1e-12);
    }

    #[test]
    fn quarter_circle_is_exact() {
        // v = 1 m/s, ω = π/2 rad/s for 1 s: quarter circle of radius 2/π.
        let r = 2.0 / PI;
        let p = integrate_twist(&Pose2::default(), &Twist::new(1.0, PI / 2.0), 1.0);
        assert!((p.x - r).abs() < 1e-12, "{p:?}");
        assert!((p.y - r).abs() < 1e-12, "{p:?}");
        assert!((p.theta - PI / 2.0).abs() < 1e-12);
    }

    #[test]
    fn arc_in_many_steps_equals_one_step() {
        let tw = Twist::new(0.3, -0.4);
        let one = integrate_twist(&Pose2::new(1.0, 2.0, 0.5), &tw, 2.0);
        let mut p = Pose2::new(1.0, 2.0, 0.5);
        for _ in 0..200 {
            p = integrate_twist(&p, &tw, 0.01);
        }
        assert!((p.x - one.x).abs() < 1e-9 && (p.y - one.y).abs() < 1e-9);
    }

    #[test]
    fn straight_line_and_lateral() {
        let p = integrate_body_velocity(&Pose2::new(0.0, 0.0, PI / 2.0), 1.0, 0.5, 0.0, 2.0);
        assert!((p.x + 1.0).abs() < 1e-12 && (p.y - 2.0).abs() < 1e-12);
    }
}
