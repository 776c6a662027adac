//! What RAPOSA's phase schemas share: the perception source and this tick's percept, the
//! odometry pose, the auxiliary commands (arm, lights, guides) every output
//! carries, the search and retry counters, and the region-II plan one phase hands the
//! next.
//!
//! The source is the pyramid perceptual schema, or Bujold's two-block schema through the
//! adapter of [`super::source`] when the profile's fiducial is a two-block flap
//! ([`Source::from_profile`]). It runs once per tick for the whole tree ([`Memory::perceive`],
//! called by the robot's [`Composed`](crate::behaviors::composed::Composed) root before the
//! arbiters), in the order the seven-state robot needs: not at all during the departure
//! (the robot drives out and imprints, [`Memory::perceiving`]), told that it is not
//! looking during the blind part of the region-II manoeuvre ([`Memory::blind`], so the
//! colour model's fallback clock pauses). The phases set both flags when they are entered;
//! the next tick's perception reads them.

use super::region2::Region2Plan;
use super::source::Source;
use super::tuning::{RaposaRobot, SevenStateGains};
use crate::behaviors::common::retries::Retries;
use crate::behaviors::composed::SharedMemory;
use crate::geometry::{Pose2, Twist, wrap_angle};
use crate::perception::PyramidPercept;
use crate::profile::{Profile, SegmentationMode};
use crate::schemas::{
    AgentStats, Auxiliary, ColourRanges, DriveCommand, Feedback, Guides, Inputs, Mission, MissionError, MotorOutput,
    Observation, ObservedPercept, PointController, ServoLaw, Step,
};

/// RAPOSA's shared memory (see the module docs).
pub struct Memory {
    /// The perception source (detector, colour model, imprint): the pyramid schema, or the
    /// two-block schema through its adapter.
    pub source: Source,
    /// The seven states' gains and thresholds (`[robot.seven_state]`).
    pub gains: SevenStateGains,
    /// The state-1 servo law.
    pub law: ServoLaw,
    /// The odometry point controller and rotations.
    pub ctrl: PointController,
    /// State 7's turn rate, rad/s.
    pub vision_turn: f64,
    /// Camera position along the body axis, m (negative: behind the centre).
    pub camera_x: f64,
    /// Centre-to-rear distance, m.
    pub half_length: f64,
    /// Camera distance in front of the socket (camera-to-ball minus socket-to-ball), m.
    pub socket_inset: f64,
    /// Camera-to-target distance when docked, m: `socket_inset` for a target that meets
    /// the socket's mouth (the pyramid), less the dock's depth for a target over a pouch
    /// the robot backs into (the two-block flap; negative: the camera is inside).
    pub docked_distance: f64,
    /// Half the image width, px.
    pub half_width_px: f64,
    /// Loop time of this tick, s.
    pub now: f64,
    /// Odometry pose of this tick.
    pub odo: Pose2,
    /// This tick's percept (the last one while perception is off).
    pub percept: PyramidPercept,
    /// When this mission began, s.
    pub run_start: Option<f64>,
    /// Arm, lights and guides: attached to every output.
    pub aux: Auxiliary,
    /// Final approaches retried this docking, of `behavior.max_retries`.
    pub retries: Retries,
    /// Consecutive frames with neither the ellipse nor the blue edges.
    pub unseen: u32,
    /// Consecutive frames with the ellipse and no pair (no α): inside the dead zone, a
    /// viewpoint from which the blue edges cannot be seen at all.
    pub lone: u32,
    /// Probes (`raposa.probe`) since a pair was last seen.
    pub probes: u32,
    /// A pair (with α) has been seen this docking: its side is known, so a lone ball
    /// later is a lost pair, not the dead zone's blind side.
    pub pair_seen: bool,
    /// When the current state-5 search began.
    pub search_start: Option<f64>,
    /// Sign of the last turn commanded (+1 CCW): searches start the other way.
    pub last_turn: f64,
    /// Right after a region-II manoeuvre: the angle threshold is widened until the next
    /// plan.
    pub settling: bool,
    /// Region-II manoeuvres planned this docking.
    pub manoeuvres: u32,
    /// A departure imprinted successfully.
    pub imprinted: bool,
    /// The region-II plan being executed.
    pub plan: Option<Region2Plan>,
    /// The ball frame in the odometry frame, reset when state 7 ends with the angle vision
    /// measured.
    pub map: Pose2,
    /// Perception runs this tick (off during the departure).
    pub perceiving: bool,
    /// The robot looks away from the pyramid on purpose (the blind part of region II).
    pub blind: bool,
}

impl Memory {
    /// The memory of a robot just switched on, built from a profile with a
    /// `pyramid` fiducial or a `two_block` fiducial, a pin-hole back camera and
    /// `[robot.seven_state]`.
    ///
    /// # Errors
    /// A message naming what is missing.
    pub fn new(profile: &Profile, robot: &RaposaRobot) -> Result<Self, String> {
        let gains = robot.seven_state;
        let source = Source::from_profile(profile, &robot.two_block)?;
        let cam = &profile.cameras[0];
        let camera_backward = wrap_angle(cam.mount.yaw_deg.to_radians()).abs() > std::f64::consts::FRAC_PI_2;
        let half_length = profile.body.length_m / 2.0;
        let camera_x = cam.mount.x_m;
        let limits = profile.drive.limits();
        let size = source.image_size();
        let socket_inset = (half_length + camera_x).max(0.0);
        let docked_distance = match (&source, profile.dock) {
            (Source::TwoBlock(_), Some(dock)) => socket_inset - dock.depth_m,
            _ => socket_inset,
        };
        Ok(Self {
            source,
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
            camera_x,
            half_length,
            socket_inset,
            docked_distance,
            half_width_px: cam.width_px as f64 / 2.0,
            now: 0.0,
            odo: Pose2::default(),
            percept: PyramidPercept::not_found(0.0, size),
            run_start: None,
            aux: Auxiliary::default(),
            retries: Retries::new(profile.behavior.max_retries),
            unseen: 0,
            lone: 0,
            probes: 0,
            pair_seen: false,
            search_start: None,
            last_turn: 1.0,
            settling: false,
            manoeuvres: 0,
            imprinted: false,
            plan: None,
            map: Pose2::default(),
            perceiving: true,
            blind: false,
        })
    }

