//! `marsupial pose-trials CAMPAIGN.toml`: Axel's perception campaigns (issue 16:
//! `axel-pose`, `axel-occlusion` and their ablations), run against the simulator's truth.
//!
//! A campaign file names a profile with circle fiducials and a grid of rover poses about
//! the central module (distance, α off its axis, the heading turned off facing it, noise
//! seeds), and optionally marks to hide behind occluding panels and false marks to place
//! near the module. Each run renders both cameras through the file's `[sensor]` (the
//! webcam's noise, vignetting, defocus, JPEG), detects, labels and poses the module
//! (stereo, and mono per camera), and compares with the truth. The ablations run on the
//! same detections: the mono pose through a pin-hole that ignores the fish-eye's
//! distortion, and the labelling that accepts 4-mark fits (seed 000 §V-D's bug,
//! [`CorrespondenceParams::ablation_four_point_fits`]). Every run is seeded from the
//! campaign's seed and its index alone, so the records are the same bytes whatever
//! `--jobs` is.

use crate::config::{self, ConfigError, Validate, Validator};
use crate::geometry::Pose2;
use crate::perception::RgbImage;
use crate::perception::camera_model::{CameraModel, Pinhole};
use crate::perception::circles::{
    CircleDetector, CircleModel, CircleParams, CorrespondenceError, CorrespondenceParams, DetectedMark,
    MarkObservations, ModelFit, ModulePose, PoseBuffers, PoseError, PoseParams, RigCamera, correspond, mono_pose,
    stereo_pose,
};
use crate::profile::Profile;
use crate::sim::SimError;
use crate::sim::camera::camera_pose;
use crate::sim::lighting::{LightingRun, LightingSpec};
use crate::sim::render::Renderer;
use crate::sim::rng::{Rng, splitmix64};
use crate::sim::scenario::SensorSpec;
use crate::sim::world::{self, ClutterKind, ClutterSpec};
use nalgebra::{Matrix3, Rotation3, Vector3};
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Options of `marsupial pose-trials` (also its command-line arguments).
#[derive(Debug, Clone, Default, clap::Args)]
pub struct PoseTrialsOptions {
    /// Campaign file: a scenario-like file with a `[pose]` table.
    #[arg(value_name = "CAMPAIGN.toml")]
    pub campaign: PathBuf,
    /// Print each run's record as one JSON line instead of the tables.
    #[arg(long)]
    pub json: bool,
    /// Output folder: DIR/runs.jsonl (one line per run, in run order) and DIR/tables.txt.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Runs rendered at once (0: one per core).
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub jobs: usize,
    /// With --out, also save each run's measured frames as DIR/frames/RUN-CAMERA.png, to
    /// look at what the detector was given.
    #[arg(long, requires = "out")]
    pub frames: bool,
}

/// `[pose]`: the grid of rover poses. Every combination is a run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PoseGrid {
    /// Distances from the module's face centre to the rover's origin, m.
    pub distances_m: Vec<f64>,
    /// Angles off the module's axis, degrees.
    pub alpha_deg: Vec<f64>,
    /// The rover's heading turned off facing the module, degrees (default `[0]`).
    #[serde(default = "zero_list")]
    pub turn_deg: Vec<f64>,
    /// Independent draws of the sensor noise per pose (default 1).
    #[serde(default = "one")]
    pub noise_seeds: u32,
    /// Frames rendered per camera before the one measured, so auto-exposure settles
    /// (default 3).
    #[serde(default = "three")]
    pub settle_frames: u32,
    /// JPEG qualities of the cameras' stream, an axis (0: raw frames); absent: the
    /// `[sensor]`'s `jpeg_quality` alone.
    #[serde(default)]
    pub jpeg_quality: Option<Vec<u32>>,
}

/// `[occlusion]`: marks hidden behind panels, and false marks near the module.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OcclusionSpec {
    /// How many marks each run hides (an axis): which ones is drawn per run. A hidden
    /// mark is covered flush with a patch of the face's grey ([`world::build_covering`]).
    /// A panel held in front of it would be more physical, but the renderer draws front
    /// to back by each primitive's centre distance, so a small panel before the large
    /// face is lost wherever its centre lies farther from the camera than the face's.
    pub hidden: Vec<usize>,
    /// False marks placed near the module; when any are given every run is made both
    /// without and with them (an axis).
    #[serde(default)]
    pub decoys: Vec<DecoySpec>,
}

/// One false mark: a circle mark of the module's pattern on a panel of the module's grey.
/// Place it clear of the face in the image (beside the module): for the reason given at
/// [`OcclusionSpec::hidden`], a patch overlapping the face would be drawn behind it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DecoySpec {
    /// Position of its centre in the module frame (x forward of the face, y, height), m.
    pub at_m: [f64; 3],
    /// Its bar's rotation, degrees.
    pub rotation_deg: f64,
    /// Side of its square panel, m (default 0.14).
    #[serde(default = "decoy_side")]
    pub panel_m: f64,
}

fn zero_list() -> Vec<f64> {
    vec![0.0]
}
fn one() -> u32 {
    1
}
fn three() -> u32 {
    3
}
fn decoy_side() -> f64 {
    0.14
}

