//! Axel's robot-wide tuning, the `[robot]` table of a profile whose `kind = "axel"`: the
//! two-arc docking's regions, tolerances and speeds. Each phase's own tuning sits with its
//! node's `params`.
//!
//! ```toml
//! [robot]
//! kind = "axel"
//! [robot.two_arc]               # seed 000
//! ```

use crate::config::{Validate, Validator};
use serde::{Deserialize, Serialize};

/// Axel's `[robot]` table (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxelRobot {
    /// The two-arc docking's gains.
    pub two_arc: TwoArcGains,
}

impl Validate for AxelRobot {
    fn validate(&self, v: &mut Validator<'_>) {
        let g = &self.two_arc;
        v.range(
            "robot.two_arc.heading_tolerance_deg",
            g.heading_tolerance_deg,
            0.0,
            90.0,
        );
        v.positive("robot.two_arc.mating_radius_m", g.mating_radius_m);
        v.positive("robot.two_arc.alignment_radius_m", g.alignment_radius_m);
        v.require(
            g.alignment_radius_m > g.mating_radius_m,
            "robot.two_arc.alignment_radius_m",
            || {
                format!(
                    "expected the alignment region ({} m) to be larger than the mating region ({} m)",
                    g.alignment_radius_m, g.mating_radius_m
                )
            },
        );
        v.positive("robot.two_arc.reel_in_m", g.reel_in_m);
        v.positive("robot.two_arc.arc_speed_mps", g.arc_speed_mps);
        if let Some(cap) = g.max_arc_turn_deg {
            v.require(
                cap.is_finite() && cap > 0.0 && cap <= 180.0,
                "robot.two_arc.max_arc_turn_deg",
                || format!("expected a number in (0, 180], got {cap}"),
            );
        }
    }
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
