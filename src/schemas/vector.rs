//! Arkin-style motion vectors: [`MotionVector`] lives with the kinematics (a drive
//! command can carry one) and is re-exported here, where motor schemas compose them.

pub use crate::kinematics::vector::MotionVector;
