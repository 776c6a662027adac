//! The planning geometry Axel's schemas share, taken from the profile: the regions, the
//! tether's geometry, the two-arc planner's limits, the speeds and the commit gate.

use super::tuning::TwoArcGains;
use crate::kinematics::tether_length::TetherGeometry;
use crate::kinematics::two_arc::{PlanParams, Regions};
use crate::perception::circles::RigCamera;
use crate::profile::Profile;

/// The planning geometry every schema shares, from the profile.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Geometry {
    /// The regions (`[robot.two_arc]` radii, `[dock]` approach radius and angle).
    pub regions: Regions,
    /// The tether's anchor and the arm (`[tether]`).
    pub tether: TetherGeometry,
    /// The planner's limits; the field of view is the cameras', the per-arc turn cap
    /// `robot.two_arc.max_arc_turn_deg` (none when absent).
    pub plan: PlanParams,
    /// Speed along arcs, m/s (`robot.two_arc.arc_speed_mps`).
    pub arc_speed: f64,
    /// The base's turn-rate limit, rad/s.
    pub max_turn_rate: f64,
    /// The reel's top rate, m/s.
    pub max_reel_rate: f64,
    /// Heading tolerance before reeling, rad (`robot.two_arc.heading_tolerance_deg`,
    /// seed 000 §V-B ±5°).
    pub heading_tolerance: f64,
    /// Tether reeled in past the cone's mouth while mating, m (`robot.two_arc.reel_in_m`).
    pub reel_in: f64,
    /// The commitment gate before mating: the arm tip's largest lateral offset from the
    /// cone's axis, m (`success.lateral_tolerance_m`).
    pub gate_lateral: f64,
    /// The commitment gate before mating: the arm's largest angle to the cone's axis, rad
    /// (`success.heading_tolerance_deg`).
    pub gate_heading: f64,
}

impl Geometry {
    /// The geometry of an Axel profile (`[dock]`, `[tether]`, `[robot.two_arc]`, two
    /// cameras).
    ///
    /// # Errors
    /// A message naming the missing table.
    pub fn from_profile(profile: &Profile, fov_half_angle: f64, gains: &TwoArcGains) -> Result<Self, String> {
        let err = |what: &str| format!("Axel's behavior needs {what}");
        let dock = profile.dock.as_ref().ok_or_else(|| err("[dock]"))?;
        let tether = profile.tether.ok_or_else(|| err("[tether]"))?;
        let limits = profile.drive.limits();
        Ok(Self {
            regions: Regions {
                mating_radius: gains.mating_radius_m,
                alignment_radius: gains.alignment_radius_m,
                approach_radius: dock.approach_radius_m,
                approach_half_angle: dock.approach_half_angle_deg.to_radians(),
            },
            tether: TetherGeometry::new(tether.anchor_depth_m, tether.arm_m),
            plan: PlanParams {
                fov_half_angle,
                max_arc_turn: gains.max_arc_turn_deg.map_or(f64::INFINITY, f64::to_radians),
                ..PlanParams::default()
            },
            arc_speed: gains.arc_speed_mps,
            max_turn_rate: limits.max_turn_rate,
            max_reel_rate: tether.max_reel_rate_mps,
            heading_tolerance: gains.heading_tolerance_deg.to_radians(),
            reel_in: gains.reel_in_m,
            gate_lateral: profile.success.lateral_tolerance_m,
            gate_heading: profile.success.heading_tolerance_deg.to_radians(),
        })
    }

    /// The camera's half field of view, rad: the bearing of the image's side edge at its
    /// middle row, through camera 0's model and mount.
    pub fn camera_half_fov(profile: &Profile) -> Option<f64> {
        let c = profile.cameras.first()?;
        let rig = RigCamera::from_profile(profile, 0).ok()?;
        let ray = rig.ray([0.0, c.height_px as f64 / 2.0]);
        Some(ray.y.atan2(ray.x).abs())
    }
}
