//! `[body]`, `[dock]`, `[tether]` and `[success]`: physical geometry and tolerances.

use crate::config::Validator;
use serde::{Deserialize, Serialize};

/// The robot's footprint.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// Length, m.
    pub length_m: f64,
    /// Width, m.
    pub width_m: f64,
    /// Height, m (lowered height for robots that change geometry).
    pub height_m: f64,
}

/// The dock (mother's pouch, docking station, tether-end target) and its approach zone.
///
/// Dock frame: origin at the middle of the entrance, +x pointing out of the dock along
/// its axis (toward where the daughter comes from), +y to the left looking along +x.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DockSpec {
    /// Width of the entrance (inner), m.
    pub entrance_width_m: f64,
    /// Depth from the entrance to the contact plates, m.
    pub depth_m: f64,
    /// Funnel half-angle: how far off axis the entrance still guides the robot in, deg.
    #[serde(default)]
    pub funnel_half_angle_deg: f64,
    /// Radius of the approach zone (where the target can be perceived), m.
    pub approach_radius_m: f64,
    /// Half-width of the approach zone, degrees off the dock axis.
    pub approach_half_angle_deg: f64,
}

/// A tether between robot and dock.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TetherSpec {
    /// Total length, m.
    pub length_m: f64,
    /// Largest reel rate, m/s.
    pub max_reel_rate_mps: f64,
    /// Distance from the dock axis pivot to the tether exit on the dock, m (Axel's d_arm).
    #[serde(default)]
    pub arm_m: f64,
}

/// When a docking run counts as a success.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SuccessSpec {
    /// Largest lateral error at the entrance, m.
    pub lateral_tolerance_m: f64,
    /// Largest heading error at the entrance, degrees.
    pub heading_tolerance_deg: f64,
    /// A run fails after this long, s.
    pub timeout_s: f64,
}

pub(crate) fn validate_body(b: &BodySpec, v: &mut Validator<'_>) {
    v.positive("body.length_m", b.length_m);
    v.positive("body.width_m", b.width_m);
    v.positive("body.height_m", b.height_m);
}

/// `target_enters_robot`: the dock is a target that enters a socket on the robot (RAPOSA's
/// pyramid), so the entrance is the socket's mouth and may be narrower than the body.
pub(crate) fn validate_dock(d: &DockSpec, body: &BodySpec, target_enters_robot: bool, v: &mut Validator<'_>) {
    v.positive("dock.entrance_width_m", d.entrance_width_m);
    v.positive("dock.depth_m", d.depth_m);
    v.range("dock.funnel_half_angle_deg", d.funnel_half_angle_deg, 0.0, 89.0);
    v.positive("dock.approach_radius_m", d.approach_radius_m);
    v.range("dock.approach_half_angle_deg", d.approach_half_angle_deg, 0.0, 180.0);
    if !target_enters_robot && d.entrance_width_m > 0.0 && body.width_m > 0.0 && d.entrance_width_m < body.width_m {
        v.problem(
            "dock.entrance_width_m",
            format!(
                "expected an entrance at least as wide as the body ({} m), got {} m",
                body.width_m, d.entrance_width_m
            ),
        );
    }
}

pub(crate) fn validate_tether(t: &TetherSpec, v: &mut Validator<'_>) {
    v.positive("tether.length_m", t.length_m);
    v.positive("tether.max_reel_rate_mps", t.max_reel_rate_mps);
    v.non_negative("tether.arm_m", t.arm_m);
}

pub(crate) fn validate_success(s: &SuccessSpec, v: &mut Validator<'_>) {
    v.positive("success.lateral_tolerance_m", s.lateral_tolerance_m);
    v.range("success.heading_tolerance_deg", s.heading_tolerance_deg, 0.0, 180.0);
    v.positive("success.timeout_s", s.timeout_s);
}
