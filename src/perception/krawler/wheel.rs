//! Wheel rotation θ from tread features (seed 003 §V-C): the geometry and the
//! statistics, given tracked pixel positions of features on a wheel's tread.
//!
//! * [`WheelCylinder`]: the wheel as a finite cylinder (radius r, axis from the axle's
//!   roll and the steering), with the ray-cylinder intersection that puts a tracked
//!   pixel on the tread in body coordinates, and the observation window's centre, the
//!   tread point 60° up the wheel's front or back (the paper's w60).
//! * [`WheelCylinder::step_angle`]: a feature's angular step between two frames. Its
//!   size is the paper's chord formula, cos⁻¹((2r² − |p1 − p2|²) / 2r²). The formula
//!   has no sign, so ours takes it from the turn of the two positions about the wheel's
//!   axis, sign(((p1 − c) × (p2 − c)) · a), with a the axis pointing to the wheel's left:
//!   positive θ rolls the robot forward.
//! * [`ransac_angle`]: the paper's RANSAC over the per-feature steps (one step as the
//!   model, the steps within a tolerance as its inliers, the largest set wins, its mean
//!   is the frame's step). The random generator comes from the caller, so a sequence
//!   and a seed give the same estimate.
//! * [`TurnCounter`]: θ accumulated frame by frame and snapped to the correction marker
//!   once per turn. The paper's eq. 7, m = (θ − c₀) div 2π, floors: when θ has
//!   under-counted by a little, the floor throws away a whole turn. Ours rounds to the
//!   nearest turn, which is right for either sign of the accumulated error up to half a
//!   turn.

use nalgebra::{Point3, Unit, Vector3};
use std::f64::consts::TAU;

/// A wheel as a finite cylinder, in body coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WheelCylinder {
    /// Centre of the wheel (on its axis, midway across the tread), m.
    pub centre: Point3<f64>,
    /// The axis, pointing to the wheel's left (the robot's left when straight).
    pub axis: Unit<Vector3<f64>>,
    /// Tread radius r, m.
    pub radius: f64,
    /// Half the tread's width, m.
    pub half_width: f64,
}

impl WheelCylinder {
    /// Where the ray `origin + t·dir` (t > 0) first meets the tread (the cylinder's side
    /// within the tread's width), or `None`.
    pub fn on_tread(&self, origin: Point3<f64>, dir: Vector3<f64>) -> Option<Point3<f64>> {
        let a = self.axis.into_inner();
        // Components perpendicular to the axis.
        let oc = origin - self.centre;
        let d_perp = dir - a * dir.dot(&a);
        let o_perp = oc - a * oc.dot(&a);
        let qa = d_perp.norm_squared();
        if qa < 1e-18 {
            return None;
        }
        let qb = 2.0 * d_perp.dot(&o_perp);
        let qc = o_perp.norm_squared() - self.radius * self.radius;
        let disc = qb * qb - 4.0 * qa * qc;
        if disc < 0.0 {
            return None;
        }
        let sq = disc.sqrt();
        for t in [(-qb - sq) / (2.0 * qa), (-qb + sq) / (2.0 * qa)] {
            if t <= 0.0 {
                continue;
            }
            let p = origin + dir * t;
            if (p - self.centre).dot(&a).abs() <= self.half_width {
                return Some(p);
            }
        }
        None
    }

    /// The signed angular step of a tread point seen at `p1` then at `p2` (both on the
    /// tread), rad: the chord formula's size with the sign of the turn about the axis
    /// (positive rolls forward, see the module docs).
    pub fn step_angle(&self, p1: Point3<f64>, p2: Point3<f64>) -> f64 {
        let r2 = self.radius * self.radius;
        let chord2 = (p1 - p2).norm_squared();
        let size = ((2.0 * r2 - chord2) / (2.0 * r2)).clamp(-1.0, 1.0).acos();
        let turn = (p1 - self.centre).cross(&(p2 - self.centre)).dot(&self.axis);
        if turn < 0.0 { -size } else { size }
    }

