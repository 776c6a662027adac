//! [`KrawlerStateSchema`]: the ten degrees of freedom from each belly-fisheye frame
//! (seed 003 Fig. 5), each with a validity flag.
//!
//! Per frame, in the paper's order:
//! 1. **Markers** ([`MarkerFinder`]): the eight magenta markers, predicted where each was
//!    last seen (at its seen size). A marker partly hidden, touching the frame's edge or
//!    not corroborated by its axle is missing, never guessed; its prediction stays where
//!    it was last seen.
//! 2. **Mount shake** ([`fit_mount`]): the camera's small rotation and shift on its
//!    mount this frame, from the four plate markers (ours: the paper names mount
//!    vibration as an error source); every later stage uses the mount so moved.
//! 3. **Roll ψ and drop d** of an axle from its two plate markers ([`AxleGeometry`]):
//!    valid only when both are found this frame.
//! 4. **Steering λ** from the tie-rod markers' ratio on the roll-corrected plane and the
//!    axle's calibration ([`SteeringPoly`]): valid only when all four of the axle's
//!    markers are found.
//! 5. **Wheel rotations θ** ([`WheelTracker`]) on tread cylinders placed by this frame's
//!    ψ, d and λ, or, for an axle whose markers were lost, by its last valid ones (the
//!    paper: "flow operations are performed using the prior state of the rover"). θ
//!    starts at 0 on the first frame; it is valid in a frame whose step was measured
//!    (never on the first frame, which has no predecessor).
//!
//! An invalid degree of freedom keeps its last valid value (or the starting state's), so
//! a consumer that ignores the flag reads a held value, never a guess.
//!
//! Deterministic: the same frames and the same generator behind `draw` give the same
//! estimates bit for bit. Every buffer is sized in [`KrawlerStateSchema::new`];
//! [`KrawlerStateSchema::estimate`] does not allocate.

use super::axle::AxleGeometry;
use super::markers::{ExpectedMarker, MarkerFinder, MarkerParams, Markers};
use super::mount::{MountOffset, MountParams, fit_mount};
use super::rotation::{AxleState, GearLayout, WheelParams, WheelStep, WheelTracker};
use super::steering::SteeringPoly;
use crate::perception::VisionError;
use crate::perception::image::RgbView;

/// One degree of freedom's estimate.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Dof {
    /// The value (rad or m); when not valid, the last valid value.
    pub value: f64,
    /// Whether this frame measured it.
    pub valid: bool,
}

/// The ten degrees of freedom of one frame, and what they were measured from.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct KrawlerEstimate {
    /// Axle roll ψ (front, rear), rad, positive lifting the left side.
    pub roll: [Dof; 2],
    /// Camera-to-axle vertical distance d (front, rear), m.
    pub drop: [Dof; 2],
    /// Steering λ (front, rear), rad, positive turning the fronts left.
    pub steer: [Dof; 2],
    /// Wheel rotations θ (FL, FR, RL, RR), rad from the first frame, positive rolling
    /// forward.
    pub wheel: [Dof; 4],
    /// The markers found this frame.
    pub markers: Markers,
    /// Each wheel's tracking figures this frame.
    pub wheels: [WheelStep; 4],
    /// The camera's offset from its nominal mount this frame (zero when the
    /// compensation is off or could not be fitted).
    pub mount: MountOffset,
}

/// The thresholds of every stage.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct KrawlerParams {
    /// The marker finder's.
    pub markers: MarkerParams,
    /// The wheel stage's.
    pub wheel: WheelParams,
    /// The mount-vibration compensation's.
    pub mount: MountParams,
}

/// The AutoKrawler's state estimator (seed 003); owns every buffer.
#[derive(Debug, Clone)]
pub struct KrawlerStateSchema {
    geometry: AxleGeometry,
    /// `geometry` with this frame's mount offset applied (a copy made once, its mount
    /// overwritten each frame).
    shaken: AxleGeometry,
    mount: MountParams,
    half_spacing: f64,
    polys: [SteeringPoly; 2],
    finder: MarkerFinder,
    wheels: WheelTracker,
    predicted: [ExpectedMarker; 8],
    axles: [AxleState; 2],
}