/// A perception campaign file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PoseCampaign {
    /// Name.
    pub name: String,
    /// Description.
    #[serde(default)]
    pub description: String,
    /// Profile path (relative to the file); it must have `[fiducial.circles]`.
    pub profile: PathBuf,
    /// Campaign seed.
    #[serde(default)]
    pub seed: u64,
    /// The pose grid.
    pub pose: PoseGrid,
    /// Hidden marks and false ones (absent: none).
    #[serde(default)]
    pub occlusion: Option<OcclusionSpec>,
    /// The light (default: the lab's uniform light).
    #[serde(default)]
    pub lighting: LightingSpec,
    /// The cameras' sensor.
    #[serde(default)]
    pub sensor: SensorSpec,
}

impl Validate for PoseCampaign {
    fn validate(&self, v: &mut Validator<'_>) {
        v.require(!self.name.trim().is_empty(), "name", || {
            "expected a non-empty name".into()
        });
        let g = &self.pose;
        for (field, list) in [
            ("pose.distances_m", &g.distances_m),
            ("pose.alpha_deg", &g.alpha_deg),
            ("pose.turn_deg", &g.turn_deg),
        ] {
            v.require(!list.is_empty(), field, || "expected at least one value".into());
        }
        for (i, d) in g.distances_m.iter().enumerate() {
            v.range(&format!("pose.distances_m[{i}]"), *d, 0.3, 50.0);
        }
        for (i, a) in g.alpha_deg.iter().enumerate() {
            v.range(&format!("pose.alpha_deg[{i}]"), *a, -89.0, 89.0);
        }
        for (i, a) in g.turn_deg.iter().enumerate() {
            v.range(&format!("pose.turn_deg[{i}]"), *a, -90.0, 90.0);
        }
        v.require((1..=1000).contains(&g.noise_seeds), "pose.noise_seeds", || {
            format!("expected 1 to 1000 noise seeds, got {}", g.noise_seeds)
        });
        if let Some(q) = &g.jpeg_quality {
            v.require(!q.is_empty(), "pose.jpeg_quality", || {
                "expected at least one value".into()
            });
            for (i, q) in q.iter().enumerate() {
                v.require(*q <= 100, &format!("pose.jpeg_quality[{i}]"), || {
                    format!("expected 0 (raw) or a quality 1–100, got {q}")
                });
            }
        }
        v.require(g.settle_frames <= 50, "pose.settle_frames", || {
            format!("expected at most 50 settling frames, got {}", g.settle_frames)
        });
        if let Some(o) = &self.occlusion {
            v.require(!o.hidden.is_empty(), "occlusion.hidden", || {
                "expected at least one value".into()
            });
            for (i, n) in o.hidden.iter().enumerate() {
                v.require(*n <= 8, &format!("occlusion.hidden[{i}]"), || {
                    format!("expected at most 8 hidden marks, got {n}")
                });
            }
            for (i, d) in o.decoys.iter().enumerate() {
                for (k, x) in d.at_m.iter().enumerate() {
                    v.finite(&format!("occlusion.decoys[{i}].at_m[{k}]"), *x);
                }
                v.finite(&format!("occlusion.decoys[{i}].rotation_deg"), d.rotation_deg);
                v.range(&format!("occlusion.decoys[{i}].panel_m"), d.panel_m, 0.01, 1.0);
            }
        }
        self.lighting.validate_at("lighting", v);
        self.sensor.validate_at("sensor", v);
    }
}

/// A loaded campaign with its profile and the circle model.
#[derive(Debug, Clone)]
pub struct LoadedCampaign {
    /// The file's contents.
    pub campaign: PoseCampaign,
    /// The profile it names.
    pub profile: Profile,
}

impl PoseCampaign {
    /// Whether a parsed TOML file is a perception campaign (it has a `[pose]` table), so
    /// `marsupial check` validates it as one.
    pub fn is_campaign(table: &toml::Table) -> bool {
        table.get("pose").is_some_and(toml::Value::is_table)
    }

    /// Loads and validates a campaign and its profile, which must have two cameras and
    /// `[fiducial.circles]`.
    ///
    /// # Errors
    /// [`ConfigError`] for the file or its profile.
    pub fn load(path: &Path) -> Result<LoadedCampaign, ConfigError> {
        let campaign: PoseCampaign = config::load(path)?;
        let profile = Profile::load(&path.parent().unwrap_or(Path::new(".")).join(&campaign.profile))?;
        if profile.fiducial.circles.is_none() || profile.cameras.len() < 2 {
            return Err(ConfigError::Invalid {
                file: path.to_path_buf(),
                problems: vec![config::Problem {
                    path: "profile".into(),
                    line: None,
                    message: format!(
                        "a perception campaign needs a stereo pair and [fiducial.circles]; profile `{}` has {} camera(s){}",
                        profile.name,
                        profile.cameras.len(),
                        if profile.fiducial.circles.is_none() {
                            " and no circles"
                        } else {
                            ""
                        }
                    ),
                }],
            });
        }
        Ok(LoadedCampaign { campaign, profile })
    }
}

