//! Arkin-style motion vectors: [`MotionVector`] lives with the kinematics (a drive
//! command can carry one) and is re-exported here, where motor schemas compose them.
//!
//! # Example
//!
//! Two schemas' vectors composed Arkin's way: a pull toward a goal ahead (1 m/s, gain 1)
//! and a push to the left (2 m/s, gain 0.5) sum to (1, 1), 45° left at √2 m/s; clipped
//! to a 1 m/s top speed, and realised as a twist by the heading controller.
//!
//! ```
//! use marsupial::schemas::MotionVector;
//! use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};
//!
//! let goal = MotionVector::new(1.0, 0.0);
//! let push = MotionVector::from_polar(2.0, FRAC_PI_2);
//! let v = MotionVector::weighted_sum([(1.0, goal), (0.5, push)]);
//! assert!((v.x - 1.0).abs() < 1e-12 && (v.y - 1.0).abs() < 1e-12);
//! assert!((v.norm() - 2f64.sqrt()).abs() < 1e-12 && (v.angle() - FRAC_PI_4).abs() < 1e-12);
//! let c = v.clip(1.0);
//! assert!((c.norm() - 1.0).abs() < 1e-12 && (c.angle() - FRAC_PI_4).abs() < 1e-12);
//! assert!((v.normalized().norm() - 1.0).abs() < 1e-12);
//! assert_eq!(MotionVector::ZERO.normalized(), MotionVector::ZERO, "no NaN");
//! assert_eq!(goal + goal.scale(2.0), MotionVector::new(3.0, 0.0));
//!
//! // ω = k_θ·45°, and v = |V|·cos 45° = 1 m/s.
//! let t = v.to_twist(2.0);
//! assert!((t.v - 1.0).abs() < 1e-12 && (t.omega - 2.0 * FRAC_PI_4).abs() < 1e-12);
//! // A vector behind the robot turns it in place first.
//! let t = MotionVector::new(-1.0, 0.1).to_twist(1.0);
//! assert!(t.v == 0.0 && t.omega > 0.0);
//! ```

pub use crate::kinematics::vector::MotionVector;
