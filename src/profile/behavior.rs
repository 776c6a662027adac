//! `[behavior]` and `[loop]`: the behavior tree, the limits its leaves share, and loop
//! timing.

use super::tree::TreeSpec;
use crate::config::Validator;
use serde::{Deserialize, Serialize};

/// The `[behavior]` table: the tree a robot kind's leaves are composed in, and the limits
/// every robot's leaves share. The robot kind's own tuning is `[robot]`
/// ([`super::RobotSpec`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BehaviorSpec {
    /// The behavior tree (leaves, arbiters, transitions); see [`TreeSpec`].
    #[serde(default)]
    pub tree: Option<TreeSpec>,
    /// Retries after a failed attempt near the dock.
    #[serde(default)]
    pub max_retries: u32,
    /// Longest search before giving up, s.
    #[serde(default = "default_search_timeout")]
    pub search_timeout_s: f64,
    /// Longest any single sequencer state may last unless it says otherwise, s.
    #[serde(default = "unbounded")]
    pub phase_timeout_s: f64,
}

fn default_search_timeout() -> f64 {
    60.0
}

fn unbounded() -> f64 {
    f64::INFINITY
}

impl Default for BehaviorSpec {
    fn default() -> Self {
        Self {
            tree: None,
            max_retries: 0,
            search_timeout_s: default_search_timeout(),
            phase_timeout_s: unbounded(),
        }
    }
}

/// The `[loop]` table.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoopSpec {
    /// Tick rate, Hz.
    pub rate_hz: f64,
    /// Cameras are required; a frame older than this stops the robot, s.
    #[serde(default)]
    pub camera_stale_s: Option<f64>,
    /// Odometry is required; older than this stops the robot, s.
    #[serde(default)]
    pub odometry_stale_s: Option<f64>,
    /// A frame bit-identical to its camera's last one is the same exposure re-sent by a
    /// frozen driver, and ages from when it first arrived (default true: a real sensor's
    /// noise makes every exposure differ). Set false for a noiseless synthetic camera.
    #[serde(default = "yes")]
    pub camera_repeats_stale: bool,
}

fn yes() -> bool {
    true
}

pub(crate) fn validate_behavior(b: &BehaviorSpec, v: &mut Validator<'_>) {
    if let Some(t) = &b.tree {
        super::tree::validate_tree(t, "behavior.tree", v);
    }
    v.positive("behavior.search_timeout_s", b.search_timeout_s);
    v.require(b.phase_timeout_s > 0.0, "behavior.phase_timeout_s", || {
        format!(
            "expected a positive number of seconds (inf: no limit), got {}",
            b.phase_timeout_s
        )
    });
}

pub(crate) fn validate_loop(l: &LoopSpec, v: &mut Validator<'_>) {
    v.require(
        l.rate_hz.is_finite() && l.rate_hz > 0.0 && l.rate_hz <= 1000.0,
        "loop.rate_hz",
        || format!("expected a rate in (0, 1000] Hz, got {}", l.rate_hz),
    );
    for (path, s) in [
        ("loop.camera_stale_s", l.camera_stale_s),
        ("loop.odometry_stale_s", l.odometry_stale_s),
    ] {
        if let Some(s) = s {
            v.positive(path, s);
            if s.is_finite() && s > 0.0 && l.rate_hz > 0.0 && s < 1.0 / l.rate_hz {
                v.problem(
                    path,
                    format!(
                        "expected a limit of at least one tick (1/rate_hz = {:.4} s), got {s}",
                        1.0 / l.rate_hz
                    ),
                );
            }
        }
    }
}
