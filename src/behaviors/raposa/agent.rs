//! RAPOSA's docking agent: the seven-state sequencer over the pyramid schema.

use super::region2::{Region2Plan, plan, robot_in_ball_frame};
use super::states::{ServoState, select_state};
use crate::behaviors::agent::BuildError;
use crate::geometry::{Pose2, Twist, wrap_angle};
use crate::perception::{PyramidPercept, PyramidSchema};
use crate::profile::{Profile, SegmentationMode, SevenStateGains};
use crate::schemas::{
    Agent, AgentStats, Auxiliary, Behavior, DriveCommand, FailureReason, Feedback, Guides, Inputs, Mission,
    MissionError, MotorOutput, Outcome, PerceptualSchema, PointController, SearchRotation, ServoLaw, Step,
};

/// Frames without anything seen before state 5 starts searching (a single dropped frame
/// should not start a rotation).
const GRACE_FRAMES: u32 = 3;
/// Distance a failed final approach backs away before trying again, m.
const RETREAT_M: f64 = 0.4;

#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    /// Select a state every tick (states 1–5 and the dead-zone exit).
    Servo,
    /// State 6 (latched).
    Final { start: f64 },
    /// State 7 (latched): vision-tracked part of the first rotation.
    Rotate7 {
        plan: Region2Plan,
        rotated: f64,
        last_bearing: f64,
        last_step: f64,
        lost: u32,
    },
    /// Odometry part of the first rotation, to `heading` in the odometry frame.
    RotateOdo { map: Pose2, plan: Region2Plan },
    /// Travel to the target by the (x_ref, y_ref) controller.
    Travel { map: Pose2, plan: Region2Plan },
    /// Last rotation φ, facing where the ball should be.
    RotatePhi { ball: (f64, f64) },
    /// After region II: look, then search slowly, starting opposite to the last turn.
    Look { start: f64, first_dir: f64 },
    /// Back away from the pyramid by odometry (dead-zone exit, retry after a failed
    /// final approach) to `distance` from `from`.
    BackAway { from: Pose2, distance: f64, retry: bool },
    /// Departure: drive out of the pyramid, body forward, to `target` (odometry frame).
    Depart { target: (f64, f64) },
    /// Departure: stopped with the pyramid straight behind, imprinting its colours.
    Imprint { frames: u32 },
    /// Finished.
    Done,
}

impl Phase {
    fn name(&self, servo: ServoState) -> &'static str {
        match self {
            Phase::Servo => servo.name(),
            Phase::Final { .. } => "state_6",
            Phase::Rotate7 { .. } => "state_7",
            Phase::RotateOdo { .. } => "state_2_rotate",
            Phase::Travel { .. } => "state_2_travel",
            Phase::RotatePhi { .. } => "state_2_rotate_phi",
            Phase::Look { .. } => "state_2_look",
            Phase::BackAway { retry: false, .. } => "leave_dead_zone",
            Phase::BackAway { retry: true, .. } => "retreat",
            Phase::Depart { .. } => "depart",
            Phase::Imprint { .. } => "imprint",
            Phase::Done => "done",
        }
    }
}

/// RAPOSA's agent (seed 001): see the [module docs](super).
pub struct RaposaAgent {
    schema: PyramidSchema,
    gains: SevenStateGains,
    law: ServoLaw,
    ctrl: PointController,
    vision_turn: f64,
    phase: Phase,
    servo: ServoState,
    phase_start: f64,
    run_start: Option<f64>,
    /// Camera position along the body axis, m (negative: behind the centre).
    camera_x: f64,
    half_length: f64,
    socket_inset: f64,
    half_width_px: f64,
    retries: u32,
    max_retries: u32,
    phase_timeout: f64,
    search_timeout: f64,
    unseen: u32,
    search_start: Option<f64>,
    last_turn: f64,
    settling: bool,
    aux: Auxiliary,
    manoeuvres: u32,
    imprinted: bool,
}

