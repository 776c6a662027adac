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
//!
//! **The final zone** (ours). With those weights a robot near the axis moves at about
//! (1 + 1/α_z)·α off it, so it closes on the axis fast but arrives still turning across
//! it, with a heading error 3.5 times its angular offset (α_z = 22.5°); backed in blind
//! from there it overshoots the entrance. So the tangential weight also varies with
//! distance: full beyond twice `final_radius`, fading linearly to nothing at it, where
//! the robot points straight at the entrance (the dead-reckoning zone's way in).
//!
//! **Keeping the dock in view** (ours). The field is computed from where the robot is, not
//! from what it sees: in the coercive zone the tangential pull points up to 90° away from
//! the dock, and a robot whose camera looks along its motion (Bujold backs in watching the
//! flap through a 70° lens) turns the fiducial out of the image, falls back to search,
//! reacquires and turns away again. Arkin & Murphy's robot bounded its approach zone by
//! its optics for the same reason. So the field's direction is clamped to within
//! `max_off_sight` of the line of sight to the dock; π leaves it free (an omnidirectional
//! or independent sensor).

use super::vector::MotionVector;
use crate::geometry::{Pose2, Twist, wrap_angle};

/// The potential-field docking schema.
///
/// # Example
///
/// On the axis the field is pure attraction, straight at the dock (−x) at the gain.
/// 60° off the axis (outside the 22.5° sector) it swings toward the axis: its −y
/// component outweighs its pull toward the dock. A robot backing in (`drive_dir` −1) on
/// the axis, facing away from the dock, backs straight in.
///
/// ```
/// use marsupial::geometry::Pose2;
/// use marsupial::schemas::PotentialField;
///
/// let pf = PotentialField {
///     sector: 22.5f64.to_radians(),
///     coercive_attraction: 0.3,
///     gain: 0.1,
///     k_theta: 1.5,
///     max_off_sight: std::f64::consts::PI,
///     final_radius: 0.0,
/// };
/// let v = pf.field(1.0, 0.0);
/// assert!((v.x + 0.1).abs() < 1e-12 && v.y.abs() < 1e-12);
///
/// let a = 60f64.to_radians();
/// let v = pf.field(1.0, a);
/// let toward_dock = -(v.x * a.cos() + v.y * a.sin());
/// let toward_axis = -(v.x * -a.sin() + v.y * a.cos());
/// assert!(toward_axis > toward_dock && toward_dock > 0.0);
/// assert!((v.norm() - 0.1).abs() < 1e-12);
/// // Within half a metre the field slows down.
/// assert!(pf.field(0.2, 0.0).norm() < 0.1);
///
/// let t = pf.twist(&Pose2::new(1.0, 0.0, 0.0), -1.0);
/// assert!((t.v + 0.1).abs() < 1e-12 && t.omega.abs() < 1e-12);
/// ```
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
    /// Largest angle between the field's direction and the line of sight to the dock, rad
    /// (half the camera's field of view less a margin; π: unconstrained).
    pub max_off_sight: f64,
    /// Radius of the final zone, m (0: the tangential weight does not fade with distance).
    pub final_radius: f64,
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
        let fade = if self.final_radius > 0.0 {
            ((rho - self.final_radius) / self.final_radius).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let wt = wt * fade;
        let v = MotionVector::weighted_sum([(wa, a), (wt, t)]).normalized();
        let sight = a.angle();
        let off = wrap_angle(v.angle() - sight).clamp(-self.max_off_sight, self.max_off_sight);
        MotionVector::from_polar(self.gain * (rho / 0.5).clamp(0.2, 1.0), sight + off)
    }

    /// The field at `pose` (dock frame) in the robot's body frame, flipped for rear-first
    /// motion (`drive_dir` −1) so that its angle is the heading error of the leading end.
    pub fn body_vector(&self, pose: &Pose2, drive_dir: f64) -> MotionVector {
        let rho = pose.x.hypot(pose.y);
        let alpha = pose.y.atan2(pose.x);
        let v = self.field(rho, alpha);
        let (s, c) = pose.theta.sin_cos();
        MotionVector::new(c * v.x + s * v.y, -s * v.x + c * v.y).scale(drive_dir)
    }

    /// The twist for a robot at `pose` (dock frame) that can turn and drive at once.
    /// `drive_dir` −1 means the robot moves rear first (its rear must lead along the
    /// field). A turn-or-drive base instead steers on the heading error
    /// `body_vector(..).angle()`.
    pub fn twist(&self, pose: &Pose2, drive_dir: f64) -> Twist {
        let t = self.body_vector(pose, drive_dir).to_twist(self.k_theta);
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
            max_off_sight: std::f64::consts::PI,
            final_radius: 0.0,
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
    fn a_camera_limited_field_stays_within_sight_of_the_dock() {
        let mut p = pf();
        p.max_off_sight = 25f64.to_radians();
        for alpha_deg in [-80.0, -60.0, -30.0, -10.0, 0.0, 10.0, 30.0, 60.0, 80.0] {
            let alpha = f64::to_radians(alpha_deg);
            let (free, held) = (pf().field(1.0, alpha), p.field(1.0, alpha));
            let sight = (-alpha.sin()).atan2(-alpha.cos());
            let off = wrap_angle(held.angle() - sight);
            assert!(
                off.abs() <= p.max_off_sight + 1e-9,
                "{alpha_deg}°: {}",
                off.to_degrees()
            );
            // Same side of the line of sight as the free field, same speed.
            assert!(off * wrap_angle(free.angle() - sight) >= 0.0, "{alpha_deg}°");
            assert!((held.norm() - free.norm()).abs() < 1e-12);
        }
        // Deep in the coercive zone the free field points ~70° off the sight line.
        let free = pf().field(1.0, 60f64.to_radians());
        assert!(wrap_angle(free.angle() - (-60f64.to_radians().sin()).atan2(-0.5)).abs() > 1.0);
    }

    #[test]
    fn in_the_final_zone_the_robot_points_at_the_entrance() {
        let mut p = pf();
        p.final_radius = 0.4;
        let alpha = 5f64.to_radians();
        let sight = (-alpha.sin()).atan2(-alpha.cos());
        let off = |rho: f64| wrap_angle(p.field(rho, alpha).angle() - sight).abs();
        // Beyond twice the radius: the full field; inside the radius: pure attraction.
        assert!((off(1.0) - wrap_angle(pf().field(1.0, alpha).angle() - sight).abs()).abs() < 1e-12);
        assert!(off(0.8) > 0.1 && off(0.4) < 1e-12 && off(0.2) < 1e-12);
        // Fading in between, monotonically.
        assert!(off(0.5) < off(0.6) && off(0.6) < off(0.7) && off(0.5) > 0.0);
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
