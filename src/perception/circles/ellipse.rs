//! Direct least-squares ellipse fit (Fitzgibbon, Pilu & Fisher 1999) in the numerically
//! stable form of Halíř & Flusser (1998): the centroid of a circle mark (seed 000
//! §III.A.2, "fitting the perimeter of the blob to an ellipse using a least-squares fit").
//!
//! The conic a·x² + b·xy + c·y² + d·x + e·y + f = 0 minimises the algebraic distance
//! subject to 4ac − b² = 1, which always yields an ellipse. Points are centred and scaled
//! to unit RMS radius first (Fitzgibbon's own caution), the 6×6 problem is reduced to a
//! 3×3 eigenproblem, and the fit is expressed as centre, semi-axes and angle. Everything
//! is on the stack: no allocation.
//!
//! Coordinates are whatever the caller gives (pixels, with y down, in this crate); the
//! angle is measured from +x toward +y in those coordinates.

use nalgebra::{Matrix2, Matrix3, Vector3};

/// An ellipse: centre, semi-axes and the major axis's direction.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Ellipse {
    /// Centre (x, y).
    pub centre: [f64; 2],
    /// Semi-major axis (≥ `semi_minor`).
    pub semi_major: f64,
    /// Semi-minor axis.
    pub semi_minor: f64,
    /// Angle of the major axis from +x toward +y, rad, in (−π/2, π/2].
    pub angle: f64,
}

impl Ellipse {
    /// The point at parameter t: centre + A·cos t·major + B·sin t·minor.
    pub fn point(&self, t: f64) -> [f64; 2] {
        let (s, c) = self.angle.sin_cos();
        let (u, v) = (self.semi_major * t.cos(), self.semi_minor * t.sin());
        [self.centre[0] + u * c - v * s, self.centre[1] + u * s + v * c]
    }

    /// Maps an image point into the ellipse's unit-circle frame: the major axis scaled to
    /// 1 and the minor axis stretched to match, with no extra rotation (the minimal
    /// affine rectification). A point on the ellipse maps to radius 1.
    pub fn rectify(&self, p: [f64; 2]) -> [f64; 2] {
        let (s, c) = self.angle.sin_cos();
        let (dx, dy) = (p[0] - self.centre[0], p[1] - self.centre[1]);
        let along = (dx * c + dy * s) / self.semi_major;
        let across = (-dx * s + dy * c) / self.semi_minor.max(1e-12);
        [along * c - across * s, along * s + across * c]
    }
}

/// A fitted ellipse and how well the points lie on it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EllipseFit {
    /// The ellipse.
    pub ellipse: Ellipse,
    /// RMS of the points' Sampson distances to it (first-order geometric distance), in
    /// the points' units.
    pub rms: f64,
}