/// One run of the grid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunSpec {
    /// Index in the campaign.
    pub index: usize,
    /// Distance, m.
    pub distance_m: f64,
    /// α, degrees.
    pub alpha_deg: f64,
    /// Heading off facing the module, degrees.
    pub turn_deg: f64,
    /// Marks hidden.
    pub hidden: usize,
    /// The decoys are placed.
    pub decoy: bool,
    /// Noise draw, 0-based.
    pub noise: u32,
    /// JPEG quality of the stream (0: raw).
    pub jpeg_quality: u32,
}

/// Every run of a campaign, in order: JPEG quality, distance, α, turn, hidden, decoy,
/// noise.
pub fn runs(c: &PoseCampaign) -> Vec<RunSpec> {
    let hidden = c.occlusion.as_ref().map_or(vec![0], |o| o.hidden.clone());
    let decoys: &[bool] = match &c.occlusion {
        Some(o) if !o.decoys.is_empty() => &[false, true],
        _ => &[false],
    };
    let qualities = c
        .pose
        .jpeg_quality
        .clone()
        .unwrap_or_else(|| vec![c.sensor.jpeg_quality]);
    let mut out = Vec::new();
    for &jpeg_quality in &qualities {
        for &distance_m in &c.pose.distances_m {
            for &alpha_deg in &c.pose.alpha_deg {
                for &turn_deg in &c.pose.turn_deg {
                    for &h in &hidden {
                        for &decoy in decoys {
                            for noise in 0..c.pose.noise_seeds {
                                out.push(RunSpec {
                                    index: out.len(),
                                    distance_m,
                                    alpha_deg,
                                    turn_deg,
                                    hidden: h,
                                    decoy,
                                    noise,
                                    jpeg_quality,
                                });
                            }
                        }
                    }
                }
            }
        }
    }
    out
}

/// A pose measured against the truth, or why there is none.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct PoseOutcome {
    /// A pose was computed.
    pub found: bool,
    /// Distance between the estimated and true module origin on the ground, m.
    pub position_err_m: Option<f64>,
    /// Error of the module's heading, degrees.
    pub heading_err_deg: Option<f64>,
    /// Angle of R̂ᵀR (all three axes), degrees.
    pub rotation_err_deg: Option<f64>,
    /// The pose's own reprojection error, px.
    pub reprojection_px: Option<f64>,
    /// Marks the pose used.
    pub marks: Option<usize>,
    /// The typed error's variant (`TooFewMarks`, `Collinear`, …) when there is no pose,
    /// or the correspondence's when there was no labelling to pose.
    pub error: Option<String>,
    /// Its message.
    pub message: Option<String>,
}

/// One camera's labelling against the truth.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct Labelling {
    /// A labelling was accepted.
    pub found: bool,
    /// Its inliers.
    pub inliers: usize,
    /// Inliers more than a mark radius (at least 3 px) from their mark's true image.
    pub mislabelled: usize,
    /// The homography's RMS reprojection error over the inliers, px.
    pub reprojection_px: Option<f64>,
    /// The correspondence's error variant when none was accepted.
    pub error: Option<String>,
}

/// One camera's part of a run.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct CameraRun {
    /// Model marks wholly in the image (their rim's four extremes), less the hidden ones.
    pub visible: usize,
    /// Marks the detector reported (decoys included).
    pub detected: usize,
    /// The labelling (≥ 5 marks).
    pub labelling: Labelling,
    /// The mono pose through the camera's lens model.
    pub mono: PoseOutcome,
    /// Ablation: the mono pose through a pin-hole of the lens's on-axis focal length.
    pub mono_pinhole: PoseOutcome,
    /// Ablation: the labelling that accepts 4 marks (seed 000's bug).
    pub labelling_four_point: Labelling,
    /// Ablation: the mono pose from that labelling.
    pub mono_four_point: PoseOutcome,
}

/// The record of one run (a line of `runs.jsonl`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PoseRun {
    /// Index in the campaign.
    pub index: usize,
    /// Distance from the face centre, m.
    pub distance_m: f64,
    /// α, degrees.
    pub alpha_deg: f64,
    /// Heading off facing the module, degrees.
    pub turn_deg: f64,
    /// Noise draw.
    pub noise: u32,
    /// JPEG quality of the stream (0: raw frames).
    pub jpeg_quality: u32,
    /// The run's seed.
    pub seed: u64,
    /// Model marks hidden behind panels.
    pub hidden: Vec<usize>,
    /// The false marks were placed.
    pub decoy: bool,
    /// Cameras 0 (left) and 1 (right).
    pub cameras: [CameraRun; 2],
    /// The stereo pose.
    pub stereo: PoseOutcome,
    /// Ablation: the stereo pose from the 4-mark labellings.
    pub stereo_four_point: PoseOutcome,
}

/// What every run shares: the profile's model and cameras, and the ablation's pin-holes.
struct Context<'a> {
    campaign: &'a PoseCampaign,
    profile: &'a Profile,
    model: CircleModel,
    cams: [RigCamera; 2],
    pinholes: [RigCamera; 2],
    frames: Option<&'a Path>,
}

/// A worker's buffers, reused from run to run.
struct Workspace {
    detectors: Vec<CircleDetector>,
    image: RgbImage,
    marks: Vec<DetectedMark>,
    buf: PoseBuffers,
}

