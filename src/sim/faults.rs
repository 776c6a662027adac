//! Faults injected into a docking run: a scenario's `[[faults]]` table.
//!
//! Each entry is one value of a campaign axis: every start (and lighting, terrain...) is
//! run once per fault. The fault strikes `at_s` seconds into the docking mission (the
//! clock restarts when the proctor places the robot) and lasts `duration_s`. The
//! simulator applies it behind the hardware traits, where a real robot's part would fail:
//! the camera delivers nothing, a wrong-sized, black or saturated frame, a late one, or
//! the same frame again as new (a frozen driver); odometry reads NaN or infinity, jumps,
//! or freezes; a track stalls or runs at half speed; commands reach the motors late; the
//! lights go out; the tether reel jams; a person steps between the robot and its target.
//!
//! `expect` states how the run must end, and `trials` reports, per fault, the runs that
//! ended that way, the ones that did not (each a bug), the time in safe stop, and the
//! ticks the robot was commanded to move while an input was stale or invalid, which must
//! be zero.
//!
//! Simplified: the occluder is seen, not touched (the robot's body passes through it),
//! and it stands still where it stepped in until it leaves.

use super::scene::{Material, Prim, Scene, Shape, Tag};
use crate::arbiter::Staleness;
use crate::config::Validator;
use crate::geometry::Pose2;
use crate::perception::RgbImage;
use crate::schemas::OdometryReading;
use nalgebra::{Point3, Vector3};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// What fails.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FaultKind {
    /// Every camera delivers nothing ([`crate::robot::HardwareError::NotReady`]).
    CameraSilent,
    /// Every camera delivers frames of half the profile's size.
    CameraWrongSize,
    /// Every camera delivers all-black frames.
    CameraBlack,
    /// Every camera delivers saturated (all-white) frames.
    CameraSaturated,
    /// Every camera delivers frames `lag_s` old (rendered at the pose of then, and stamped
    /// so by the driver).
    CameraLate,
    /// Every camera re-delivers the frame it took when the fault struck, stamped as new
    /// (a driver stuck re-publishing its buffer).
    CameraFrozen,
    /// Odometry reads NaN.
    OdometryNan,
    /// Odometry reads infinity.
    OdometryInfinite,
    /// Odometry jumps by `jump` (x m, y m, θ deg) at `at_s` and keeps the offset.
    OdometryJump,
    /// Odometry re-delivers the reading it had when the fault struck, stamped as new.
    OdometryFrozen,
    /// One track (`side`) stalls: its motor turns nothing, and its encoder reads still.
    TrackStall,
    /// Both motors deliver half their commanded speed.
    HalfSpeed,
    /// Commands reach the motors `latency_s` after they were sent (in order).
    CommandLatency,
    /// The lights go out: only a faint ambient glow remains.
    LightsOut,
    /// The tether reel jams: it neither reels in nor pays out.
    ReelJam,
    /// A person steps into the line of sight: a 0.45 × 1.7 m dark figure standing halfway
    /// between the robot's first camera and the target's centre (0.15–1.5 m from the
    /// camera), seen for `duration_s`, then gone.
    Occluder,
}

/// Which track.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Side {
    /// The left track.
    Left,
    /// The right track.
    Right,
}

/// How a run with the fault must end.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Expected {
    /// Docked (after a safe stop, or by riding the fault out).
    Dock,
    /// A typed failure from the behavior (`target_lost`, `retries_exhausted`...), never a
    /// timeout, a collision or a dock on the wrong object.
    TypedFailure,
    /// Either of the above.
    DockOrTypedFailure,
}

impl Expected {
    /// True when a run that ended with `outcome` (`docked`, or the failure reason) ended
    /// as expected.
    pub fn accepts(&self, outcome: &str) -> bool {
        let docked = outcome == "docked";
        let typed = !docked && !UNTYPED.contains(&outcome);
        match self {
            Expected::Dock => docked,
            Expected::TypedFailure => typed,
            Expected::DockOrTypedFailure => docked || typed,
        }
    }
}

/// Run endings that are not a behavior's typed failure: the world ended the run.
const UNTYPED: [&str; 4] = ["timeout", "collision", "stuck_contact", "false_dock"];

