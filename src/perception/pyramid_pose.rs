//! RAPOSA's pyramid geometry (seed 001 §II.C.2) and what the pyramid schema reports.
//!
//! Pin-hole relations, with f the focal length in pixels:
//!
//! * distance from the blue height g: **d = f·h/g** (h the real blue edge length);
//! * from the top view, with c the horizontal image distance from the ellipse centre to
//!   the far side of the blue region and m the distance from the blue edges' midpoint to
//!   the ball: m·sin α + (h/2)·cos α = K with **K = c·h/g**. As a quadratic in s = sin α:
//!   (m² + h²/4)·s² − 2·K·m·s + (K² − h²/4) = 0, and the paper always takes the minus
//!   root, s = [K·m − (h/2)·√(m² + h²/4 − K²)] / (m² + h²/4), which gives α = 0 at
//!   c/g = ½. The left side peaks at α* = atan(2m/h) (73° for the paper's pyramid): the
//!   estimate is valid in [0, α*] and saturates beyond;
//! * when aligned, the distance from the ellipse area alone: d = √(A₁/A), A₁ being the
//!   ball's area at 1 m (computed from the profile's ball diameter and the focal length,
//!   where the paper used an offline reference image).
//!
//! Sign: α is the robot's angle around the pyramid axis, positive toward the dock frame's
//! +y. Seen from +y the blue edges (behind the ball) appear to the right of the ball, so a
//! ball left of the blue centre means α > 0.

use super::pyramid::{PyramidDetection, PyramidPair, PyramidShape};
use serde::Serialize;

/// The largest angle the quadratic can return, atan(2m/h), rad.
///
/// ```
/// use marsupial::perception::pyramid_pose::{alpha_from_k, max_alpha};
/// // The paper's pyramid: h = 10 cm, m = 16 cm.
/// let peak = max_alpha(0.10, 0.16);
/// assert!((peak.to_degrees() - 72.6).abs() < 0.1);
/// assert_eq!(alpha_from_k(1.0, 0.10, 0.16), peak, "K beyond the peak saturates");
/// ```
pub fn max_alpha(h: f64, m: f64) -> f64 {
    (2.0 * m / h).atan()
}

/// The minus root of the α quadratic for K = c·h/g, rad in [0, α*]. K beyond the peak
/// (no real root) saturates at α*; K ≤ h/2 gives 0.
///
/// ```
/// use marsupial::perception::pyramid_pose::alpha_from_k;
/// let (h, m) = (0.10, 0.16);
/// let k = |a: f64| m * a.sin() + h / 2.0 * a.cos();
/// assert!(alpha_from_k(h / 2.0, h, m).abs() < 1e-12);
/// assert!((alpha_from_k(k(0.5), h, m) - 0.5).abs() < 1e-9);
/// ```
pub fn alpha_from_k(k: f64, h: f64, m: f64) -> f64 {
    let a = m * m + h * h / 4.0;
    let disc = a - k * k;
    if disc <= 0.0 {
        return max_alpha(h, m);
    }
    let s = (k * m - h / 2.0 * disc.sqrt()) / a;
    s.clamp(0.0, 1.0).asin()
}

