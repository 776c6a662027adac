//! Bujold's docking (seed 004): undock and imprint on departure, then close-dock.
//!
//! Departure: back out of the pouch lowered (the camera watching the flap), raise, and at
//! the profile's imprint distance stop for `imprint.frames` frames to imprint the blocks'
//! colours; keep adapting while driving on out (seed 004 §IV.C).
//!
//! Docking (the paper's "close dock" within the whole docking behavior):
//!
//! 0. **ballistic** (only when given the dock's location a priori, [`Agent::set_dock_hint`]):
//!    turn, drive and turn by odometry to [`BALLISTIC_STAGING_M`] out on the dock axis,
//!    facing along it (the repositioning manoeuvre), then look;
//! 1. **search**: rotate in place until the fiducial is acquired (toward the side it was
//!    last seen), bounded by `search_timeout_s`. A turn that does not change the view for
//!    1.5 s is jammed against the body (the tracks spin, the camera sees it): **unjam**
//!    by turning back to the heading the close dock began with, driving out 20 cm front
//!    first, and searching the other way, at most three times;
//! 2. **approach**: ratio steering ([`RatioSteering`]) or potential fields
//!    ([`PotentialField`], realised through the ratio-steering schema's dead band,
//!    understeer and turn-or-drive alternation) on the fiducial's relative pose, speed
//!    falling with the summed pixel count; the fiducial lost for 1.5 s sends the robot back
//!    to search;
//! 3. **decide** at `dock_total_px`: stop, average five frames; balanced and centred
//!    (estimated lateral and heading errors within the profile's tolerances) → back in;
//!    otherwise **move away** 35 cm and retry, up to `max_retries`;
//! 4. **back in**: lower and drive blind by odometry until the dock switch closes.
//!
//! Every phase has a timeout (`phase_timeout_s`). Every exit commands zero velocity; a
//! failure close to the dock first moves away from the entrance, then stops.

use super::agent::{Agent, BuildError};
use crate::geometry::Pose2;
use crate::perception::TwoBlockSchema;
use crate::perception::frame_change::FrameChange;
use crate::perception::two_block_pose::{FiducialView, TwoBlockGeometry};
use crate::profile::{ApproachKind, Profile};
use crate::schemas::{
    Auxiliary, Behavior, DeadReckoning, DriveCommand, FailureReason, Feedback, Inputs, MotorOutput, Outcome, Percept,
    PerceptualSchema, Posture, PotentialField, RatioSteering, SearchRotation, Step,
};

#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    Idle,
    Undock,
    Imprint {
        frames: u32,
    },
    DriveOut,
    Search,
    /// The search rotation is jammed against the body: turn back to the heading docking
    /// began with (stage 0), drive out front first (stage 1), search the other way.
    Unjam {
        stage: u8,
    },
    Approach,
    Decide,
    BackIn,
    MoveAway {
        failing: Option<FailureReason>,
    },
    /// Turn, drive and turn by odometry to a staging pose on the dock axis.
    Reposition {
        stage: u8,
        target: Pose2,
    },
    Done,
}

impl Phase {
    fn name(&self) -> &'static str {
        match self {
            Phase::Idle => "idle",
            Phase::Undock => "undock",
            Phase::Imprint { .. } => "imprint",
            Phase::DriveOut => "drive_out",
            Phase::Search => "search",
            Phase::Unjam { .. } => "unjam",
            Phase::Approach => "approach",
            Phase::Decide => "decide",
            Phase::BackIn => "back_in",
            Phase::MoveAway { .. } => "move_away",
            Phase::Reposition { .. } => "reposition",
            Phase::Done => "done",
        }
    }
}

/// Bujold's agent.
pub struct BujoldAgent {
    schema: TwoBlockSchema,
    geometry: TwoBlockGeometry,
    steering: RatioSteering,
    field: Option<PotentialField>,
    search: SearchRotation,
    phase: Phase,
    phase_start: f64,
    run_start: Option<f64>,
    odo_mark: Pose2,
    retries: u32,
    max_retries: u32,
    phase_timeout: f64,
    search_timeout: f64,
    ever_seen: bool,
    last_seen: Option<f64>,
    last_side: f64,
    samples: Vec<FiducialView>,
    tol_lateral: f64,
    tol_heading: f64,
    depth: f64,
    /// Distance from the camera back to the robot's rear, m.
    rear_behind_camera: f64,
    /// Odometry travel from the start of departure at which to imprint, m.
    imprint_at: f64,
    drive_out: f64,
    imprint_frames: u32,
    imprinted: bool,
    samples_distance: f64,
    /// Low-passed viewing angle (rad): single-frame estimates are noisy at range.
    alpha_filtered: Option<f64>,
    /// The last raw viewing angles of reliable frames, for the repositioning decision.
    alpha_window: MedianWindow,
    /// How much the view changes from frame to frame: a turn that does not change it is
    /// jammed.
    frame_change: FrameChange,
    /// Since when the view has been still while the search turns.
    still_since: Option<f64>,
    /// Unjamming manoeuvres this docking attempt.
    unjams: u32,
    /// Odometry heading the close dock began facing along, front away from the dock
    /// (where the robot was placed, or where the ballistic drive left it), rad: unjamming
    /// turns back to it.
    start_heading: Option<f64>,
    /// The a-priori dock pose in the odometry frame of the next docking (see
    /// [`Agent::set_dock_hint`]).
    dock_hint: Option<Pose2>,
}

