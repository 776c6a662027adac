//! The belly camera's frames of a driving sequence, as `marsupial estimate` renders them:
//! the gear built from the true state, rendered by the fisheye with sensor noise and the
//! sequence's error knobs (lost frames, mount vibration, mud on a marker, a light change,
//! the body's shadow, the mount's plates, the floor moving under the rover).
//!
//! One source for both of `estimate`'s paths, the offline loop and the robot's camera in
//! the loop (`--runtime`), so that both see the same pixels: frames must be asked for in
//! order, since the error knobs draw from one generator frame by frame.

use crate::geometry::Pose2;
use crate::perception::RgbImage;
use crate::perception::krawler::ExpectedMarker;
use crate::profile::Profile;
use crate::sim::camera::camera_pose;
use crate::sim::krawler::{GearExtras, GroundPose, build_with};
use crate::sim::krawler_sequence::{LightChange, SequenceSpec, TruthFrame, drive_of, odometry, shaken};
use crate::sim::render::{CameraPose, Renderer, SensorParams};
use crate::sim::rng::Rng;
use nalgebra::Point3;

/// The rendered frames of one sequence (see the module docs).
pub(super) struct SequenceFrames {
    profile: Profile,
    truth: Vec<TruthFrame>,
    knobs: crate::sim::krawler_sequence::ErrorKnobs,
    renderer: Renderer,
    model: crate::perception::CameraModel,
    base: CameraPose,
    sensor: SensorParams,
    ground: Vec<[f64; 3]>,
    errors: Rng,
    side: f64,
}

/// Each frame's time step to the next (0 after the last) and body speed.
pub(super) fn steps_of(truth: &[TruthFrame]) -> (Vec<f64>, Vec<f64>) {
    let dts = truth
        .windows(2)
        .map(|w| w[1].t - w[0].t)
        .chain(std::iter::once(0.0))
        .collect();
    (dts, truth.iter().map(|f| f.speed).collect())
}

/// The rover's true path (x, y, heading per frame) from the truth's speeds and steering.
pub(super) fn true_path(drive: &crate::kinematics::ackermann::DoubleAckermann, truth: &[TruthFrame]) -> Vec<[f64; 3]> {
    let (dts, speed) = steps_of(truth);
    let steer: Vec<[f64; 2]> = truth.iter().map(|f| f.state.steer).collect();
    odometry(drive, &dts, &speed, &steer)
}

impl SequenceFrames {
    /// The frames of `spec` on `profile`'s camera 0, for the truth `truth`, noise and
    /// knobs seeded with `seed`.
    ///
    /// # Errors
    /// Names the profile's problem (no camera).
    pub(super) fn new(spec: &SequenceSpec, profile: &Profile, truth: &[TruthFrame], seed: u64) -> Result<Self, String> {
        let cam = profile
            .cameras
            .first()
            .ok_or_else(|| format!("profile `{}`: no camera", profile.name))?;
        let model = crate::perception::CameraModel::from_spec(cam);
        let dt = truth.get(1).map_or(1.0 / cam.fps, |f| f.t - truth[0].t);
        let knobs = spec.errors;
        // The rover's true path over the floor, when the floor is fixed to the world.
        let ground = match (knobs.moving_ground, drive_of(profile)) {
            (true, Some(drive)) => true_path(&drive, truth),
            _ => Vec::new(),
        };
        Ok(Self {
            renderer: Renderer::new(model.clone(), cam.width_px, cam.height_px, seed),
            model,
            base: camera_pose(&Pose2::new(0.0, 0.0, 0.0), &cam.mount),
            sensor: SensorParams {
                frame_interval_s: dt as f32,
                ..SensorParams::default()
            },
            side: profile
                .fiducial
                .get::<crate::profile::MarkersSpec>()
                .map_or(0.03, |m| m.side_m),
            profile: profile.clone(),
            truth: truth.to_vec(),
            knobs,
            ground,
            errors: Rng::named(seed, "krawler-errors"),
        })
    }

    /// The number of frames.
    pub(super) fn len(&self) -> usize {
        self.truth.len()
    }

    /// Renders frame `i` (the next in order) into `image`; false when the frame-drop knob
    /// lost it.
    ///
    /// # Errors
    /// Names the profile's problem when its gear cannot be built.
    pub(super) fn render(&mut self, i: usize, image: &mut RgbImage) -> Result<bool, String> {
        let k = self.knobs;
        let f = self.truth[i];
        if k.frame_drop > 0.0 && i > 0 && self.errors.uniform() < k.frame_drop {
            return Ok(false);
        }
        let pose = if k.vibration_deg > 0.0 || k.vibration_mm > 0.0 {
            shaken(&self.base, k.vibration_deg, k.vibration_mm, &mut self.errors)
        } else {
            self.base
        };
        let light = LightChange::light_at(k.light.as_ref(), f.t);
        let extras = GearExtras {
            shadow: k.self_shadow.and_then(|s| s.at(f.t)),
            mount_plates: k.mount_plates,
            ground: self.ground.get(i).map(|p| GroundPose {
                x: p[0],
                y: p[1],
                heading: p[2],
            }),
        };
        let gear = build_with(&self.profile, &f.state, &extras)
            .map_err(|e| format!("profile `{}`: {e}", self.profile.name))?;
        self.renderer
            .render(&gear.scene, &pose, &light, &self.sensor, i as u64, image);
        if let Some(m) = k.mud
            && f.t >= m.start_s
            && f.t < m.start_s + m.duration_s
        {
            mud(image, &self.model, &pose, &gear.markers[m.marker], self.side);
        }
        Ok(true)
    }
}

/// Paints mud over marker `marker` of the gear: a brown patch 1.6 times the marker's
/// side, centred where it projects.
fn mud(
    image: &mut RgbImage,
    model: &crate::perception::CameraModel,
    pose: &CameraPose,
    centre: &Point3<f64>,
    side: f64,
) {
    let project = |q: [f64; 3]| model.project(&pose.to_camera(&Point3::from(q)));
    let Some(m) = ExpectedMarker::from_square(
        project,
        centre.coords.into(),
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        side * 1.6,
    ) else {
        return;
    };
    let half = m.area.sqrt() / 2.0;
    let (w, h) = (image.width() as f64, image.height() as f64);
    let x0 = (m.at[0] - half).floor().clamp(0.0, w) as usize;
    let x1 = (m.at[0] + half).ceil().clamp(0.0, w) as usize;
    let y0 = (m.at[1] - half).floor().clamp(0.0, h) as usize;
    let y1 = (m.at[1] + half).ceil().clamp(0.0, h) as usize;
    for y in y0..y1 {
        for x in x0..x1 {
            let n = ((x * 31 + y * 17) % 21) as u8;
            image.put(x, y, [88 + n, 72 + n, 56 + n]);
        }
    }
}
