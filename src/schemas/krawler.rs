//! [`KrawlerSchema`]: the AutoKrawler's state estimator (seed 003,
//! [`KrawlerStateSchema`]) as a perceptual schema, so it runs on the loop's ticks from the
//! robot's own belly camera, on the threaded runtime, in `Lockstep` and in a replay alike.
//!
//! The estimator must see each frame once, in order: its wheel stage measures the
//! rotation between consecutive frames, so a frame seen twice would read as a wheel at
//! rest. The schema therefore estimates only when the camera's stamp is new, and
//! otherwise hands back the last estimate marked not fresh. RANSAC draws come from the
//! schema's own seeded generator (deterministic, no random source), or from one the caller
//! installs ([`KrawlerSchema::set_draw`]) to match an offline run draw for draw.

use super::inputs::Inputs;
use super::percept::Percept;
use super::traits::PerceptualSchema;
use crate::perception::{
    AxleGeometry, GearGeometry, GearSpec, KrawlerEstimate, KrawlerParams, KrawlerStateSchema, SteeringPoly, VisionError,
};
use crate::profile::Profile;
use serde::Serialize;

/// A RANSAC index draw: an index below its argument.
pub type Draw = Box<dyn FnMut(usize) -> usize + Send>;

/// What the estimator made of the current tick.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct KrawlerPercept {
    /// The frame's stamp (the last estimated frame's when not fresh), s.
    pub stamp: f64,
    /// A new frame was estimated this tick.
    pub fresh: bool,
    /// The ten degrees of freedom (the last frame's when not fresh).
    pub estimate: KrawlerEstimate,
    /// Frames estimated so far.
    pub frames: u64,
    /// Frames the estimator refused (another size than the profile's camera).
    pub refused: u64,
}

impl KrawlerPercept {
    /// The percept as recorders and replays show it.
    pub fn observation(&self) -> KrawlerObservation {
        let e = &self.estimate;
        KrawlerObservation {
            stamp: self.stamp,
            fresh: self.fresh,
            markers: e.markers.at,
            roll_rad: e.roll.map(|d| d.value),
            drop_m: e.drop.map(|d| d.value),
            steer_rad: e.steer.map(|d| d.value),
            wheel_rad: e.wheel.map(|d| d.value),
            wheel_measured: e.wheel.map(|d| d.valid),
        }
    }
}

/// A [`KrawlerPercept`] for recorders and replays
/// ([`ObservedPercept::Krawler`](super::ObservedPercept::Krawler)): the ten degrees of
/// freedom and the markers found.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct KrawlerObservation {
    /// The frame's stamp, s.
    pub stamp: f64,
    /// A new frame was estimated this tick.
    pub fresh: bool,
    /// Each marker's centre found this frame, px (front plate left, right; front tie rod
    /// left, right; then the rear's).
    pub markers: [Option<[f64; 2]>; 8],
    /// Axle roll ψ (front, rear), rad.
    pub roll_rad: [f64; 2],
    /// Camera-to-axle drop d (front, rear), m.
    pub drop_m: [f64; 2],
    /// Steering λ (front, rear), rad.
    pub steer_rad: [f64; 2],
    /// Wheel rotations θ (FL, FR, RL, RR) from the first frame, rad.
    pub wheel_rad: [f64; 4],
    /// Whether this frame measured each wheel's step.
    pub wheel_measured: [bool; 4],
}

impl Percept for KrawlerPercept {
    fn stamp(&self) -> f64 {
        self.stamp
    }
    /// Found: a new frame was estimated with all eight markers.
    fn found(&self) -> bool {
        self.fresh && self.estimate.markers.found() == 8
    }
}

/// The estimator on the loop's camera `camera` (see the module docs).
pub struct KrawlerSchema {
    estimator: KrawlerStateSchema,
    camera: usize,
    percept: KrawlerPercept,
    seen: bool,
    rng: u64,
    draw: Option<Draw>,
}

impl KrawlerSchema {
    /// The estimator of an AutoKrawler `profile`'s camera 0 with the gear `gear` (its
    /// `[robot.gear]`), the profile's steering calibration, `params`, and RANSAC draws
    /// seeded with `seed`. It starts from the gear's rest state and its markers'
    /// projections, from its own model ([`GearGeometry::start`]).
    ///
    /// # Errors
    /// [`VisionError::Profile`] without the camera, the drive's dimensions, the `markers`
    /// fiducial's steering calibration, or markers that project at rest.
    pub fn from_profile(
        profile: &Profile,
        gear: GearSpec,
        params: KrawlerParams,
        seed: u64,
    ) -> Result<Self, VisionError> {
        let why = |what: String| VisionError::Profile {
            what: format!("profile `{}` {what}", profile.name),
        };
        let cam = profile.cameras.first().ok_or_else(|| why("has no camera".into()))?;
        let geometry = AxleGeometry::from_profile(profile, 0)?;
        let gear = GearGeometry::from_profile(profile, gear)?;
        let polys = SteeringPoly::from_profile(profile).ok_or_else(|| {
            why(
                "has a `markers` fiducial without steering_poly_deg (run `marsupial calibrate-steering --write`)"
                    .into(),
            )
        })?;
        let side = profile
            .fiducial
            .get::<crate::profile::MarkersSpec>()
            .map(|m| m.side_m)
            .ok_or_else(|| why("has no `markers` fiducial".into()))?;
        let (start, axles) = gear
            .start(&geometry, side)
            .ok_or_else(|| why("has a gear whose markers at rest do not project into the camera".into()))?;
        let estimator = KrawlerStateSchema::new(
            (cam.width_px, cam.height_px),
            geometry,
            gear.layout(),
            polys,
            params,
            start,
            axles,
        );
        Ok(Self {
            estimator,
            camera: 0,
            percept: KrawlerPercept::default(),
            seen: false,
            rng: seed ^ 0x9e37_79b9_7f4a_7c15,
            draw: None,
        })
    }

    /// Replaces the schema's generator with `draw` (for example the simulator's, to
    /// reproduce an offline run).
    pub fn set_draw(&mut self, draw: Draw) {
        self.draw = Some(draw);
    }

    /// The estimator.
    pub fn estimator(&self) -> &KrawlerStateSchema {
        &self.estimator
    }

    /// The latest percept.
    pub fn percept(&self) -> &KrawlerPercept {
        &self.percept
    }

    /// The next index below `n` from the schema's xorshift64* generator.
    fn next(rng: &mut u64, n: usize) -> usize {
        let mut x = *rng;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        *rng = x;
        (x.wrapping_mul(0x2545_f491_4f6c_dd1d) % n.max(1) as u64) as usize
    }
}

impl PerceptualSchema for KrawlerSchema {
    type Percept = KrawlerPercept;

    fn perceive(&mut self, inputs: &Inputs<'_>) -> KrawlerPercept {
        self.percept.fresh = false;
        let Some(cam) = inputs.camera(self.camera) else {
            return self.percept;
        };
        if self.seen && cam.stamp <= self.percept.stamp {
            return self.percept;
        }
        let rng = &mut self.rng;
        let result = match self.draw.as_mut() {
            Some(draw) => self.estimator.estimate(&cam.image, draw),
            None => self.estimator.estimate(&cam.image, |n| Self::next(rng, n)),
        };
        match result {
            Ok(estimate) => {
                self.percept.estimate = estimate;
                self.percept.fresh = true;
                self.percept.frames += 1;
            }
            Err(_) => self.percept.refused += 1,
        }
        self.percept.stamp = cam.stamp;
        self.seen = true;
        self.percept
    }
}
