//! The region-II alignment manoeuvre (seed 001 §II.C.2, Fig. 3): rotate −β, travel d,
//! rotate φ, landing on the pyramid axis at distance δ, facing the pyramid.
//!
//! Planned in the **ball frame**: origin at the ball, +x along the pyramid axis out toward
//! the approach side. From a pair, the camera sits at D·(cos α, sin α) (D camera to ball)
//! and looks at the ball offset by its bearing, which places the robot. The target puts
//! the socket (the robot's rear) at (δ, 0) with the camera facing the ball. The robot
//! travels front first or back first, whichever needs the smaller first rotation: a robot
//! already inside δ (the paper's points 4 and 6) backs away from the pyramid, which is why
//! those points were the slowest in the paper.

use crate::geometry::{Pose2, wrap_angle};
use crate::perception::pyramid_pose::PyramidView;
use std::f64::consts::PI;

/// The manoeuvre, in the ball frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Region2Plan {
    /// The robot's pose when planned.
    pub start: Pose2,
    /// Target of the robot's centre.
    pub target: (f64, f64),
    /// Body heading to travel on.
    pub travel_heading: f64,
    /// Travel back first (camera leading).
    pub reverse: bool,
    /// First rotation (−β in the paper's terms), rad, CCW positive.
    pub rotation: f64,
    /// Travel distance d, m.
    pub distance: f64,
    /// Last rotation φ, rad.
    pub final_rotation: f64,
}

/// The robot's pose in the ball frame from a pair's reading. `camera_x` is the camera's
/// position along the body axis (negative: behind the centre); the camera looks backward.
pub fn robot_in_ball_frame(view: &PyramidView, alpha: f64, camera_x: f64) -> Pose2 {
    let d = view.ball_distance_m;
    let cam = (d * alpha.cos(), d * alpha.sin());
    // The camera looks along (α + π − bearing); the body faces the opposite way.
    let theta = wrap_angle(alpha - view.bearing);
    let (s, c) = theta.sin_cos();
    Pose2::new(cam.0 - camera_x * c, cam.1 - camera_x * s, theta)
}

/// Plans the manoeuvre from `start` to the socket at distance `delta` on the axis;
/// `half_length` is the centre-to-rear distance.
pub fn plan(start: Pose2, delta: f64, half_length: f64) -> Region2Plan {
    plan_to(start, (delta + half_length, 0.0), 0.0)
}

/// The same manoeuvre to any `target` of the robot's centre in the ball frame, ending at
/// heading `final_heading`: rotate onto the line to the target (front or back first,
/// whichever turns less), travel, rotate.
pub fn plan_to(start: Pose2, target: (f64, f64), final_heading: f64) -> Region2Plan {
    let (dx, dy) = (target.0 - start.x, target.1 - start.y);
    let forward = dy.atan2(dx);
    let backward = wrap_angle(forward + PI);
    let (rf, rb) = (wrap_angle(forward - start.theta), wrap_angle(backward - start.theta));
    let (travel_heading, rotation, reverse) = if rf.abs() <= rb.abs() {
        (forward, rf, false)
    } else {
        (backward, rb, true)
    };
    Region2Plan {
        start,
        target,
        travel_heading,
        reverse,
        rotation,
        distance: dx.hypot(dy),
        final_rotation: wrap_angle(final_heading - travel_heading),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn view(d: f64, bearing: f64) -> PyramidView {
        PyramidView {
            blue_distance_m: Some(d + 0.16),
            ball_distance_m: d,
            alpha: None,
            alpha_saturated: false,
            bearing,
            dev_px: [0.0, 0.0],
            area_px: 100,
        }
    }

    #[test]
    fn robot_pose_from_a_pair() {
        // On the axis, looking straight at the ball: heading 0 (front away from the ball),
        // centre 0.3 m further out than the camera.
        let p = robot_in_ball_frame(&view(1.0, 0.0), 0.0, -0.3);
        assert!((p.x - 1.3).abs() < 1e-12 && p.y.abs() < 1e-12 && p.theta.abs() < 1e-12);
        // At 90°, ball 0.1 rad left of the optical axis.
        let p = robot_in_ball_frame(&view(1.0, 0.1), PI / 2.0, -0.3);
        assert!((p.theta - (PI / 2.0 - 0.1)).abs() < 1e-12);
    }

    #[test]
    fn plan_lands_on_the_axis_and_faces_the_pyramid() {
        for (alpha_deg, d) in [(30.0f64, 1.33), (60.0, 2.0), (-60.0, 1.33), (90.0, 1.5), (110.0, 1.5)] {
            let a = alpha_deg.to_radians();
            let start = robot_in_ball_frame(&view(d, 0.0), a, -0.3);
            let pl = plan(start, 0.9, 0.4);
            // Executing the plan exactly ends at the target, heading 0.
            let h1 = wrap_angle(start.theta + pl.rotation);
            assert!((h1 - pl.travel_heading).abs() < 1e-9);
            let dir = if pl.reverse { h1 + PI } else { h1 };
            let end = (start.x + pl.distance * dir.cos(), start.y + pl.distance * dir.sin());
            assert!((end.0 - 1.3).abs() < 1e-9 && end.1.abs() < 1e-9, "{alpha_deg}");
            assert!(wrap_angle(h1 + pl.final_rotation).abs() < 1e-9);
            assert!(
                pl.rotation.abs() <= PI / 2.0 + 1e-9,
                "never more than a quarter turn first"
            );
        }
    }

    #[test]
    fn inside_delta_backs_away_front_first() {
        // Point 4/6 of the grid: 0.5 m at 30°, socket target 0.9 m out: the robot drives
        // away from the pyramid, i.e. front first (its front faces away).
        let start = robot_in_ball_frame(&view(0.6, 0.0), 30f64.to_radians(), -0.3);
        let pl = plan(start, 0.9, 0.4);
        assert!(!pl.reverse);
    }
}
