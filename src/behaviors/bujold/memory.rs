//! What Bujold's phase schemas share: the two-block perceptual schema, this tick's
//! fiducial views, the robot's memory of the fiducial, and the plans one phase hands the
//! next.
//!
//! The perceptual schema runs once per tick for the whole tree ([`Memory::perceive`],
//! called by the robot's [`Composed`](crate::behaviors::composed::Composed) root before the
//! arbiters), so colour adaptation
//! follows the light whichever phase runs; the phase schemas then read the views.

pub use super::motor::{ApproachMotor, lowered, raised};
use super::tuning::{Approach, BujoldRobot, BujoldTuning};
use crate::behaviors::common::median::MedianWindow;
use crate::behaviors::common::retries::Retries;
use crate::behaviors::composed::SharedMemory;
use crate::geometry::Pose2;
use crate::perception::TwoBlockPercept;
use crate::perception::frame_change::FrameChange;
use crate::perception::two_block_pose::{FiducialView, RatioJumpGate, TwoBlockGeometry};
use crate::profile::{Profile, TwoBlockSpec};
use crate::schemas::TwoBlockSchema;
use crate::schemas::{
    ColourRanges, Feedback, Inputs, Mission, MissionError, Observation, ObservedPercept, Percept, PerceptualSchema,
    PotentialField, RatioSteering,
};

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
    /// This tick's view for planning: viewing angle low-passed, not scaled. `None` on a
    /// frame whose block ratio jumped ([`RatioJumpGate`]): no decision is made on it.
    pub planning: Option<FiducialView>,
    /// The fiducial was found this tick.
    pub found: bool,
    /// This tick's percept, as the schema reported it (for [`Agent::observe`]).
    ///
    /// [`Agent::observe`]: crate::schemas::Agent::observe
    pub percept: Option<TwoBlockPercept>,
    /// Low-passed viewing angle, rad: single-frame estimates are noisy at range.
    pub alpha_filtered: Option<f64>,
    /// The last raw viewing angles of reliable frames, for the repositioning decision.
    pub alpha_window: MedianWindow,
    /// Rejects frames whose block ratio jumped (a flash or a shadow on one block).
    pub ratio_gate: RatioJumpGate,
    /// How much the view changes from frame to frame (a turn that does not change it is
    /// jammed); observed by the phases that search or may fall back to search.
    pub frame_change: FrameChange,
    /// Seen at least once this docking.
    pub ever_seen: bool,
    /// When last seen, s.
    pub last_seen: Option<f64>,
    /// Where the dock was at the last sighting, in the odometry frame (from the planning
    /// view): the remembered dock direction while the fiducial is out of sight.
    pub dock_in_odometry: Option<Pose2>,
    /// Side it was last seen on (+1 left of the image centre line, −1 right): the search
    /// turns that way.
    pub last_side: f64,
    /// When this run began, s.
    pub run_start: Option<f64>,
    /// This docking's retries, of `behavior.max_retries`.
    pub retries: Retries,
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
    /// The staging pose the running repositioning drives to, odometry frame (set as it
    /// is entered, from the plan or the dock hint).
    pub staging: Option<Pose2>,
    /// Why the run is being abandoned (the give-up phase reports it; timeout when unset).
    pub failing: Option<crate::schemas::FailureReason>,
    /// Distance from the camera back to the robot's rear, m.
    pub rear_behind_camera: f64,
    /// The first docking tick is still to come (it notes the start heading).
    pub docking_first_tick: bool,
}