/// Reliable frames the repositioning decision looks back over (1.6 s at 10 Hz: longer
/// than a rotating beacon's period, so a flash that brightens one block for part of a turn
/// cannot fake an off-axis view).
const ALPHA_WINDOW: usize = 16;

/// The last [`ALPHA_WINDOW`] samples in a fixed ring, with their median: a robust
/// summary that ignores the minority of frames a flash, a shadow edge or a glare notch
/// biases, where a low-pass filter would follow them part of the way.
#[derive(Debug, Clone, Copy, PartialEq)]
struct MedianWindow {
    values: [f64; ALPHA_WINDOW],
    len: usize,
    next: usize,
}

impl MedianWindow {
    const fn new() -> Self {
        Self {
            values: [0.0; ALPHA_WINDOW],
            len: 0,
            next: 0,
        }
    }

    fn clear(&mut self) {
        self.len = 0;
        self.next = 0;
    }

    fn push(&mut self, v: f64) {
        self.values[self.next] = v;
        self.next = (self.next + 1) % ALPHA_WINDOW;
        self.len = (self.len + 1).min(ALPHA_WINDOW);
    }

    fn is_full(&self) -> bool {
        self.len == ALPHA_WINDOW
    }

    /// Median of the samples held (`None` when empty); an even count averages the middle two.
    fn median(&self) -> Option<f64> {
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

/// Distance from the dock the robot drives to on departure, m.
pub const DEPARTURE_DISTANCE_M: f64 = 1.2;
/// Speed driving away from the dock (departure, backing off), m/s.
pub const DEPARTURE_SPEED_MPS: f64 = 0.06;
/// How far a retry backs off, m.
pub const MOVE_AWAY_M: f64 = 0.35;
/// Staging distance on the dock axis for repositioning, m.
pub const STAGING_X_M: f64 = 0.75;
/// Where on the dock axis the ballistic drive to an a-priori dock location ends, m: far
/// enough that an a-priori error of a few decimetres still leaves the flap in view.
pub const BALLISTIC_STAGING_M: f64 = 1.2;
/// Lateral error (m) above which a reliable view triggers repositioning.
pub const REPOSITION_LATERAL_M: f64 = 0.08;
/// Closer to the body than this (m along the axis) the robot drives out before turning.
pub const CLEARANCE_X_M: f64 = 0.45;
/// Blocks at least this tall (px) give a viewing angle good enough to plan on.
pub const RELIABLE_HEIGHT_PX: f64 = 40.0;
/// A view changing less than this (mean 8-bit levels per frame, see [`FrameChange`]) is
/// still: pixel noise of ±6 levels reads under 0.5 (`frame_change`'s tests), one tick of
/// the search turn 3.6–8.2 on rendered scenes (`tests/sim_render.rs`).
pub const STILL_LEVELS: f32 = 1.0;
/// The search turn jammed: the view still for this long while turning, s.
pub const JAMMED_AFTER_S: f64 = 1.5;
/// How far an unjamming manoeuvre drives out, front first, m.
pub const UNJAM_M: f64 = 0.2;
/// Unjamming manoeuvres allowed per docking attempt (the search stays bounded).
pub const MAX_UNJAMS: u32 = 3;

impl BujoldAgent {
    /// Builds the agent from a profile with a `[fiducial.two_block]` and
    /// `[behavior.ratio_steering]` (and `[behavior.potential_field]` when selected).
    ///
    /// # Errors
    /// [`BuildError::Profile`] when something it needs is missing.
    pub fn new(profile: &Profile) -> Result<Self, BuildError> {
        let missing = |what: &str| BuildError::Profile {
            profile: profile.name.clone(),
            what: what.into(),
        };
        let fid = profile
            .fiducial
            .two_block
            .ok_or_else(|| missing("needs [fiducial.two_block]"))?;
        let cam = profile.cameras.first().ok_or_else(|| missing("needs a camera"))?;
        let dock = profile.dock.ok_or_else(|| missing("needs [dock]"))?;
        let g = profile
            .behavior
            .ratio_steering
            .ok_or_else(|| missing("needs [behavior.ratio_steering]"))?;
        let schema = TwoBlockSchema::from_profile(profile, 0).map_err(|e| missing(&e.to_string()))?;
        let geometry = TwoBlockGeometry::new(cam, &fid);
        let tick_s = 1.0 / profile.loop_.rate_hz;
        let restricted = profile.drive.kind == crate::profile::DriveKind::TurnOrDrive;
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
        Ok(Self {
            schema,
            geometry,
            steering: RatioSteering {
                geometry,
                image_width: cam.width_px as f64,
                dead_band: g.dead_band,
                understeer: g.understeer,
                turn_rate: g.turn_rate_dps.to_radians(),
                speed: g.drive_speed_mps,
                dock_total_px: g.dock_total_px as f64,
                tick_s,
                restricted,
            },
            field,
            search: SearchRotation {
                rate: g.turn_rate_dps.to_radians(),
                first_sweep: 0.0,
                doubling: false,
            },
            phase: Phase::Idle,
            phase_start: 0.0,
            run_start: None,
            odo_mark: Pose2::default(),
            retries: 0,
            max_retries: profile.behavior.max_retries,
            phase_timeout: profile.behavior.phase_timeout_s,
            search_timeout: profile.behavior.search_timeout_s,
            ever_seen: false,
            last_seen: None,
            last_side: 1.0,
            samples: Vec::with_capacity(8),
            tol_lateral: profile.success.lateral_tolerance_m,
            tol_heading: profile.success.heading_tolerance_deg.to_radians(),
            depth: dock.depth_m,
            rear_behind_camera: profile.body.length_m / 2.0 + cam.mount.x_m * geometry.drive_dir,
            // Departure starts with the rear at the plates: the camera is then
            // depth − rear_behind_camera inside the entrance.
            imprint_at: profile.perception.imprint.at_distance_m + dock.depth_m
                - (profile.body.length_m / 2.0 + cam.mount.x_m * geometry.drive_dir),
            drive_out: DEPARTURE_DISTANCE_M,
            imprint_frames: profile.perception.imprint.frames,
            imprinted: false,
            samples_distance: 0.0,
            alpha_filtered: None,
            alpha_window: MedianWindow::new(),
            frame_change: FrameChange::new(),
            still_since: None,
            unjams: 0,
            start_heading: None,
            dock_hint: None,
        })
    }

    /// The perceptual schema (colour model state, last detection).
    pub fn schema(&self) -> &TwoBlockSchema {
        &self.schema
    }

    /// True once a departure imprinted successfully.
    pub fn imprinted(&self) -> bool {
        self.imprinted
    }

    fn enter(&mut self, phase: Phase, now: f64, odo: Pose2) {
        tracing::debug!(target: "marsupial::behavior", from = self.phase.name(), to = phase.name(), now, "bujold phase");
        self.phase = phase;
        self.phase_start = now;
        self.odo_mark = odo;
        self.samples.clear();
        self.still_since = None;
    }

    fn travelled(&self, odo: &Pose2) -> f64 {
        (odo.x - self.odo_mark.x).hypot(odo.y - self.odo_mark.y)
    }

    /// Stand still, raised.
    fn hold(&self, now: f64) -> Step {
        Step::running(MotorOutput::stop().with_aux(raised()), self.feedback(now))
    }

    /// Turn in place toward a heading error `err` (rad), raised: twice the error per
    /// second, capped at the turn rate (the odometry manoeuvres' turns).
    fn turn_by(&self, err: f64, now: f64) -> Step {
        let omega = (2.0 * err).clamp(-self.steering.turn_rate, self.steering.turn_rate);
        Step::running(
            MotorOutput::drive(DriveCommand::Turn { omega }).with_aux(raised()),
            self.feedback(now),
        )
    }

    /// Drive straight away from the dock (front first), raised, at the departure speed.
    fn drive_away(&self, now: f64) -> Step {
        let v = -self.geometry.drive_dir * DEPARTURE_SPEED_MPS;
        Step::running(
            MotorOutput::drive(DriveCommand::Straight { v }).with_aux(raised()),
            self.feedback(now),
        )
    }

    fn feedback(&self, now: f64) -> Feedback {
        Feedback {
            phase: self.phase.name(),
            elapsed: now - self.run_start.unwrap_or(now),
            retries: self.retries,
        }
    }

    fn fail(&mut self, reason: FailureReason, now: f64, odo: Pose2, near_dock: bool) -> Step {
        if near_dock {
            self.enter(Phase::MoveAway { failing: Some(reason) }, now, odo);
            return Step::running(MotorOutput::stop(), self.feedback(now));
        }
        self.phase = Phase::Done;
        Step::done(
            Outcome::Failed(reason),
            MotorOutput::stop().with_aux(raised()),
            self.feedback(now),
        )
    }

    /// The planning view with the median viewing angle of the last [`ALPHA_WINDOW`]
    /// reliable frames, when that window is full, the blocks are tall enough to trust and
    /// the robot is more than [`REPOSITION_LATERAL_M`] off the axis; `None` otherwise.
    fn off_axis_view(&self, planning: &FiducialView) -> Option<FiducialView> {
        if !self.alpha_window.is_full() || planning.height_px < RELIABLE_HEIGHT_PX {
            return None;
        }
        let alpha = self.alpha_window.median()?;
        ((planning.distance * alpha.sin()).abs() > REPOSITION_LATERAL_M).then(|| planning.with_alpha(alpha))
    }

    /// Starts a repositioning to the staging point on the dock axis, from the estimated
    /// pose in the dock frame (`view`) and the current odometry pose.
    fn reposition(&mut self, view: &FiducialView, now: f64, odo: Pose2) {
        // Robot centre in the dock frame: the camera sits `rear_behind_camera − L/2` ahead
        // of the rear; near enough to treat the camera as the centre here.
        let here = view.dock_pose();
        let stage_x = (here.x + 0.15).max(STAGING_X_M);
        let stage = Pose2::new(stage_x, 0.0, 0.0);
        // dock → odometry: odo = T ⊕ dock, T = odo ⊕ here⁻¹.
        let t = odo.compose(&here.relative(&Pose2::default()));
        let target = t.compose(&stage);
        tracing::debug!(target: "marsupial::behavior", now, x = here.x, y = here.y, heading_deg = here.theta.to_degrees(), "reposition to the axis");
        // Beside the gate there is no room to turn in place (the body's corners sweep a
        // circle of half the diagonal): first drive straight out, front first.
        let clear = here.x < CLEARANCE_X_M;
        self.enter(
            Phase::Reposition {
                stage: if clear { 3 } else { 0 },
                target,
            },
            now,
            odo,
        );
    }

    /// True when the search has turned for [`JAMMED_AFTER_S`] without the view changing
    /// (and unjams are left). `change` is this tick's [`FrameChange`] cue.
    fn search_jammed(&mut self, change: Option<f32>, now: f64) -> bool {
        match change {
            Some(c) if c < STILL_LEVELS => {
                let since = *self.still_since.get_or_insert(now);
                now - since >= JAMMED_AFTER_S && self.unjams < MAX_UNJAMS
            }
            _ => {
                self.still_since = None;
                false
            }
        }
    }

    fn approach_command(&self, view: &FiducialView) -> MotorOutput {
        match &self.field {
            None => self.steering.act(view),
            // The field gives a heading error; the ratio-steering schema realises it with
            // the same dead band, understeer and turn-or-drive alternation.
            Some(pf) if self.steering.restricted => {
                let error = pf.body_vector(&view.dock_pose(), self.geometry.drive_dir).angle();
                self.steering
                    .steer(error, self.steering.speed_for(view.total_px as f64))
            }
            Some(pf) => MotorOutput::drive(DriveCommand::Twist(
                pf.twist(&view.dock_pose(), self.geometry.drive_dir),
            )),
        }
    }
}

/// The at-dock decision (seed 004 §V): "if the ratio of left to right pixel counts is close
/// to one and the fiducial is centred, back in; otherwise move away and retry", made
/// metric: average the views, predict the lateral error where the rear will reach the
/// entrance, and back in only if that and the heading are within 80 % of the profile's
/// tolerances. The rear sits `rear_behind_camera` behind the camera along the heading θ
/// and backs a further `to_go` to the entrance, so its lateral error there is the
/// camera's, d·sin α, less (rear_behind_camera + to_go)·sin θ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Decision {
    /// Back in now.
    pub back_in: bool,
    /// Mean viewing angle, rad.
    pub alpha: f64,
    /// Mean heading, rad.
    pub heading: f64,
    /// Mean camera distance, m.
    pub distance: f64,
    /// Predicted lateral error at the entrance, m.
    pub lateral_at_entrance: f64,
}

/// See [`Decision`]. `samples` must not be empty (an empty slice decides "no").
pub fn at_dock_decision(
    samples: &[FiducialView],
    rear_behind_camera: f64,
    tol_lateral: f64,
    tol_heading: f64,
) -> Decision {
    let n = samples.len().max(1) as f64;
    let alpha = samples.iter().map(|s| s.alpha).sum::<f64>() / n;
    let heading = samples.iter().map(|s| s.heading).sum::<f64>() / n;
    let distance = samples.iter().map(|s| s.distance).sum::<f64>() / n;
    let to_go = (distance - rear_behind_camera).max(0.0);
    let lateral_at_entrance = distance * alpha.sin() - (rear_behind_camera + to_go) * heading.sin();
    Decision {
        back_in: !samples.is_empty()
            && lateral_at_entrance.abs() <= 0.8 * tol_lateral
            && heading.abs() <= 0.8 * tol_heading,
        alpha,
        heading,
        distance,
        lateral_at_entrance,
    }
}

fn lowered() -> Auxiliary {
    Auxiliary {
        posture: Some(Posture::Lowered),
        ..Auxiliary::default()
    }
}

fn raised() -> Auxiliary {
    Auxiliary {
        posture: Some(Posture::Raised),
        ..Auxiliary::default()
    }
}

impl Behavior for BujoldAgent {
    fn name(&self) -> &str {
        "bujold"
    }

