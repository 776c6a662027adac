//! What Bujold's phase schemas share: the two-block perceptual schema, this tick's
//! fiducial views, the robot's memory of the fiducial, and the plans one phase hands the
//! next.
//!
//! The perceptual schema runs once per tick for the whole tree ([`Memory::perceive`],
//! called by the robot's [`Composed`](crate::behaviors::composed::Composed) root before the
//! arbiters), so colour adaptation
//! follows the light whichever phase runs; the phase schemas then read the views.

use super::params::BujoldTuning;
use crate::behaviors::BuildError;
use crate::behaviors::composed::SharedMemory;
use crate::geometry::Pose2;
use crate::perception::frame_change::FrameChange;
use crate::perception::two_block_pose::{FiducialView, TwoBlockGeometry};
use crate::profile::{ApproachKind, Profile};
use crate::schemas::TwoBlockSchema;
use crate::schemas::{
    Auxiliary, DriveCommand, Feedback, Inputs, Mission, MissionError, MotorOutput, Percept, PerceptualSchema, Posture,
    PotentialField, RatioSteering, Step,
};

/// Largest median window the repositioning decision may look back over, frames.
pub const MAX_ALPHA_WINDOW: usize = 64;

/// The last `capacity` samples in a fixed ring, with their median: a robust summary that
/// ignores the minority of frames a flash, a shadow edge or a glare notch biases, where a
/// low-pass filter would follow them part of the way.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MedianWindow {
    values: [f64; MAX_ALPHA_WINDOW],
    capacity: usize,
    len: usize,
    next: usize,
}

impl MedianWindow {
    /// An empty window of `capacity` samples (clamped to 1..=[`MAX_ALPHA_WINDOW`]).
    pub fn new(capacity: usize) -> Self {
        Self {
            values: [0.0; MAX_ALPHA_WINDOW],
            capacity: capacity.clamp(1, MAX_ALPHA_WINDOW),
            len: 0,
            next: 0,
        }
    }

    /// Forgets every sample.
    pub fn clear(&mut self) {
        self.len = 0;
        self.next = 0;
    }

    /// Adds a sample, dropping the oldest when full.
    pub fn push(&mut self, v: f64) {
        self.values[self.next] = v;
        self.next = (self.next + 1) % self.capacity;
        self.len = (self.len + 1).min(self.capacity);
    }

    /// True when the window holds `capacity` samples.
    pub fn is_full(&self) -> bool {
        self.len == self.capacity
    }

    /// Median of the samples held (`None` when empty); an even count averages the middle two.
    pub fn median(&self) -> Option<f64> {
        if self.len == 0 {
            return None;
        }
        let mut v = self.values;
        let v = &mut v[..self.len];
        v.sort_by(f64::total_cmp);
        let m = self.len / 2;
        Some(if self.len % 2 == 1 {
            v[m]
        } else {
            0.5 * (v[m - 1] + v[m])
        })
    }
}

/// The approach motor schema the profile selects (`behavior.approach`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ApproachMotor {
    /// Ratio steering: also realises the field's heading error on a turn-or-drive base.
    pub steering: RatioSteering,
    /// The potential field, when selected.
    pub field: Option<PotentialField>,
}

impl ApproachMotor {
    /// The approach command for a view (raised).
    pub fn act(&self, view: &FiducialView) -> MotorOutput {
        let out = match &self.field {
            None => self.steering.act(view),
            // The field gives a heading error; the ratio-steering schema realises it with
            // the same dead band, understeer and turn-or-drive alternation.
            Some(pf) if self.steering.restricted => {
                let error = pf
                    .body_vector(&view.dock_pose(), self.steering.geometry.drive_dir)
                    .angle();
                self.steering
                    .steer(error, self.steering.speed_for(view.total_px as f64))
            }
            Some(pf) => MotorOutput::drive(DriveCommand::Twist(
                pf.twist(&view.dock_pose(), self.steering.geometry.drive_dir),
            )),
        };
        out.with_aux(raised())
    }
}

/// A repositioning plan one phase hands the reposition phase: the staging pose in the
/// odometry frame, and whether to drive straight out first (no room to turn by the gate).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RepositionPlan {
    /// Staging pose, odometry frame.
    pub target: Pose2,
    /// Drive straight out, front first, before turning.
    pub clear_first: bool,
}

