//! RAPOSA's robot-wide tuning, the `[robot]` table of a profile whose `kind = "raposa"`:
//! the seven states' gains and thresholds, and, on a two-block flap, how the flap's views
//! are filtered. Each phase's own tuning sits with its node's `params` ([`super::params`]).
//!
//! ```toml
//! [robot]
//! kind = "raposa"
//! [robot.seven_state]           # seed 001 §II.D–E
//! [robot.two_block]             # only on a two-block flap (the adapter of super::source)
//! ```

use crate::behaviors::bujold::tuning::BujoldTuning;
use crate::config::{Validate, Validator};
use serde::{Deserialize, Serialize};

/// RAPOSA's `[robot]` table (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RaposaRobot {
    /// The seven states' gains and thresholds.
    pub seven_state: SevenStateGains,
    /// How a two-block flap's views are filtered (the two-block adapter; defaults).
    #[serde(default)]
    pub two_block: BujoldTuning,
}

impl Validate for RaposaRobot {
    fn validate(&self, v: &mut Validator<'_>) {
        self.two_block.check("robot.two_block", v);
        let g = &self.seven_state;
        let n = |f: &str| format!("robot.seven_state.{f}");
        for (f, x) in [
            ("k_lin", g.k_lin),
            ("k_ang", g.k_ang),
            ("far_speed_mps", g.far_speed_mps),
            ("far_distance_m", g.far_distance_m),
            ("distance_threshold_m", g.distance_threshold_m),
            ("dead_zone_exit_m", g.dead_zone_exit_m),
            ("final_distance_m", g.final_distance_m),
            ("final_speed_mps", g.final_speed_mps),
            ("final_time_s", g.final_time_s),
            ("region2_distance_m", g.region2_distance_m),
            ("vision_turn_rate_dps", g.vision_turn_rate_dps),
            ("turn_rate_dps", g.turn_rate_dps),
            ("travel_speed_mps", g.travel_speed_mps),
            ("k_rho", g.k_rho),
            ("k_heading", g.k_heading),
            ("position_tolerance_m", g.position_tolerance_m),
            ("rotation_tolerance_deg", g.rotation_tolerance_deg),
            ("search_rate_dps", g.search_rate_dps),
            ("search_sweep_deg", g.search_sweep_deg),
        ] {
            v.positive(&n(f), x);
        }
        v.non_negative(&n("k_arm"), g.k_arm);
        v.non_negative(&n("fov_margin_px"), g.fov_margin_px);
        v.non_negative(&n("settle_tolerance_deg"), g.settle_tolerance_deg);
        v.range(&n("angle_threshold_deg"), g.angle_threshold_deg, 0.0, 90.0);
        v.require(g.search_sweep_deg < 360.0, &n("search_sweep_deg"), || {
            format!("expected a first sweep under 360°, got {}", g.search_sweep_deg)
        });
        v.nonzero(&n("lost_frames"), g.lost_frames as usize);
        v.require(
            g.dead_zone_exit_m > g.distance_threshold_m,
            &n("dead_zone_exit_m"),
            || {
                format!(
                    "expected more than distance_threshold_m ({}), got {}",
                    g.distance_threshold_m, g.dead_zone_exit_m
                )
            },
        );
    }
}

/// Gains and thresholds of RAPOSA's seven-state servo (seed 001 §II.D–E). The paper gives
/// the control laws and a few thresholds; `profiles/raposa.toml` says where each value
/// comes from.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SevenStateGains {
    /// State 1 near law v = K_lin·√(A₁/A), m/s (A₁ the ball's area at 1 m, so v ≈ K_lin·d).
    pub k_lin: f64,
    /// ω = −K_ang·x_dev, rad/s per pixel.
    pub k_ang: f64,
    /// Arm = −K_arm·y_dev at the end of state 1, rad per pixel.
    pub k_arm: f64,
    /// Constant state-1 speed beyond `far_distance_m`, m/s.
    pub far_speed_mps: f64,
    /// Beyond this camera-to-ball distance state 1 drives at constant speed, and a lone
    /// ellipse selects state 3, m (paper: about 1 m).
    pub far_distance_m: f64,
    /// Region II above this α, degrees (paper: 15).
    pub angle_threshold_deg: f64,
    /// Extra α allowed right after a region-II manoeuvre, degrees (the paper's "tolerance
    /// within a certain distance range" for odometry error).
    pub settle_tolerance_deg: f64,
    /// Region II only beyond this socket-to-ball distance; closer, α is unreliable and
    /// state 1 runs (the paper's dead zone), m (paper: 0.34).
    pub distance_threshold_m: f64,
    /// Leave the dead zone first: a misaligned robot closer than `distance_threshold_m`
    /// backs away to `dead_zone_exit_m` before choosing again (not in the paper, whose
    /// points 1 and 3 never docked).
    pub leave_dead_zone: bool,
    /// Socket-to-ball distance to back off to when leaving the dead zone, m.
    pub dead_zone_exit_m: f64,
    /// State 6 starts at this camera-to-ball distance (area threshold), m (paper: 0.3).
    pub final_distance_m: f64,
    /// State 6 speed, m/s.
    pub final_speed_mps: f64,
    /// State 6 duration, s.
    pub final_time_s: f64,
    /// Region II lands the socket on the axis at this distance δ from the ball, m.
    pub region2_distance_m: f64,
    /// State 7 (vision-tracked rotation) turn rate, degrees per second: low, so the
    /// ellipse can be tracked.
    pub vision_turn_rate_dps: f64,
    /// State 7 ends when the predicted ellipse comes this close to the image edge, px.
    pub fov_margin_px: f64,
    /// State 7 stops on a lost ellipse and gives up after this many frames without it.
    pub lost_frames: u32,
    /// Odometry rotation rate, degrees per second.
    pub turn_rate_dps: f64,
    /// Largest travel speed of the (x_ref, y_ref) controller, m/s.
    pub travel_speed_mps: f64,
    /// Inverse controller: speed per metre of remaining distance, 1/s.
    pub k_rho: f64,
    /// Inverse controller: yaw rate per radian of heading error, 1/s.
    pub k_heading: f64,
    /// Travel ends within this distance of (x_ref, y_ref), m.
    pub position_tolerance_m: f64,
    /// Rotations end within this angle, degrees.
    pub rotation_tolerance_deg: f64,
    /// Slow search: turn rate, degrees per second.
    pub search_rate_dps: f64,
    /// Slow search: first sweep, degrees (doubles after each switch, capped below 360°).
    pub search_sweep_deg: f64,
}
