//! The command a base executes: what motor schemas propose and
//! [`DriveModel::realise`](super::DriveModel::realise) saturates. It lives with the
//! kinematics, below the schemas, so the kinematics depend on nothing above them;
//! `schemas` re-exports it.

use super::vector::MotionVector;
use crate::geometry::Twist;
use serde::{Deserialize, Serialize};

/// How the base should move this tick.
///
/// `Turn` and `Straight` are the two halves of the restricted skid-steer command of
/// Bujold's VGTv (turn in place OR drive straight, never both); a gradual turn alternates
/// them. `Vector` is an Arkin-style desired velocity in the body frame, turned into a
/// twist by a heading controller (see [`MotionVector::to_twist`]).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum DriveCommand {
    /// Zero velocity.
    #[default]
    Stop,
    /// Continuous body twist.
    Twist(Twist),
    /// Turn in place at `omega` rad/s (CCW positive).
    Turn {
        /// Yaw rate, rad/s.
        omega: f64,
    },
    /// Drive straight at `v` m/s (negative reverses).
    Straight {
        /// Forward speed, m/s.
        v: f64,
    },
    /// A desired body-frame velocity vector (m/s), Arkin style.
    Vector(MotionVector),
}

impl DriveCommand {
    /// The equivalent body twist. Vectors are converted with the default heading
    /// controller ([`MotionVector::to_twist`] with `k_theta = 1.5`).
    pub fn to_twist(&self) -> Twist {
        match *self {
            DriveCommand::Stop => Twist::ZERO,
            DriveCommand::Twist(t) => t,
            DriveCommand::Turn { omega } => Twist::new(0.0, omega),
            DriveCommand::Straight { v } => Twist::new(v, 0.0),
            DriveCommand::Vector(m) => m.to_twist(1.5),
        }
    }

    /// True when every number in the command is finite.
    pub fn is_finite(&self) -> bool {
        match *self {
            DriveCommand::Stop => true,
            DriveCommand::Twist(t) => t.is_finite(),
            DriveCommand::Turn { omega } => omega.is_finite(),
            DriveCommand::Straight { v } => v.is_finite(),
            DriveCommand::Vector(m) => m.x.is_finite() && m.y.is_finite(),
        }
    }

    /// True when the command asks for no motion.
    pub fn is_stop(&self) -> bool {
        let t = self.to_twist();
        t.v == 0.0 && t.omega == 0.0
    }
}