/// Bujold's shared memory (see the module docs).
pub struct Memory {
    /// The two-block perceptual schema (colour model, imprint, adaptation).
    pub schema: TwoBlockSchema,
    /// Camera and fiducial geometry.
    pub geometry: TwoBlockGeometry,
    /// The approach motor schema.
    pub approach: ApproachMotor,
    /// How views are filtered.
    pub tuning: BujoldTuning,
    /// Loop time of this tick, s.
    pub now: f64,
    /// Odometry pose of this tick.
    pub odo: Pose2,
    /// This tick's view for steering: viewing angle low-passed and scaled by its trust.
    pub view: Option<FiducialView>,
    /// This tick's view for planning: viewing angle low-passed, not scaled.
    pub planning: Option<FiducialView>,
    /// The fiducial was found this tick.
    pub found: bool,
    /// Low-passed viewing angle, rad: single-frame estimates are noisy at range.
    pub alpha_filtered: Option<f64>,
    /// The last raw viewing angles of reliable frames, for the repositioning decision.
    pub alpha_window: MedianWindow,
    /// How much the view changes from frame to frame (a turn that does not change it is
    /// jammed); observed by the phases that search or may fall back to search.
    pub frame_change: FrameChange,
    /// Seen at least once this docking.
    pub ever_seen: bool,
    /// When last seen, s.
    pub last_seen: Option<f64>,
    /// Side it was last seen on (+1 left of the image centre line, −1 right): the search
    /// turns that way.
    pub last_side: f64,
    /// When this run began, s.
    pub run_start: Option<f64>,
    /// Retries used this docking.
    pub retries: u32,
    /// Unjamming manoeuvres this docking.
    pub unjams: u32,
    /// Odometry heading the close dock began facing along (front away from the dock), rad:
    /// unjamming turns back to it.
    pub start_heading: Option<f64>,
    /// The a-priori dock pose in the odometry frame of the next docking.
    pub dock_hint: Option<Pose2>,
    /// Odometry where the departure began (its distances are measured from there).
    pub departure_mark: Pose2,
    /// A departure imprinted successfully.
    pub imprinted: bool,
    /// Camera distance the at-dock decision measured, for backing in, m.
    pub samples_distance: f64,
    /// The plan for the next repositioning.
    pub plan: Option<RepositionPlan>,
    /// Why the run is being abandoned (the give-up phase reports it; timeout when unset).
    pub failing: Option<crate::schemas::FailureReason>,
    /// Distance from the camera back to the robot's rear, m.
    pub rear_behind_camera: f64,
    /// The first docking tick is still to come (it notes the start heading).
    pub docking_first_tick: bool,
}

impl Memory {
    /// The memory of a robot just switched on, built from a profile with a
    /// `[fiducial.two_block]`, a camera, a `[dock]` and `[behavior.ratio_steering]` (and
    /// `[behavior.potential_field]` when `behavior.approach` selects it).
    ///
    /// # Errors
    /// [`BuildError::Profile`] naming what is missing.
    pub fn from_profile(profile: &Profile) -> Result<Self, BuildError> {
        let missing = |what: &str| BuildError::Profile {
            profile: profile.name.clone(),
            what: what.into(),
        };
        let fid = profile
            .fiducial
            .two_block
            .ok_or_else(|| missing("needs [fiducial.two_block]"))?;
        let cam = profile.cameras.first().ok_or_else(|| missing("needs a camera"))?;
        profile.dock.ok_or_else(|| missing("needs [dock]"))?;
        let g = profile
            .behavior
            .ratio_steering
            .ok_or_else(|| missing("needs [behavior.ratio_steering]"))?;
        let schema = TwoBlockSchema::from_profile(profile, 0).map_err(|e| missing(&e.to_string()))?;
        let geometry = TwoBlockGeometry::new(cam, &fid);
        let field = match profile.behavior.approach {
            ApproachKind::PotentialField => {
                let p = profile
                    .behavior
                    .potential_field
                    .ok_or_else(|| missing("needs [behavior.potential_field]"))?;
                Some(PotentialField {
                    sector: p.approach_sector_deg.to_radians(),
                    coercive_attraction: p.coercive_attraction,
                    gain: p.gain,
                    k_theta: p.k_theta,
                    max_off_sight: p.max_off_sight_deg.to_radians(),
                    final_radius: p.final_radius_m,
                })
            }
            _ => None,
        };
        let steering = RatioSteering {
            geometry,
            image_width: cam.width_px as f64,
            dead_band: g.dead_band,
            understeer: g.understeer,
            turn_rate: g.turn_rate_dps.to_radians(),
            speed: g.drive_speed_mps,
            dock_total_px: g.dock_total_px as f64,
            tick_s: 1.0 / profile.loop_.rate_hz,
            restricted: profile.drive.kind == crate::profile::DriveKind::TurnOrDrive,
        };
        let tuning = profile.behavior.bujold.unwrap_or_default();
        Ok(Memory {
            schema,
            geometry,
            approach: ApproachMotor { steering, field },
            tuning,
            now: 0.0,
            odo: Pose2::default(),
            view: None,
            planning: None,
            found: false,
            alpha_filtered: None,
            alpha_window: MedianWindow::new(tuning.alpha_window_frames),
            frame_change: FrameChange::new(),
            ever_seen: false,
            last_seen: None,
            last_side: 1.0,
            run_start: None,
            retries: 0,
            unjams: 0,
            start_heading: None,
            dock_hint: None,
            departure_mark: Pose2::default(),
            imprinted: false,
            samples_distance: 0.0,
            plan: None,
            failing: None,
            rear_behind_camera: super::rear_behind_camera(profile, &geometry).unwrap_or(0.0),
            docking_first_tick: false,
        })
    }