    fn tick(&mut self, inputs: &Inputs<'_>) -> Option<Step> {
        let now = inputs.now;
        self.run_start.get_or_insert(now);
        let odo = inputs.odometry.map(|o| o.value.pose).unwrap_or_default();
        // Perception runs every tick so adaptation follows the light, except while
        // imprinting (the imprint must not be mixed with adapted statistics).
        let percept = self.schema.perceive(inputs);
        // The frame-change cue is read only while searching. It also runs in the phases a
        // search is entered from (approach, unjam), so a search's first frame is compared
        // with the frame just before it; elsewhere (departure, decision, back-in,
        // manoeuvres) it is skipped.
        let change = match self.phase {
            Phase::Search | Phase::Approach | Phase::Unjam { .. } => {
                inputs.camera(0).and_then(|c| self.frame_change.observe(&c.image))
            }
            _ => None,
        };
        let mut view = FiducialView::from_percept(&percept, &self.geometry);
        let mut planning: Option<FiducialView> = None;
        if let Some(v) = view.as_mut() {
            // The ratio cue is only as good as the blocks are big: at 1.3 m two-pixel noise
            // is ±35° of viewing angle. Weight it by reliability (zero for blocks under
            // 18 px tall, full above 43 px), then low-pass. Far away the robot therefore
            // pursues the fiducial along the line of sight; the aim point fades in close.
            let trust = ((v.height_px - 18.0) / 25.0).clamp(0.0, 1.0);
            let a = match self.alpha_filtered {
                None => v.alpha,
                Some(prev) => prev + 0.3 * (v.alpha - prev),
            };
            self.alpha_filtered = Some(a);
            if v.height_px >= RELIABLE_HEIGHT_PX {
                self.alpha_window.push(v.alpha);
            }
            // The final decision uses the filtered estimate (repositioning the median of
            // `alpha_window`, see `off_axis_view`); steering uses it scaled by its trust.
            planning = Some(v.with_alpha(a));
            *v = v.with_alpha(a * trust);
        }
        if percept.found() {
            self.ever_seen = true;
            self.last_seen = Some(now);
            if let Some(v) = &view {
                self.last_side = if v.bearing >= 0.0 { 1.0 } else { -1.0 };
            }
        }
        if self.phase_start == f64::NEG_INFINITY {
            self.phase_start = now;
            self.odo_mark = odo;
            self.start_heading.get_or_insert(odo.theta);
        }
        let in_phase = now - self.phase_start;
        let dir = self.geometry.drive_dir;
        if let Some(v) = &view {
            tracing::trace!(target: "marsupial::behavior", now, phase = self.phase.name(), d = v.distance, alpha_deg = v.alpha.to_degrees(), heading_deg = v.heading.to_degrees(), offset = v.offset_px, total = v.total_px, mode = %percept.mode, "view");
        } else {
            tracing::trace!(target: "marsupial::behavior", now, phase = self.phase.name(), mode = %percept.mode, "no fiducial");
        }
        if inputs.docked_contact() && !matches!(self.phase, Phase::Undock | Phase::Idle | Phase::Done) {
            self.phase = Phase::Done;
            return Some(Step::done(
                Outcome::Docked,
                MotorOutput::stop().with_aux(lowered()),
                self.feedback(now),
            ));
        }
        if !matches!(self.phase, Phase::Idle | Phase::Done | Phase::MoveAway { .. }) && in_phase > self.phase_timeout {
            let near = matches!(self.phase, Phase::Decide | Phase::BackIn | Phase::Approach);
            return Some(self.fail(FailureReason::Timeout, now, odo, near));
        }
        // Repositioning is decided on the median viewing angle, not the filtered one.
        let off_axis = match (&self.phase, &planning) {
            (Phase::Approach, Some(p)) if self.retries < self.max_retries => self.off_axis_view(p),
            _ => None,
        };
        let step = match self.phase {
            Phase::Idle | Phase::Done => return None,
            // ---- departure ----
            Phase::Undock => {
                // Drive out of the pouch (front first, away from the dock), lowered.
                if self.travelled(&odo) >= self.depth + 0.05 {
                    self.enter(Phase::DriveOut, now, self.odo_mark);
                }
                Step::running(
                    MotorOutput {
                        drive: DriveCommand::Straight { v: -dir * 0.05 },
                        aux: lowered(),
                    },
                    self.feedback(now),
                )
            }
            Phase::DriveOut => {
                let out = self.travelled(&odo);
                if !self.imprinted && out >= self.imprint_at {
                    self.enter(Phase::Imprint { frames: 0 }, now, self.odo_mark);
                    self.hold(now)
                } else if out >= self.drive_out {
                    self.phase = Phase::Done;
                    let outcome = if self.imprinted {
                        Outcome::Completed
                    } else {
                        Outcome::Failed(FailureReason::TargetNeverDetected)
                    };
                    Step::done(outcome, MotorOutput::stop().with_aux(raised()), self.feedback(now))
                } else {
                    self.drive_away(now)
                }
            }
            Phase::Imprint { frames } => {
                if let Some(cam) = inputs.camera(0) {
                    self.schema.imprint_frame(&cam.image);
                }
                let frames = frames + 1;
                if frames >= self.imprint_frames {
                    self.imprinted = self.schema.finish_imprint(now);
                    let mark = self.odo_mark;
                    self.enter(Phase::DriveOut, now, mark);
                } else {
                    self.phase = Phase::Imprint { frames };
                }
                self.hold(now)
            }
            // ---- docking ----
            Phase::Search => {
                if let Some(v) = view {
                    self.enter(Phase::Approach, now, odo);
                    Step::running(self.approach_command(&v).with_aux(raised()), self.feedback(now))
                } else if in_phase > self.search_timeout {
                    let reason = if self.ever_seen {
                        FailureReason::TargetLost
                    } else {
                        FailureReason::TargetNeverDetected
                    };
                    self.fail(reason, now, odo, false)
                } else if self.search_jammed(change, now) {
                    // Beside the gate a corner catches the body: the tracks spin, the view
                    // does not move. Drive out, front first, and search again turning the
                    // other way, which swings the caught corner off the body.
                    self.unjams += 1;
                    self.last_side = -self.last_side;
                    tracing::debug!(target: "marsupial::behavior", now, unjams = self.unjams, "search turn jammed");
                    self.enter(Phase::Unjam { stage: 0 }, now, odo);
                    self.hold(now)
                } else {
                    let mut s = self.search;
                    s.rate *= self.last_side;
                    Step::running(
                        MotorOutput::drive(s.act(in_phase)).with_aux(raised()),
                        self.feedback(now),
                    )
                }
            }
            Phase::Unjam { stage: 0 } => {
                // Turning back over the ground just swept is free.
                let err = crate::geometry::wrap_angle(self.start_heading.unwrap_or(odo.theta) - odo.theta);
                if err.abs() < 5f64.to_radians() || in_phase > 20.0 {
                    self.enter(Phase::Unjam { stage: 1 }, now, odo);
                    self.hold(now)
                } else {
                    self.turn_by(err, now)
                }
            }
            Phase::Unjam { .. } => {
                if self.travelled(&odo) >= UNJAM_M || in_phase > 2.0 * UNJAM_M / DEPARTURE_SPEED_MPS {
                    self.enter(Phase::Search, now, odo);
                    self.hold(now)
                } else {
                    self.drive_away(now)
                }
            }
            Phase::Approach => match (view, off_axis) {
                (Some(v), _) if v.total_px as f64 >= self.steering.dock_total_px => {
                    self.enter(Phase::Decide, now, odo);
                    self.hold(now)
                }
                (Some(_), Some(off)) => {
                    // Close enough to trust the viewing angle and clearly off the axis for
                    // most of the last 1.6 s: creeping in would only arrive misaligned.
                    self.retries += 1;
                    self.reposition(&off, now, odo);
                    self.hold(now)
                }
                (Some(v), _) => Step::running(self.approach_command(&v).with_aux(raised()), self.feedback(now)),
                (None, _) => {
                    if self.last_seen.is_none_or(|t| now - t > 1.5) {
                        self.enter(Phase::Search, now, odo);
                    }
                    self.hold(now)
                }
            },
            Phase::Decide => {
                if let Some(v) = planning {
                    self.samples.push(v);
                }
                if self.samples.len() < 5 {
                    if in_phase > 3.0 {
                        // Lost at the gate: back off and look again.
                        self.retries += 1;
                        self.enter(Phase::MoveAway { failing: None }, now, odo);
                    }
                    self.hold(now)
                } else {
                    let d = at_dock_decision(
                        &self.samples,
                        self.rear_behind_camera,
                        self.tol_lateral,
                        self.tol_heading,
                    );
                    let (alpha, heading, dist) = (d.alpha, d.heading, d.distance);
                    if d.back_in {
                        self.samples_distance = dist;
                        self.enter(Phase::BackIn, now, odo);
                        Step::running(MotorOutput::stop().with_aux(lowered()), self.feedback(now))
                    } else {
                        self.retries += 1;
                        if self.retries > self.max_retries {
                            return Some(self.fail(FailureReason::RetriesExhausted, now, odo, true));
                        }
                        let mean = FiducialView {
                            alpha,
                            heading,
                            distance: dist,
                            ..self.samples[0]
                        };
                        self.reposition(&mean, now, odo);
                        self.hold(now)
                    }
                }
            }
            Phase::BackIn => {
                // Blind: the entrance is about `distance − rear_behind_camera` away, then the
                // pouch; 15 cm of margin before declaring a miss.
                let est = self.samples_distance.max(0.1);
                let dr = DeadReckoning {
                    speed: dir * 0.04,
                    distance: (est - self.rear_behind_camera).max(0.0) + self.depth + 0.15,
                };
                match dr.act(self.travelled(&odo)) {
                    Some(cmd) => Step::running(
                        MotorOutput {
                            drive: cmd,
                            aux: lowered(),
                        },
                        self.feedback(now),
                    ),
                    None => self.fail(FailureReason::FailedToControl, now, odo, true),
                }
            }
            Phase::Reposition { stage, target } => {
                let (dx, dy) = (target.x - odo.x, target.y - odo.y);
                let dist = dx.hypot(dy);
                let tol = 3f64.to_radians();
                match stage {
                    3 => {
                        // Clear the body: straight out, front first, 0.3 m.
                        if self.travelled(&odo) >= 0.3 {
                            self.phase = Phase::Reposition { stage: 0, target };
                            self.hold(now)
                        } else {
                            Step::running(
                                MotorOutput::drive(DriveCommand::Straight {
                                    v: -dir * self.steering.speed,
                                })
                                .with_aux(raised()),
                                self.feedback(now),
                            )
                        }
                    }
                    0 | 1 if dist < 0.03 => {
                        self.phase = Phase::Reposition { stage: 2, target };
                        self.hold(now)
                    }
                    0 => {
                        // Face the staging point with the end that leads toward it.
                        let bearing = dy.atan2(dx);
                        let forward =
                            crate::geometry::wrap_angle(bearing - odo.theta).abs() <= std::f64::consts::FRAC_PI_2;
                        let want = if forward {
                            bearing
                        } else {
                            bearing + std::f64::consts::PI
                        };
                        let err = crate::geometry::wrap_angle(want - odo.theta);
                        if err.abs() < tol {
                            self.phase = Phase::Reposition { stage: 1, target };
                            self.hold(now)
                        } else {
                            self.turn_by(err, now)
                        }
                    }
                    1 => {
                        // Drive along the heading until the target is abeam: the signed
                        // distance to it along the heading crosses zero (a target off the
                        // line of travel is never reached exactly).
                        let along = dx * odo.theta.cos() + dy * odo.theta.sin();
                        if along.abs() < 0.02 {
                            self.phase = Phase::Reposition { stage: 2, target };
                            self.hold(now)
                        } else {
                            let v = self
                                .steering
                                .speed
                                .min(along.abs() / self.steering.tick_s)
                                .copysign(along);
                            Step::running(
                                MotorOutput::drive(DriveCommand::Straight { v }).with_aux(raised()),
                                self.feedback(now),
                            )
                        }
                    }
                    _ => {
                        let err = crate::geometry::wrap_angle(target.theta - odo.theta);
                        if err.abs() < tol {
                            self.alpha_filtered = None;
                            self.alpha_window.clear();
                            self.enter(Phase::Approach, now, odo);
                            self.hold(now)
                        } else {
                            self.turn_by(err, now)
                        }
                    }
                }
            }
            Phase::MoveAway { failing } => {
                if self.travelled(&odo) >= MOVE_AWAY_M || in_phase > 20.0 {
                    match failing {
                        Some(reason) => {
                            self.phase = Phase::Done;
                            Step::done(
                                Outcome::Failed(reason),
                                MotorOutput::stop().with_aux(raised()),
                                self.feedback(now),
                            )
                        }
                        None => {
                            self.enter(Phase::Approach, now, odo);
                            self.hold(now)
                        }
                    }
                } else {
                    self.drive_away(now)
                }
            }
        };
        Some(step)
    }

