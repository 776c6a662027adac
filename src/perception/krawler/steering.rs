//! Steering λ from each axle's tie-rod markers (seed 003 §V-B).
//!
//! The tie-rod markers' rays are intersected with the plane through the axle's roll
//! centre (the plate markers' midpoint, [`AxlePose`]) whose normal is the vertical rolled
//! with the axle, R_x(ψ)·ẑ in our frame (the paper's R_y(θ)·[0 0 1]ᵀ, eq. 4; paper
//! (x, y, z) = ours (−y, x, z)). The ratio of the left pair's distance to the right
//! pair's, x = d(B1, A1) / d(B2, A2) (eq. 5, 1 being the left side), is about 1 with the
//! wheels straight and moves above or below 1 as they steer one way or the other. A
//! second-order polynomial λ = f(x), fitted to a calibration sweep over ±30°
//! ([`fit_steering`], `marsupial calibrate-steering`), turns it into the angle.
//!
//! Why a ratio and a calibration, not the linkage's geometry: the ratio cancels the
//! distance to the camera and most of the fisheye's residual error, and the polynomial
//! absorbs the linkage's exact shape, which a real rover's drawings rarely give to the
//! millimetre. The polynomial is per axle: the front arms point back and the rear arms
//! forward, so the same λ moves the two ratios in opposite directions.

use super::axle::{AxleGeometry, AxlePose};
use nalgebra::{Matrix4, Point3, Vector3, Vector4};

/// λ = f(x) for one axle, a polynomial written in powers of x − 1 (the ratio's offset
/// from straight), `deg[0] + deg[1]·(x − 1) + deg[2]·(x − 1)² + deg[3]·(x − 1)³`, in
/// degrees. The paper's calibration is second order (`deg[3]` = 0); a third-order term
/// is our option for linkages whose ratio saturates toward full lock (see
/// [`fit_steering`]). Powers of x − 1 give coefficients of a readable size that can be
/// rounded in a profile (in powers of x they reach hundreds and cancel).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SteeringPoly {
    /// Coefficients of 1, (x − 1), (x − 1)² and (x − 1)³, degrees.
    pub deg: [f64; 4],
}

impl SteeringPoly {
    /// λ for ratio `x`, rad.
    pub fn steer(&self, x: f64) -> f64 {
        let v = x - 1.0;
        (self.deg[0] + v * (self.deg[1] + v * (self.deg[2] + v * self.deg[3]))).to_radians()
    }
}

impl AxleGeometry {
    /// Where the ray through pixel `at` meets the rolled plane of an axle whose plate
    /// markers gave `pose`: through the markers' midpoint, normal R_x(ψ)·ẑ. `None` when
    /// the ray runs parallel to it or meets it behind the camera.
    pub fn on_rolled_plane(&self, at: [f64; 2], pose: &AxlePose) -> Option<Point3<f64>> {
        let ray: Vector3<f64> = self.body_from_camera * self.model.ray(at[0], at[1]);
        let normal = Vector3::new(0.0, -pose.roll.sin(), pose.roll.cos());
        let centre = nalgebra::center(&pose.markers[0], &pose.markers[1]);
        let den = normal.dot(&ray);
        if den.abs() < 1e-12 {
            return None;
        }
        let t = normal.dot(&(centre - self.camera)) / den;
        (t > 0.0).then(|| self.camera + ray * t)
    }

    /// The paper's ratio x = d(B1, A1) / d(B2, A2) (eq. 5) for an axle whose plate
    /// markers gave `pose`, from its tie-rod markers' pixel centres `rod` (left, right);
    /// `None` when a ray misses the plane or the right pair coincides.
    pub fn steering_ratio(&self, pose: &AxlePose, rod: [[f64; 2]; 2]) -> Option<f64> {
        let b1 = self.on_rolled_plane(rod[0], pose)?;
        let b2 = self.on_rolled_plane(rod[1], pose)?;
        let (d1, d2) = ((b1 - pose.markers[0]).norm(), (b2 - pose.markers[1]).norm());
        (d2 > 1e-9).then(|| d1 / d2)
    }
}

/// A fitted calibration and how well it fits its sweep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SteeringFit {
    /// The polynomial.
    pub poly: SteeringPoly,
    /// Root-mean-square residual over the sweep, degrees.
    pub rms_deg: f64,
    /// Largest residual, degrees.
    pub max_deg: f64,
    /// The ratios' range over the sweep.
    pub ratio_range: (f64, f64),
}

/// Why a sweep cannot be fitted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SteeringFitError {
    /// Fewer than five usable samples.
    #[error("{0} usable samples; a calibration sweep needs at least 5, over both directions")]
    TooFew(usize),
    /// A ratio or angle is not finite.
    #[error("sample {0} is not finite")]
    NotFinite(usize),
    /// An order other than 2 or 3.
    #[error("order {0}: the steering polynomial is of order 2 (the paper's) or 3")]
    Order(usize),
    /// The ratios do not vary enough for a polynomial (the sweep did not steer, or the
    /// markers did not move).
    #[error("the ratios span only {0:.2e}: the sweep must steer both ways")]
    Degenerate(f64),
}

