//! `axel.mate_close` and `axel.mate_reel`, the two states of the profile's `mate`
//! sequence: the mating (seed 000 §II, §IV). Committed at the look pose
//! ([`Memory::commit`]), the markers now too close to identify, the rover drives blind
//! by odometry straight in until its arm's tip is `standoff_m` from the cone's mouth,
//! reeling in to the exposed length at its end (by the reel's reading); then it puts its
//! wheels in free rotation and reels in until the reel's paid-out length is `robot.two_arc.reel_in_m` short
//! of the exposed length at the mouth (about 25 cm into the module, §II), the tether
//! pulling the arm into the cone. The reel's own length reading decides, so slack left
//! from the approach is taken up first. Whether it seated is the
//! cone's business (the simulator's judge ends the run when it does); the paper had no
//! sensor to confirm it and ended on the penultimate pose, so once the reel has wound in
//! its length the schema reports `docked` as the paper's robot would. A stall is the
//! separate `axel.stall` leaf's (by the reel's current).

use super::memory::Memory;
use crate::geometry::Pose2;
use crate::kinematics::two_arc::Arc;
use crate::schemas::{Behavior, DriveCommand, FailureReason, Inputs, Outcome, Step};
use serde::Deserialize;

/// `axel.mate_close`'s params.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MateParams {
    /// The blind drive ends with the tip this far from the mouth, m.
    pub standoff_m: f64,
    /// Speed of the blind drive, m/s (slow in the mating region, §IV).
    pub speed_mps: f64,
}

impl Default for MateParams {
    fn default() -> Self {
        Self {
            standoff_m: 0.05,
            speed_mps: 0.04,
        }
    }
}

/// `axel.mate_close`: the blind drive (see the module docs); event `closed` with the tip
/// at the standoff, or the docking failed without a committed pose to mate from.
pub struct Close {
    params: MateParams,
    /// Path left to drive, m, and the odometry pose it was measured at.
    left: f64,
    last: Pose2,
    reel: f64,
}

impl Close {
    /// A leaf with `params`.
    pub fn new(params: MateParams) -> Self {
        Self {
            params,
            left: 0.0,
            last: Pose2::default(),
            reel: 0.0,
        }
    }
}

impl Behavior<Memory> for Close {
    fn enter(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) {
        let g = m.geometry;
        let Some(at) = m.commit else {
            return;
        };
        self.left = (at.x - g.tether.arm - self.params.standoff_m).max(0.0);
        let arc = Arc {
            curvature: 0.0,
            length: self.left,
        };
        self.last = m.odo;
        self.reel = g
            .tether
            .reel_rate(m.reel.map(|r| r.length), &at, &arc, self.params.speed_mps);
    }

    fn tick(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) -> Option<Step> {
        if m.commit.is_none() {
            // Entered without a committed pose: nothing aligned to mate.
            return Some(
                m.hold("mate")
                    .finishing(Outcome::Failed(FailureReason::FailedToControl)),
            );
        }
        self.left -= m.odo.distance(&self.last);
        if self.left <= 0.0 {
            return Some(m.hold("mate_close").with_event("closed"));
        }
        self.last = m.odo;
        let drive = DriveCommand::Straight {
            v: self.params.speed_mps,
        };
        Some(m.drive(drive, self.reel, "mate_close"))
    }
}

/// `axel.mate_reel`: wheels free, reel in until the reel's paid-out length is
/// `robot.two_arc.reel_in_m` short of the exposed length with the tip at the mouth; then
/// docked (see the module docs).
pub struct Reel {
    until: f64,
}

impl Default for Reel {
    fn default() -> Self {
        Self { until: f64::INFINITY }
    }
}

impl Behavior<Memory> for Reel {
    fn enter(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) {
        // The exposed length with the tip at the mouth, less the reel-in.
        let g = m.geometry;
        let mouth = Pose2::new(g.tether.arm, 0.0, std::f64::consts::PI);
        self.until = (g.tether.length_at(&mouth) - g.reel_in).max(0.0);
    }

    fn tick(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) -> Option<Step> {
        if m.commit.is_none() {
            return Some(
                m.hold("mate")
                    .finishing(Outcome::Failed(FailureReason::FailedToControl)),
            );
        }
        let reeled = m.reel.is_some_and(|r| r.length <= self.until);
        let step = m.free_reel("mate_reel");
        Some(if reeled { step.finishing(Outcome::Docked) } else { step })
    }
}
