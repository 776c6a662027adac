//! Fitting skid-steer odometry to ground truth (seed 001 §II.F: the effective track "was
//! empirically estimated and considered a constant").
//!
//! Input: a log of cumulative wheel travel (left, right, m, as the encoders report it)
//! with the true pose at the same instants, from a motion-capture system, a surveyed
//! run, or the simulator. Between consecutive samples the unicycle model of the paper
//! says
//!
//! * travel: Δs = k·(Δl + Δr)/2, k the wheel-speed scale (slip, wheel radius error);
//! * turn: Δθ = k·(Δr − Δl)/d, d the effective track.
//!
//! Both are linear in one unknown, so each is a one-parameter least-squares fit:
//! k = Σ Δs·m / Σ m² with m = (Δl + Δr)/2, the true Δs being the displacement projected on
//! the mean heading; then with u = k·(Δr − Δl), 1/d = Σ u·Δθ / Σ u². The fit works on a
//! real robot's log exactly as on a simulated one (`marsupial calibrate-odometry LOG.csv`).

use crate::geometry::{Pose2, wrap_angle};
use thiserror::Error;

/// One log sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OdometrySample {
    /// Time, s.
    pub t: f64,
    /// Cumulative left wheel travel, m.
    pub left_m: f64,
    /// Cumulative right wheel travel, m.
    pub right_m: f64,
    /// True pose.
    pub pose: Pose2,
}

/// The fitted constants.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Calibration {
    /// Effective track d, m.
    pub effective_track_m: f64,
    /// Wheel-speed scale k (true travel over encoder travel).
    pub wheel_scale: f64,
    /// RMS per-step heading error of the fitted model, rad.
    pub rms_heading_error_rad: f64,
    /// RMS per-step travel error of the fitted model, m.
    pub rms_travel_error_m: f64,
    /// Steps used.
    pub steps: usize,
}

/// Why a log cannot be fitted.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CalibrationError {
    /// Too few samples.
    #[error("need at least 3 samples, got {0}")]
    TooFew(usize),
    /// A value is NaN or infinite, or time does not increase.
    #[error("sample {0}: non-finite value or time not increasing")]
    BadSample(usize),
    /// The robot barely drove straight or barely turned.
    #[error("the log has too little {0} to fit (drive straight and turn both ways)")]
    NotExcited(&'static str),
    /// A CSV line could not be read.
    #[error("line {line}: {message}")]
    Parse {
        /// 1-based line.
        line: usize,
        /// What was wrong.
        message: String,
    },
}

/// Fits the wheel scale and effective track to a log.
///
/// # Errors
/// [`CalibrationError`] for short, non-finite or unexciting logs.
pub fn calibrate(samples: &[OdometrySample]) -> Result<Calibration, CalibrationError> {
    if samples.len() < 3 {
        return Err(CalibrationError::TooFew(samples.len()));
    }
    for (i, w) in samples.windows(2).enumerate() {
        let ok =
            |s: &OdometrySample| s.t.is_finite() && s.left_m.is_finite() && s.right_m.is_finite() && s.pose.is_finite();
        if !ok(&w[0]) || !ok(&w[1]) || w[1].t <= w[0].t {
            return Err(CalibrationError::BadSample(i + 1));
        }
    }
    let steps: Vec<(f64, f64, f64, f64)> = samples
        .windows(2)
        .map(|w| {
            let (a, b) = (&w[0], &w[1]);
            let (dl, dr) = (b.left_m - a.left_m, b.right_m - a.right_m);
            let mid = a.pose.theta + wrap_angle(b.pose.theta - a.pose.theta) / 2.0;
            let ds = (b.pose.x - a.pose.x) * mid.cos() + (b.pose.y - a.pose.y) * mid.sin();
            (dl, dr, ds, wrap_angle(b.pose.theta - a.pose.theta))
        })
        .collect();
    let (smm, sms) = steps.iter().fold((0.0, 0.0), |(smm, sms), &(dl, dr, ds, _)| {
        let m = (dl + dr) / 2.0;
        (smm + m * m, sms + m * ds)
    });
    if smm < 1e-6 {
        return Err(CalibrationError::NotExcited("straight driving"));
    }
    let k = sms / smm;
    let (suu, sut) = steps.iter().fold((0.0, 0.0), |(suu, sut), &(dl, dr, _, dth)| {
        let u = k * (dr - dl);
        (suu + u * u, sut + u * dth)
    });
    if suu < 1e-6 || sut <= 0.0 {
        return Err(CalibrationError::NotExcited("turning"));
    }
    let d = suu / sut;
    let n = steps.len() as f64;
    let (eh, et) = steps.iter().fold((0.0, 0.0), |(eh, et), &(dl, dr, ds, dth)| {
        let h = k * (dr - dl) / d - dth;
        let t = k * (dl + dr) / 2.0 - ds;
        (eh + h * h, et + t * t)
    });
    Ok(Calibration {
        effective_track_m: d,
        wheel_scale: k,
        rms_heading_error_rad: (eh / n).sqrt(),
        rms_travel_error_m: (et / n).sqrt(),
        steps: steps.len(),
    })
}