/// Camera and target constants of the pyramid geometry. A profile gives them through
/// `PyramidGeometry::from_profile` (in `profile`).
///
/// # Example
///
/// With f = 360 px and blue edges h = 10 cm tall, blue edges 18 px tall are
/// 360·0.1/18 = 2 m away. A ball whose centre is 9 px (half the blue height) from the
/// blue box's far side gives K = h/2, α = 0: the robot is on the axis; the ball further
/// left means α > 0. Without the blue edges the distance comes from the ball's area.
///
/// ```
/// use marsupial::perception::{BlueRegion, Ellipse, PyramidDetection, PyramidGeometry, PyramidPair};
///
/// let g = PyramidGeometry { f_px: 360.0, principal: [80.0, 60.0], h: 0.1, m: 0.16, ball_diameter: 0.07 };
/// assert!((g.distance_from_blue(18.0) - 2.0).abs() < 1e-12);
/// assert!((g.distance_from_area(g.reference_area_px() / 4.0) - 2.0).abs() < 1e-12);
/// assert!((g.shape().offset_ratio - 1.6).abs() < 1e-12);
///
/// let blue = BlueRegion { bbox: [60, 40, 77, 57], count: 200 }; // 18 × 18 px, centre x 68.5
/// let ball = |x: f64| Ellipse {
///     centre: [x, 50.0],
///     semi_major: 5.0,
///     semi_minor: 5.0,
///     angle: 0.0,
///     count: 80,
///     bbox: [0; 4],
/// };
/// let pair = |x: f64| PyramidPair { ellipse: ball(x), blue, score: 0.0 };
/// let (alpha, saturated) = g.alpha(&pair(68.5)); // c = 77 + 1 − 68.5 − 0.5 = 9 px
/// assert!(alpha.abs() < 1e-9 && !saturated);
/// assert!(g.alpha(&pair(62.5)).0 > 0.2); // c = 15 px
///
/// let det = PyramidDetection { pair: Some(pair(68.5)), ellipse: Some(ball(68.5)), blue: Some(blue), candidates: 1 };
/// let v = g.view(&det).unwrap();
/// assert!((v.blue_distance_m.unwrap() - 2.0).abs() < 1e-12);
/// assert!((v.ball_distance_m - (2.0 - 0.16)).abs() < 1e-9); // the ball is m in front
/// // The ball is 11 px left of the principal point: a bearing to the left (positive).
/// assert_eq!(v.dev_px, [-11.0, -9.5]);
/// assert!((v.bearing - (11.0f64 / 360.0).atan()).abs() < 1e-12);
///
/// // A ninth of the ball's area at 1 m (498.8 px): about 3 m.
/// let alone = Ellipse { count: 55, ..ball(68.5) };
/// let det = PyramidDetection { pair: None, ellipse: Some(alone), blue: None, candidates: 0 };
/// let v = g.view(&det).unwrap();
/// assert!(v.alpha.is_none() && v.blue_distance_m.is_none());
/// assert_eq!(v.ball_distance_m, g.distance_from_area(55.0));
/// assert!((v.ball_distance_m - 3.0).abs() < 0.02);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PyramidGeometry {
    /// Focal length, px.
    pub f_px: f64,
    /// Principal point (x, y), px.
    pub principal: [f64; 2],
    /// Blue edge length h, m.
    pub h: f64,
    /// Blue midpoint to ball distance m, m.
    pub m: f64,
    /// Ball diameter, m.
    pub ball_diameter: f64,
}

/// One frame's geometric reading of the pyramid.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PyramidView {
    /// Camera to blue edges, d = f·h/g, m (pairs only).
    pub blue_distance_m: Option<f64>,
    /// Camera to ball centre, m: from the blue distance and α with a pair, else from the
    /// ellipse area.
    pub ball_distance_m: f64,
    /// Signed α, rad (pairs only).
    pub alpha: Option<f64>,
    /// True when K reached the peak of the quadratic (α ≥ α*, estimate saturated).
    pub alpha_saturated: bool,
    /// Ball bearing from the optical axis, rad, positive to the image left.
    pub bearing: f64,
    /// Ellipse centre minus image centre, px (x right, y down).
    pub dev_px: [f64; 2],
    /// Ellipse pixels.
    pub area_px: u64,
}

impl PyramidGeometry {
    /// The proportions the detector's pair filters use.
    pub fn shape(&self) -> PyramidShape {
        PyramidShape {
            size_ratio: self.h / self.ball_diameter,
            offset_ratio: self.m / self.h,
        }
    }

    /// d = f·h/g, m.
    pub fn distance_from_blue(&self, g_px: f64) -> f64 {
        self.f_px * self.h / g_px.max(1e-9)
    }

    /// The ball's pixel area at 1 m, A₁ = π·(f·D/2)².
    pub fn reference_area_px(&self) -> f64 {
        std::f64::consts::PI * (self.f_px * self.ball_diameter / 2.0).powi(2)
    }

    /// Camera to ball from the ellipse area, d = √(A₁/A), m.
    pub fn distance_from_area(&self, area_px: f64) -> f64 {
        (self.reference_area_px() / area_px.max(1e-9)).sqrt()
    }