/// A pin-hole with a fish-eye's on-axis focal length and centre (what a pose that ignores
/// the distortion assumes); a pin-hole camera stays as it is.
fn pinhole_of(cam: &RigCamera) -> RigCamera {
    let mut out = cam.clone();
    if let CameraModel::Fisheye(f) = &cam.model {
        let fx = -f.poly.first().copied().unwrap_or(-1.0);
        out.model = CameraModel::Pinhole(Pinhole {
            fx,
            fy: fx,
            cx: f.center[0],
            cy: f.center[1],
            k1: 0.0,
            k2: 0.0,
        });
    }
    out
}

fn wrap(a: f64) -> f64 {
    (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
}

/// The module's true pose in the rover frame at `robot` (the module frame is the world's).
fn truth(robot: &Pose2) -> (Matrix3<f64>, Vector3<f64>) {
    let r = *Rotation3::from_axis_angle(&Vector3::z_axis(), -robot.theta).matrix();
    (r, r * Vector3::new(-robot.x, -robot.y, 0.0))
}

fn outcome(res: Result<ModulePose, PoseError>, robot: &Pose2) -> PoseOutcome {
    match res {
        Ok(p) => {
            let (r, t) = truth(robot);
            let c = ((r.transpose() * p.rotation).trace() - 1.0) / 2.0;
            PoseOutcome {
                found: true,
                position_err_m: Some((p.x() - t.x).hypot(p.y() - t.y)),
                heading_err_deg: Some(wrap(p.heading() + robot.theta).to_degrees().abs()),
                rotation_err_deg: Some(c.clamp(-1.0, 1.0).acos().to_degrees()),
                reprojection_px: Some(p.reprojection_px),
                marks: Some(p.marks_used),
                error: None,
                message: None,
            }
        }
        Err(e) => PoseOutcome {
            error: Some(pose_error_kind(&e).into()),
            message: Some(e.to_string()),
            ..Default::default()
        },
    }
}

fn pose_error_kind(e: &PoseError) -> &'static str {
    match e {
        PoseError::TooFewMarks { .. } => "TooFewMarks",
        PoseError::Collinear { .. } => "Collinear",
        PoseError::BadInput { .. } => "BadInput",
        PoseError::Degenerate { .. } => "Degenerate",
    }
}

fn correspondence_kind(e: &CorrespondenceError) -> &'static str {
    match e {
        CorrespondenceError::TooFewMarks { .. } => "TooFewMarks",
        CorrespondenceError::NoConsistentFit { .. } => "NoConsistentFit",
    }
}

/// A pose outcome standing for "no labelling to pose".
fn unlabelled(e: &CorrespondenceError) -> PoseOutcome {
    PoseOutcome {
        error: Some(correspondence_kind(e).into()),
        message: Some(e.to_string()),
        ..Default::default()
    }
}

/// Labels `marks` with `params` and checks each label against the true image of its mark.
fn label(
    model: &CircleModel,
    marks: &[DetectedMark],
    params: &CorrespondenceParams,
    true_px: &[Option<[f64; 2]>],
) -> (Result<ModelFit, CorrespondenceError>, Labelling) {
    let res = correspond(model, marks, params);
    let l = match &res {
        Ok(fit) => Labelling {
            found: true,
            inliers: fit.inliers,
            mislabelled: (0..model.len())
                .filter(|&j| {
                    fit.detection_of(j).and_then(|i| marks.get(i)).is_some_and(|m| {
                        let tol = m.ellipse.semi_major.max(3.0);
                        true_px[j].is_none_or(|t| (m.centre[0] - t[0]).hypot(m.centre[1] - t[1]) > tol)
                    })
                })
                .count(),
            reprojection_px: Some(fit.rms_px),
            error: None,
        },
        Err(e) => Labelling {
            error: Some(correspondence_kind(e).into()),
            ..Default::default()
        },
    };
    (res, l)
}

/// The rover's pose for a run: `distance_m` from the face centre, `alpha_deg` off the
/// axis, facing the module and then turned `turn_deg`.
pub fn rover_pose(spec: &RunSpec) -> Pose2 {
    let a = spec.alpha_deg.to_radians();
    Pose2::new(
        spec.distance_m * a.cos(),
        spec.distance_m * a.sin(),
        a + std::f64::consts::PI + spec.turn_deg.to_radians(),
    )
}

/// The marks a run hides: `n` of the model's, drawn from the run's seed.
fn hidden_marks(n: usize, len: usize, seed: u64) -> Vec<usize> {
    let mut ids: Vec<usize> = (0..len).collect();
    let mut rng = Rng::named(seed, "hidden_marks");
    for i in (1..len).rev() {
        ids.swap(i, (rng.next_u64() % (i as u64 + 1)) as usize);
    }
    let mut out: Vec<usize> = ids.into_iter().take(n.min(len)).collect();
    out.sort_unstable();
    out
}

