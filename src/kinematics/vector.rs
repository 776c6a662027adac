//! Arkin-style motion vectors and their gain-weighted composition.
//!
//! A motor schema in Arkin's sense returns a velocity vector computed at the robot's
//! current position only; the commanded vector is the gain-weighted sum of the active
//! schemas' vectors, clipped to the robot's maximum speed (../ALGORITHMS.md §1.1).

use crate::geometry::{Twist, wrap_angle};
use serde::{Deserialize, Serialize};

/// A desired velocity in the robot's body frame: +x forward, +y left, m/s.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct MotionVector {
    /// Forward component, m/s.
    pub x: f64,
    /// Leftward component, m/s.
    pub y: f64,
}

impl MotionVector {
    /// The zero vector.
    pub const ZERO: MotionVector = MotionVector { x: 0.0, y: 0.0 };

    /// Builds a vector.
    pub fn new(x: f64, y: f64) -> Self {
        Self { x, y }
    }

    /// Builds a vector of magnitude `mag` pointing at `angle` (rad, CCW from body +x).
    pub fn from_polar(mag: f64, angle: f64) -> Self {
        Self::new(mag * angle.cos(), mag * angle.sin())
    }

    /// Euclidean length.
    pub fn norm(&self) -> f64 {
        self.x.hypot(self.y)
    }

    /// Direction, rad CCW from body +x (0 for the zero vector).
    pub fn angle(&self) -> f64 {
        if self.x == 0.0 && self.y == 0.0 {
            0.0
        } else {
            self.y.atan2(self.x)
        }
    }

    /// Scales by a gain.
    pub fn scale(&self, g: f64) -> Self {
        Self::new(self.x * g, self.y * g)
    }

    /// Unit vector in the same direction; the zero vector stays zero (no NaN).
    pub fn normalized(&self) -> Self {
        let n = self.norm();
        if n > 0.0 { self.scale(1.0 / n) } else { Self::ZERO }
    }

    /// Clips the length to at most `max`.
    pub fn clip(&self, max: f64) -> Self {
        let n = self.norm();
        if n > max && n > 0.0 { self.scale(max / n) } else { *self }
    }

    /// Gain-weighted sum `Σ gᵢ·Vᵢ` (Arkin's composition).
    ///
    /// ```
    /// use marsupial::schemas::MotionVector;
    /// let v = MotionVector::weighted_sum([(1.0, MotionVector::new(1.0, 0.0)), (0.5, MotionVector::new(0.0, 2.0))]);
    /// assert_eq!(v, MotionVector::new(1.0, 1.0));
    /// ```
    pub fn weighted_sum(parts: impl IntoIterator<Item = (f64, MotionVector)>) -> Self {
        parts
            .into_iter()
            .fold(Self::ZERO, |acc, (g, v)| Self::new(acc.x + g * v.x, acc.y + g * v.y))
    }

    /// Turns the vector into a unicycle twist with a heading controller:
    /// ω = k_θ · angle(V), v = |V| · max(0, cos angle(V)).
    ///
    /// A vector pointing behind the robot therefore turns it in place first. A robot that
    /// backs in (Bujold) flips its vectors before calling this.
    pub fn to_twist(&self, k_theta: f64) -> Twist {
        let a = wrap_angle(self.angle());
        Twist::new(self.norm() * a.cos().max(0.0), k_theta * a)
    }
}

impl std::ops::Add for MotionVector {
    type Output = MotionVector;
    fn add(self, o: MotionVector) -> MotionVector {
        MotionVector::new(self.x + o.x, self.y + o.y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sum_and_clip() {
        let v = MotionVector::weighted_sum([(2.0, MotionVector::new(3.0, 0.0)), (1.0, MotionVector::new(0.0, 8.0))]);
        assert_eq!(v, MotionVector::new(6.0, 8.0));
        let c = v.clip(5.0);
        assert!((c.norm() - 5.0).abs() < 1e-12);
        assert!((c.angle() - v.angle()).abs() < 1e-12);
        assert_eq!(MotionVector::ZERO.normalized(), MotionVector::ZERO);
    }

    #[test]
    fn heading_controller() {
        let t = MotionVector::new(1.0, 0.0).to_twist(2.0);
        assert_eq!(t, Twist::new(1.0, 0.0));
        let t = MotionVector::new(0.0, 1.0).to_twist(2.0);
        assert!(t.v.abs() < 1e-12 && (t.omega - std::f64::consts::PI).abs() < 1e-12);
        let t = MotionVector::new(-1.0, 0.1).to_twist(1.0);
        assert_eq!(t.v, 0.0);
        assert!(t.omega > 0.0);
    }
}
