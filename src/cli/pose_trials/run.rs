//! One run of a campaign: the world with its hidden marks and decoys, both cameras'
//! frames rendered through the campaign's sensor, the detections, the labellings (strict
//! and the 4-mark ablation) and the mono and stereo poses (with the lens model and the
//! pin-hole ablation), each scored against the truth into a [`PoseRun`]. What runs share
//! ([`Context`]) and what a worker reuses ([`Workspace`]) are built once.

use super::score::{label, outcome, truth, unlabelled};
use super::{CameraRun, Labelling, LoadedCampaign, PoseCampaign, PoseOutcome, PoseRun, RunSpec, rover_pose};
use crate::perception::RgbImage;
use crate::perception::camera_model::CameraModel;
use crate::perception::circles::{
    CircleDetector, CircleModel, CircleParams, CorrespondenceParams, DetectedMark, LensPlane, MarkObservations,
    PoseBuffers, PoseParams, RigCamera, mono_pose, stereo_pose,
};
use crate::profile::CirclePlacement;
use crate::profile::Profile;
use crate::sim::SimError;
use crate::sim::camera::camera_pose;
use crate::sim::lighting::LightingRun;
use crate::sim::render::Renderer;
use crate::sim::rng::{Rng, splitmix64};
use crate::sim::world::{self, ClutterKind, ClutterSpec};
use nalgebra::Vector3;
use std::path::Path;

/// What every run shares: the profile's model and cameras, and the ablation's pin-holes.
pub(super) struct Context<'a> {
    campaign: &'a PoseCampaign,
    profile: &'a Profile,
    model: CircleModel,
    cams: [RigCamera; 2],
    pinholes: [RigCamera; 2],
    frames: Option<&'a Path>,
}

/// A worker's buffers, reused from run to run.
pub(super) struct Workspace {
    detectors: Vec<CircleDetector>,
    /// Each camera's lens, which the labelling sees through as the robot's does.
    lenses: Vec<LensPlane>,
    image: RgbImage,
    marks: Vec<DetectedMark>,
    buf: PoseBuffers,
}

impl<'a> Context<'a> {
    /// The context of a loaded campaign's runs, saving their measured frames in `frames`
    /// when given.
    ///
    /// # Errors
    /// [`SimError`] when the profile's model or cameras cannot be built.
    pub(super) fn new(loaded: &'a LoadedCampaign, frames: Option<&'a Path>) -> Result<Self, SimError> {
        let p = &loaded.profile;
        let model = CircleModel::from_profile(p).map_err(|e| SimError::Unsupported(e.to_string()))?;
        let cam = |k: usize| RigCamera::from_profile(p, k).map_err(|e| SimError::Unsupported(e.to_string()));
        let cams = [cam(0)?, cam(1)?];
        Ok(Context {
            campaign: &loaded.campaign,
            profile: p,
            pinholes: [pinhole_of(&cams[0]), pinhole_of(&cams[1])],
            cams,
            model,
            frames,
        })
    }
}

impl Workspace {
    /// A worker's buffers: a detector for each of the profile's two cameras.
    pub(super) fn new(p: &Profile) -> Self {
        Workspace {
            detectors: p
                .cameras
                .iter()
                .take(2)
                .map(|c| CircleDetector::new(c.width_px, c.height_px, CircleParams::from_profile(p, c.width_px)))
                .collect(),
            lenses: p
                .cameras
                .iter()
                .take(2)
                .map(|c| LensPlane::new(CameraModel::from_spec(c)))
                .collect(),
            image: RgbImage::default(),
            marks: Vec::new(),
            buf: PoseBuffers::new(),
        }
    }
}

/// The camera as a pose that ignores the distortion sees it: its ideal pin-hole
/// ([`CameraModel::ideal_pinhole`], a fish-eye's on-axis focal length and centre).
fn pinhole_of(cam: &RigCamera) -> RigCamera {
    RigCamera {
        model: CameraModel::Pinhole(cam.model.ideal_pinhole()),
        ..cam.clone()
    }
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
    /// the run places them (on panels, or painted on the face).
    fn world(&self, hidden: &[usize], decoy: bool) -> Result<world::World, SimError> {
        let mut clutter = Vec::new();
        let mut painted = Vec::new();
        let decoys = match &self.campaign.occlusion {
            Some(o) if decoy => o.decoys.as_slice(),
            _ => &[],
        };
        for d in decoys {
            if d.painted {
                painted.push(CirclePlacement {
                    y_m: d.at_m[1],
                    z_m: d.at_m[2],
                    rotation_deg: d.rotation_deg,
                });
            } else {
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
        world::build_face(self.profile, &clutter, &[], hidden, &painted)
    }

    /// Renders, detects, labels and poses one run and scores it against the truth.
    ///
    /// # Errors
    /// [`SimError`] when its world cannot be built, a frame cannot be saved or searched.
    pub(super) fn run(&self, spec: &RunSpec, ws: &mut Workspace) -> Result<PoseRun, SimError> {
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
            let (res, l) = label(&self.model, &ws.marks, &mut ws.lenses[c], &strict, &true_px);
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
            let (res, l) = label(&self.model, &ws.marks, &mut ws.lenses[c], &four, &true_px);
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