/// One `[[faults]]` entry.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FaultSpec {
    /// Its label in `runs.jsonl` and the tables (unique in the scenario).
    pub name: String,
    /// What fails.
    pub kind: FaultKind,
    /// When, s after the docking mission starts.
    pub at_s: f64,
    /// For how long, s (ignored by `odometry_jump`, which keeps its offset).
    pub duration_s: f64,
    /// How the run must end.
    pub expect: Expected,
    /// `camera_late`: the frames' age, s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lag_s: Option<f64>,
    /// `command_latency`: the commands' delay, s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub latency_s: Option<f64>,
    /// `odometry_jump`: the jump, [x m, y m, θ deg] in the odometry frame.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub jump: Option<[f64; 3]>,
    /// `track_stall`: which track.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub side: Option<Side>,
}

impl FaultSpec {
    /// True while the fault is in force at docking time `t`.
    pub fn active(&self, t: f64) -> bool {
        t >= self.at_s && (self.kind == FaultKind::OdometryJump || t < self.at_s + self.duration_s)
    }

    /// Checks the entry (`at` is its field path, `faults[i]`).
    pub fn validate(&self, at: &str, v: &mut Validator<'_>) {
        v.require(!self.name.trim().is_empty(), &format!("{at}.name"), || {
            "expected a non-empty name".into()
        });
        v.non_negative(&format!("{at}.at_s"), self.at_s);
        v.positive(&format!("{at}.duration_s"), self.duration_s);
        let needs = |v: &mut Validator<'_>, field: &str, present: bool, wanted: bool| {
            v.require(present == wanted, &format!("{at}.{field}"), || {
                if wanted {
                    format!("`{}` needs `{field}`", kind_name(self.kind))
                } else {
                    format!("`{}` takes no `{field}`", kind_name(self.kind))
                }
            });
        };
        needs(v, "lag_s", self.lag_s.is_some(), self.kind == FaultKind::CameraLate);
        needs(
            v,
            "latency_s",
            self.latency_s.is_some(),
            self.kind == FaultKind::CommandLatency,
        );
        needs(v, "jump", self.jump.is_some(), self.kind == FaultKind::OdometryJump);
        needs(v, "side", self.side.is_some(), self.kind == FaultKind::TrackStall);
        if let Some(lag) = self.lag_s {
            v.positive(&format!("{at}.lag_s"), lag);
        }
        if let Some(l) = self.latency_s {
            v.positive(&format!("{at}.latency_s"), l);
        }
        if let Some(j) = self.jump {
            v.require(j.iter().all(|x| x.is_finite()), &format!("{at}.jump"), || {
                "expected finite numbers".into()
            });
        }
    }
}

impl FaultSpec {
    /// True when, at docking time `t`, the fault has left an input the loop must not act
    /// on (stale, missing, the wrong size, or not finite), so any motion commanded then is
    /// a bug. `limits` are the loop's staleness limits and `tick_s` its period: a silent
    /// or frozen device's last reading goes stale one limit after the fault struck, and
    /// the tick that notices may be one period later. (Frozen odometry is invalid once
    /// stale even when it froze on a still base, which the loop cannot tell from a stall:
    /// such a run would count motion here, and show it.)
    pub fn inputs_invalid(&self, t: f64, limits: &Staleness, tick_s: f64) -> bool {
        if !self.active(t) {
            return false;
        }
        let outlived = |limit: Option<f64>| limit.is_some_and(|l| t >= self.at_s + l + tick_s + 1e-9);
        match self.kind {
            FaultKind::CameraSilent => outlived(limits.camera),
            FaultKind::CameraFrozen => limits.camera_repeats_stale && outlived(limits.camera),
            FaultKind::OdometryFrozen => outlived(limits.odometry),
            FaultKind::CameraLate => limits.camera.is_some_and(|l| self.lag_s.unwrap_or(0.0) > l),
            FaultKind::CameraWrongSize | FaultKind::OdometryNan | FaultKind::OdometryInfinite => true,
            _ => false,
        }
    }
}

/// What a fault latched when it struck, for the rest of the mission: the frames and the
/// odometry a frozen driver re-sends, the offset of a jump, the scene with the occluder.
#[derive(Debug, Default)]
pub struct Latched {
    /// Per camera, the frame it froze on.
    pub frames: Vec<Option<RgbImage>>,
    /// The odometry reading it froze on.
    pub odometry: Option<OdometryReading>,
    /// The odometry offset of an `odometry_jump` (x, y, θ).
    pub jump: Option<Pose2>,
    /// The world's scene with the occluder standing in it.
    pub scene: Option<Arc<Scene>>,
}

/// The occluder's half width and height, m: a person.
const OCCLUDER_HALF_WIDTH_M: f64 = 0.225;
const OCCLUDER_HEIGHT_M: f64 = 1.7;