    /// Runs the perceptual schema on this tick's inputs and updates the views and the
    /// memory of the fiducial.
    pub fn perceive(&mut self, inputs: &Inputs<'_>) {
        let now = inputs.now;
        self.now = now;
        self.run_start.get_or_insert(now);
        self.odo = inputs.odometry.map(|o| o.value.pose).unwrap_or_default();
        let percept = self.schema.perceive(inputs);
        let p = self.tuning;
        let mut view = FiducialView::from_percept(&percept, &self.geometry);
        self.planning = None;
        if let Some(v) = view.as_mut() {
            // The ratio cue is only as good as the blocks are big: at 1.3 m two-pixel noise
            // is ±35° of viewing angle. Weight it by reliability (zero for blocks under
            // `trust_from_px` tall, full `trust_ramp_px` above), then low-pass. Far away the
            // robot therefore pursues the fiducial along the line of sight; the aim point
            // fades in close.
            let trust = ((v.height_px - p.trust_from_px) / p.trust_ramp_px).clamp(0.0, 1.0);
            let a = match self.alpha_filtered {
                None => v.alpha,
                Some(prev) => prev + p.alpha_low_pass * (v.alpha - prev),
            };
            self.alpha_filtered = Some(a);
            if v.height_px >= p.reliable_height_px {
                self.alpha_window.push(v.alpha);
            }
            // The final decision uses the filtered estimate (repositioning the median of
            // `alpha_window`); steering uses it scaled by its trust.
            self.planning = Some(v.with_alpha(a));
            *v = v.with_alpha(a * trust);
        }
        self.view = view;
        self.found = percept.found();
        if self.found {
            self.ever_seen = true;
            self.last_seen = Some(now);
            if let Some(v) = &view {
                self.last_side = if v.bearing >= 0.0 { 1.0 } else { -1.0 };
            }
        }
        if self.docking_first_tick {
            self.docking_first_tick = false;
            self.start_heading.get_or_insert(self.odo.theta);
        }
        if let Some(v) = &view {
            tracing::trace!(target: "marsupial::behavior", now, d = v.distance, alpha_deg = v.alpha.to_degrees(), heading_deg = v.heading.to_degrees(), offset = v.offset_px, total = v.total_px, mode = %percept.mode, "view");
        } else {
            tracing::trace!(target: "marsupial::behavior", now, mode = %percept.mode, "no fiducial");
        }
    }

    /// A repositioning plan from an estimated pose in the dock frame (`view`) and this
    /// tick's odometry pose: stage on the axis `staging_margin_m` farther out than the
    /// robot is (at least `staging_x_m`), and drive straight out first when closer to the
    /// body than `clearance_x_m`.
    pub fn plan_reposition(&self, view: &FiducialView) -> RepositionPlan {
        let t = &self.tuning;
        // Robot centre in the dock frame: the camera sits `rear_behind_camera − L/2` ahead
        // of the rear; near enough to treat the camera as the centre here.
        let here = view.dock_pose();
        let stage = Pose2::new((here.x + t.staging_margin_m).max(t.staging_x_m), 0.0, 0.0);
        // dock → odometry: odo = T ⊕ dock, T = odo ⊕ here⁻¹.
        let to_odo = self.odo.compose(&here.relative(&Pose2::default()));
        tracing::debug!(target: "marsupial::behavior", now = self.now, x = here.x, y = here.y, heading_deg = here.theta.to_degrees(), "reposition to the axis");
        RepositionPlan {
            target: to_odo.compose(&stage),
            clear_first: here.x < t.clearance_x_m,
        }
    }