/// Fits an ellipse to `points` by direct least squares.
///
/// Returns `None` for fewer than 6 points (5 determine a conic exactly, leaving no
/// residual to judge the fit by), non-finite input, or a degenerate configuration
/// (collinear points, all points equal).
///
/// # Example
///
/// Twelve points of an ellipse centred at (10, 5) with semi-axes 4 and 2, its major
/// axis turned 0.3 rad.
///
/// ```
/// use marsupial::perception::circles::{Ellipse, fit_ellipse};
///
/// let truth = Ellipse { centre: [10.0, 5.0], semi_major: 4.0, semi_minor: 2.0, angle: 0.3 };
/// let pts: Vec<[f64; 2]> = (0..12).map(|k| truth.point(k as f64 * 0.5236)).collect();
/// let fit = fit_ellipse(&pts).unwrap();
/// let e = fit.ellipse;
/// assert!((e.centre[0] - 10.0).abs() < 1e-9 && (e.centre[1] - 5.0).abs() < 1e-9);
/// assert!((e.semi_major - 4.0).abs() < 1e-9 && (e.semi_minor - 2.0).abs() < 1e-9);
/// assert!((e.angle - 0.3).abs() < 1e-9 && fit.rms < 1e-9);
/// assert!(fit_ellipse(&pts[..5]).is_none());
/// ```
pub fn fit_ellipse(points: &[[f64; 2]]) -> Option<EllipseFit> {
    let n = points.len();
    if n < 6 || points.iter().any(|p| !p[0].is_finite() || !p[1].is_finite()) {
        return None;
    }
    let nf = n as f64;
    let (mx, my) = points.iter().fold((0.0, 0.0), |(sx, sy), p| (sx + p[0], sy + p[1]));
    let (mx, my) = (mx / nf, my / nf);
    let ms = points
        .iter()
        .map(|p| (p[0] - mx).powi(2) + (p[1] - my).powi(2))
        .sum::<f64>()
        / nf;
    let scale = ms.sqrt();
    if scale.is_nan() || scale < 1e-12 {
        return None;
    }
    let (mut s1, mut s2, mut s3) = (
        Matrix3::<f64>::zeros(),
        Matrix3::<f64>::zeros(),
        Matrix3::<f64>::zeros(),
    );
    for p in points {
        let (x, y) = ((p[0] - mx) / scale, (p[1] - my) / scale);
        let d1 = Vector3::new(x * x, x * y, y * y);
        let d2 = Vector3::new(x, y, 1.0);
        s1 += d1 * d1.transpose();
        s2 += d1 * d2.transpose();
        s3 += d2 * d2.transpose();
    }
    let t = -(s3.try_inverse()? * s2.transpose());
    let m = s1 + s2 * t;
    // C1⁻¹·M with C1⁻¹ = [[0, 0, ½], [0, −1, 0], [½, 0, 0]].
    let m = Matrix3::new(
        m[(2, 0)] / 2.0,
        m[(2, 1)] / 2.0,
        m[(2, 2)] / 2.0,
        -m[(1, 0)],
        -m[(1, 1)],
        -m[(1, 2)],
        m[(0, 0)] / 2.0,
        m[(0, 1)] / 2.0,
        m[(0, 2)] / 2.0,
    );
    let mut best: Option<(f64, Vector3<f64>)> = None;
    for ev in m.complex_eigenvalues().iter() {
        if !ev.re.is_finite() || ev.im.abs() > 1e-9 * (1.0 + ev.re.abs()) {
            continue;
        }
        let Some(a1) = null_vector(&(m - Matrix3::identity() * ev.re)) else {
            continue;
        };
        let cond = 4.0 * a1[0] * a1[2] - a1[1] * a1[1];
        if cond > 0.0 && best.is_none_or(|(c, _)| cond > c) {
            best = Some((cond, a1));
        }
    }
    let (_, a1) = best?;
    let a2 = t * a1;
    let conic = [a1[0], a1[1], a1[2], a2[0], a2[1], a2[2]];
    let unit = ellipse_from_conic(conic)?;
    let mut rms = 0.0;
    for p in points {
        let (x, y) = ((p[0] - mx) / scale, (p[1] - my) / scale);
        let [a, b, c, d, e, f] = conic;
        let val = a * x * x + b * x * y + c * y * y + d * x + e * y + f;
        let gx = 2.0 * a * x + b * y + d;
        let gy = b * x + 2.0 * c * y + e;
        let g2 = gx * gx + gy * gy;
        rms += if g2 > 0.0 { val * val / g2 } else { 0.0 };
    }
    let ellipse = Ellipse {
        centre: [mx + scale * unit.centre[0], my + scale * unit.centre[1]],
        semi_major: scale * unit.semi_major,
        semi_minor: scale * unit.semi_minor,
        angle: unit.angle,
    };
    Some(EllipseFit {
        ellipse,
        rms: scale * (rms / nf).sqrt(),
    })
}

/// A unit vector spanning the null space of a rank-2 3×3 matrix: the largest of the
/// rows' pairwise cross products.
fn null_vector(a: &Matrix3<f64>) -> Option<Vector3<f64>> {
    let r = [a.row(0).transpose(), a.row(1).transpose(), a.row(2).transpose()];
    let c = [r[0].cross(&r[1]), r[0].cross(&r[2]), r[1].cross(&r[2])];
    let v = c.iter().max_by(|p, q| p.norm_squared().total_cmp(&q.norm_squared()))?;
    let n = v.norm();
    (n > 1e-300 && n.is_finite()).then(|| v / n)
}