/// `scene` with a person standing between `camera` (its optical centre) and `target`
/// (the target's centre): halfway, 0.15–1.5 m from the camera, facing it, in dark
/// clothing (8 % reflectance, slightly blue: denim). A clone of the scene, once per fault.
///
/// The figure is a column of ten tiles: the renderer draws primitives front to back by
/// the distance of their centres, so one 1.7 m panel, whose centre is high above the
/// camera's line of sight, would be drawn after a target it stands in front of.
pub fn occluded(scene: &Scene, camera: Point3<f64>, target: Point3<f64>) -> Scene {
    const TILES: usize = 10;
    let mut flat = target - camera;
    flat.z = 0.0;
    let range = flat.norm();
    let toward = if range > 1e-6 { flat / range } else { Vector3::x() };
    let at = camera.coords + toward * (range / 2.0).clamp(0.15, 1.5);
    let tile = OCCLUDER_HEIGHT_M / TILES as f64;
    let mut out = scene.clone();
    for k in 0..TILES {
        let mut part = Prim::new(
            Shape::Rect {
                centre: Point3::new(at.x, at.y, tile * (k as f64 + 0.5)),
                u: Vector3::new(-toward.y, toward.x, 0.0),
                v: Vector3::z(),
                half: [OCCLUDER_HALF_WIDTH_M, tile / 2.0],
            },
            Material::Solid([0.06, 0.07, 0.09]),
            Tag::Clutter,
        );
        part.two_sided = true;
        out.prims.push(part);
    }
    out
}

/// The TOML spelling of `kind`.
pub fn kind_name(kind: FaultKind) -> String {
    serde_json::to_value(kind)
        .ok()
        .and_then(|v| v.as_str().map(str::to_owned))
        .unwrap_or_default()
}

/// Validates a scenario's `[[faults]]`: each entry, and unique names.
pub fn validate_all(faults: &[FaultSpec], v: &mut Validator<'_>) {
    for (i, f) in faults.iter().enumerate() {
        f.validate(&format!("faults[{i}]"), v);
        v.require(
            !faults[..i].iter().any(|g| g.name == f.name),
            &format!("faults[{i}].name"),
            || format!("`{}` names another fault too", f.name),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expected_endings() {
        assert!(Expected::Dock.accepts("docked"));
        assert!(!Expected::Dock.accepts("target_lost"));
        assert!(Expected::TypedFailure.accepts("target_lost"));
        for untyped in UNTYPED {
            assert!(!Expected::TypedFailure.accepts(untyped));
            assert!(!Expected::DockOrTypedFailure.accepts(untyped));
        }
        assert!(Expected::DockOrTypedFailure.accepts("docked"));
    }

    #[test]
    fn the_occluder_stands_in_the_line_of_sight() {
        let scene = Scene::on_floor(Vec::new());
        let camera = Point3::new(2.0, 1.0, 0.3);
        let target = Point3::new(0.0, 0.0, 0.3);
        let out = occluded(&scene, camera, target);
        assert_eq!(out.prims.len(), 10);
        // The tile at the camera's height holds the midpoint of the sight line, and
        // its plane faces the camera.
        let mid = Point3::from((camera.coords + target.coords) / 2.0);
        let tile = out
            .prims
            .iter()
            .find(|p| (p.shape.centre().z - 0.3).abs() <= 0.085)
            .expect("a tile at eye height");
        let Shape::Rect { centre, u, half, .. } = &tile.shape else {
            panic!("tiles are rectangles")
        };
        let d = mid - centre;
        assert!(d.dot(u).abs() < half[0] && d.z.abs() <= half[1] + 1e-9, "{d:?}");
        assert!(u.dot(&(target - camera)).abs() < 1e-9, "faces the camera");
        // 0.15–1.5 m from the camera, however far the target is.
        let far = occluded(&scene, camera, Point3::new(-20.0, 1.0, 0.3));
        let c = far.prims[0].shape.centre();
        assert!(((c.x - camera.x).hypot(c.y - camera.y) - 1.5).abs() < 1e-9);
    }

    #[test]
    fn a_jump_stays_and_other_faults_end() {
        let mut f = FaultSpec {
            name: "x".into(),
            kind: FaultKind::CameraSilent,
            at_s: 2.0,
            duration_s: 1.0,
            expect: Expected::Dock,
            lag_s: None,
            latency_s: None,
            jump: None,
            side: None,
        };
        assert!(!f.active(1.9) && f.active(2.0) && f.active(2.9) && !f.active(3.0));
        f.kind = FaultKind::OdometryJump;
        assert!(f.active(100.0));
    }
}