    fn reset(&mut self) {
        self.phase = Phase::Idle;
        self.run_start = None;
        self.retries = 0;
    }
}

impl Agent for BujoldAgent {
    fn begin_departure(&mut self) -> bool {
        self.run_start = None;
        self.phase = Phase::Undock;
        self.phase_start = f64::NEG_INFINITY;
        self.imprinted = false;
        true
    }

    fn begin_docking(&mut self) {
        self.run_start = None;
        self.alpha_filtered = None;
        self.alpha_window.clear();
        self.retries = 0;
        self.unjams = 0;
        self.ever_seen = false;
        self.last_seen = None;
        // Ballistic region: drive by odometry to the approach zone's staging point and face
        // along the axis, then look (the repositioning manoeuvre does exactly this).
        let staging = self
            .dock_hint
            .map(|dock| dock.compose(&Pose2::new(BALLISTIC_STAGING_M, 0.0, 0.0)));
        self.start_heading = staging.map(|t| t.theta);
        self.phase = match staging {
            Some(target) => Phase::Reposition { stage: 0, target },
            None => Phase::Search,
        };
        self.phase_start = f64::NEG_INFINITY;
    }

    fn set_dock_hint(&mut self, hint: Option<Pose2>) {
        self.dock_hint = hint;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_window_ignores_a_minority_of_outliers_and_forgets_the_oldest() {
        let mut w = MedianWindow::new();
        assert_eq!(w.median(), None);
        w.push(3.0);
        w.push(1.0);
        assert_eq!(w.median(), Some(2.0));
        // A steady 0.1 rad with a third of the frames pushed to 0.5 by a flash.
        w.clear();
        for k in 0..ALPHA_WINDOW {
            w.push(if k % 3 == 0 { 0.5 } else { 0.1 });
        }
        assert!(w.is_full());
        assert_eq!(w.median(), Some(0.1));
        // A full window of new values replaces the old ones entirely.
        for _ in 0..ALPHA_WINDOW {
            w.push(-0.2);
        }
        assert_eq!(w.median(), Some(-0.2));
        assert_eq!(w.len, ALPHA_WINDOW);
    }

    fn view(alpha_deg: f64, heading_deg: f64) -> FiducialView {
        FiducialView {
            distance: 0.38,
            alpha: alpha_deg.to_radians(),
            asym: 0.0,
            offset_px: 0.0,
            bearing: 0.0,
            heading: heading_deg.to_radians(),
            total_px: 4600,
            height_px: 50.0,
        }
    }

    #[test]
    fn centred_and_balanced_backs_in() {
        let d = at_dock_decision(&[view(0.5, 0.5); 5], 0.15, 0.02, 5f64.to_radians());
        assert!(d.back_in, "{d:?}");
    }

    #[test]
    fn off_axis_or_skewed_moves_away() {
        // 3° off the axis at 0.38 m is 2 cm: beyond 80 % of the ±2 cm tolerance.
        assert!(!at_dock_decision(&[view(3.0, 0.0); 5], 0.15, 0.02, 5f64.to_radians()).back_in);
        // On the axis but heading 4.5°: within 5° but beyond 80 % of it.
        assert!(!at_dock_decision(&[view(0.0, 4.5); 5], 0.15, 0.02, 5f64.to_radians()).back_in);
        // A small offset cancelled by a heading that steers back onto the axis: backs in.
        let d = at_dock_decision(&[view(2.0, 2.0); 5], 0.15, 0.02, 5f64.to_radians());
        assert!(d.lateral_at_entrance.abs() < 1e-12 && d.back_in, "{d:?}");
        // The lever arm from camera to rear counts: 1° off with the heading 4° back toward
        // the axis leaves the camera 6.6 mm off, but the rear reaches the entrance 20 mm
        // past the axis (ignoring the 0.15 m arm would predict 10 mm and back in).
        let d = at_dock_decision(&[view(1.0, 4.0); 5], 0.15, 0.02, 5f64.to_radians());
        let expected = 0.38 * 1f64.to_radians().sin() - 0.38 * 4f64.to_radians().sin();
        assert!((d.lateral_at_entrance - expected).abs() < 1e-12, "{d:?}");
        assert!(!d.back_in, "{d:?}");
        assert!(!at_dock_decision(&[], 0.15, 0.02, 0.1).back_in);
    }

    #[test]
    fn averages_the_samples() {
        let d = at_dock_decision(&[view(2.0, 0.0), view(-2.0, 0.0)], 0.15, 0.02, 0.1);
        assert!(d.alpha.abs() < 1e-12 && d.back_in);
    }
}