/// Reads a log: a header line, then `t,left_m,right_m,x_m,y_m,theta_rad` per line.
///
/// # Errors
/// [`CalibrationError::Parse`] naming the line.
pub fn parse_log(text: &str) -> Result<Vec<OdometrySample>, CalibrationError> {
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if i == 0 || line.is_empty() || line.starts_with('#') {
            continue;
        }
        let vals: Result<Vec<f64>, _> = line.split(',').map(|f| f.trim().parse::<f64>()).collect();
        let vals = vals.map_err(|e| CalibrationError::Parse {
            line: i + 1,
            message: format!("expected numbers: {e}"),
        })?;
        if vals.len() != 6 {
            return Err(CalibrationError::Parse {
                line: i + 1,
                message: format!(
                    "expected 6 columns (t,left_m,right_m,x_m,y_m,theta_rad), got {}",
                    vals.len()
                ),
            });
        }
        out.push(OdometrySample {
            t: vals[0],
            left_m: vals[1],
            right_m: vals[2],
            pose: Pose2 {
                x: vals[3],
                y: vals[4],
                theta: vals[5],
            },
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Twist, integrate_twist};

    /// A log from an ideal skid steer with true scale `k` and track `d`: straight, spin
    /// left, arc, spin right.
    fn log(k: f64, d: f64) -> Vec<OdometrySample> {
        let mut pose = Pose2::default();
        let (mut l, mut r, mut t) = (0.0, 0.0, 0.0);
        let mut out = vec![OdometrySample {
            t,
            left_m: l,
            right_m: r,
            pose,
        }];
        let dt = 0.1;
        for (vl, vr, n) in [(0.1, 0.1, 50), (-0.05, 0.05, 40), (0.06, 0.1, 60), (0.05, -0.05, 40)] {
            for _ in 0..n {
                l += vl * dt;
                r += vr * dt;
                t += dt;
                let tw = Twist::new(k * (vl + vr) / 2.0, k * (vr - vl) / d);
                pose = integrate_twist(&pose, &tw, dt);
                out.push(OdometrySample {
                    t,
                    left_m: l,
                    right_m: r,
                    pose,
                });
            }
        }
        out
    }

    #[test]
    fn recovers_scale_and_track_from_closed_form_motion() {
        let c = calibrate(&log(0.92, 0.55)).unwrap();
        assert!((c.wheel_scale - 0.92).abs() < 1e-3, "{c:?}");
        assert!((c.effective_track_m - 0.55).abs() < 2e-3, "{c:?}");
        assert!(c.rms_heading_error_rad < 1e-3);
    }

    #[test]
    fn rejects_bad_logs() {
        assert_eq!(calibrate(&log(1.0, 0.5)[..2]), Err(CalibrationError::TooFew(2)));
        let mut bad = log(1.0, 0.5);
        bad[5].left_m = f64::NAN;
        assert!(matches!(calibrate(&bad), Err(CalibrationError::BadSample(_))));
        // Straight only: no turning to fit the track.
        let straight: Vec<_> = log(1.0, 0.5).into_iter().take(40).collect();
        assert_eq!(calibrate(&straight), Err(CalibrationError::NotExcited("turning")));
    }

    #[test]
    fn parses_csv_and_reports_lines() {
        let text = "t,left_m,right_m,x_m,y_m,theta_rad\n0,0,0,0,0,0\n0.1,0.01,0.01,0.01,0,0\n";
        assert_eq!(parse_log(text).unwrap().len(), 2);
        let e = parse_log("h\n0,0,0,0,0\n").unwrap_err();
        assert!(matches!(e, CalibrationError::Parse { line: 2, .. }), "{e}");
        let e = parse_log("h\n0,a,0,0,0,0\n").unwrap_err();
        assert!(e.to_string().contains("line 2"));
    }
}