/// Least-squares fit of λ = f(x) (degrees) of `order` 2 (the paper's) or 3 to `samples`
/// of (ratio, λ in degrees).
///
/// The fit is made on u = (x − 1)/s, s the largest |x − 1|, so the normal equations stay
/// well conditioned although the ratios cluster around 1, and scaled back.
///
/// Why a third order is offered: with an Ackermann trapezoid the tie rod's sideways
/// travel slows toward full lock, so λ(x) steepens at both ends, an odd (cubic) shape a
/// quadratic cannot follow. On our simulated gear the exact ratios leave a quadratic
/// 1.3° RMS (2.5° worst) and a cubic 0.3° RMS (0.5° worst) over ±30°.
///
/// # Errors
/// [`SteeringFitError`] for an order other than 2 or 3, fewer than five samples,
/// non-finite values, or ratios that do not vary.
pub fn fit_steering(samples: &[(f64, f64)], order: usize) -> Result<SteeringFit, SteeringFitError> {
    if !(2..=3).contains(&order) {
        return Err(SteeringFitError::Order(order));
    }
    if let Some(i) = samples.iter().position(|(x, l)| !x.is_finite() || !l.is_finite()) {
        return Err(SteeringFitError::NotFinite(i));
    }
    if samples.len() < 5 {
        return Err(SteeringFitError::TooFew(samples.len()));
    }
    let n = samples.len() as f64;
    let (lo, hi) = samples.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| {
        (lo.min(s.0), hi.max(s.0))
    });
    if hi - lo < 1e-6 {
        return Err(SteeringFitError::Degenerate(hi - lo));
    }
    let s = (hi - 1.0).abs().max((lo - 1.0).abs());
    let mut a = Matrix4::zeros();
    let mut b = Vector4::zeros();
    for &(x, l) in samples {
        let u = (x - 1.0) / s;
        let row = Vector4::new(1.0, u, u * u, if order == 3 { u * u * u } else { 0.0 });
        a += row * row.transpose();
        b += row * l;
    }
    if order == 2 {
        // No cubic term: its row and column pin c3 to 0.
        a[(3, 3)] = 1.0;
    }
    let c = a.lu().solve(&b).ok_or(SteeringFitError::Degenerate(hi - lo))?;
    let poly = SteeringPoly {
        deg: [c[0], c[1] / s, c[2] / (s * s), c[3] / (s * s * s)],
    };
    let residuals = samples.iter().map(|&(x, l)| poly.steer(x).to_degrees() - l);
    let (sum2, max) = residuals.fold((0.0, 0.0f64), |(s2, m), r| (s2 + r * r, m.max(r.abs())));
    Ok(SteeringFit {
        poly,
        rms_deg: (sum2 / n).sqrt(),
        max_deg: max,
        ratio_range: (lo, hi),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// Samples drawn exactly from a quadratic give that quadratic back.
        #[test]
        fn an_exact_polynomial_is_recovered(
            c0 in -50.0f64..50.0, c1 in -800.0f64..800.0, c2 in -300.0f64..300.0,
            c3 in -3000.0f64..3000.0, cubic: bool,
            centre in 0.8f64..1.2, span in 0.01f64..0.3, n in 6usize..40,
        ) {
            let c3 = if cubic { c3 } else { 0.0 };
            let f = |x: f64| c0 + c1 * (x - 1.0) + c2 * (x - 1.0).powi(2) + c3 * (x - 1.0).powi(3);
            let samples: Vec<(f64, f64)> = (0..n)
                .map(|i| {
                    let x = centre - span + 2.0 * span * i as f64 / (n - 1) as f64;
                    (x, f(x))
                })
                .collect();
            let fit = fit_steering(&samples, if cubic { 3 } else { 2 }).unwrap();
            let scale = 1.0 + f(centre - span).abs() + f(centre + span).abs();
            prop_assert!(fit.max_deg < 1e-6 * scale, "{fit:?}");
            if !cubic {
                prop_assert_eq!(fit.poly.deg[3], 0.0);
            }
        }
    }

    #[test]
    fn bad_sweeps_are_refused() {
        assert_eq!(fit_steering(&[(1.0, 0.0); 4], 2), Err(SteeringFitError::TooFew(4)));
        assert!(matches!(
            fit_steering(&[(1.0, 0.0); 9], 2),
            Err(SteeringFitError::Degenerate(_))
        ));
        let mut s = vec![(1.0, 0.0), (1.1, 10.0), (0.9, -10.0), (1.2, 20.0), (0.8, -20.0)];
        assert!(fit_steering(&s, 2).is_ok() && fit_steering(&s, 3).is_ok());
        assert_eq!(fit_steering(&s, 4), Err(SteeringFitError::Order(4)));
        assert_eq!(fit_steering(&s, 1), Err(SteeringFitError::Order(1)));
        s[3].1 = f64::NAN;
        assert_eq!(fit_steering(&s, 2), Err(SteeringFitError::NotFinite(3)));
    }
}
