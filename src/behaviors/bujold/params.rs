//! Tuning of Bujold's phase schemas, each read from its node's `params` table in
//! `profiles/bujold.toml` (`[behavior.tree.nodes.<phase>.params]`). Every field has the
//! default the campaigns were tuned with, so a profile states only what it changes; the
//! shipped profile states them all, with where each value comes from.

use serde::{Deserialize, Serialize};

pub use super::tuning::BujoldTuning;

/// `undock`: leave the pouch front first, lowered.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct UndockParams {
    /// Speed, m/s.
    pub speed_mps: f64,
    /// Drive this far beyond the pouch's depth before raising, m.
    pub beyond_depth_m: f64,
}

impl Default for UndockParams {
    fn default() -> Self {
        Self {
            speed_mps: 0.05,
            beyond_depth_m: 0.05,
        }
    }
}

/// `drive_out`: drive away from the dock, raised, imprinting on the way.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DriveOutParams {
    /// Departure distance from where it began, m.
    pub distance_m: f64,
    /// Speed, m/s.
    pub speed_mps: f64,
}

impl Default for DriveOutParams {
    fn default() -> Self {
        Self {
            distance_m: 1.2,
            speed_mps: 0.06,
        }
    }
}

/// `search`: rotate in place toward the side the fiducial was last seen.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SearchParams {
    /// A view changing less than this (mean 8-bit levels per frame, see
    /// [`FrameChange`](crate::perception::frame_change::FrameChange)) is still: pixel
    /// noise of ±6 levels reads under 0.5, one tick of the search turn 3.6–8.2 on rendered
    /// scenes (`tests/sim_render.rs`).
    pub still_levels: f32,
    /// The turn is jammed when the view stays still this long, s.
    pub jammed_after_s: f64,
    /// Unjamming manoeuvres allowed per docking attempt (the search stays bounded).
    pub max_unjams: u32,
}

impl Default for SearchParams {
    fn default() -> Self {
        Self {
            still_levels: 1.0,
            jammed_after_s: 1.5,
            max_unjams: 3,
        }
    }
}

/// `approach`: steer on the fiducial; reposition when clearly off the axis.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ApproachParams {
    /// Back to search after the fiducial has been out of sight this long, s.
    pub lost_after_s: f64,
    /// A reliable view more than this far off the axis triggers repositioning, m.
    pub reposition_lateral_m: f64,
    /// What the leaf proposes: a steering command, or the field's motion vector for a
    /// vector-sum arbiter to combine with other schemas (needs
    /// `robot.approach = "potential_field"`).
    pub output: ApproachOutput,
    /// When set, the event `near` fires once the fiducial is closer than this to the
    /// camera, m: the dock area, where a composition may hand over to a state without
    /// obstacle avoidance (Murphy: the docking behavior lowers avoid's gain near the dock,
    /// whose own body would repel the robot).
    pub near_m: Option<f64>,
}

impl Default for ApproachParams {
    fn default() -> Self {
        Self {
            lost_after_s: 1.5,
            reposition_lateral_m: 0.08,
            output: ApproachOutput::Steer,
            near_m: None,
        }
    }
}

/// What `bujold.approach` proposes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ApproachOutput {
    /// A turn-or-drive command from the approach motor schema (seed 004 §V).
    Steer,
    /// The potential field's body-frame motion vector.
    Vector,
}

/// `decide`: average views at the dock and decide to back in or retry.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DecideParams {
    /// Views averaged.
    pub frames: usize,
    /// Lost at the gate: back off after this long without enough views, s.
    pub lost_after_s: f64,
    /// Back in only within this fraction of the profile's success tolerances.
    pub tolerance_fraction: f64,
    /// And only with the heading at least this far inside its tolerance, degrees: the
    /// error of the heading estimate at the gate, which the blind back-in cannot correct.
    /// Default 0 (the fraction alone). The margin is insurance for a robot that can still
    /// retry: the last decision, with the retries used up, backs in within the fraction
    /// alone, since declining it ends the mission in a certain failure.
    pub heading_margin_deg: f64,
}

impl Default for DecideParams {
    fn default() -> Self {
        Self {
            frames: 5,
            lost_after_s: 3.0,
            tolerance_fraction: 0.8,
            heading_margin_deg: 0.0,
        }
    }
}

/// `back_in`: lower and back in blind by odometry.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BackInParams {
    /// Speed, m/s.
    pub speed_mps: f64,
    /// Distance beyond the pouch's depth before declaring a miss, m.
    pub margin_m: f64,
    /// Smallest camera distance trusted from the decision, m.
    pub min_distance_m: f64,
    /// Heading change by odometry since the back-in began beyond which the robot is
    /// veering (a track slipping or stalled) and will miss the entrance, degrees: the
    /// back-in stops with the event `veered`. Default the dock's ±5° heading tolerance
    /// (seed 004); a straight back-in changes odometry's yaw by a fraction of a degree.
    pub max_yaw_drift_deg: f64,
}

impl Default for BackInParams {
    fn default() -> Self {
        Self {
            speed_mps: 0.04,
            margin_m: 0.15,
            min_distance_m: 0.1,
            max_yaw_drift_deg: 5.0,
        }
    }
}