impl Memory {
    /// The memory of a robot just switched on, built from a profile with a two-block
    /// fiducial, a camera and a `[dock]`, with Bujold's `[robot]` tuning.
    ///
    /// # Errors
    /// A message naming what the profile lacks.
    pub fn new(profile: &Profile, robot: &BujoldRobot) -> Result<Self, String> {
        let missing = |what: &str| what.to_string();
        let fid = *profile.fiducial.require::<TwoBlockSpec>()?;
        let cam = profile.cameras.first().ok_or_else(|| missing("needs a camera"))?;
        profile.dock.ok_or_else(|| missing("needs [dock]"))?;
        let g = robot.ratio_steering;
        let schema = TwoBlockSchema::from_profile(profile, 0).map_err(|e| missing(&e.to_string()))?;
        let geometry = TwoBlockGeometry::new(cam, &fid);
        let field = match robot.approach {
            Approach::PotentialField => {
                let p = robot
                    .potential_field
                    .ok_or_else(|| missing("needs [robot.potential_field]"))?;
                Some(PotentialField {
                    sector: p.approach_sector_deg.to_radians(),
                    coercive_attraction: p.coercive_attraction,
                    gain: p.gain,
                    k_theta: p.k_theta,
                    max_off_sight: p.max_off_sight_deg.to_radians(),
                    final_radius: p.final_radius_m,
                })
            }
            Approach::RatioSteering => None,
        };
        let steering = RatioSteering {
            geometry,
            image_width: cam.width_px as f64,
            dead_band: g.dead_band,
            understeer: g.understeer,
            turn_rate: g.turn_rate_dps.to_radians(),
            speed: g.drive_speed_mps,
            dock_total_px: g.dock_total_px as f64,
            aim_fraction: g.aim_fraction,
            tick_s: 1.0 / profile.loop_.rate_hz,
            restricted: profile.drive.kind == crate::profile::DriveKind::TurnOrDrive,
        };
        let tuning = robot.shared;
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
            percept: None,
            alpha_filtered: None,
            alpha_window: MedianWindow::new(tuning.alpha_window_frames),
            ratio_gate: RatioJumpGate::new(tuning.ratio_jump, tuning.ratio_jump_reset_frames),
            frame_change: FrameChange::new(),
            ever_seen: false,
            last_seen: None,
            dock_in_odometry: None,
            last_side: 1.0,
            run_start: None,
            retries: Retries::new(profile.behavior.max_retries),
            unjams: 0,
            start_heading: None,
            dock_hint: None,
            departure_mark: Pose2::default(),
            imprinted: false,
            samples_distance: 0.0,
            plan: None,
            staging: None,
            failing: None,
            rear_behind_camera: super::rear_behind_camera(profile, &geometry).unwrap_or(0.0),
            docking_first_tick: false,
        })
    }

    /// Runs the perceptual schema on this tick's inputs and updates the views and the
    /// memory of the fiducial.
    pub fn perceive(&mut self, inputs: &Inputs<'_>) {
        let percept = self.schema.perceive(inputs);
        self.digest(inputs, &percept);
    }

    /// What [`Memory::perceive`] does with the two-block schema's percept: the viewing
    /// angle's trust, low-pass and median window, the dock's pose in odometry, the last
    /// sighting. Public so that a percept computed elsewhere (replayed from a log, or on
    /// another core) can drive the same memory, and so that the decision's cost can be
    /// measured without perception (`benches/tick.rs`).
    pub fn digest(&mut self, inputs: &Inputs<'_>, percept: &TwoBlockPercept) {
        let now = inputs.now;
        self.now = now;
        self.percept = Some(*percept);
        self.run_start.get_or_insert(now);
        self.odo = inputs.odometry.map(|o| o.value.pose).unwrap_or_default();
        let p = self.tuning;
        let mut view = FiducialView::from_percept(percept, &self.geometry);
        self.planning = None;
        if let Some(v) = view.as_mut() {
            // The ratio cue is only as good as the blocks are big: at 1.3 m two-pixel noise
            // is ±35° of viewing angle. Weight it by reliability (zero for blocks under
            // `trust_from_px` tall, full `trust_ramp_px` above), then low-pass. Far away the
            // robot therefore pursues the fiducial along the line of sight; the aim point
            // fades in close.
            let trust = ((v.height_px - p.trust_from_px) / p.trust_ramp_px).clamp(0.0, 1.0);
            // A frame whose ratio jumped (one block flashed or shadowed) keeps the last
            // viewing angle and gives no planning view; the bearing still steers.
            let consistent = self.ratio_gate.check(v.asym);
            let a = match self.alpha_filtered {
                None => v.alpha,
                Some(prev) if !consistent => prev,
                Some(prev) => prev + p.alpha_low_pass * (v.alpha - prev),
            };
            self.alpha_filtered = Some(a);
            if consistent && v.height_px >= p.reliable_height_px {
                self.alpha_window.push(v.alpha);
            }
            // The final decision uses the filtered estimate (repositioning the median of
            // `alpha_window`); steering uses it scaled by its trust.
            let planning = v.with_alpha(a);
            if consistent {
                self.planning = Some(planning);
                // dock → odometry: odo = T ⊕ here, so T = odo ⊕ here⁻¹.
                let here = planning.dock_pose();
                self.dock_in_odometry = Some(self.odo.compose(&here.relative(&Pose2::default())));
            }
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

    /// The robot's pose in the dock frame as odometry carries it on from the last
    /// sighting (`None` before any).
    pub fn remembered_pose(&self) -> Option<Pose2> {
        self.dock_in_odometry.map(|dock| dock.relative(&self.odo))
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
            retries: self.retries.used(),
        }
    }

    /// Distance travelled from `mark` to this tick's odometry pose, m.
    pub fn travelled(&self, mark: &Pose2) -> f64 {
        self.odo.distance(mark)
    }
}

