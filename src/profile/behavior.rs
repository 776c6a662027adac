//! `[behavior]` and `[loop]`: which behaviors run, their gains, and loop timing.

use super::tree::TreeSpec;
use crate::config::Validator;
use serde::{Deserialize, Serialize};

/// The approach behavior a profile selects.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ApproachKind {
    /// Bujold's pixel-ratio steering (seed 004 §V).
    RatioSteering,
    /// Arkin & Murphy potential-field docking on a relative pose.
    PotentialField,
    /// RAPOSA's seven-state vision servo (seed 001 §II).
    SevenState,
    /// Axel's region planner with two-arc manoeuvres (seed 000).
    TwoArc,
    /// No docking behavior (state estimation only, e.g. AutoKrawler).
    None,
}

/// What Bujold's phase schemas share (`[behavior.bujold]`): how the fiducial views are
/// filtered and where repositioning stages. Each phase's own tuning sits with its node in
/// `[behavior.tree]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BujoldTuning {
    /// The viewing angle from the block ratio is not trusted for blocks under this
    /// height, px (at 1.3 m two-pixel noise is ±35° of viewing angle).
    pub trust_from_px: f64,
    /// ... and fully trusted this much taller, px.
    pub trust_ramp_px: f64,
    /// Low-pass gain on the viewing angle per frame.
    pub alpha_low_pass: f64,
    /// Blocks at least this tall give a viewing angle good enough to plan on, px.
    pub reliable_height_px: f64,
    /// Reliable frames the repositioning decision takes the median over (longer than a
    /// rotating beacon's period: a flash cannot fake an off-axis view), at most 64.
    pub alpha_window_frames: usize,
    /// Largest change of the block asymmetry (L − R)/(L + R) from one trusted frame to
    /// the next; a larger jump is a flash or a shadow on one block, and that frame's ratio
    /// is not used (`inf` trusts every frame). See `perception::RatioJumpGate`.
    pub ratio_jump: f64,
    /// Rejected frames in a row after which a changed ratio is accepted as real.
    pub ratio_jump_reset_frames: u32,
    /// Staging distance on the dock axis for repositioning, m.
    pub staging_x_m: f64,
    /// Staging at least this much farther out than the robot is, m.
    pub staging_margin_m: f64,
    /// Closer to the body than this (m along the axis) the robot drives out before turning.
    pub clearance_x_m: f64,
    /// Where on the dock axis the ballistic drive to an a-priori dock location ends, m:
    /// far enough that an a-priori error of a few decimetres still leaves the flap in view.
    pub ballistic_staging_m: f64,
}

impl Default for BujoldTuning {
    fn default() -> Self {
        Self {
            trust_from_px: 18.0,
            trust_ramp_px: 25.0,
            alpha_low_pass: 0.3,
            reliable_height_px: 40.0,
            alpha_window_frames: 16,
            ratio_jump: 0.04,
            ratio_jump_reset_frames: 3,
            staging_x_m: 0.75,
            staging_margin_m: 0.15,
            clearance_x_m: 0.45,
            ballistic_staging_m: 1.2,
        }
    }
}

/// Gains of the ratio-steering motor schema.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RatioSteeringGains {
    /// Half-width of the dead band around a ratio of 1 (no turn inside it).
    pub dead_band: f64,
    /// Fraction of the needed turn actually commanded (< 1 understeers).
    pub understeer: f64,
    /// Turn-in-place rate, degrees per second.
    pub turn_rate_dps: f64,
    /// Straight-drive speed far from the dock, m/s.
    pub drive_speed_mps: f64,
    /// Summed pixel count at which the robot is at (or beside) the dock.
    pub dock_total_px: u32,
    /// Largest horizontal offset of the pair from the image centre to back in, px.
    pub centre_tolerance_px: f64,
    /// Where the aim point sits on the dock axis, as a fraction f of the robot's distance
    /// along it (0.5, the default: halfway in). Heading at it, the robot's lateral offset
    /// shrinks as (x/x₀)^(1/(1−f)) while it closes from x₀ to x: halfway gives a square
    /// law, two thirds a cube.
    #[serde(default = "default_aim_fraction")]
    pub aim_fraction: f64,
}

