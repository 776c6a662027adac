//! Percepts: what a perceptual schema hands to a motor schema.

use serde::{Deserialize, Serialize};

/// What every percept carries: when its sensor data was taken, and whether the stimulus
/// was found (with a confidence in [0, 1]).
pub trait Percept {
    /// Time the underlying sensor data was captured, seconds on the loop clock.
    fn stamp(&self) -> f64;
    /// True when the schema's stimulus (fiducial, target …) was detected.
    fn found(&self) -> bool;
    /// Confidence in [0, 1]; by default 1 when found and 0 otherwise.
    fn confidence(&self) -> f64 {
        if self.found() { 1.0 } else { 0.0 }
    }
}

/// A value with the time (seconds on the loop clock) it was measured.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Stamped<T> {
    /// Measurement time, seconds.
    pub stamp: f64,
    /// The measured value.
    pub value: T,
}

impl<T> Stamped<T> {
    /// Pairs a value with its time stamp.
    pub fn new(stamp: f64, value: T) -> Self {
        Self { stamp, value }
    }

    /// Age of the measurement at time `now`, seconds.
    pub fn age(&self, now: f64) -> f64 {
        now - self.stamp
    }
}
