//! `axel.reel`: pure reeling, the paper's no-vision baseline (seed 000 §V-C) as a leaf.
//! The wheels go to free rotation and the reel winds in at its top rate from the first
//! tick; no camera is read and nothing is planned. Whether the arm finds the cone is the
//! tether's and the cone's physics (`sim::tether`, `sim::dock::Cone`), so the paper's two
//! limits (docks for |α| < 5°, tolerates |h| < 90°) must come out of the simulator, not
//! out of this leaf. It never finishes by itself: the judge ends the run when the arm
//! seats, and a reel pulling against a caught arm is the `axel.stall` leaf's to end
//! (`stuck_contact`), as on the paper's robot, which had no other way to know.
//!
//! `scenarios/axel-reel-only.toml` runs it from a grid over α and h;
//! `tests/axel_reel.rs` checks the same limits through the engine alone.

use super::memory::Memory;
use crate::schemas::{Behavior, Inputs, Step};

/// See the module docs.
pub struct Reel;

impl Behavior<Memory> for Reel {
    fn tick(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) -> Option<Step> {
        Some(m.free_reel("reel"))
    }
}