fn default_aim_fraction() -> f64 {
    0.5
}

/// Gains of the potential-field docking schema (ALGORITHMS §1.3).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PotentialFieldGains {
    /// Half-width of the approach sector where attraction dominates, degrees.
    pub approach_sector_deg: f64,
    /// Attraction weight in the coercive zone (tangential weight is 1 there).
    pub coercive_attraction: f64,
    /// Overall gain (m/s at full field).
    pub gain: f64,
    /// Heading-controller gain turning the field vector into a twist, 1/s.
    pub k_theta: f64,
    /// Radius of the final zone, m: the tangential pull fades from full at twice this
    /// distance from the dock to nothing at it, so the robot arrives pointing at the
    /// entrance (0, the default: no fading).
    #[serde(default)]
    pub final_radius_m: f64,
    /// Largest angle between the field's direction and the line of sight to the dock,
    /// degrees: a camera that looks along the motion keeps the dock in view with about
    /// half its field of view less a margin (Bujold: 25° of a 70° lens). 180, the
    /// default, leaves the field free.
    #[serde(default = "free_field_deg")]
    pub max_off_sight_deg: f64,
}

fn free_field_deg() -> f64 {
    180.0
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

/// Gains of Axel's two-arc docking (seed 000).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TwoArcGains {
    /// Heading tolerance before reeling in, degrees (paper: ±5).
    pub heading_tolerance_deg: f64,
    /// Radius of the mating region, m.
    pub mating_radius_m: f64,
    /// Radius of the alignment region, m.
    pub alignment_radius_m: f64,
    /// Tether reeled in during mating, m (paper: about 0.25).
    pub reel_in_m: f64,
    /// Speed along arcs, m/s.
    pub arc_speed_mps: f64,
    /// Largest heading change of any one planned arc, degrees; absent: no cap. The reel
    /// pays out at a constant rate along each arc, the paper's linear approximation of
    /// the tether's length, which it found sufficient below 30° (seed 000 §V-F); a cap
    /// keeps every arc in that range (`axel-arc-cap` measures it against none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_arc_turn_deg: Option<f64>,
}