    /// Feeds this tick's first camera frame to the frame-change cue.
    pub fn observe_change(&mut self, inputs: &Inputs<'_>) -> Option<f32> {
        inputs.camera(0).and_then(|c| self.frame_change.observe(&c.image))
    }

    /// Feedback for a phase.
    pub fn feedback(&self, phase: &'static str) -> Feedback {
        Feedback {
            phase,
            elapsed: self.now - self.run_start.unwrap_or(self.now),
            retries: self.retries,
        }
    }

    /// Stand still, raised.
    pub fn hold(&self, phase: &'static str) -> Step {
        Step::running(MotorOutput::stop().with_aux(raised()), self.feedback(phase))
    }

    /// Turn in place toward a heading error `err` (rad), raised: twice the error per
    /// second, capped at the turn rate (the odometry manoeuvres' turns).
    pub fn turn_by(&self, err: f64, phase: &'static str) -> Step {
        let rate = self.approach.steering.turn_rate;
        let omega = (2.0 * err).clamp(-rate, rate);
        Step::running(
            MotorOutput::drive(DriveCommand::Turn { omega }).with_aux(raised()),
            self.feedback(phase),
        )
    }

    /// Drive straight away from the dock (front first), raised, at `speed`.
    pub fn drive_away(&self, speed: f64, phase: &'static str) -> Step {
        let v = -self.geometry.drive_dir * speed;
        Step::running(
            MotorOutput::drive(DriveCommand::Straight { v }).with_aux(raised()),
            self.feedback(phase),
        )
    }

    /// Distance travelled from `mark` to this tick's odometry pose, m.
    pub fn travelled(&self, mark: &Pose2) -> f64 {
        (self.odo.x - mark.x).hypot(self.odo.y - mark.y)
    }
}

impl SharedMemory for Memory {
    fn perceive(&mut self, inputs: &Inputs<'_>) {
        Memory::perceive(self, inputs);
    }

    fn begin(&mut self, mission: &Mission) -> Result<(), MissionError> {
        self.run_start = None;
        match mission {
            Mission::Departure => self.imprinted = false,
            Mission::Docking { dock_hint } => {
                self.alpha_filtered = None;
                self.alpha_window.clear();
                self.retries = 0;
                self.unjams = 0;
                self.ever_seen = false;
                self.last_seen = None;
                self.failing = None;
                self.plan = None;
                self.dock_hint = *dock_hint;
                // Ballistic region: the drive by odometry ends facing along the axis at the
                // staging point; unjamming turns back to that heading.
                self.start_heading = dock_hint.map(|dock| {
                    dock.compose(&Pose2::new(self.tuning.ballistic_staging_m, 0.0, 0.0))
                        .theta
                });
                self.docking_first_tick = true;
            }
        }
        Ok(())
    }
}

/// Lowered posture (backing in, leaving the pouch).
pub fn lowered() -> Auxiliary {
    Auxiliary {
        posture: Some(Posture::Lowered),
        ..Auxiliary::default()
    }
}

/// Raised posture (everywhere else).
pub fn raised() -> Auxiliary {
    Auxiliary {
        posture: Some(Posture::Raised),
        ..Auxiliary::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_window_ignores_a_minority_of_outliers_and_forgets_the_oldest() {
        let mut w = MedianWindow::new(16);
        assert_eq!(w.median(), None);
        w.push(3.0);
        w.push(1.0);
        assert_eq!(w.median(), Some(2.0));
        // A steady 0.1 rad with a third of the frames pushed to 0.5 by a flash.
        w.clear();
        for k in 0..16 {
            w.push(if k % 3 == 0 { 0.5 } else { 0.1 });
        }
        assert!(w.is_full());
        assert_eq!(w.median(), Some(0.1));
        // A full window of new values replaces the old ones entirely.
        for _ in 0..16 {
            w.push(-0.2);
        }
        assert_eq!(w.median(), Some(-0.2));
        assert_eq!(w.len, 16);
    }
}