    /// The observation window's centre on the tread, 60° up from the wheel's centre
    /// toward its front (`front` true) or back: the paper's w60 = [0, ±r cos 60°,
    /// r sin 60°] in the wheel's frame, with `forward` the wheel's heading (the
    /// direction it rolls, perpendicular to the axis) and up completing the frame.
    pub fn window_centre(&self, forward: Vector3<f64>, front: bool) -> Point3<f64> {
        let a = self.axis.into_inner();
        let fwd = (forward - a * forward.dot(&a)).normalize();
        let up = fwd.cross(&a);
        let s = if front { 1.0 } else { -1.0 };
        self.centre + fwd * (s * self.radius * 60f64.to_radians().cos()) + up * (self.radius * 60f64.to_radians().sin())
    }
}

/// The RANSAC consensus of per-feature angular steps: `iterations` times, one step
/// drawn by `draw(n)` (an index below n, from the caller's generator) is the model and
/// the steps within `tolerance` of it its inliers; the largest set (the first drawn on a
/// tie) gives the mean. Returns (mean step, inliers), or `None` without steps.
pub fn ransac_angle(
    steps: &[f64],
    tolerance: f64,
    iterations: usize,
    mut draw: impl FnMut(usize) -> usize,
) -> Option<(f64, usize)> {
    if steps.is_empty() {
        return None;
    }
    let mut best = (0usize, 0.0f64);
    for _ in 0..iterations.max(1) {
        let model = steps[draw(steps.len()) % steps.len()];
        let (mut n, mut sum) = (0usize, 0.0);
        for &s in steps {
            if (s - model).abs() <= tolerance {
                n += 1;
                sum += s;
            }
        }
        if n > best.0 {
            best = (n, sum / n as f64);
        }
    }
    Some((best.1, best.0))
}

/// A wheel's rotation θ, accumulated from per-frame steps and corrected once per turn
/// by the white correction marker.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TurnCounter {
    /// The rotation, rad.
    pub theta: f64,
    /// θ at the first sighting of the correction marker (the paper's c₀), once seen.
    pub c0: Option<f64>,
}

impl TurnCounter {
    /// Adds one frame's step, rad.
    pub fn step(&mut self, delta: f64) {
        self.theta += delta;
    }

    /// The correction marker is seen in its place: the first time, remember θ as c₀;
    /// after that, snap θ to the nearest 2πm + c₀ (eq. 7 with rounding instead of the
    /// printed floor, see the module docs). Returns the correction applied, rad.
    pub fn marker_seen(&mut self) -> f64 {
        self.snap(self.theta)
    }

    /// As [`TurnCounter::marker_seen`], for a sighting whose θ was `at` (for example the
    /// midpoint of the frames the marker was seen in, which does not depend on the
    /// direction of rotation): the correction `at` needs is added to the current θ. The
    /// first sighting remembers `at` as c₀. Returns the correction applied, rad.
    pub fn snap(&mut self, at: f64) -> f64 {
        match self.c0 {
            None => {
                self.c0 = Some(at);
                0.0
            }
            Some(c0) => {
                let m = ((at - c0) / TAU).round();
                let delta = m * TAU + c0 - at;
                self.theta += delta;
                delta
            }
        }
    }
}

