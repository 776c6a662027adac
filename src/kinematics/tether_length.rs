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
//! sufficient for turns under about 30°, §V-F). Ours also closes the loop on the reel's
//! own length reading at the arc's start ([`TetherGeometry::pay_out_along`]), so slack
//! from slip or a turn in place does not accumulate from step to step;
//! [`TetherGeometry::length_at`] gives the instantaneous length for finer control. Polar coordinates here are about the anchor,
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

    /// The farthest the axle can be from the mouth with `exposed` m of tether paid out, m:
    /// the tip lies within `exposed` of the anchor and the axle within the arm of the tip.
    /// Exact for a taut tether with the arm pointing at the anchor from the module's axis;
    /// off the axis the anchor's depth shortens the span by `depth·(1 − cos α)`, under
    /// 6 cm within α = 40°. Slack only makes the true distance shorter. The paper had no
    /// range sensor beyond the cameras; the reel's own length reading is this one.
    pub fn farthest_from_mouth(&self, exposed: f64) -> f64 {
        exposed.max(0.0) + self.arm + self.anchor.0
    }

    /// The change of exposed length over `arc` from `from`, m (negative: shorter).
    pub fn change_along(&self, from: &Pose2, arc: &Arc) -> f64 {
        self.length_at(&arc.end(from)) - self.length_at(from)
    }

    /// How far the paper's linear approximation strays along `arc` from `from`, m: the
    /// largest difference, over 32 equal steps, between the exact exposed length and the
    /// straight line from its start value to its end value that a constant reel rate
    /// pays out. The paper found the approximation sufficient for turns under about 30°
    /// (§V-F); `tests`' table measures it over the approach workspace.
    pub fn linear_error(&self, from: &Pose2, arc: &Arc) -> f64 {
        let (l0, l1) = (self.length_at(from), self.length_at(&arc.end(from)));
        (1..32)
            .map(|i| {
                let f = i as f64 / 32.0;
                (self.length_at(&arc.at(from, arc.length * f)) - (l0 + (l1 - l0) * f)).abs()
            })
            .fold(0.0, f64::max)
    }

    /// The tether to pay out over `arc` from `from`, m (negative: reel in), so that it
    /// ends the arc just taut: the exposed length at the arc's end less what the reel
    /// has paid out at its start (`paid_out`, the reel's own length reading). That is
    /// the change of length along the arc plus whatever the reading differs from the
    /// exposed length at the start: slack left by wheel slip on the last arc or by a
    /// turn in place is taken up, a stretched tether eased. Without a reading, the change
    /// along the arc alone (the paper's open-loop reel).
    pub fn pay_out_along(&self, paid_out: Option<f64>, from: &Pose2, arc: &Arc) -> f64 {
        match paid_out {
            Some(l) => self.length_at(&arc.end(from)) - l,
            None => self.change_along(from, arc),
        }
    }

    /// The reel rate (m/s, positive reels in) over `arc` from `from` driven at `speed`
    /// m/s: [`TetherGeometry::pay_out_along`] spread evenly over the arc's duration, the
    /// paper's linear approximation. 0 for an arc of no length or a non-positive speed.
    pub fn reel_rate(&self, paid_out: Option<f64>, from: &Pose2, arc: &Arc, speed: f64) -> f64 {
        if arc.length.abs() < 1e-9 || speed <= 0.0 {
            return 0.0;
        }
        let duration = arc.length.abs() / speed;
        -self.pay_out_along(paid_out, from, arc) / duration
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
        assert!((g.reel_rate(None, &p, &arc, 0.08) - 0.08).abs() < 1e-12);
        // Reversing pays out.
        let back = Arc {
            curvature: 0.0,
            length: -0.5,
        };
        assert!((g.reel_rate(None, &p, &back, 0.08) + 0.08).abs() < 1e-12);
        // With the reel's reading: 10 cm of slack at the start is taken up over the arc
        // as well (1.1 m reeled in over 12.5 s), and a tether read 10 cm short of the
        // exposed length (stretched) is eased (0.9 m).
        let l = g.length_at(&p);
        assert!((g.pay_out_along(Some(l + 0.1), &p, &arc) + 1.1).abs() < 1e-12);
        assert!((g.reel_rate(Some(l + 0.1), &p, &arc, 0.08) - 1.1 / 12.5).abs() < 1e-12);
        assert!((g.pay_out_along(Some(l - 0.1), &p, &arc) + 0.9).abs() < 1e-12);
        // A reading equal to the exposed length changes nothing.
        assert!((g.reel_rate(Some(l), &p, &back, 0.08) + 0.08).abs() < 1e-12);
    }

    /// The linear approximation's error against the arc's turn, over 4 000 arcs from the
    /// approach workspace (axle 1.5–5 m from the mouth, |α| ≤ 40°, |h| ≤ 30°; radius
    /// 0.5–4 m, at most 1.5 m long: an approach step), Axel's arm and anchor. Prints the
    /// table the README quotes (`cargo test --lib linear_approximation -- --nocapture`).
    #[test]
    fn the_linear_approximation_strays_with_the_turn() {
        let g = TetherGeometry::new(0.25, 0.55);
        let mut s = 0x2013u64;
        let mut rnd = move |lo: f64, hi: f64| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            lo + (hi - lo) * ((s >> 11) as f64 / (1u64 << 53) as f64)
        };
        let edges = [0.0, 15.0, 30.0, 45.0, 90.0];
        let mut errs: Vec<Vec<f64>> = vec![Vec::new(); 4];
        while errs.iter().map(Vec::len).sum::<usize>() < 4000 {
            let (r, a, h) = (
                rnd(1.5, 5.0),
                rnd(-40.0, 40.0).to_radians(),
                rnd(-30.0, 30.0).to_radians(),
            );
            let from = Pose2::new(r * a.cos(), r * a.sin(), PI + h);
            let turn = rnd(2.0, 90.0);
            let radius = rnd(0.5, 4.0);
            let length = turn.to_radians() * radius;
            if length > 1.5 {
                continue;
            }
            let sign = if rnd(0.0, 1.0) < 0.5 { -1.0 } else { 1.0 };
            let arc = Arc {
                curvature: sign / radius,
                length,
            };
            let bin = edges.windows(2).position(|w| turn >= w[0] && turn < w[1]).unwrap();
            errs[bin].push(g.linear_error(&from, &arc));
        }
        let mut means = [0.0; 4];
        println!("| turn | arcs | mean error | 95th percentile |");
        for (i, e) in errs.iter_mut().enumerate() {
            e.sort_by(f64::total_cmp);
            means[i] = e.iter().sum::<f64>() / e.len() as f64;
            let p95 = e[(e.len() * 95) / 100];
            println!(
                "| {}–{}° | {} | {:.1} cm | {:.1} cm |",
                edges[i],
                edges[i + 1],
                e.len(),
                means[i] * 100.0,
                p95 * 100.0
            );
        }
        // The error grows with the turn, bin by bin.
        assert!(means.windows(2).all(|w| w[0] < w[1]), "{means:?}");
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

        /// Whatever the heading and slack, the axle is no farther from the mouth than the
        /// reel's length says, give or take the anchor's depth off the axis; and the bound
        /// is exact facing the anchor from the axis.
        #[test]
        fn the_reel_length_bounds_the_distance_to_the_mouth(
            r in 0.7f64..8.0, alpha in -0.7f64..0.7, th in -PI..PI,
            slack in 0.0f64..1.0, arm in 0.1f64..1.0, depth in 0.0f64..0.5,
        ) {
            let g = TetherGeometry::new(depth, arm);
            let p = Pose2::new(r * alpha.cos(), r * alpha.sin(), th);
            let bound = g.farthest_from_mouth(g.length_at(&p) + slack);
            prop_assert!(r <= bound + depth * (1.0 - alpha.cos()) + 1e-9, "{r} > {bound}");
            if r > arm {
                let facing = Pose2::new(r, 0.0, PI);
                prop_assert!((g.farthest_from_mouth(g.length_at(&facing)) - r).abs() < 1e-9);
            }
        }
    }
}
