//! The circle-fiducial perceptual schema Axel's memory runs while a schema looks: both
//! cameras' detectors, the module's model and the stereo rig, every buffer owned and
//! reused (seed 000 §III). Detection, correspondence and the stereo or mono pose are
//! `perception::circles`'; this file only owns them for the two cameras.

use crate::perception::circles::{
    CircleDetector, CircleModel, CircleParams, CorrespondenceParams, LensPlane, MarkObservations, ModulePose,
    PoseBuffers, PoseParams, RigCamera, correspond_through, module_pose,
};
use crate::profile::Profile;
use crate::schemas::Inputs;

/// The circle pipeline for both cameras, every buffer owned and reused.
pub(super) struct Perception {
    detectors: [CircleDetector; 2],
    model: CircleModel,
    cams: [RigCamera; 2],
    /// Each camera's lens, for labelling through its distortion.
    lenses: [LensPlane; 2],
    corr: CorrespondenceParams,
    params: PoseParams,
    buf: PoseBuffers,
}

impl Perception {
    pub(super) fn from_profile(profile: &Profile) -> Result<Self, String> {
        let err = |what: String| what;
        if profile.cameras.len() < 2 {
            return Err(err("Axel's behavior needs the stereo pair: two [[cameras]]".into()));
        }
        let detector = |i: usize| {
            let c = &profile.cameras[i];
            CircleDetector::new(c.width_px, c.height_px, CircleParams::from_profile(profile, c.width_px))
        };
        let cam = |i: usize| RigCamera::from_profile(profile, i).map_err(|e| err(e.to_string()));
        let cams = [cam(0)?, cam(1)?];
        Ok(Self {
            detectors: [detector(0), detector(1)],
            model: CircleModel::from_profile(profile).map_err(|e| err(e.to_string()))?,
            lenses: [
                LensPlane::new(cams[0].model.clone()),
                LensPlane::new(cams[1].model.clone()),
            ],
            cams,
            corr: CorrespondenceParams::default(),
            params: PoseParams::default(),
            buf: PoseBuffers::new(),
        })
    }

    /// The module's pose from this tick's frames, if both cameras have one and the rig
    /// makes a pose of what they saw.
    pub(super) fn look(&mut self, inputs: &Inputs<'_>) -> Option<(f64, ModulePose)> {
        let mut obs = [MarkObservations::new(self.model.len()); 2];
        let mut stamp = f64::NEG_INFINITY;
        for (i, o) in obs.iter_mut().enumerate() {
            let Some(frame) = inputs.camera(i) else { continue };
            stamp = stamp.max(frame.stamp);
            let Ok(marks) = self.detectors[i].detect(&frame.image) else {
                continue;
            };
            if let Ok(fit) = correspond_through(&self.model, marks, &mut self.lenses[i], &self.corr) {
                *o = MarkObservations::from_fit(&fit, marks);
            }
        }
        let pose = module_pose(
            &self.model,
            [&self.cams[0], &self.cams[1]],
            [&obs[0], &obs[1]],
            &self.params,
            &mut self.buf,
        )
        .ok()?;
        Some((stamp, pose))
    }
}
