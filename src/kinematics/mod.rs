//! Drive kinematics, command realisation and odometry.
//!
//! [`DriveModel`] is the runtime form of a profile's `[drive]` table. It maps wheel speeds
//! to body twists and back, and [`DriveModel::realise`] turns whatever the arbiter
//! proposed into a command the base can actually execute (saturated to its limits; a
//! restricted turn-or-drive base gets a turn OR a straight, never both).

pub mod ackermann;
pub mod calibration;
pub mod command;
pub mod differential;
pub mod odometry;
pub mod skid_steer;
pub mod tether_length;
pub mod two_arc;
pub mod vector;

pub use ackermann::{BodyVelocity, DoubleAckermann};
pub use calibration::{Calibration, CalibrationError, OdometrySample, calibrate, parse_log};
pub use command::DriveCommand;
pub use differential::Differential;
pub use odometry::Odometry;
pub use skid_steer::{SkidSteer, SkidSteerError};
pub use vector::MotionVector;

use crate::geometry::Twist;

/// Speed limits of a base.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriveLimits {
    /// Largest |v|, m/s.
    pub max_speed: f64,
    /// Largest |ω|, rad/s.
    pub max_turn_rate: f64,
}

/// A base's kinematic model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DriveModel {
    /// Ideal differential drive / unicycle.
    Differential(Differential),
    /// Skid steer with an effective track.
    SkidSteer(SkidSteer),
    /// Restricted skid steer: turn in place OR drive straight (Bujold's VGTv).
    TurnOrDrive(SkidSteer),
    /// Four-wheel double-Ackermann steering.
    DoubleAckermann(DoubleAckermann),
}

impl DriveModel {
    /// Body twist from left/right wheel (or track) speeds. For double-Ackermann the two
    /// speeds are averaged into the forward speed and the yaw rate is zero (steering
    /// angles are needed; use [`DoubleAckermann::body_velocity`]).
    pub fn twist_from_wheels(&self, v_left: f64, v_right: f64) -> Twist {
        match self {
            DriveModel::Differential(d) => d.twist_from_wheels(v_left, v_right),
            DriveModel::SkidSteer(s) | DriveModel::TurnOrDrive(s) => s.twist_from_wheels(v_left, v_right),
            DriveModel::DoubleAckermann(_) => Twist::new((v_left + v_right) / 2.0, 0.0),
        }
    }

    /// Turns a proposed command into one this base can execute within `limits`.
    ///
    /// * Speeds are clamped to the limits; non-finite commands become `Stop`.
    /// * `Vector` commands go through the heading controller first.
    /// * On [`DriveModel::TurnOrDrive`], a twist with both parts non-zero becomes the part
    ///   with the larger wheel-speed demand (|v| against |ω|·d/2, as asked, before
    ///   saturation), then saturated.
    /// * On [`DriveModel::DoubleAckermann`], the yaw rate is limited by the steering
    ///   range at the commanded speed, and turning in place becomes `Stop`.
    pub fn realise(&self, cmd: &DriveCommand, limits: &DriveLimits) -> DriveCommand {
        if !cmd.is_finite() {
            return DriveCommand::Stop;
        }
        let clamp_v = |v: f64| v.clamp(-limits.max_speed, limits.max_speed);
        let clamp_w = |w: f64| w.clamp(-limits.max_turn_rate, limits.max_turn_rate);
        match (self, *cmd) {
            (_, DriveCommand::Stop) => DriveCommand::Stop,
            (DriveModel::TurnOrDrive(s), c) => {
                // The demands as asked, not as saturated: a large heading error asks for
                // more turning than the base can give, and must still win over driving.
                let t = c.to_twist();
                if t.v == 0.0 && t.omega == 0.0 {
                    DriveCommand::Stop
                } else if t.omega.abs() * s.effective() / 2.0 > t.v.abs() {
                    DriveCommand::Turn {
                        omega: clamp_w(t.omega),
                    }
                } else {
                    DriveCommand::Straight { v: clamp_v(t.v) }
                }
            }
            (DriveModel::DoubleAckermann(a), c) => {
                let t = c.to_twist();
                let v = clamp_v(t.v);
                let wmax = a.max_yaw_rate(v).min(limits.max_turn_rate);
                let w = t.omega.clamp(-wmax, wmax);
                if v == 0.0 {
                    DriveCommand::Stop
                } else {
                    DriveCommand::Twist(Twist::new(v, w))
                }
            }
            (_, DriveCommand::Turn { omega }) => DriveCommand::Turn { omega: clamp_w(omega) },
            (_, DriveCommand::Straight { v }) => DriveCommand::Straight { v: clamp_v(v) },
            (_, c) => {
                let t = c.to_twist();
                DriveCommand::Twist(Twist::new(clamp_v(t.v), clamp_w(t.omega)))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const LIM: DriveLimits = DriveLimits {
        max_speed: 0.5,
        max_turn_rate: 1.0,
    };

    #[test]
    fn turn_or_drive_never_does_both() {
        let m = DriveModel::TurnOrDrive(SkidSteer::new(0.2, 0.25, 0.3).unwrap());
        assert_eq!(
            m.realise(&DriveCommand::Twist(Twist::new(0.2, 0.5)), &LIM),
            DriveCommand::Straight { v: 0.2 }
        );
        assert_eq!(
            m.realise(&DriveCommand::Twist(Twist::new(0.01, 0.5)), &LIM),
            DriveCommand::Turn { omega: 0.5 }
        );
        assert_eq!(
            m.realise(&DriveCommand::Twist(Twist::new(0.0, 5.0)), &LIM),
            DriveCommand::Turn { omega: 1.0 }
        );
        assert_eq!(m.realise(&DriveCommand::Twist(Twist::ZERO), &LIM), DriveCommand::Stop);
    }

    #[test]
    fn clamps_and_rejects_nan() {
        let m = DriveModel::Differential(Differential { track: 0.3 });
        assert_eq!(
            m.realise(&DriveCommand::Straight { v: 3.0 }, &LIM),
            DriveCommand::Straight { v: 0.5 }
        );
        assert_eq!(
            m.realise(&DriveCommand::Twist(Twist::new(f64::NAN, 0.0)), &LIM),
            DriveCommand::Stop
        );
        assert_eq!(
            m.realise(&DriveCommand::Twist(Twist::new(-1.0, -2.0)), &LIM),
            DriveCommand::Twist(Twist::new(-0.5, -1.0))
        );
    }

    #[test]
    fn ackermann_cannot_spin() {
        let m = DriveModel::DoubleAckermann(DoubleAckermann {
            wheelbase: 0.6,
            track: 0.5,
            max_steer: 0.5,
        });
        assert_eq!(m.realise(&DriveCommand::Turn { omega: 0.5 }, &LIM), DriveCommand::Stop);
        match m.realise(&DriveCommand::Twist(Twist::new(0.2, 1.0)), &LIM) {
            DriveCommand::Twist(t) => assert!((t.omega - 2.0 * 0.2 * 0.5f64.tan() / 0.6).abs() < 1e-12),
            other => panic!("{other:?}"),
        }
    }
}
