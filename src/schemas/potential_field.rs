//! Potential-field docking after Arkin & Murphy 1990 (ALGORITHMS §1.2–1.3).
//!
//! In the dock frame (origin at the entrance, +x out along the axis), a robot at polar
//! position (ρ, α) feels an attraction `a` toward the dock and a tangential (coercive)
//! component `t` that swings it toward the axis (a rotated by +sign(α)·90°). Outside the
//! approach sector |α| > α_z the tangential term dominates (w_t = 1, w_a = coercive
//! attraction); inside, attraction dominates and the tangential weight fades linearly to
//! zero on the axis (w_t = |α|/α_z, w_a = 1), continuous at the sector edge. The sum is
//! normalised and scaled by the gain, slowing within half a metre of the dock. Any robot
//! whose percept gives a relative pose can use it.

use super::vector::MotionVector;
use crate::geometry::{Pose2, Twist};

/// The potential-field docking schema.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PotentialField {
    /// Half-width of the approach sector α_z, rad.
    pub sector: f64,
    /// Attraction weight in the coercive zone.
    pub coercive_attraction: f64,
    /// Speed at full field, m/s.
    pub gain: f64,
    /// Heading-controller gain, 1/s.
    pub k_theta: f64,
}

impl PotentialField {
    /// The field at polar position (ρ, α), in the dock frame.
    pub fn field(&self, rho: f64, alpha: f64) -> MotionVector {
        let a = MotionVector::new(-alpha.cos(), -alpha.sin());
        let s = if alpha >= 0.0 { 1.0 } else { -1.0 };
        let t = MotionVector::new(-s * a.y, s * a.x);
        let (wa, wt) = if alpha.abs() > self.sector {
            (self.coercive_attraction, 1.0)
        } else {
            (1.0, alpha.abs() / self.sector)
        };
        let v = MotionVector::weighted_sum([(wa, a), (wt, t)]).normalized();
        v.scale(self.gain * (rho / 0.5).clamp(0.2, 1.0))
    }

    /// The twist for a robot at `pose` (dock frame). `drive_dir` −1 means the robot moves
    /// rear first (its rear must lead along the field).
    pub fn twist(&self, pose: &Pose2, drive_dir: f64) -> Twist {
        let rho = pose.x.hypot(pose.y);
        let alpha = pose.y.atan2(pose.x);
        let v = self.field(rho, alpha);
        let (s, c) = pose.theta.sin_cos();
        // World → body, then flip for rear-first motion so the heading controller steers
        // the leading end.
        let body = MotionVector::new(c * v.x + s * v.y, -s * v.x + c * v.y).scale(drive_dir);
        let t = body.to_twist(self.k_theta);
        Twist::new(t.v * drive_dir, t.omega)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    fn pf() -> PotentialField {
        PotentialField {
            sector: 22.5f64.to_radians(),
            coercive_attraction: 0.3,
            gain: 0.1,
            k_theta: 1.5,
        }
    }

    #[test]
    fn on_axis_pure_attraction() {
        let v = pf().field(1.0, 0.0);
        assert!((v.x + 0.1).abs() < 1e-12 && v.y.abs() < 1e-12);
    }

    #[test]
    fn tangential_pulls_toward_the_axis_and_dominates_outside_the_sector() {
        let v = pf().field(1.0, 60f64.to_radians());
        // At α = 60° (robot at +y), the field points toward −y more than toward the dock.
        let a = MotionVector::new(-0.5, -(60f64.to_radians()).sin());
        let tang = MotionVector::new(-a.y, a.x);
        let comp_t = v.x * tang.x + v.y * tang.y;
        let comp_a = v.x * a.x + v.y * a.y;
        assert!(comp_t > comp_a && comp_a > 0.0, "{v:?}");
        let w = pf().field(1.0, -60f64.to_radians());
        assert!(
            (w.x - v.x).abs() < 1e-12 && (w.y + v.y).abs() < 1e-12,
            "mirror symmetric"
        );
    }

    #[test]
    fn weights_are_continuous_at_the_sector_edge() {
        let e = 22.5f64.to_radians();
        let inside = pf().field(1.0, e - 1e-9);
        let outside = pf().field(1.0, e + 1e-9);
        let mut p = pf();
        p.coercive_attraction = 1.0; // continuity needs w_a = 1 on both sides
        let (i, o) = (p.field(1.0, e - 1e-9), p.field(1.0, e + 1e-9));
        assert!((i.x - o.x).abs() < 1e-6 && (i.y - o.y).abs() < 1e-6);
        assert!(inside.norm() > 0.0 && outside.norm() > 0.0);
    }

    #[test]
    fn slows_near_the_dock_and_backs_rear_first() {
        assert!(pf().field(0.1, 0.0).norm() < pf().field(1.0, 0.0).norm());
        // A backing robot on the axis facing away from the dock backs straight in.
        let t = pf().twist(&Pose2::new(1.0, 0.0, 0.0), -1.0);
        assert!(t.v < 0.0 && t.omega.abs() < 1e-12, "{t:?}");
        // Facing the wrong way it turns first.
        let t = pf().twist(&Pose2::new(1.0, 0.0, FRAC_PI_2), -1.0);
        assert!(t.omega.abs() > 1.0 && t.v.abs() < 1e-9, "{t:?}");
    }
}