impl Context<'_> {
    /// The world of a run: the module with its hidden marks covered, and the decoys when
    /// the run places them.
    fn world(&self, hidden: &[usize], decoy: bool) -> Result<world::World, SimError> {
        let mut clutter = Vec::new();
        if let Some(o) = &self.campaign.occlusion
            && decoy
        {
            {
                for d in &o.decoys {
                    clutter.push(ClutterSpec {
                        kind: ClutterKind::CircleMark,
                        x_m: d.at_m[0],
                        y_m: d.at_m[1],
                        z_m: d.at_m[2],
                        size_m: vec![d.panel_m, d.panel_m],
                        color: None,
                        facing_deg: 0.0,
                        mark_rotation_deg: d.rotation_deg,
                    });
                }
            }
        }
        world::build_covering(self.profile, &clutter, &[], hidden)
    }

    fn run(&self, spec: &RunSpec, ws: &mut Workspace) -> Result<PoseRun, SimError> {
        let seed = splitmix64(self.campaign.seed ^ splitmix64(spec.index as u64));
        let robot = rover_pose(spec);
        let hidden = hidden_marks(spec.hidden, self.model.len(), seed);
        let w = self.world(&hidden, spec.decoy)?;
        let lighting = self.campaign.lighting.resolve();
        let mut sensor = self.campaign.sensor.params(&lighting);
        sensor.jpeg_quality = spec.jpeg_quality.min(100) as u8;
        let light = LightingRun::new(lighting, &mut Rng::named(seed, "lighting"), 1.0).at(0.0);
        let (r, t) = truth(&robot);
        let strict = CorrespondenceParams::default();
        let four = CorrespondenceParams {
            min_inliers: 4,
            ablation_four_point_fits: true,
            ..CorrespondenceParams::default()
        };
        let params = PoseParams::default();
        let mut cameras: [CameraRun; 2] = Default::default();
        let mut obs = [MarkObservations::new(self.model.len()); 2];
        let mut obs4 = obs;
        for c in 0..2 {
            let spec_c = &self.profile.cameras[c];
            let (width, height) = (spec_c.width_px, spec_c.height_px);
            let mut renderer = Renderer::new(CameraModel::from_spec(spec_c), width, height, seed ^ (c as u64 + 1));
            let cam_pose = camera_pose(&robot, &spec_c.mount);
            for k in 0..=self.campaign.pose.settle_frames {
                renderer.render(
                    &w.scene,
                    &cam_pose,
                    &light,
                    &sensor,
                    seed.wrapping_add(k as u64),
                    &mut ws.image,
                );
            }
            if let Some(dir) = self.frames {
                let path = dir.join(format!("{:04}-{c}.png", spec.index));
                crate::image_io::save_png(&path, &ws.image)?;
            }
            ws.marks.clear();
            let found = ws.detectors[c]
                .detect(&ws.image.view())
                .map_err(|e| SimError::Unsupported(format!("detection failed: {e}")))?;
            ws.marks.extend_from_slice(found);
            let true_px: Vec<Option<[f64; 2]>> = self
                .model
                .centres()
                .iter()
                .map(|m| self.cams[c].project(&(r * Vector3::new(0.0, m[0], m[1]) + t)))
                .collect();
            let in_image = |p: [f64; 2]| p[0] >= 0.0 && p[1] >= 0.0 && p[0] < width as f64 && p[1] < height as f64;
            // A mark is visible when it is not hidden and its rim's extremes project into
            // the image.
            let rad = self.model.radius_m();
            let whole = |m: &[f64; 2]| {
                [[rad, 0.0], [-rad, 0.0], [0.0, rad], [0.0, -rad]].iter().all(|d| {
                    self.cams[c]
                        .project(&(r * Vector3::new(0.0, m[0] + d[0], m[1] + d[1]) + t))
                        .is_some_and(in_image)
                })
            };
            let run = &mut cameras[c];
            run.visible = (0..self.model.len())
                .filter(|&j| !hidden.contains(&j) && whole(&self.model.centres()[j]))
                .count();
            run.detected = ws.marks.len();
            let (res, l) = label(&self.model, &ws.marks, &strict, &true_px);
            run.labelling = l;
            match res {
                Ok(fit) => {
                    obs[c] = MarkObservations::from_fit(&fit, &ws.marks);
                    run.mono = outcome(
                        mono_pose(&self.model, &self.cams[c], c, &obs[c], &params, &mut ws.buf),
                        &robot,
                    );
                    run.mono_pinhole = outcome(
                        mono_pose(&self.model, &self.pinholes[c], c, &obs[c], &params, &mut ws.buf),
                        &robot,
                    );
                }
                Err(e) => {
                    run.mono = unlabelled(&e);
                    run.mono_pinhole = unlabelled(&e);
                }
            }
            let (res, l) = label(&self.model, &ws.marks, &four, &true_px);
            run.labelling_four_point = l;
            run.mono_four_point = match res {
                Ok(fit) => {
                    obs4[c] = MarkObservations::from_fit(&fit, &ws.marks);
                    outcome(
                        mono_pose(&self.model, &self.cams[c], c, &obs4[c], &params, &mut ws.buf),
                        &robot,
                    )
                }
                Err(e) => unlabelled(&e),
            };
        }
        let stereo_of = |o: &[MarkObservations; 2], labelled: [&Labelling; 2], buf: &mut PoseBuffers| match labelled
            .iter()
            .find(|l| !l.found)
        {
            Some(l) => PoseOutcome {
                error: l.error.clone(),
                message: Some("a camera's labelling failed".into()),
                ..Default::default()
            },
            None => outcome(
                stereo_pose(
                    &self.model,
                    [&self.cams[0], &self.cams[1]],
                    [&o[0], &o[1]],
                    &params,
                    buf,
                ),
                &robot,
            ),
        };
        let stereo = stereo_of(&obs, [&cameras[0].labelling, &cameras[1].labelling], &mut ws.buf);
        let stereo_four_point = stereo_of(
            &obs4,
            [&cameras[0].labelling_four_point, &cameras[1].labelling_four_point],
            &mut ws.buf,
        );
        Ok(PoseRun {
            index: spec.index,
            distance_m: spec.distance_m,
            alpha_deg: spec.alpha_deg,
            turn_deg: spec.turn_deg,
            noise: spec.noise,
            jpeg_quality: spec.jpeg_quality,
            seed,
            hidden,
            decoy: spec.decoy,
            cameras,
            stereo,
            stereo_four_point,
        })
    }
}

