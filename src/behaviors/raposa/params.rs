//! Tuning of RAPOSA's phase schemas, each read from its node's `params` table in
//! `profiles/raposa.toml` (`[behavior.tree.nodes.<phase>.params]`). The robot-wide gains
//! and thresholds of the seven states stay in `[robot.seven_state]`
//! ([`SevenStateGains`](super::tuning::SevenStateGains)); what is here is what one phase
//! alone uses. Every field has the default the campaigns were tuned with, so a profile
//! states only what it changes; the shipped profile states them all, with where each
//! value comes from.

use crate::schemas::Posture;
use serde::{Deserialize, Serialize};

/// `search` (state 5): the slow doubling search when nothing is seen.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SearchParams {
    /// Frames without anything seen before the search starts turning (a single dropped
    /// frame should not start a rotation).
    pub grace_frames: u32,
}

impl Default for SearchParams {
    fn default() -> Self {
        Self { grace_frames: 3 }
    }
}

/// `blue_only` (state 4): turn toward the blue edges, creep once centred.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BlueOnlyParams {
    /// Creep at the final speed once the blue region's centre is within this many pixels
    /// of the image centre, px.
    pub centred_px: f64,
}

impl Default for BlueOnlyParams {
    fn default() -> Self {
        Self { centred_px: 10.0 }
    }
}

/// `look`: after the region-II manoeuvre, stand still, then search slowly.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LookParams {
    /// Stand still this long first, letting the image settle after stopping, s.
    pub settle_s: f64,
}

impl Default for LookParams {
    fn default() -> Self {
        Self { settle_s: 0.5 }
    }
}

/// `leave_dead_zone`: back away until the socket is `dead_zone_exit_m` from the ball
/// (`[robot.seven_state]`), at least `min_distance_m`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LeaveDeadZoneParams {
    /// Shortest back-away, m.
    pub min_distance_m: f64,
}

impl Default for LeaveDeadZoneParams {
    fn default() -> Self {
        Self { min_distance_m: 0.05 }
    }
}

/// `retreat`: after a final approach without the dock switch, back away before retrying.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RetreatParams {
    /// How far, m.
    pub distance_m: f64,
}

impl Default for RetreatParams {
    fn default() -> Self {
        Self { distance_m: 0.4 }
    }
}

/// `final` (state 6): the final approach.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FinalParams {
    /// The body posture the final approach commands, and leaves raised again when it
    /// retries (`"lowered"` for a robot that must lower itself into its dock, as Bujold
    /// enters the pouch; RAPOSA lowers its back with the arm command instead). Absent (the
    /// default): no posture command.
    pub posture: Option<Posture>,
}

/// `probe` (ours): a lone ball in the dead zone, side unknown.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ProbeParams {
    /// Angle around the ball of the first probe, degrees; each next probe goes the other
    /// way and one step further (+1, −2, +3, −4 steps: ending ±1 and ±2 steps from the
    /// start).
    pub step_deg: f64,
}

impl Default for ProbeParams {
    fn default() -> Self {
        Self { step_deg: 35.0 }
    }
}
