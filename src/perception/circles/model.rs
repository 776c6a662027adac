//! The a-priori model the correspondence search matches detections to: the marks' centres
//! on the module's face and their rotations.
//!
//! **Face coordinates** (u, v), metres: u across the face to the right as seen from in
//! front of it, v up. For Axel's module, whose face looks along the dock frame's +x, that
//! is (u, v) = (y, z) of the dock frame (`profile` builds it from `circles` fiducial).

use super::detect::MarkRotation;
use thiserror::Error;

/// Most marks a model holds (the paper's module has 8); fixed so fits stay on the stack.
pub const MAX_MODEL_MARKS: usize = 16;

/// Why a model cannot be built.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ModelError {
    /// Fewer than 5 marks (a homography from 4 has no redundancy) or more than
    /// [`MAX_MODEL_MARKS`].
    #[error("a circle model needs 5 to {MAX_MODEL_MARKS} marks, got {got}")]
    Count {
        /// Marks given.
        got: usize,
    },
    /// A position or the radius is not finite and positive where it must be.
    #[error("circle model: {what} is not a finite {expected}")]
    NotFinite {
        /// Which value.
        what: &'static str,
        /// What was expected.
        expected: &'static str,
    },
    /// Two marks overlap (centres closer than a diameter).
    #[error("circle model: marks {a} and {b} overlap")]
    Overlap {
        /// First mark.
        a: usize,
        /// Second mark.
        b: usize,
    },
}

/// The marks' layout on the face: centre (u, v) in metres and rotation of each.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CircleModel {
    centres: [[f64; 2]; MAX_MODEL_MARKS],
    rotations: [MarkRotation; MAX_MODEL_MARKS],
    len: usize,
    radius_m: f64,
}

impl CircleModel {
    /// A model of marks of outer radius `radius_m` at the given centres and rotations.
    ///
    /// # Errors
    /// [`ModelError`] for fewer than 5 or more than [`MAX_MODEL_MARKS`] marks, non-finite
    /// numbers, a radius that is not positive, or overlapping marks.
    pub fn new(radius_m: f64, marks: &[([f64; 2], MarkRotation)]) -> Result<Self, ModelError> {
        if !(5..=MAX_MODEL_MARKS).contains(&marks.len()) {
            return Err(ModelError::Count { got: marks.len() });
        }
        if !(radius_m.is_finite() && radius_m > 0.0) {
            return Err(ModelError::NotFinite {
                what: "radius",
                expected: "positive number",
            });
        }
        let mut m = Self {
            centres: [[0.0; 2]; MAX_MODEL_MARKS],
            rotations: [MarkRotation::Zero; MAX_MODEL_MARKS],
            len: marks.len(),
            radius_m,
        };
        for (i, (c, r)) in marks.iter().enumerate() {
            if !(c[0].is_finite() && c[1].is_finite()) {
                return Err(ModelError::NotFinite {
                    what: "mark centre",
                    expected: "number",
                });
            }
            for (j, (d, _)) in marks[..i].iter().enumerate() {
                if (c[0] - d[0]).hypot(c[1] - d[1]) < 2.0 * radius_m {
                    return Err(ModelError::Overlap { a: j, b: i });
                }
            }
            m.centres[i] = *c;
            m.rotations[i] = *r;
        }
        Ok(m)
    }

    /// Number of marks.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Never true (a model has at least 5 marks); here for the `len` convention.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Mark centres (u, v), metres.
    pub fn centres(&self) -> &[[f64; 2]] {
        &self.centres[..self.len]
    }

    /// Mark rotations.
    pub fn rotations(&self) -> &[MarkRotation] {
        &self.rotations[..self.len]
    }

    /// Outer radius of every mark, m.
    pub fn radius_m(&self) -> f64 {
        self.radius_m
    }
}