/// Runs every run of a loaded campaign on `jobs` threads (0: one per core) and returns
/// the records in run order; `each` sees each record as it finishes, in any order. With
/// `frames`, each run's measured frames are saved there as `RUN-CAMERA.png`.
///
/// # Errors
/// [`SimError`] when the profile's model or cameras cannot be built, or a frame cannot
/// be searched.
pub fn run_campaign(
    loaded: &LoadedCampaign,
    jobs: usize,
    frames: Option<&Path>,
    each: &(dyn Fn(&PoseRun) + Sync),
) -> Result<Vec<PoseRun>, SimError> {
    let p = &loaded.profile;
    let model = CircleModel::from_profile(p).map_err(|e| SimError::Unsupported(e.to_string()))?;
    let cam = |k: usize| RigCamera::from_profile(p, k).map_err(|e| SimError::Unsupported(e.to_string()));
    let cams = [cam(0)?, cam(1)?];
    let ctx = Context {
        campaign: &loaded.campaign,
        profile: p,
        pinholes: [pinhole_of(&cams[0]), pinhole_of(&cams[1])],
        cams,
        model,
        frames,
    };
    let specs = runs(&loaded.campaign);
    let jobs = if jobs == 0 {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    } else {
        jobs
    };
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<Result<PoseRun, SimError>>>> = Mutex::new((0..specs.len()).map(|_| None).collect());
    std::thread::scope(|s| {
        for _ in 0..jobs.min(specs.len()).max(1) {
            s.spawn(|| {
                let mut ws = Workspace {
                    detectors: p
                        .cameras
                        .iter()
                        .take(2)
                        .map(|c| {
                            CircleDetector::new(c.width_px, c.height_px, CircleParams::from_profile(p, c.width_px))
                        })
                        .collect(),
                    image: RgbImage::default(),
                    marks: Vec::new(),
                    buf: PoseBuffers::new(),
                };
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    let Some(spec) = specs.get(i) else { break };
                    let r = ctx.run(spec, &mut ws);
                    if let Ok(rec) = &r {
                        each(rec);
                    }
                    if let Ok(mut all) = results.lock() {
                        all[i] = Some(r);
                    }
                }
            });
        }
    });
    results
        .into_inner()
        .map_err(poisoned)?
        .into_iter()
        .map(|r| r.unwrap_or_else(|| Err(SimError::Unsupported("a run did not finish".into()))))
        .collect()
}

fn poisoned<T>(_: T) -> SimError {
    SimError::Unsupported("a worker panicked".into())
}

/// A pose so far off that a planner trusting it would go the wrong way: more than 10 %
/// of the distance or 10° of heading out (the paper's worst, 30 cm at 4 m, is 7.5 %).
pub fn is_wrong(o: &PoseOutcome, distance_m: f64) -> bool {
    o.found && (o.position_err_m.unwrap_or(0.0) > 0.1 * distance_m || o.heading_err_deg.unwrap_or(0.0) > 10.0)
}

/// The paper's pose error at a distance (seed 000 §V-C), where it gives one.
pub fn paper_figure(distance_m: f64) -> Option<&'static str> {
    match (distance_m * 10.0).round() as i64 {
        10 => Some("2.56 cm / 2.5°"),
        20 => Some("4.12 cm / 4.58°"),
        40 => Some("up to 30 cm"),
        50 => Some("about 20 cm"),
        _ => None,
    }
}

/// Mean, SD and largest of some values (zeros when there are none).
fn stats(v: &[f64]) -> (f64, f64, f64) {
    if v.is_empty() {
        return (0.0, 0.0, 0.0);
    }
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let sd = (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / n).sqrt();
    (m, sd, v.iter().copied().fold(f64::MIN, f64::max))
}