impl RaposaAgent {
    /// Builds the agent from a profile with a `[fiducial.pyramid]`, a pin-hole back camera
    /// and `[behavior.seven_state]`.
    ///
    /// # Errors
    /// [`BuildError::Profile`] when something it needs is missing.
    pub fn new(profile: &Profile) -> Result<Self, BuildError> {
        let missing = |what: String| BuildError::Profile {
            profile: profile.name.clone(),
            what,
        };
        let gains = profile
            .behavior
            .seven_state
            .ok_or_else(|| missing("needs [behavior.seven_state]".into()))?;
        let schema = PyramidSchema::from_profile(profile, 0).map_err(|e| missing(e.to_string()))?;
        let cam = &profile.cameras[0];
        let camera_backward = wrap_angle(cam.mount.yaw_deg.to_radians()).abs() > std::f64::consts::FRAC_PI_2;
        let half_length = profile.body.length_m / 2.0;
        let camera_x = cam.mount.x_m;
        let limits = profile.drive.limits();
        Ok(Self {
            schema,
            gains,
            law: ServoLaw {
                k_lin: gains.k_lin,
                k_ang: gains.k_ang,
                k_arm: gains.k_arm,
                far_speed: gains.far_speed_mps,
                far_distance: gains.far_distance_m,
                camera_backward,
            },
            ctrl: PointController {
                k_rho: gains.k_rho,
                k_heading: gains.k_heading,
                max_speed: gains.travel_speed_mps.min(limits.max_speed),
                max_turn: gains.turn_rate_dps.to_radians().min(limits.max_turn_rate),
                position_tolerance: gains.position_tolerance_m,
                rotation_tolerance: gains.rotation_tolerance_deg.to_radians(),
            },
            vision_turn: gains.vision_turn_rate_dps.to_radians(),
            phase: Phase::Servo,
            servo: ServoState::S5Nothing,
            phase_start: 0.0,
            run_start: None,
            camera_x,
            half_length,
            socket_inset: (half_length + camera_x).max(0.0),
            half_width_px: cam.width_px as f64 / 2.0,
            retries: 0,
            max_retries: profile.behavior.max_retries,
            phase_timeout: profile.behavior.phase_timeout_s,
            search_timeout: profile.behavior.search_timeout_s,
            unseen: 0,
            search_start: None,
            last_turn: 1.0,
            settling: false,
            aux: Auxiliary::default(),
            manoeuvres: 0,
            imprinted: false,
        })
    }

    /// The perceptual schema (to retune its HSV bands live).
    pub fn schema_mut(&mut self) -> &mut PyramidSchema {
        &mut self.schema
    }

    /// The perceptual schema (colour model state, last detection).
    pub fn schema(&self) -> &PyramidSchema {
        &self.schema
    }

    /// True once a departure imprinted successfully.
    pub fn imprinted(&self) -> bool {
        self.imprinted
    }

    fn enter(&mut self, phase: Phase, now: f64) {
        self.phase = phase;
        self.phase_start = now;
    }

    fn feedback(&self, now: f64) -> Feedback {
        Feedback {
            phase: self.phase.name(self.servo),
            elapsed: now - self.run_start.unwrap_or(now),
            retries: self.retries,
        }
    }

    fn drive(&self, twist: Twist, now: f64) -> Step {
        let out = MotorOutput::drive(DriveCommand::Twist(twist)).with_aux(self.aux);
        Step::running(out, self.feedback(now))
    }

    fn hold(&self, now: f64) -> Step {
        Step::running(MotorOutput::stop().with_aux(self.aux), self.feedback(now))
    }

    fn finish(&mut self, outcome: Outcome, now: f64) -> Step {
        let fb = self.feedback(now);
        self.phase = Phase::Done;
        Step::done(outcome, MotorOutput::stop().with_aux(self.aux), fb)
    }

    fn turn(&mut self, omega: f64, now: f64) -> Step {
        if omega != 0.0 {
            self.last_turn = omega.signum();
        }
        self.drive(Twist::new(0.0, omega), now)
    }

    /// Approach law of states 1 and 3 on the ellipse.
    fn approach(&mut self, p: &PyramidPercept, far: bool, now: f64) -> Step {
        let Some(v) = p.view else {
            return self.hold(now);
        };
        // √(A₁/A) is the area's distance estimate.
        let area_root = self.schema.geometry().distance_from_area(v.area_px as f64);
        let speed = if far {
            self.law.far_speed
        } else {
            self.law.speed(v.ball_distance_m, area_root)
        };
        let omega = self.law.turn(v.dev_px[0]);
        self.drive(self.law.twist(speed, omega), now)
    }

