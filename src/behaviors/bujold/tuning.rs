//! Bujold's robot-wide tuning, the `[robot]` table of a profile whose `kind = "bujold"`:
//! which approach motor schema runs, its gains, and what the phase schemas share. Each
//! phase's own tuning sits with its node's `params` ([`super::params`]).
//!
//! ```toml
//! [robot]
//! kind = "bujold"
//! approach = "ratio_steering"   # or "potential_field" (then [robot.potential_field])
//! [robot.ratio_steering]        # seed 004 §V
//! [robot.shared]                # view filtering and staging (defaults: ours)
//! ```

use crate::config::{Validate, Validator};
use serde::{Deserialize, Serialize};

/// The approach motor schema Bujold's phases steer with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Approach {
    /// Pixel-ratio steering (seed 004 §V).
    #[default]
    RatioSteering,
    /// Arkin & Murphy's potential field on the relative pose, realised by the ratio
    /// steering's turn-or-drive alternation on a restricted base.
    PotentialField,
}

/// Bujold's `[robot]` table (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BujoldRobot {
    /// The approach motor schema.
    #[serde(default)]
    pub approach: Approach,
    /// Ratio-steering gains (also realise the field on a turn-or-drive base).
    pub ratio_steering: RatioSteeringGains,
    /// Potential-field gains (required when `approach = "potential_field"`).
    #[serde(default)]
    pub potential_field: Option<PotentialFieldGains>,
    /// What the phase schemas share.
    #[serde(default)]
    pub shared: BujoldTuning,
}

impl Validate for BujoldRobot {
    fn validate(&self, v: &mut Validator<'_>) {
        self.shared.check("robot.shared", v);
        let g = &self.ratio_steering;
        v.range("robot.ratio_steering.dead_band", g.dead_band, 0.0, 1.0);
        v.range("robot.ratio_steering.understeer", g.understeer, 0.0, 1.0);
        v.positive("robot.ratio_steering.turn_rate_dps", g.turn_rate_dps);
        v.positive("robot.ratio_steering.drive_speed_mps", g.drive_speed_mps);
        v.require(g.dock_total_px > 0, "robot.ratio_steering.dock_total_px", || {
            "expected a count ≥ 1".into()
        });
        v.positive("robot.ratio_steering.centre_tolerance_px", g.centre_tolerance_px);
        v.range("robot.ratio_steering.aim_fraction", g.aim_fraction, 0.0, 0.9);
        match (&self.approach, &self.potential_field) {
            (Approach::PotentialField, None) => v.problem(
                "robot.approach",
                "approach = \"potential_field\" needs a [robot.potential_field] table",
            ),
            (_, Some(g)) => {
                v.range(
                    "robot.potential_field.approach_sector_deg",
                    g.approach_sector_deg,
                    0.0,
                    90.0,
                );
                v.range(
                    "robot.potential_field.coercive_attraction",
                    g.coercive_attraction,
                    0.0,
                    1.0,
                );
                v.positive("robot.potential_field.gain", g.gain);
                v.positive("robot.potential_field.k_theta", g.k_theta);
                v.non_negative("robot.potential_field.final_radius_m", g.final_radius_m);
                v.range(
                    "robot.potential_field.max_off_sight_deg",
                    g.max_off_sight_deg,
                    0.0,
                    180.0,
                );
            }
            _ => {}
        }
    }
}

impl BujoldTuning {
    /// Checks the tuning found at `path` (`robot.shared`).
    pub fn check(&self, path: &str, v: &mut Validator<'_>) {
        let t = self;
        v.range(&format!("{path}.alpha_low_pass"), t.alpha_low_pass, 0.0, 1.0);
        v.positive(&format!("{path}.trust_ramp_px"), t.trust_ramp_px);
        v.require(t.ratio_jump > 0.0, &format!("{path}.ratio_jump"), || {
            format!(
                "expected a positive number (inf trusts every frame), got {}",
                t.ratio_jump
            )
        });
        v.require(
            (1..=64).contains(&t.alpha_window_frames),
            &format!("{path}.alpha_window_frames"),
            || format!("expected 1 to 64 frames, got {}", t.alpha_window_frames),
        );
    }
}

/// What Bujold's phase schemas share (`[robot.shared]`): how the fiducial views are
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