/// The `[behavior]` table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BehaviorSpec {
    /// Approach behavior.
    pub approach: ApproachKind,
    /// The behavior tree (leaves, arbiters, transitions); see [`TreeSpec`].
    #[serde(default)]
    pub tree: Option<TreeSpec>,
    /// Tuning Bujold's phase schemas share.
    #[serde(default)]
    pub bujold: Option<BujoldTuning>,
    /// Retries after a failed attempt near the dock.
    pub max_retries: u32,
    /// Longest search rotation before giving up, s.
    pub search_timeout_s: f64,
    /// Longest any single phase may last, s.
    pub phase_timeout_s: f64,
    /// Ratio-steering gains (required when `approach = "ratio_steering"`).
    #[serde(default)]
    pub ratio_steering: Option<RatioSteeringGains>,
    /// Potential-field gains (required when `approach = "potential_field"`).
    #[serde(default)]
    pub potential_field: Option<PotentialFieldGains>,
    /// Seven-state gains (required when `approach = "seven_state"`).
    #[serde(default)]
    pub seven_state: Option<SevenStateGains>,
    /// Two-arc gains (required when `approach = "two_arc"`).
    #[serde(default)]
    pub two_arc: Option<TwoArcGains>,
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
    /// Tether sensing is required; older than this stops the robot, s.
    #[serde(default)]
    pub tether_stale_s: Option<f64>,
    /// The dock switch is required; a reading older than this stops the robot, s (a
    /// docking that ends on the switch must not trust a switch that stopped answering).
    #[serde(default)]
    pub dock_switch_stale_s: Option<f64>,
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
    if let Some(t) = &b.bujold {
        v.range("behavior.bujold.alpha_low_pass", t.alpha_low_pass, 0.0, 1.0);
        v.positive("behavior.bujold.trust_ramp_px", t.trust_ramp_px);
        v.require(t.ratio_jump > 0.0, "behavior.bujold.ratio_jump", || {
            format!(
                "expected a positive number (inf trusts every frame), got {}",
                t.ratio_jump
            )
        });
        v.require(
            (1..=64).contains(&t.alpha_window_frames),
            "behavior.bujold.alpha_window_frames",
            || format!("expected 1 to 64 frames, got {}", t.alpha_window_frames),
        );
    }
    v.positive("behavior.search_timeout_s", b.search_timeout_s);
    v.positive("behavior.phase_timeout_s", b.phase_timeout_s);
    let missing = |v: &mut Validator<'_>, table: &str| {
        v.problem(
            "behavior.approach",
            format!("approach needs a [behavior.{table}] table"),
        );
    };
    match b.approach {
        ApproachKind::RatioSteering => match &b.ratio_steering {
            None => missing(v, "ratio_steering"),
            Some(g) => {
                v.range("behavior.ratio_steering.dead_band", g.dead_band, 0.0, 1.0);
                v.range("behavior.ratio_steering.understeer", g.understeer, 0.0, 1.0);
                v.positive("behavior.ratio_steering.turn_rate_dps", g.turn_rate_dps);
                v.positive("behavior.ratio_steering.drive_speed_mps", g.drive_speed_mps);
                v.require(g.dock_total_px > 0, "behavior.ratio_steering.dock_total_px", || {
                    "expected a count ≥ 1".into()
                });
                v.positive("behavior.ratio_steering.centre_tolerance_px", g.centre_tolerance_px);
                v.range("behavior.ratio_steering.aim_fraction", g.aim_fraction, 0.0, 0.9);
            }
        },
        ApproachKind::PotentialField => match &b.potential_field {
            None => missing(v, "potential_field"),
            Some(g) => {
                v.range(
                    "behavior.potential_field.approach_sector_deg",
                    g.approach_sector_deg,
                    0.0,
                    90.0,
                );
                v.range(
                    "behavior.potential_field.coercive_attraction",
                    g.coercive_attraction,
                    0.0,
                    1.0,
                );
                v.positive("behavior.potential_field.gain", g.gain);
                v.positive("behavior.potential_field.k_theta", g.k_theta);
                v.non_negative("behavior.potential_field.final_radius_m", g.final_radius_m);
                v.range(
                    "behavior.potential_field.max_off_sight_deg",
                    g.max_off_sight_deg,
                    0.0,
                    180.0,
                );
            }
        },
        ApproachKind::SevenState => match &b.seven_state {
            None => missing(v, "seven_state"),
            Some(g) => {
                let n = |f: &str| format!("behavior.seven_state.{f}");
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
        },
        ApproachKind::TwoArc => match &b.two_arc {
            None => missing(v, "two_arc"),
            Some(g) => {
                v.range(
                    "behavior.two_arc.heading_tolerance_deg",
                    g.heading_tolerance_deg,
                    0.0,
                    90.0,
                );
                v.positive("behavior.two_arc.mating_radius_m", g.mating_radius_m);
                v.positive("behavior.two_arc.alignment_radius_m", g.alignment_radius_m);
                v.require(
                    g.alignment_radius_m > g.mating_radius_m,
                    "behavior.two_arc.alignment_radius_m",
                    || {
                        format!(
                            "expected the alignment region ({} m) to be larger than the mating region ({} m)",
                            g.alignment_radius_m, g.mating_radius_m
                        )
                    },
                );
                v.positive("behavior.two_arc.reel_in_m", g.reel_in_m);
                v.positive("behavior.two_arc.arc_speed_mps", g.arc_speed_mps);
                if let Some(cap) = g.max_arc_turn_deg {
                    v.require(
                        cap.is_finite() && cap > 0.0 && cap <= 180.0,
                        "behavior.two_arc.max_arc_turn_deg",
                        || format!("expected a number in (0, 180], got {cap}"),
                    );
                }
            }
        },
        ApproachKind::None => {}
    }
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
        ("loop.tether_stale_s", l.tether_stale_s),
        ("loop.dock_switch_stale_s", l.dock_switch_stale_s),
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
