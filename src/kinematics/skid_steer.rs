//! Skid steer with an effective track width (RAPOSA, DESIGN §2.2; ALGORITHMS §5).
//!
//! Tracks and skidding wheels turn less than the ideal differential model predicts. The
//! symmetric ICR model keeps v = (v_r + v_l)/2 and replaces the physical track by an
//! effective one, ω = (v_r − v_l)/d. The true d varies between `d_min` (no skid) and
//! `d_max` (most skid) with surface and curvature; odometry uses a calibrated constant
//! `effective` in that interval.

use super::differential::Differential;
use crate::geometry::Twist;
use thiserror::Error;

/// Inconsistent skid-steer parameters.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SkidSteerError {
    /// A track width is not a positive finite number.
    #[error("track widths must be positive and finite (d_min {d_min}, effective {effective}, d_max {d_max})")]
    NonPositive {
        /// Lower bound.
        d_min: f64,
        /// Effective value.
        effective: f64,
        /// Upper bound.
        d_max: f64,
    },
    /// Not `d_min ≤ effective ≤ d_max`.
    #[error("expected d_min ≤ effective ≤ d_max, got {d_min} ≤ {effective} ≤ {d_max}")]
    Order {
        /// Lower bound.
        d_min: f64,
        /// Effective value.
        effective: f64,
        /// Upper bound.
        d_max: f64,
    },
}

/// Skid-steer kinematics with an effective track between `d_min` and `d_max`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SkidSteer {
    d_min: f64,
    d_max: f64,
    effective: f64,
}

impl SkidSteer {
    /// Builds the model.
    ///
    /// # Errors
    /// When a width is not positive and finite, or `d_min ≤ effective ≤ d_max` fails.
    pub fn new(d_min: f64, effective: f64, d_max: f64) -> Result<Self, SkidSteerError> {
        if ![d_min, effective, d_max].iter().all(|d| d.is_finite() && *d > 0.0) {
            return Err(SkidSteerError::NonPositive {
                d_min,
                effective,
                d_max,
            });
        }
        if !(d_min <= effective && effective <= d_max) {
            return Err(SkidSteerError::Order {
                d_min,
                effective,
                d_max,
            });
        }
        Ok(Self {
            d_min,
            d_max,
            effective,
        })
    }

    /// Builds the model from possibly inconsistent numbers without failing: the bounds
    /// are ordered, the effective track clamped into them, and non-positive values
    /// replaced by a 1 mm floor. Used after validation, where it changes nothing.
    pub fn clamped(d_min: f64, effective: f64, d_max: f64) -> Self {
        let fix = |d: f64| if d.is_finite() && d > 1e-3 { d } else { 1e-3 };
        let (a, b) = (fix(d_min), fix(d_max));
        let (d_min, d_max) = if a <= b { (a, b) } else { (b, a) };
        Self {
            d_min,
            d_max,
            effective: fix(effective).clamp(d_min, d_max),
        }
    }

    /// Lower bound of the effective track, m.
    pub fn d_min(&self) -> f64 {
        self.d_min
    }

    /// Upper bound of the effective track, m.
    pub fn d_max(&self) -> f64 {
        self.d_max
    }

    /// Calibrated effective track used for odometry, m.
    pub fn effective(&self) -> f64 {
        self.effective
    }

    /// The equivalent differential drive with track `effective`.
    pub fn as_differential(&self) -> Differential {
        Differential { track: self.effective }
    }

    /// Body twist from track speeds, using the effective track.
    pub fn twist_from_wheels(&self, v_left: f64, v_right: f64) -> Twist {
        self.as_differential().twist_from_wheels(v_left, v_right)
    }

    /// Track speeds realising a twist, using the effective track.
    pub fn wheels_from_twist(&self, t: &Twist) -> (f64, f64) {
        self.as_differential().wheels_from_twist(t)
    }

    /// The interval of yaw rates the track speeds may really produce:
    /// (ω at `d_max`, ω at `d_min`), ordered by magnitude, for uncertainty bounds.
    pub fn omega_bounds(&self, v_left: f64, v_right: f64) -> (f64, f64) {
        let dv = v_right - v_left;
        (dv / self.d_max, dv / self.d_min)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_bad_widths() {
        assert!(matches!(
            SkidSteer::new(0.5, 0.4, 0.6),
            Err(SkidSteerError::Order { .. })
        ));
        assert!(matches!(
            SkidSteer::new(0.5, 0.6, 0.4),
            Err(SkidSteerError::Order { .. })
        ));
        assert!(matches!(
            SkidSteer::new(-0.1, 0.4, 0.6),
            Err(SkidSteerError::NonPositive { .. })
        ));
        assert!(matches!(
            SkidSteer::new(0.1, f64::NAN, 0.6),
            Err(SkidSteerError::NonPositive { .. })
        ));
    }

    #[test]
    fn effective_track_turns_less() {
        let s = SkidSteer::new(0.4, 0.6, 0.8).unwrap();
        let t = s.twist_from_wheels(-0.3, 0.3);
        assert!((t.omega - 1.0).abs() < 1e-12);
        let (lo, hi) = s.omega_bounds(-0.3, 0.3);
        assert!(lo < t.omega && t.omega < hi);
        assert!((hi - 1.5).abs() < 1e-12);
    }
}