/// "found/total, mean / worst cm, mean / worst °" of some pose outcomes.
fn pose_cells(outcomes: &[&PoseOutcome]) -> (String, String, String) {
    let found: Vec<&&PoseOutcome> = outcomes.iter().filter(|o| o.found).collect();
    let pos: Vec<f64> = found
        .iter()
        .filter_map(|o| o.position_err_m)
        .map(|e| 100.0 * e)
        .collect();
    let head: Vec<f64> = found.iter().filter_map(|o| o.heading_err_deg).collect();
    let (pm, _, pw) = stats(&pos);
    let (hm, _, hw) = stats(&head);
    let none = found.is_empty();
    let cell = |m: f64, w: f64, unit: &str| {
        if none {
            "–".to_string()
        } else {
            format!("{m:.2} / {w:.2}{unit}")
        }
    };
    (
        format!("{}/{}", found.len(), outcomes.len()),
        cell(pm, pw, " cm"),
        cell(hm, hw, "°"),
    )
}

/// Writes the campaign's tables: per distance, the stereo and mono pose errors beside the
/// paper's, the reprojection errors, the two ablations, and per number of visible marks
/// what the labelling and pose did.
///
/// # Errors
/// Writing to `out`.
pub fn write_tables(c: &PoseCampaign, recs: &[PoseRun], out: &mut dyn Write) -> std::io::Result<()> {
    // Rows: each stream (JPEG quality) and distance, in run order.
    let mut keys: Vec<(u32, f64)> = Vec::new();
    for r in recs {
        if !keys.contains(&(r.jpeg_quality, r.distance_m)) {
            keys.push((r.jpeg_quality, r.distance_m));
        }
    }
    let at = |(q, d): (u32, f64)| recs.iter().filter(move |r| r.jpeg_quality == q && r.distance_m == d);
    let stream = |q: u32| if q == 0 { "raw".to_string() } else { format!("JPEG {q}") };
    writeln!(out, "{}: {} runs ({})", c.name, recs.len(), c.description)?;
    writeln!(out)?;
    writeln!(
        out,
        "| stream | distance | stereo found | stereo position mean / worst | stereo heading mean / worst | mono found (per camera) | mono position mean / worst | mono heading mean / worst | wrong poses (stereo, mono) | paper (stereo) |"
    )?;
    writeln!(out, "|---|---|---|---|---|---|---|---|---|---|")?;
    for &(q, d) in &keys {
        let st: Vec<&PoseOutcome> = at((q, d)).map(|r| &r.stereo).collect();
        let mo: Vec<&PoseOutcome> = at((q, d)).flat_map(|r| r.cameras.iter().map(|k| &k.mono)).collect();
        let (sf, sp, sh) = pose_cells(&st);
        let (mf, mp, mh) = pose_cells(&mo);
        let ws = st.iter().filter(|o| is_wrong(o, d)).count();
        let wm = mo.iter().filter(|o| is_wrong(o, d)).count();
        writeln!(
            out,
            "| {} | {d:.1} m | {sf} | {sp} | {sh} | {mf} | {mp} | {mh} | {ws}, {wm} | {} |",
            stream(q),
            paper_figure(d).unwrap_or("")
        )?;
    }
    writeln!(out)?;
    writeln!(
        out,
        "| stream | distance | labelled frames | homography reprojection mean ± SD (worst) | stereo pose reprojection mean ± SD (worst) | paper |"
    )?;
    writeln!(out, "|---|---|---|---|---|---|")?;
    for &(q, d) in &keys {
        let frames: Vec<&CameraRun> = at((q, d)).flat_map(|r| r.cameras.iter()).collect();
        let h: Vec<f64> = frames.iter().filter_map(|k| k.labelling.reprojection_px).collect();
        let s: Vec<f64> = at((q, d)).filter_map(|r| r.stereo.reprojection_px).collect();
        let (hm, hs, hw) = stats(&h);
        let (sm, ss, sw) = stats(&s);
        writeln!(
            out,
            "| {} | {d:.1} m | {}/{} | {hm:.2} ± {hs:.2} px ({hw:.2}) | {sm:.2} ± {ss:.2} px ({sw:.2}) | 8.21 ± 2.4 px |",
            stream(q),
            h.len(),
            frames.len()
        )?;
    }
    writeln!(out)?;
    writeln!(
        out,
        "| stream | distance | mono, lens model: position / heading (mean / worst) | mono, pin-hole (distortion ignored) | 4-point labelling: frames labelled, mislabelled | ≥ 5 (ours): labelled, mislabelled | 4-point stereo: found, wrong | ours stereo: found, wrong |"
    )?;
    writeln!(out, "|---|---|---|---|---|---|---|---|")?;
    for &(q, d) in &keys {
        let frames: Vec<&CameraRun> = at((q, d)).flat_map(|r| r.cameras.iter()).collect();
        let lens: Vec<&PoseOutcome> = frames.iter().map(|k| &k.mono).collect();
        let pin: Vec<&PoseOutcome> = frames.iter().map(|k| &k.mono_pinhole).collect();
        let (_, lp, lh) = pose_cells(&lens);
        let (pf, pp, ph) = pose_cells(&pin);
        let count = |f: &dyn Fn(&CameraRun) -> bool| frames.iter().filter(|k| f(k)).count();
        let l4 = count(&|k| k.labelling_four_point.found);
        let m4 = count(&|k| k.labelling_four_point.mislabelled > 0);
        let l5 = count(&|k| k.labelling.found);
        let m5 = count(&|k| k.labelling.mislabelled > 0);
        let s4f = at((q, d)).filter(|r| r.stereo_four_point.found).count();
        let s4w = at((q, d)).filter(|r| is_wrong(&r.stereo_four_point, d)).count();
        let s5f = at((q, d)).filter(|r| r.stereo.found).count();
        let s5w = at((q, d)).filter(|r| is_wrong(&r.stereo, d)).count();
        writeln!(
            out,
            "| {} | {d:.1} m | {lp}, {lh} | {pp}, {ph} ({pf}) | {l4}, {m4} | {l5}, {m5} | {s4f}, {s4w} | {s5f}, {s5w} |",
            stream(q)
        )?;
    }
    writeln!(out)?;
    writeln!(
        out,
        "| stream | visible marks | decoy | frames | labelled (≥ 5) | mono pose | wrong | clean failures | 4-point: labelled | mislabelled | wrong mono poses |"
    )?;
    writeln!(out, "|---|---|---|---|---|---|---|---|---|---|---|")?;
    let mut qualities: Vec<u32> = keys.iter().map(|k| k.0).collect();
    qualities.dedup();
    for q in qualities {
        for decoy in [false, true] {
            for v in (0..=8).rev() {
                let frames: Vec<(&PoseRun, &CameraRun)> = recs
                    .iter()
                    .filter(|r| r.decoy == decoy && r.jpeg_quality == q)
                    .flat_map(|r| r.cameras.iter().map(move |k| (r, k)))
                    .filter(|(_, k)| k.visible == v)
                    .collect();
                if frames.is_empty() {
                    continue;
                }
                let n = |f: &dyn Fn(&PoseRun, &CameraRun) -> bool| frames.iter().filter(|(r, k)| f(r, k)).count();
                let mut failures: Vec<(String, usize)> = Vec::new();
                for (_, k) in &frames {
                    if let Some(e) = &k.mono.error {
                        match failures.iter_mut().find(|(name, _)| name == e) {
                            Some(f) => f.1 += 1,
                            None => failures.push((e.clone(), 1)),
                        }
                    }
                }
                failures.sort();
                let failures = if failures.is_empty() {
                    "–".to_string()
                } else {
                    failures
                        .iter()
                        .map(|(e, n)| format!("{e} {n}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                };
                writeln!(
                    out,
                    "| {} | {v} | {} | {} | {} | {} | {} | {failures} | {} | {} | {} |",
                    stream(q),
                    if decoy { "yes" } else { "no" },
                    frames.len(),
                    n(&|_, k| k.labelling.found),
                    n(&|_, k| k.mono.found),
                    n(&|r, k| is_wrong(&k.mono, r.distance_m)),
                    n(&|_, k| k.labelling_four_point.found),
                    n(&|_, k| k.labelling_four_point.mislabelled > 0),
                    n(&|r, k| is_wrong(&k.mono_four_point, r.distance_m)),
                )?;
            }
        }
    }
    Ok(())
}

/// Runs `marsupial pose-trials`: the campaign's records (as JSON lines with `--json`,
/// else the tables) to `out`, and with `--out DIR` DIR/runs.jsonl and DIR/tables.txt.
///
/// # Errors
/// [`SimError`] for a bad campaign file, a failed run or unwritable output.
pub fn run(opts: &PoseTrialsOptions, out: &mut dyn Write) -> Result<Vec<PoseRun>, SimError> {
    let loaded = PoseCampaign::load(&opts.campaign)?;
    let total = runs(&loaded.campaign).len();
    let done = AtomicUsize::new(0);
    let progress = |_: &PoseRun| {
        let k = done.fetch_add(1, Ordering::Relaxed) + 1;
        if k.is_multiple_of(10) || k == total {
            eprintln!("{k}/{total} runs");
        }
    };
    let io = |path: &Path| {
        let path = path.display().to_string();
        move |source| SimError::Io { path, source }
    };
    let frames = match (&opts.out, opts.frames) {
        (Some(dir), true) => {
            let f = dir.join("frames");
            std::fs::create_dir_all(&f).map_err(io(&f))?;
            Some(f)
        }
        _ => None,
    };
    let recs = run_campaign(&loaded, opts.jobs, frames.as_deref(), &progress)?;
    let mut tables = Vec::new();
    write_tables(&loaded.campaign, &recs, &mut tables).map_err(io(Path::new("<tables>")))?;
    if opts.json {
        for r in &recs {
            super::json_line(out, r).map_err(io(Path::new("<stdout>")))?;
        }
    } else {
        out.write_all(&tables).map_err(io(Path::new("<stdout>")))?;
    }
    if let Some(dir) = &opts.out {
        std::fs::create_dir_all(dir).map_err(io(dir))?;
        let mut lines = Vec::new();
        for r in &recs {
            super::json_line(&mut lines, r).map_err(io(dir))?;
        }
        let runs_path = dir.join("runs.jsonl");
        std::fs::write(&runs_path, lines).map_err(io(&runs_path))?;
        let tables_path = dir.join("tables.txt");
        std::fs::write(&tables_path, tables).map_err(io(&tables_path))?;
    }
    Ok(recs)
}