    /// Signed α for a pair, and whether it saturated.
    pub fn alpha(&self, pair: &PyramidPair) -> (f64, bool) {
        let b = &pair.blue;
        let g = b.height();
        let ex = pair.ellipse.centre[0];
        // Box edges at pixel boundaries: x_min and x_max + 1.
        let (c, sign) = if ex <= b.centre()[0] {
            (b.bbox[2] as f64 + 1.0 - ex - 0.5, 1.0)
        } else {
            (ex + 0.5 - b.bbox[0] as f64, -1.0)
        };
        let k = c.max(0.0) * self.h / g;
        let saturated = k * k >= self.m * self.m + self.h * self.h / 4.0;
        (sign * alpha_from_k(k, self.h, self.m), saturated)
    }

    /// The geometric reading of a detection (None without an ellipse).
    pub fn view(&self, det: &PyramidDetection) -> Option<PyramidView> {
        let e = det.ellipse?;
        let u = e.centre[0] + 0.5 - self.principal[0];
        let v = e.centre[1] + 0.5 - self.principal[1];
        let (blue_distance_m, alpha, alpha_saturated, ball_distance_m) = match &det.pair {
            Some(p) => {
                let d = self.distance_from_blue(p.blue.height());
                let (a, sat) = self.alpha(p);
                (Some(d), Some(a), sat, (d - self.m * a.cos()).max(0.05))
            }
            None => (None, None, false, self.distance_from_area(e.count as f64)),
        };
        Some(PyramidView {
            blue_distance_m,
            ball_distance_m,
            alpha,
            alpha_saturated,
            bearing: (-u / self.f_px).atan(),
            dev_px: [u, v],
            area_px: e.count,
        })
    }
}

/// What the pyramid schema reports each frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PyramidPercept {
    /// Capture time, s.
    pub stamp: f64,
    /// The raw detection.
    pub detection: PyramidDetection,
    /// Its geometric reading, when an ellipse was found.
    pub view: Option<PyramidView>,
    /// Frame size.
    pub image_size: (usize, usize),
}

impl PyramidPercept {
    /// Nothing seen.
    pub fn not_found(stamp: f64, image_size: (usize, usize)) -> Self {
        Self {
            stamp,
            detection: PyramidDetection {
                pair: None,
                ellipse: None,
                blue: None,
                candidates: 0,
            },
            view: None,
            image_size,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Synthetic projection of the top view: the image extent c for a robot at angle α
    /// and distance d, per the paper's model, then back through the quadratic.
    #[test]
    fn quadratic_inverts_the_projection_over_the_valid_range() {
        let (h, m, f, d) = (0.10, 0.16, 360.0, 1.2);
        let g = f * h / d;
        let amax = max_alpha(h, m);
        assert!((amax.to_degrees() - 72.6).abs() < 0.1);
        for i in 0..=72 {
            let a = (i as f64).to_radians();
            let c = f * (m * a.sin() + h / 2.0 * a.cos()) / d;
            let est = alpha_from_k(c * h / g, h, m);
            assert!((est - a).abs() < 1e-9, "α = {i}°: {}", est.to_degrees());
        }
        // Beyond the peak the estimate folds back below α* (the paper's ambiguity) or
        // saturates, never above α*.
        for i in 73..=110 {
            let a = (i as f64).to_radians();
            let c = f * (m * a.sin() + h / 2.0 * a.cos()).abs() / d;
            assert!(alpha_from_k(c * h / g, h, m) <= amax + 1e-12);
        }
    }

    #[test]
    fn minus_root_is_zero_at_half() {
        assert_eq!(alpha_from_k(0.05, 0.10, 0.16), 0.0);
        assert_eq!(alpha_from_k(0.0, 0.10, 0.16), 0.0, "K below h/2 clamps to 0");
    }

    #[test]
    fn distances() {
        let g = PyramidGeometry {
            f_px: 360.0,
            principal: [80.0, 60.0],
            h: 0.1,
            m: 0.16,
            ball_diameter: 0.07,
        };
        assert!((g.distance_from_blue(18.0) - 2.0).abs() < 1e-12);
        let a1 = g.reference_area_px();
        assert!((g.distance_from_area(a1 / 4.0) - 2.0).abs() < 1e-12);
    }
}
