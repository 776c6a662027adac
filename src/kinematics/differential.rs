//! Unicycle / differential-drive kinematics.

use crate::geometry::Twist;

/// An ideal differential drive with track width `track` (m) between the wheel contact
/// lines: v = (v_r + v_l)/2, ω = (v_r − v_l)/track.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Differential {
    /// Distance between left and right wheel contact lines, metres.
    pub track: f64,
}

impl Differential {
    /// Body twist from left and right wheel surface speeds (m/s).
    pub fn twist_from_wheels(&self, v_left: f64, v_right: f64) -> Twist {
        Twist::new((v_right + v_left) / 2.0, (v_right - v_left) / self.track)
    }

    /// Left and right wheel surface speeds (m/s) realising a twist.
    pub fn wheels_from_twist(&self, t: &Twist) -> (f64, f64) {
        let half = t.omega * self.track / 2.0;
        (t.v - half, t.v + half)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_spin() {
        let d = Differential { track: 0.4 };
        let (l, r) = d.wheels_from_twist(&Twist::new(0.3, 0.5));
        assert!((l - 0.2).abs() < 1e-12 && (r - 0.4).abs() < 1e-12);
        let t = d.twist_from_wheels(l, r);
        assert!((t.v - 0.3).abs() < 1e-12 && (t.omega - 0.5).abs() < 1e-12);
        let t = d.twist_from_wheels(-0.1, 0.1);
        assert_eq!(t.v, 0.0);
        assert!((t.omega - 0.5).abs() < 1e-12);
    }
}