    fn servo_tick(&mut self, p: &PyramidPercept, odo: Pose2, now: f64) -> Step {
        let state = select_state(p, &self.gains, self.socket_inset, self.settling);
        if p.view.is_some() {
            self.search_start = None;
        }
        self.servo = state;
        match state {
            ServoState::S1Approach => self.approach(p, false, now),
            ServoState::S3FarEllipse => self.approach(p, true, now),
            ServoState::S6Final => {
                let dev = p.view.map_or(0.0, |v| v.dev_px[1]);
                self.aux.arm = Some(self.law.arm(dev));
                self.aux.lights = Some(true);
                self.enter(Phase::Final { start: now }, now);
                self.approach(p, false, now)
            }
            ServoState::S2Align => {
                let (Some(view), Some(alpha)) = (p.view, p.view.and_then(|v| v.alpha)) else {
                    return self.hold(now);
                };
                let start = robot_in_ball_frame(&view, alpha, self.camera_x);
                let pl = plan(start, self.gains.region2_distance_m, self.half_length);
                tracing::debug!(
                    target: "marsupial::behavior",
                    now,
                    alpha_deg = alpha.to_degrees(),
                    beta_deg = -pl.rotation.to_degrees(),
                    d_m = pl.distance,
                    phi_deg = pl.final_rotation.to_degrees(),
                    reverse = pl.reverse,
                    "region II: rotate −β, travel d, rotate φ"
                );
                self.manoeuvres += 1;
                self.settling = false;
                self.enter(
                    Phase::Rotate7 {
                        plan: pl,
                        rotated: 0.0,
                        last_bearing: view.bearing,
                        last_step: 0.0,
                        lost: 0,
                    },
                    now,
                );
                self.servo = ServoState::S7Rotate;
                self.turn(self.vision_turn * pl.rotation.signum(), now)
            }
            ServoState::S4BlueOnly => {
                let Some(b) = p.detection.blue else {
                    return self.hold(now);
                };
                let dev = b.centre()[0] + 0.5 - self.half_width_px;
                let omega = self.law.turn(dev);
                let creep = if dev.abs() < 10.0 {
                    self.gains.final_speed_mps
                } else {
                    0.0
                };
                self.drive(self.law.twist(creep, omega), now)
            }
            ServoState::S5Nothing => {
                self.unseen += 1;
                if self.unseen <= GRACE_FRAMES {
                    return self.hold(now);
                }
                let start = *self.search_start.get_or_insert(now);
                if now - start > self.search_timeout {
                    return self.finish(Outcome::Failed(FailureReason::TargetLost), now);
                }
                let search = SearchRotation {
                    rate: self.gains.search_rate_dps.to_radians() * -self.last_turn,
                    first_sweep: self.gains.search_sweep_deg.to_radians(),
                    doubling: true,
                };
                let cmd = search.act(now - start);
                Step::running(MotorOutput::drive(cmd).with_aux(self.aux), self.feedback(now))
            }
            ServoState::LeaveDeadZone => {
                let socket = p.view.map_or(0.0, |v| v.ball_distance_m - self.socket_inset);
                let distance = (self.gains.dead_zone_exit_m - socket).max(0.05);
                self.enter(
                    Phase::BackAway {
                        from: odo,
                        distance,
                        retry: false,
                    },
                    now,
                );
                self.back_away(p, now)
            }
            // State 7 is entered from state 2 above, never selected.
            ServoState::S7Rotate => self.hold(now),
        }
    }

    /// Drive away from the pyramid (body forward for a backward camera), keeping the
    /// ellipse centred when it is seen.
    fn back_away(&mut self, p: &PyramidPercept, now: f64) -> Step {
        let omega = p.view.map_or(0.0, |v| self.law.turn(v.dev_px[0]));
        let speed = self.gains.far_speed_mps;
        self.drive(self.law.twist(-speed, omega), now)
    }

