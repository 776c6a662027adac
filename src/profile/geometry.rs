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
    /// A funnel-like docking cone that only the robot's leading arm enters (Axel's central
    /// module, seed 000): the entrance is then the cone's round mouth, `depth_m` runs from
    /// the mouth to the throat where the arm's tip seats, and `funnel_half_angle_deg` is
    /// the angle of the cone's walls to its axis. Without it the entrance is a pouch the
    /// whole body enters.
    #[serde(default)]
    pub cone: Option<ConeSpec>,
}

/// The mechanical parts of a docking cone that decide whether a tether-pulled arm seats
/// (seed 000 §V-C, §V-F). The paper gives none of these numbers: they are ours.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConeSpec {
    /// Height of the cone's axis (the centre of its mouth) above the ground, m.
    pub axis_height_m: f64,
    /// The station tipped forward (its face turned toward the ground), degrees: the paper
    /// cured an arm tip catching on the cone's flat face by tipping it 5° (seed 000 §V-F).
    #[serde(default)]
    pub tilt_deg: f64,
    /// Length of the bore behind the throat that the arm's tip slides into, m: with the
    /// throat's clearance around the tip it bounds how far off the cone's axis the arm
    /// may lie and still seat.
    pub seat_length_m: f64,
}

impl DockSpec {
    /// Half-width of a cone's throat, m: the mouth's half-width narrowed by the walls over
    /// the depth (negative when the walls meet before the throat).
    pub fn throat_half_width(&self) -> f64 {
        self.entrance_width_m / 2.0 - self.depth_m * self.funnel_half_angle_deg.to_radians().tan()
    }
}

/// A tether between robot and dock.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TetherSpec {
    /// Total length, m.
    pub length_m: f64,
    /// Largest reel rate, m/s.
    pub max_reel_rate_mps: f64,
    /// The rover's arm, from its axle to its tip, where the tether leaves it, m: `d_arm`
    /// in eq. 1 of seed 000 §IV. Positive: the arm leads (it points forward, toward the
    /// dock, as Axel's caster arm must while docking) and the tether pulls at its tip. 0:
    /// no arm, the tether leaves the body's rear (RAPOSA).
    #[serde(default)]
    pub arm_m: f64,
    /// How far inside the dock, along its axis, the tether is anchored, m (Axel's: about
    /// 25 cm inside the central module, seed 000 §II).
    #[serde(default)]
    pub anchor_depth_m: f64,
    /// Height of the arm's tip above the ground while it is reeled in, m (arm only).
    #[serde(default)]
    pub tip_height_m: f64,
    /// Diameter of the arm's tip, m (arm only): it must fit the cone's throat.
    #[serde(default)]
    pub tip_diameter_m: f64,
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
    if let Some(c) = &d.cone {
        v.positive("dock.cone.axis_height_m", c.axis_height_m);
        v.range("dock.cone.tilt_deg", c.tilt_deg, -30.0, 30.0);
        v.positive("dock.cone.seat_length_m", c.seat_length_m);
        if c.axis_height_m < d.entrance_width_m / 2.0 {
            v.problem(
                "dock.cone.axis_height_m",
                format!(
                    "expected the cone's mouth ({} m wide) above the ground, got its axis at {} m",
                    d.entrance_width_m, c.axis_height_m
                ),
            );
        }
        if d.throat_half_width() <= 0.0 {
            v.problem(
                "dock.funnel_half_angle_deg",
                format!(
                    "the cone's walls meet before its throat: a {} m mouth narrowing at {}° over {} m",
                    d.entrance_width_m, d.funnel_half_angle_deg, d.depth_m
                ),
            );
        }
    }
    if !target_enters_robot
        && d.cone.is_none()
        && d.entrance_width_m > 0.0
        && body.width_m > 0.0
        && d.entrance_width_m < body.width_m
    {
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
    v.non_negative("tether.anchor_depth_m", t.anchor_depth_m);
    v.non_negative("tether.tip_height_m", t.tip_height_m);
    v.non_negative("tether.tip_diameter_m", t.tip_diameter_m);
}

/// A docking cone is entered by a leading arm whose tip fits its throat, and that reaches
/// past the rover's body far enough for the tip to seat before the body meets the face.
pub(crate) fn validate_cone_arm(d: &DockSpec, t: Option<&TetherSpec>, body: &BodySpec, v: &mut Validator<'_>) {
    if d.cone.is_none() {
        return;
    }
    let Some(t) = t else {
        v.problem(
            "tether",
            "a docking cone is entered by a tether-pulled arm: add a [tether] table",
        );
        return;
    };
    if t.arm_m <= body.length_m / 2.0 + d.depth_m {
        v.problem(
            "tether.arm_m",
            format!(
                "expected an arm reaching past half the body ({} m) plus the cone's depth ({} m), got {} m",
                body.length_m / 2.0,
                d.depth_m,
                t.arm_m
            ),
        );
    }
    if t.tip_diameter_m <= 0.0 || t.tip_diameter_m / 2.0 >= d.throat_half_width() {
        v.problem(
            "tether.tip_diameter_m",
            format!(
                "expected a positive tip narrower than the cone's throat ({:.3} m), got {} m",
                2.0 * d.throat_half_width(),
                t.tip_diameter_m
            ),
        );
    }
    v.positive("tether.tip_height_m", t.tip_height_m);
}

pub(crate) fn validate_success(s: &SuccessSpec, v: &mut Validator<'_>) {
    v.positive("success.lateral_tolerance_m", s.lateral_tolerance_m);
    v.range("success.heading_tolerance_deg", s.heading_tolerance_deg, 0.0, 180.0);
    v.positive("success.timeout_s", s.timeout_s);
}
