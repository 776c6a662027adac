//! RAPOSA's region-I visual servo laws (seed 001 §II.E), on the ellipse of the orange
//! guide.
//!
//! * speed: constant `far_speed` beyond `far_distance`; closer, v = K_lin·√(A₁/A), where
//!   A₁ is the ball's area at 1 m and A the current area: the area falls with the square
//!   of distance, so v ≈ K_lin·d falls linearly as the robot closes in;
//! * turn: ω = −K_ang·x_dev, x_dev the ellipse centre's offset from the image centre
//!   (positive right). The sign holds for a backward-looking camera too: turning the body
//!   turns the camera by the same angle;
//! * arm: −K_arm·y_dev, set once at the end of state 1 (lowering the back onto the
//!   target's height).
//!
//! Speeds are in the camera's direction of travel ("forward" in the paper, which is the
//! robot's backward): [`ServoLaw::twist`] turns them into a body twist for a camera that
//! looks forward or backward.

use crate::geometry::Twist;

/// The state-1 law's gains.
///
/// # Example
///
/// ```
/// use marsupial::schemas::ServoLaw;
///
/// let law = ServoLaw {
///     k_lin: 0.045,
///     k_ang: 0.004,
///     k_arm: 0.003,
///     far_speed: 0.05,
///     far_distance: 1.0,
///     camera_backward: true,
/// };
/// assert_eq!(law.speed(2.0, 2.0), 0.05, "far: constant");
/// // Near: K_lin·√(A₁/A); the ball's area is 4 × its area at 1 m, so √(A₁/A) = 0.5.
/// assert!((law.speed(0.5, 0.5) - 0.0225).abs() < 1e-12);
/// // A ball 10 px right of centre: turn clockwise; 20 px low: arm −0.06 rad.
/// assert!((law.turn(10.0) + 0.04).abs() < 1e-12);
/// assert!((law.arm(20.0) + 0.06).abs() < 1e-12);
/// // The camera looks backward: travel toward the target is body-backward.
/// let t = law.twist(0.03, 0.1);
/// assert_eq!((t.v, t.omega), (-0.03, 0.1));
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ServoLaw {
    /// K_lin, m/s at 1 m.
    pub k_lin: f64,
    /// K_ang, rad/s per px.
    pub k_ang: f64,
    /// K_arm, rad per px.
    pub k_arm: f64,
    /// Constant speed far away, m/s.
    pub far_speed: f64,
    /// Distance beyond which the speed is constant, m.
    pub far_distance: f64,
    /// True when the camera looks backward (travel toward the target is body-backward).
    pub camera_backward: bool,
}

impl ServoLaw {
    /// Speed toward the target for a camera-to-ball distance `d` (m) and ellipse area
    /// ratio √(A₁/A) = `area_root`.
    pub fn speed(&self, d: f64, area_root: f64) -> f64 {
        if d >= self.far_distance {
            self.far_speed
        } else {
            (self.k_lin * area_root).min(self.far_speed)
        }
    }

    /// ω = −K_ang·x_dev.
    pub fn turn(&self, x_dev_px: f64) -> f64 {
        -self.k_ang * x_dev_px
    }

    /// Arm angle −K_arm·y_dev.
    pub fn arm(&self, y_dev_px: f64) -> f64 {
        -self.k_arm * y_dev_px
    }

    /// Body twist for speed `v` toward the target and yaw rate `omega`.
    pub fn twist(&self, v: f64, omega: f64) -> Twist {
        Twist::new(if self.camera_backward { -v } else { v }, omega)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn law() -> ServoLaw {
        ServoLaw {
            k_lin: 0.045,
            k_ang: 0.004,
            k_arm: 0.003,
            far_speed: 0.05,
            far_distance: 1.0,
            camera_backward: true,
        }
    }

    #[test]
    fn speed_is_constant_far_and_linear_near() {
        let l = law();
        assert_eq!(l.speed(2.0, 2.0), 0.05);
        assert!((l.speed(0.5, 0.5) - 0.0225).abs() < 1e-12);
        assert!(
            (l.speed(0.25, 0.25) * 2.0 - l.speed(0.5, 0.5)).abs() < 1e-12,
            "linear in √(A₁/A)"
        );
    }

    #[test]
    fn turn_and_arm_oppose_the_deviation_and_travel_is_backward() {
        let l = law();
        assert!(l.turn(10.0) < 0.0 && l.turn(-10.0) > 0.0 && l.turn(0.0) == 0.0);
        assert!((l.arm(20.0) + 0.06).abs() < 1e-12);
        assert!(l.twist(0.03, 0.1).v < 0.0);
        assert!(
            ServoLaw {
                camera_backward: false,
                ..l
            }
            .twist(0.03, 0.1)
            .v > 0.0
        );
    }
}