impl KrawlerStateSchema {
    /// An estimator for frames of `size` (width, height) from a camera with `geometry`,
    /// a gear laid out as `layout`, steering calibrations `polys` (front, rear), the
    /// markers first expected at `start` (for example the rest state's projections) and
    /// the axles first assumed in `axles` (used for the wheels until the markers are seen).
    pub fn new(
        size: (usize, usize),
        geometry: AxleGeometry,
        layout: GearLayout,
        polys: [SteeringPoly; 2],
        params: KrawlerParams,
        start: [ExpectedMarker; 8],
        axles: [AxleState; 2],
    ) -> Self {
        let (width, height) = size;
        Self {
            shaken: geometry.clone(),
            geometry,
            mount: params.mount,
            half_spacing: layout.marker_half_spacing,
            polys,
            finder: MarkerFinder::new(width, height, params.markers),
            wheels: WheelTracker::new(width, height, layout, params.wheel),
            predicted: start,
            axles,
        }
    }

    /// The back-projection geometry in use.
    pub fn geometry(&self) -> &AxleGeometry {
        &self.geometry
    }

    /// Where each marker is expected in the next frame.
    pub fn predicted(&self) -> &[ExpectedMarker; 8] {
        &self.predicted
    }

    /// Estimates the ten degrees of freedom from `frame`, the next frame of the
    /// sequence. `draw(n)` gives an index below n from the caller's random generator
    /// (the wheels' RANSAC).
    ///
    /// # Errors
    /// [`VisionError::SizeMismatch`] when `frame` is not the size given to
    /// [`KrawlerStateSchema::new`].
    pub fn estimate(
        &mut self,
        frame: &RgbView<'_>,
        draw: impl FnMut(usize) -> usize,
    ) -> Result<KrawlerEstimate, VisionError> {
        let markers = self.finder.find(frame, &self.predicted)?;
        for blob in self.finder.blobs().iter().filter(|b| !b.rejected) {
            if let Some(m) = blob.marker {
                self.predicted[m] = ExpectedMarker {
                    at: blob.centre,
                    area: blob.area as f64,
                };
            }
        }
        let mut est = KrawlerEstimate {
            markers,
            ..KrawlerEstimate::default()
        };
        let at = &markers.at;
        let start = self.axles.map(|a| (a.roll, a.drop));
        est.mount = fit_mount(
            &self.geometry,
            [at[0], at[1], at[4], at[5]],
            start,
            self.half_spacing,
            &self.mount,
        )
        .unwrap_or_default();
        est.mount.apply(&self.geometry, &mut self.shaken);
        for axle in 0..2 {
            let o = axle * 4;
            let pose = match (at[o], at[o + 1]) {
                (Some(a1), Some(a2)) => self.shaken.axle_pose(axle, a1, a2),
                _ => None,
            };
            let held = &mut self.axles[axle];
            if let Some(p) = pose {
                held.roll = p.roll;
                held.drop = p.drop;
                if let (Some(b1), Some(b2)) = (at[o + 2], at[o + 3])
                    && let Some(x) = self.shaken.steering_ratio(&p, [b1, b2])
                {
                    held.steer = self.polys[axle].steer(x);
                    est.steer[axle].valid = true;
                }
            }
            est.roll[axle] = Dof {
                value: held.roll,
                valid: pose.is_some(),
            };
            est.drop[axle] = Dof {
                value: held.drop,
                valid: pose.is_some(),
            };
            est.steer[axle].value = held.steer;
        }
        est.wheels = self.wheels.update(frame, &self.shaken, &self.axles, draw);
        let theta = self.wheels.theta();
        for ((dof, value), step) in est.wheel.iter_mut().zip(theta).zip(&est.wheels) {
            *dof = Dof {
                value,
                valid: step.step.is_some(),
            };
        }
        Ok(est)
    }
}