/// Centre, semi-axes and angle of the ellipse a·x² + b·xy + c·y² + d·x + e·y + f = 0, or
/// `None` when the conic is not a real ellipse.
pub fn ellipse_from_conic(conic: [f64; 6]) -> Option<Ellipse> {
    let [a, b, c, d, e, f] = conic;
    let det = 4.0 * a * c - b * b;
    if det <= 0.0 || !det.is_finite() {
        return None;
    }
    let x0 = (b * e - 2.0 * c * d) / det;
    let y0 = (b * d - 2.0 * a * e) / det;
    // At the centre the conic reads [p]ᵀ·A2·[p] = −f′.
    let f0 = f + (d * x0 + e * y0) / 2.0;
    let a2 = Matrix2::new(a, b / 2.0, b / 2.0, c);
    let eig = a2.symmetric_eigen();
    let (l0, l1) = (eig.eigenvalues[0], eig.eigenvalues[1]);
    let (q0, q1) = (-f0 / l0, -f0 / l1);
    if !(q0 > 0.0 && q1 > 0.0) {
        return None;
    }
    // The major axis belongs to the eigenvalue of smaller magnitude.
    let (major_i, major_sq, minor_sq) = if q0 >= q1 { (0, q0, q1) } else { (1, q1, q0) };
    let v = eig.eigenvectors.column(major_i);
    let mut angle = v[1].atan2(v[0]);
    if angle > std::f64::consts::FRAC_PI_2 {
        angle -= std::f64::consts::PI;
    } else if angle <= -std::f64::consts::FRAC_PI_2 {
        angle += std::f64::consts::PI;
    }
    Some(Ellipse {
        centre: [x0, y0],
        semi_major: major_sq.sqrt(),
        semi_minor: minor_sq.sqrt(),
        angle,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn angle_diff(a: f64, b: f64) -> f64 {
        let d = (a - b).rem_euclid(std::f64::consts::PI);
        d.min(std::f64::consts::PI - d)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]

        /// Noisy samples of random ellipses: the fit recovers the centre to a fraction of
        /// the noise, the axes and (unless nearly circular) the angle.
        #[test]
        fn the_fit_recovers_sampled_noisy_ellipses(
            cx in -500.0f64..500.0, cy in -500.0f64..500.0,
            major in 3.0f64..200.0, ratio in 0.25f64..1.0, angle in -1.5f64..1.5,
            n in 12usize..120, sigma_frac in 0.0f64..0.02, seed in any::<u64>(),
        ) {
            let truth = Ellipse { centre: [cx, cy], semi_major: major, semi_minor: major * ratio, angle };
            let sigma = sigma_frac * truth.semi_minor;
            let mut s = seed | 1;
            let mut gauss = move || {
                // Sum of 12 uniforms − 6: a cheap unit normal.
                (0..12).map(|_| { s ^= s << 13; s ^= s >> 7; s ^= s << 17; (s >> 11) as f64 / (1u64 << 53) as f64 }).sum::<f64>() - 6.0
            };
            let pts: Vec<[f64; 2]> = (0..n)
                .map(|k| {
                    let p = truth.point(k as f64 * std::f64::consts::TAU / n as f64 + 0.1);
                    [p[0] + sigma * gauss(), p[1] + sigma * gauss()]
                })
                .collect();
            let fit = fit_ellipse(&pts).expect("fit");
            let e = fit.ellipse;
            let tol = 1e-7 * major + 6.0 * sigma;
            prop_assert!((e.centre[0] - cx).abs() < tol && (e.centre[1] - cy).abs() < tol, "{e:?}");
            prop_assert!((e.semi_major - truth.semi_major).abs() < 2.0 * tol, "{e:?}");
            prop_assert!((e.semi_minor - truth.semi_minor).abs() < 2.0 * tol, "{e:?}");
            if ratio < 0.9 {
                prop_assert!(angle_diff(e.angle, angle) < 0.02 + 20.0 * sigma_frac, "{e:?}");
            }
            prop_assert!(fit.rms < 3.0 * sigma + 1e-6 * major, "rms {} σ {}", fit.rms, sigma);
        }
    }

    #[test]
    fn a_square_fits_badly() {
        // The boundary of a 20-px square: an ellipse fits, but with a large residual
        // (what the detector's shape check rejects).
        let mut pts = Vec::new();
        for k in 0..20 {
            let t = k as f64;
            pts.extend([[t, 0.0], [20.0, t], [20.0 - t, 20.0], [0.0, 20.0 - t]]);
        }
        let fit = fit_ellipse(&pts).expect("fit");
        assert!(fit.rms > 0.05 * fit.ellipse.semi_minor, "{fit:?}");
    }

    #[test]
    fn degenerate_inputs_return_none() {
        assert!(fit_ellipse(&[]).is_none());
        let line: Vec<[f64; 2]> = (0..10).map(|k| [k as f64, 2.0 * k as f64]).collect();
        assert!(fit_ellipse(&line).is_none());
        assert!(fit_ellipse(&[[1.0, 1.0]; 10]).is_none());
        let mut pts: Vec<[f64; 2]> = (0..10).map(|k| [(k as f64).cos(), (k as f64).sin()]).collect();
        pts[3][0] = f64::NAN;
        assert!(fit_ellipse(&pts).is_none());
    }

    #[test]
    fn rectify_maps_the_ellipse_to_the_unit_circle() {
        let e = Ellipse {
            centre: [3.0, -2.0],
            semi_major: 5.0,
            semi_minor: 2.0,
            angle: 0.7,
        };
        for k in 0..8 {
            let q = e.rectify(e.point(k as f64));
            assert!((q[0].hypot(q[1]) - 1.0).abs() < 1e-12);
        }
        // The major axis keeps its direction.
        let q = e.rectify(e.point(0.0));
        assert!((q[1].atan2(q[0]) - 0.7).abs() < 1e-12);
    }
}