impl SharedMemory for Memory {
    fn perceive(&mut self, inputs: &Inputs<'_>) {
        Memory::perceive(self, inputs);
    }

    fn observe(&self) -> Option<Observation> {
        Some(Observation {
            camera: self.schema.camera(),
            percept: ObservedPercept::TwoBlock(self.percept?),
            ranges: Some(ColourRanges::Sct(self.schema.model().ranges())),
        })
    }

    fn begin(&mut self, mission: &Mission) -> Result<(), MissionError> {
        self.run_start = None;
        match mission {
            Mission::Departure => self.imprinted = false,
            Mission::Docking { dock_hint, .. } => {
                self.alpha_filtered = None;
                self.alpha_window.clear();
                self.ratio_gate.reset();
                self.retries.reset();
                self.unjams = 0;
                self.ever_seen = false;
                self.last_seen = None;
                self.dock_in_odometry = None;
                self.failing = None;
                self.plan = None;
                self.staging = None;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::perception::ColorMode;

    /// A found pair 60 px tall at the image centre with `left` and `right` pixels.
    fn pair(now: f64, left: u64, right: u64) -> TwoBlockPercept {
        TwoBlockPercept {
            found: true,
            left_px: left,
            right_px: right,
            total_px: left + right,
            left_centroid: [113.0, 96.0],
            right_centroid: [143.0, 96.0],
            left_bbox: [98, 66, 127, 125],
            right_bbox: [128, 66, 157, 125],
            ..TwoBlockPercept::not_found(now, ColorMode::Table, (256, 192))
        }
    }

    /// A frame whose block ratio jumps (one block flashed) keeps the filtered viewing
    /// angle and gives no planning view; the consistent frames around it do.
    #[test]
    fn a_flashed_block_moves_neither_the_angle_nor_the_plan() {
        let profile = Profile::load("profiles/bujold.toml".as_ref()).unwrap();
        let mut m = crate::behaviors::catalog::memory(&crate::behaviors::bujold::Bujold, &profile).unwrap();
        m.digest(&Inputs::empty(0.0), &pair(0.0, 2250, 2250));
        assert!(m.planning.is_some());
        let alpha = m.alpha_filtered.unwrap();
        m.digest(&Inputs::empty(0.1), &pair(0.1, 1000, 2250));
        assert!(m.planning.is_none(), "the flashed frame is not planned on");
        assert!(m.view.is_some(), "its bearing still steers");
        assert_eq!(m.alpha_filtered, Some(alpha));
        m.digest(&Inputs::empty(0.2), &pair(0.2, 2260, 2240));
        assert!(m.planning.is_some());
    }
}