/// Eq. 7 exactly as printed, m = (θ − c₀) div 2π (floor), for comparison in tests and
/// docs: it loses a turn whenever θ under-counts.
pub fn paper_correction(theta: f64, c0: f64) -> f64 {
    ((theta - c0) / TAU).floor() * TAU + c0
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn wheel() -> WheelCylinder {
        WheelCylinder {
            centre: Point3::new(0.33, 0.28, 0.115),
            axis: Vector3::y_axis(),
            radius: 0.115,
            half_width: 0.04,
        }
    }

    /// A tread point at rotation φ (0 on top, positive rolling forward) and across
    /// offset s.
    fn tread(w: &WheelCylinder, phi: f64, s: f64) -> Point3<f64> {
        w.centre + Vector3::new(w.radius * phi.sin(), s, w.radius * phi.cos())
    }

    proptest! {
        /// The step between two tread points is their rotation, with its sign.
        #[test]
        fn the_signed_chord_angle_is_the_rotation(phi in -3.0f64..3.0, step in -1.5f64..1.5, s1 in -0.04f64..0.04) {
            let w = wheel();
            let got = w.step_angle(tread(&w, phi, s1), tread(&w, phi + step, s1));
            prop_assert!((got - step).abs() < 1e-9, "{got} vs {step}");
        }

        /// A ray from a camera above and inside the wheel meets the tread where the
        /// point it was aimed at lies (on the upper quarter facing the camera, which the
        /// rest of the wheel does not hide).
        #[test]
        fn rays_meet_the_tread_where_aimed(phi in -1.4f64..-0.3, s in -0.035f64..0.035) {
            let w = wheel();
            let camera = Point3::new(0.0, 0.0, 0.40);
            let target = tread(&w, phi, s);
            let p = w.on_tread(camera, target - camera).expect("hits");
            prop_assert!((p - target).norm() < 1e-9, "{p:?} vs {target:?}");
        }

        /// With up to 40 % wild outliers among steps clustered around the truth, the
        /// consensus is within the cluster's spread of it.
        #[test]
        fn ransac_ignores_outliers(truth in -0.3f64..0.3, n in 10usize..40, frac in 0.0f64..0.4, seed in any::<u64>()) {
            let mut s = seed | 1;
            let mut next = move || { s ^= s << 13; s ^= s >> 7; s ^= s << 17; s };
            let outliers = (frac * n as f64) as usize;
            let steps: Vec<f64> = (0..n)
                .map(|i| {
                    let u = (next() % 10_000) as f64 / 10_000.0;
                    if i < outliers { truth + 0.1 + 2.0 * u } else { truth + 0.004 * (u - 0.5) }
                })
                .collect();
            let (mean, inliers) = ransac_angle(&steps, 0.01, 50, |k| (next() % k as u64) as usize).unwrap();
            prop_assert!((mean - truth).abs() < 0.003, "{mean} vs {truth}");
            prop_assert!(inliers >= n - outliers);
        }
    }

    #[test]
    fn the_correction_rounds_to_the_nearest_turn_both_ways() {
        let c0 = 0.7;
        for (err, turns) in [(-0.3, 3.0), (0.3, 3.0), (-2.9, 5.0), (2.9, 5.0)] {
            let mut t = TurnCounter {
                theta: c0 + turns * TAU + err,
                c0: Some(c0),
            };
            let applied = t.marker_seen();
            assert!((t.theta - (c0 + turns * TAU)).abs() < 1e-12, "{err}: {t:?}");
            assert!((applied + err).abs() < 1e-12);
        }
        // The printed eq. 7 floors: an under-count loses a whole turn.
        let under = paper_correction(c0 + 3.0 * TAU - 0.3, c0);
        assert!((under - (c0 + 2.0 * TAU)).abs() < 1e-12);
        let over = paper_correction(c0 + 3.0 * TAU + 0.3, c0);
        assert!((over - (c0 + 3.0 * TAU)).abs() < 1e-12);
        // The first sighting only remembers c₀.
        let mut t = TurnCounter::default();
        t.step(1.25);
        assert_eq!(t.marker_seen(), 0.0);
        assert_eq!(t.c0, Some(1.25));
    }

    #[test]
    fn rays_that_miss_and_empty_steps() {
        let w = wheel();
        let camera = Point3::new(0.0, 0.0, 0.40);
        assert!(w.on_tread(camera, Vector3::new(-1.0, 0.0, 0.0)).is_none());
        assert!(
            w.on_tread(camera, Vector3::new(0.0, 1.0, 0.0)).is_none(),
            "parallel to the axis"
        );
        assert!(ransac_angle(&[], 0.01, 10, |_| 0).is_none());
        let c = w.window_centre(Vector3::x(), true);
        assert!(
            (c - tread(&w, 30f64.to_radians(), 0.0)).norm() < 1e-12,
            "60° up the front is φ = 30°"
        );
    }
}