    /// Runs the perceptual schema on this tick's inputs (see the module docs).
    pub fn perceive(&mut self, inputs: &Inputs<'_>) {
        let now = inputs.now;
        self.now = now;
        self.run_start.get_or_insert(now);
        self.odo = inputs.odometry.map(|o| o.value.pose).unwrap_or_default();
        if !self.perceiving {
            return;
        }
        let p = self.source.perceive(inputs, !self.blind);
        if p.view.is_some() || p.detection.blue.is_some() {
            self.unseen = 0;
        }
        match p.view {
            Some(v) if v.alpha.is_some() => {
                self.lone = 0;
                self.probes = 0;
                self.pair_seen = true;
            }
            Some(_) => self.lone += 1,
            None => {}
        }
        self.percept = p;
    }

    /// Feedback for a phase.
    pub fn feedback(&self, phase: &'static str) -> Feedback {
        Feedback {
            phase,
            elapsed: self.now - self.run_start.unwrap_or(self.now),
            retries: self.retries.used(),
        }
    }

    /// Drive with `twist`, carrying the auxiliary commands.
    pub fn drive(&self, twist: Twist, phase: &'static str) -> Step {
        self.command(DriveCommand::Twist(twist), phase)
    }

    /// Any drive command, carrying the auxiliary commands.
    pub fn command(&self, drive: DriveCommand, phase: &'static str) -> Step {
        Step::running(MotorOutput::drive(drive).with_aux(self.aux), self.feedback(phase))
    }

    /// Stand still, carrying the auxiliary commands.
    pub fn hold(&self, phase: &'static str) -> Step {
        Step::running(MotorOutput::stop().with_aux(self.aux), self.feedback(phase))
    }

    /// Turn in place at `omega`, remembering the side (searches start the other way).
    pub fn turn(&mut self, omega: f64, phase: &'static str) -> Step {
        if omega != 0.0 {
            self.last_turn = omega.signum();
        }
        self.drive(Twist::new(0.0, omega), phase)
    }

    /// Starts executing a region-II plan (the `region_2` sequence runs it): counts the
    /// manoeuvre, ends the settling, keeps the plan and ends the planning state with
    /// event `planned`, already turning toward −β at the vision-tracked rate (state 7).
    pub fn start_manoeuvre(&mut self, plan: Region2Plan) -> Step {
        self.manoeuvres += 1;
        self.settling = false;
        self.plan = Some(plan);
        let omega = self.vision_turn * plan.rotation.signum();
        self.turn(omega, "state_7").with_event("planned")
    }

    /// The state-1 approach law on this tick's ellipse (`far`: at the constant far speed,
    /// state 3); stands still without one.
    pub fn approach(&self, far: bool, phase: &'static str) -> Step {
        let Some(v) = self.percept.view else {
            return self.hold(phase);
        };
        // √(A₁/A) is the area's distance estimate.
        let area_root = self.source.distance_from_area(v.area_px as f64);
        let speed = if far {
            self.law.far_speed
        } else {
            self.law.speed(v.ball_distance_m, area_root)
        };
        let omega = self.law.turn(v.dev_px[0]);
        self.drive(self.law.twist(speed, omega), phase)
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
        let ranges = match &self.source {
            Source::Pyramid(s) => ColourRanges::Hsv(s.bands()),
            Source::TwoBlock(c) => ColourRanges::Sct(c.schema.model().ranges()),
        };
        Some(Observation {
            camera: 0,
            percept: ObservedPercept::Pyramid(self.percept),
            ranges: Some(ranges),
        })
    }

    /// Departure (seed 001's robot leaves the pyramid to explore): the perception is off
    /// while it drives out and imprints; refused in `fixed` segmentation, which has
    /// nothing to imprint. Docking: guides open, counters and tracking forgotten.
    fn begin(&mut self, mission: &Mission) -> Result<(), MissionError> {
        match mission {
            Mission::Departure => {
                if self.source.mode() == SegmentationMode::Fixed {
                    return Err(MissionError::Unavailable {
                        robot: "raposa".into(),
                        mission: "departure",
                        why: "fixed segmentation has nothing to imprint".into(),
                    });
                }
                self.imprinted = false;
                self.run_start = None;
                self.perceiving = false;
            }
            Mission::Docking { .. } => {
                self.run_start = None;
                self.retries.reset();
                self.unseen = 0;
                self.lone = 0;
                self.probes = 0;
                self.pair_seen = false;
                self.search_start = None;
                self.settling = false;
                self.aux = Auxiliary::with(Guides::Open);
                self.manoeuvres = 0;
                self.plan = None;
                self.perceiving = true;
                self.blind = false;
                self.source.reset();
            }
        }
        Ok(())
    }

    fn stats(&self) -> AgentStats {
        AgentStats {
            manoeuvres: self.manoeuvres,
        }
    }
}