    fn tick_inner(&mut self, inputs: &Inputs<'_>) -> Step {
        let now = inputs.now;
        self.run_start.get_or_insert(now);
        let odo = inputs.odometry.map(|o| o.value.pose).unwrap_or_default();
        match self.phase {
            Phase::Depart { target } => {
                return match self.ctrl.travel(&odo, target, false) {
                    Some(t) => self.drive(t, now),
                    None => {
                        self.enter(Phase::Imprint { frames: 0 }, now);
                        self.hold(now)
                    }
                };
            }
            Phase::Imprint { frames } => {
                // The first frame after stopping may still be blurred by the motion.
                if frames > 0
                    && let Some(cam) = inputs.camera(0)
                {
                    let _ = self.schema.imprint_frame(&cam.image);
                }
                if frames >= self.schema.imprint_frames_wanted() {
                    self.imprinted = self.schema.finish_imprint(now);
                    // As Bujold's departure: a failed imprint ends the departure failed.
                    let outcome = if self.imprinted {
                        Outcome::Completed
                    } else {
                        Outcome::Failed(FailureReason::TargetNeverDetected)
                    };
                    return self.finish(outcome, now);
                }
                self.phase = Phase::Imprint { frames: frames + 1 };
                return self.hold(now);
            }
            _ => {}
        }
        // The blind part of region II looks away from the pyramid on purpose.
        let blind = matches!(
            self.phase,
            Phase::RotateOdo { .. } | Phase::Travel { .. } | Phase::RotatePhi { .. }
        );
        self.schema.set_looking(!blind, now);
        let p = self.schema.perceive(inputs);
        if p.view.is_some() || p.detection.blue.is_some() {
            self.unseen = 0;
        }
        if inputs.docked_contact() {
            self.aux.guides = Some(Guides::Closed);
            return self.finish(Outcome::Docked, now);
        }
        if now - self.phase_start > self.phase_timeout && !matches!(self.phase, Phase::Servo) {
            return self.finish(Outcome::Failed(FailureReason::Timeout), now);
        }
        match self.phase {
            Phase::Done => self.finish(Outcome::Failed(FailureReason::Timeout), now),
            // Handled before perception above.
            Phase::Depart { .. } | Phase::Imprint { .. } => self.hold(now),
            Phase::Servo => self.servo_tick(&p, odo, now),
            Phase::Final { start } => {
                if now - start < self.gains.final_time_s {
                    let omega = p.view.map_or(0.0, |v| self.law.turn(v.dev_px[0]));
                    return self.drive(self.law.twist(self.gains.final_speed_mps, omega), now);
                }
                // Time is up without the dock switch: stop, and retry from further out.
                self.aux.lights = Some(false);
                self.retries += 1;
                if self.retries > self.max_retries {
                    return self.finish(Outcome::Failed(FailureReason::RetriesExhausted), now);
                }
                self.enter(
                    Phase::BackAway {
                        from: odo,
                        distance: RETREAT_M,
                        retry: true,
                    },
                    now,
                );
                self.hold(now)
            }
            Phase::Rotate7 {
                plan: pl,
                rotated,
                last_bearing,
                last_step,
                lost,
            } => self.rotate7(&p, odo, now, pl, rotated, last_bearing, last_step, lost),
            Phase::RotateOdo { map, plan: pl } => {
                let heading = map.theta + pl.travel_heading;
                match self.ctrl.rotate(&odo, heading) {
                    Some(t) => self.turn(t.omega, now),
                    None => {
                        self.enter(Phase::Travel { map, plan: pl }, now);
                        self.hold(now)
                    }
                }
            }
            Phase::Travel { map, plan: pl } => {
                let target = map.to_world(pl.target.0, pl.target.1);
                match self.ctrl.travel(&odo, target, pl.reverse) {
                    Some(t) => self.drive(t, now),
                    None => {
                        let ball = map.to_world(0.0, 0.0);
                        self.enter(Phase::RotatePhi { ball }, now);
                        self.hold(now)
                    }
                }
            }
            Phase::RotatePhi { ball } => {
                // Face the ball from where the robot actually is: the camera looks back.
                let heading = (ball.1 - odo.y).atan2(ball.0 - odo.x) + std::f64::consts::PI;
                match self.ctrl.rotate(&odo, heading) {
                    Some(t) => self.turn(t.omega, now),
                    None => {
                        self.schema.reset();
                        self.enter(
                            Phase::Look {
                                start: now,
                                first_dir: -self.last_turn,
                            },
                            now,
                        );
                        self.hold(now)
                    }
                }
            }
            Phase::Look { start, first_dir } => {
                if p.view.is_some() {
                    self.settling = true;
                    self.phase = Phase::Servo;
                    return self.servo_tick(&p, odo, now);
                }
                let t = now - start;
                if t < 0.5 {
                    return self.hold(now); // let the image settle after stopping
                }
                if t > self.search_timeout {
                    return self.finish(Outcome::Failed(FailureReason::TargetLost), now);
                }
                let search = SearchRotation {
                    rate: self.gains.search_rate_dps.to_radians() * first_dir,
                    first_sweep: self.gains.search_sweep_deg.to_radians(),
                    doubling: true,
                };
                let cmd = search.act(t - 0.5);
                Step::running(MotorOutput::drive(cmd).with_aux(self.aux), self.feedback(now))
            }
            Phase::BackAway { from, distance, .. } => {
                let moved = (odo.x - from.x).hypot(odo.y - from.y);
                if moved >= distance {
                    self.phase = Phase::Servo;
                    self.schema.reset();
                    return self.hold(now);
                }
                self.back_away(&p, now)
            }
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn rotate7(
        &mut self,
        p: &PyramidPercept,
        odo: Pose2,
        now: f64,
        pl: Region2Plan,
        rotated: f64,
        last_bearing: f64,
        last_step: f64,
        lost: u32,
    ) -> Step {
        let dir = pl.rotation.signum();
        let want = pl.rotation.abs();
        let Some(v) = p.view else {
            // Lost: stop; give up on the vision part after too many frames.
            if lost + 1 >= self.gains.lost_frames {
                self.phase = Phase::Servo;
                return self.hold(now);
            }
            self.phase = Phase::Rotate7 {
                plan: pl,
                rotated,
                last_bearing,
                last_step: 0.0,
                lost: lost + 1,
            };
            return self.hold(now);
        };
        // Turning the camera by +Δ moves the ball's bearing by −Δ.
        let step = last_bearing - v.bearing;
        let rotated = rotated + step * dir;
        // Predict the next frame from the frame-to-frame change (the control delay), and
        // stop before the goal or the image edge is passed. Turning the camera in `dir`
        // moves the ellipse toward the image side `dir` (+1: right).
        let per_frame = step.abs().max(last_step.abs());
        let predicted_rot = rotated + per_frame;
        let x_next = v.dev_px[0] + dir * per_frame * self.schema.geometry().f_px;
        let near_edge = x_next * dir > self.half_width_px - self.gains.fov_margin_px;
        let done = predicted_rot >= want - self.ctrl.rotation_tolerance;
        if done || near_edge {
            // Reset the odometry origin with the angle rotated by vision.
            let start = Pose2::new(pl.start.x, pl.start.y, pl.start.theta + rotated * dir);
            let map = odo.compose(&start.relative(&Pose2::default()));
            let next = if done {
                Phase::Travel { map, plan: pl }
            } else {
                Phase::RotateOdo { map, plan: pl }
            };
            self.enter(next, now);
            return self.hold(now);
        }
        self.phase = Phase::Rotate7 {
            plan: pl,
            rotated,
            last_bearing: v.bearing,
            last_step: step,
            lost: 0,
        };
        self.turn(self.vision_turn * dir, now)
    }
}

impl Behavior for RaposaAgent {
    fn name(&self) -> &str {
        "raposa_seven_state"
    }

    fn tick(&mut self, inputs: &Inputs<'_>) -> Option<Step> {
        Some(self.tick_inner(inputs))
    }

    fn reset(&mut self) {
        self.begin_docking();
    }
}

impl RaposaAgent {
    /// Departure (seed 001's robot leaves the pyramid to explore): drive straight out
    /// until the camera is `imprint_distance_m` from the ball, stop, and imprint the
    /// pyramid's colours. In `fixed` segmentation there is nothing to imprint and the
    /// agent has no departure.
    fn begin_departure(&mut self) -> Result<(), MissionError> {
        if self.schema.mode() == SegmentationMode::Fixed {
            return Err(MissionError::Unavailable {
                robot: "raposa".into(),
                mission: "departure",
                why: "fixed segmentation has nothing to imprint".into(),
            });
        }
        self.imprinted = false;
        self.run_start = None;
        // Odometry starts at the docked pose; the camera is then `socket_inset` from the
        // ball, and the body's forward direction leads away from it.
        let travel = (self.schema.imprint_distance() - self.socket_inset).max(0.0);
        self.enter(Phase::Depart { target: (travel, 0.0) }, 0.0);
        Ok(())
    }

    fn begin_docking(&mut self) {
        self.phase = Phase::Servo;
        self.servo = ServoState::S5Nothing;
        self.run_start = None;
        self.phase_start = 0.0;
        self.retries = 0;
        self.unseen = 0;
        self.search_start = None;
        self.settling = false;
        self.aux = Auxiliary {
            guides: Some(Guides::Open),
            ..Auxiliary::default()
        };
        self.manoeuvres = 0;
        self.schema.reset();
    }
}

impl Agent for RaposaAgent {
    fn begin(&mut self, mission: &Mission) -> Result<(), MissionError> {
        match mission {
            Mission::Departure => self.begin_departure(),
            Mission::Docking { .. } => {
                self.begin_docking();
                Ok(())
            }
        }
    }

    fn stats(&self) -> AgentStats {
        AgentStats {
            manoeuvres: self.manoeuvres,
        }
    }
}
