//! The exposed tether of a leading-arm rover (Axel, seed 000 §IV-A-2), and how fast to
//! reel along an arc so it neither slackens nor tangles.
//!
//! The tether runs from the tip of the rover's arm (`d_arm` ahead of the axle) to an
//! anchor inside the module. With the axle `d_rvr` from the anchor at angle α about the
//! module's axis, and the heading h from that axis (see [`super::two_arc`]), the cosine
//! law gives the exposed length (seed 000 eq. 1):
//!
//! d_tether = √(d_arm² + d_rvr² − 2·d_arm·d_rvr·cos(α − h)).
//!
//! As in the paper, the reel follows each arc by the change of length between its ends,
//! at a constant rate over the arc's duration (the linear approximation the paper found
//! sufficient for turns under about 30°, §V-F); [`TetherGeometry::length_at`] gives the
//! instantaneous length for finer control. Polar coordinates here are about the anchor,
//! not the mouth: the tether pulls toward the anchor.

use super::two_arc::Arc;
use crate::geometry::{Pose2, wrap_angle};
use std::f64::consts::PI;

/// Seed 000 eq. 1: the exposed tether from the arm's tip to the anchor, m, for an arm
/// `d_arm`, the axle `d_rvr` from the anchor at angle `alpha`, heading `h` from the axis.
pub fn exposed_length(d_arm: f64, d_rvr: f64, alpha: f64, h: f64) -> f64 {
    (d_arm * d_arm + d_rvr * d_rvr - 2.0 * d_arm * d_rvr * (alpha - h).cos())
        .max(0.0)
        .sqrt()
}

/// Where the tether is anchored and the arm it leaves from (module frame).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TetherGeometry {
    /// The anchor, module frame, m (on the axis, `anchor_depth_m` inside the face).
    pub anchor: (f64, f64),
    /// The arm, axle to tip, m.
    pub arm: f64,
}

impl TetherGeometry {
    /// The anchor `anchor_depth` m inside the module on its axis, arm `arm` m.
    pub fn new(anchor_depth: f64, arm: f64) -> Self {
        Self {
            anchor: (-anchor_depth, 0.0),
            arm,
        }
    }

    /// The exposed length with the rover at module-frame `pose`, by eq. 1.
    pub fn length_at(&self, pose: &Pose2) -> f64 {
        let (dx, dy) = (pose.x - self.anchor.0, pose.y - self.anchor.1);
        exposed_length(self.arm, dx.hypot(dy), dy.atan2(dx), wrap_angle(pose.theta - PI))
    }

    /// The change of exposed length over `arc` from `from`, m (negative: shorter).
    pub fn change_along(&self, from: &Pose2, arc: &Arc) -> f64 {
        self.length_at(&arc.end(from)) - self.length_at(from)
    }

    /// The reel rate (m/s, positive reels in) that follows `arc` from `from` driven at
    /// `speed` m/s: the change of length over the arc's duration, the paper's linear
    /// approximation. 0 for an arc of no length or a non-positive speed.
    pub fn reel_rate(&self, from: &Pose2, arc: &Arc, speed: f64) -> f64 {
        if arc.length.abs() < 1e-9 || speed <= 0.0 {
            return 0.0;
        }
        let duration = arc.length.abs() / speed;
        -self.change_along(from, arc) / duration
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The tip's distance from the anchor, directly.
    fn direct(g: &TetherGeometry, p: &Pose2) -> f64 {
        let tip = p.to_world(g.arm, 0.0);
        (tip.0 - g.anchor.0).hypot(tip.1 - g.anchor.1)
    }

    #[test]
    fn facing_the_anchor_the_tether_is_the_distance_less_the_arm() {
        let g = TetherGeometry::new(0.25, 0.55);
        let p = Pose2::new(3.0, 0.0, PI);
        assert!((g.length_at(&p) - (3.25 - 0.55)).abs() < 1e-12);
        // Driving straight in 1 m shortens it by 1 m: reel in at the driving speed.
        let arc = Arc {
            curvature: 0.0,
            length: 1.0,
        };
        assert!((g.change_along(&p, &arc) + 1.0).abs() < 1e-12);
        assert!((g.reel_rate(&p, &arc, 0.08) - 0.08).abs() < 1e-12);
        // Reversing pays out.
        let back = Arc {
            curvature: 0.0,
            length: -0.5,
        };
        assert!((g.reel_rate(&p, &back, 0.08) + 0.08).abs() < 1e-12);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(128))]

        /// Along random arcs from random poses, eq. 1 is the tip's distance to the anchor.
        #[test]
        fn the_cosine_law_matches_the_geometry_along_random_arcs(
            x in 0.5f64..7.0, y in -5.0f64..5.0, th in -PI..PI,
            k in -2.0f64..2.0, len in -3.0f64..3.0, arm in 0.1f64..1.0, depth in 0.0f64..0.5,
        ) {
            let g = TetherGeometry::new(depth, arm);
            let from = Pose2::new(x, y, th);
            let arc = Arc { curvature: k, length: len };
            for i in 0..=20 {
                let p = arc.at(&from, len * i as f64 / 20.0);
                prop_assert!((g.length_at(&p) - direct(&g, &p)).abs() < 1e-9, "{p:?}");
            }
            let change = g.change_along(&from, &arc);
            prop_assert!((change - (direct(&g, &arc.end(&from)) - direct(&g, &from))).abs() < 1e-9);
        }
    }
}
