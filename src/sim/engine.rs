//! The simulated world of one run: the robot's true pose and motion, its cameras'
//! renderers, the lighting, tether and dock contact. No behavior runs here: the robot is
//! driven through the hardware traits ([`super::robot`]), stepped in lockstep with the
//! reactive loop by the campaign. Each tick the cameras render at the current true pose
//! under the lighting of this instant, the loop decides, the commands are queued on the
//! motors, then [`Sim::advance`] moves the physics in small steps (motion with latency and
//! slip, tether pull, contact and the docking judge). Time and randomness are the run's
//! own: the same seed reproduces the run bit for bit.

use super::camera::camera_pose;
use super::dock::{Contact, judge};
use super::faults::{self, FaultKind, FaultSpec, Latched, Side};
use super::lighting::{LightState, LightingRun, ShadowBand};
use super::motion::Motion;
use super::render::{CameraMotion, Renderer, SensorParams};
use super::rng::Rng;
use super::tether::{Tether, TetherTally};
use super::world::World;
use crate::geometry::Pose2;
use crate::kinematics::Odometry;
use crate::perception::RgbImage;
use crate::perception::camera_model::CameraModel;
use crate::profile::Profile;
use crate::robot::{Exposure, HardwareError};
use crate::schemas::{DriveCommand, OdometryReading, Outcome, Posture, TetherCommand, TetherReading};
use std::collections::VecDeque;
use std::sync::Arc;

/// How a phase of a run ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PhaseEnd {
    /// The behavior reported an outcome.
    Finished(Outcome),
    /// The robot reached the contact plates.
    Docked,
    /// The robot caught the entrance edge; for a docking cone, the arm's tip caught on
    /// the cone's face or pushed against its throat misaligned, or the tether fouled the
    /// wheels (lateral: the tip's, heading: the arm's angle to the cone's axis).
    Stuck {
        /// Lateral error, m.
        lateral: f64,
        /// Heading error, rad.
        heading: f64,
    },
    /// The robot drove into an obstacle (a scenario box).
    Collision {
        /// Index of the obstacle's footprint in the world.
        obstacle: usize,
    },
    /// Time ran out.
    Timeout,
}

/// Track samples reserved up front: ten minutes at two a second.
const TRACK_CAPACITY: usize = 1200;

/// A running simulation.
pub struct Sim {
    profile: Arc<Profile>,
    world: Arc<World>,
    renderers: Vec<Renderer>,
    sensor: SensorParams,
    light: LightingRun,
    /// This tick's lighting (filled when camera 0 renders; its lists keep their
    /// allocation).
    light_now: LightState,
    motion: Motion,
    pose: Pose2,
    /// The true body velocity over the last physics substep: forward m/s, leftward m/s,
    /// yaw rad/s (slip, the pouch's walls and blocking included), which the cameras'
    /// motion blur and rolling shutter see.
    body_velocity: [f64; 3],
    odometry: Odometry,
    tether: Option<Tether>,
    posture: Posture,
    /// The reel's last command.
    reel: Option<TetherCommand>,
    inside: bool,
    docked: bool,
    rng: Rng,
    /// The run's seed (devices derive their own streams from it).
    seed: u64,
    t: f64,
    dt: f64,
    frame_count: u64,
    /// Path length driven (true), m.
    pub path_m: f64,
    /// Drive command changes issued by the behaviors.
    pub drive_changes: u32,
    last_drive: DriveCommand,
    /// Entrance errors of the robot's first arrival at the entrance since it was placed
    /// (lateral m, heading rad): the arrival the judge accepted, or the one it refused.
    pub entrance: Option<(f64, f64)>,
    /// The lateral offset the pouch's walls hold the robot at: its rear's at its latest
    /// entry (0 when placed inside).
    pouch_lateral: f64,
    /// True pose samples (t, x, y, θ) every `track_every` s.
    pub track: Vec<[f64; 4]>,
    track_every: f64,
    /// When the next track sample is due, s.
    next_track: f64,
    /// Ticks spent in safe stop.
    pub safe_stops: u64,
    /// Ticks the behaviors commanded motion while the injected fault had left an input
    /// the loop must not act on ([`FaultSpec::inputs_invalid`]); must stay 0.
    pub stale_motion_ticks: u64,
    encoder_ref: (f64, f64),
    /// The fault injected into this mission, if any ([`super::faults`]).
    fault: Option<FaultSpec>,
    /// What the fault latched when it struck.
    latched: Latched,
    /// The true pose at each of the last ticks (for late frames), oldest first.
    past: VecDeque<(f64, Pose2)>,
    /// When the current mission began, s of simulation time: 0 after [`Sim::place`],
    /// the clock's reading at [`Sim::begin_leg`] in an endurance outing.
    mission_start: f64,
    /// The dock has let go ([`Sim::release`]): contact with the dock's socket does not
    /// hold or judge the robot until it is clear of the dock.
    releasing: bool,
    /// The tether's extremes this mission ([`Sim::tether_tally`]).
    tally: TetherTally,
}

/// Ticks of pose history kept for `camera_late` frames.
const PAST_CAPACITY: usize = 256;

impl Sim {
    /// A simulation of `profile` in `world`. The sensor's frame interval is set to the
    /// loop tick, since every camera renders once a tick.
    pub fn new(
        profile: Arc<Profile>,
        world: Arc<World>,
        light: LightingRun,
        mut sensor: SensorParams,
        motion: Motion,
        dt: f64,
        seed: u64,
    ) -> Self {
        // Every camera renders once a loop tick: that is the sensor's frame interval.
        sensor.frame_interval_s = (1.0 / profile.loop_.rate_hz) as f32;
        let renderers = profile
            .cameras
            .iter()
            .enumerate()
            .map(|(i, c)| {
                Renderer::new(
                    CameraModel::from_spec(c),
                    c.width_px,
                    c.height_px,
                    seed ^ (i as u64 + 1).wrapping_mul(0x9E37),
                )
            })
            .collect();
        // A leading arm's tether runs from its tip to its anchor inside the dock (Axel);
        // otherwise from the body's rear to the dock's entrance (RAPOSA).
        let tether = profile.tether.map(|t| {
            if t.arm_m > 0.0 {
                Tether::with_arm((-t.anchor_depth_m, 0.0), 1.0, t.length_m, t.max_reel_rate_mps, t.arm_m)
            } else {
                Tether::new(
                    (0.0, 0.0),
                    1.0,
                    t.length_m,
                    t.max_reel_rate_mps,
                    profile.body.length_m / 2.0,
                )
            }
        });
        let drive_model = profile.drive.model();
        Self {
            profile,
            world,
            renderers,
            sensor,
            light,
            light_now: LightState::uniform(0.0),
            motion,
            pose: Pose2::default(),
            body_velocity: [0.0; 3],
            odometry: Odometry::new(drive_model, Pose2::default()),
            tether,
            posture: Posture::Raised,
            reel: None,
            inside: false,
            docked: false,
            rng: Rng::new(seed),
            seed,
            t: 0.0,
            dt,
            frame_count: 0,
            path_m: 0.0,
            drive_changes: 0,
            last_drive: DriveCommand::Stop,
            entrance: None,
            pouch_lateral: 0.0,
            // Sized for a ten-minute phase (longer than any campaign's), so the physics
            // step allocates nothing per tick (`tests/no_alloc.rs`).
            track: Vec::with_capacity(TRACK_CAPACITY),
            track_every: 0.5,
            next_track: 0.0,
            safe_stops: 0,
            stale_motion_ticks: 0,
            encoder_ref: (0.0, 0.0),
            fault: None,
            latched: Latched::default(),
            past: VecDeque::with_capacity(PAST_CAPACITY),
            mission_start: 0.0,
            releasing: false,
            tally: TetherTally::default(),
        }
    }

    /// Injects `fault` into the mission that starts now (its clock is this run's, which
    /// [`Sim::place`] restarts), or clears it.
    pub fn set_fault(&mut self, fault: Option<FaultSpec>) {
        self.fault = fault;
        self.latched = Latched::default();
        self.motion.set_side_gain(1.0, 1.0);
    }

    /// The fault injected into this mission, in force or not.
    pub fn fault(&self) -> Option<&FaultSpec> {
        self.fault.as_ref()
    }

    /// The fault in force now, if any.
    pub fn fault_now(&self) -> Option<&FaultSpec> {
        self.fault.as_ref().filter(|f| f.active(self.t))
    }

    /// What camera `i` delivers now: a rendered frame, or what the fault in force makes of
    /// it (nothing, a wrong-sized, black, saturated, late or frozen frame).
    ///
    /// # Errors
    /// [`HardwareError::NotReady`] while a `camera_silent` fault is in force.
    pub fn capture(&mut self, i: usize, frame: &mut RgbImage) -> Result<Exposure, HardwareError> {
        let Some(f) = self.fault_now().cloned() else {
            self.render(i, frame);
            return Ok(Exposure::NOW);
        };
        match f.kind {
            FaultKind::CameraSilent => Err(HardwareError::NotReady),
            FaultKind::CameraLate => {
                let lag = f.lag_s.unwrap_or(0.0);
                let then = self.t - lag;
                let past = self
                    .past
                    .iter()
                    .rev()
                    .find(|(t, _)| *t <= then + 1e-9)
                    .or(self.past.front())
                    .map_or(self.pose, |p| p.1);
                let now = std::mem::replace(&mut self.pose, past);
                self.render(i, frame);
                self.pose = now;
                Ok(Exposure::ago(std::time::Duration::from_secs_f64(lag)))
            }
            FaultKind::CameraFrozen => {
                let frozen = &mut self.latched.frames;
                frozen.resize_with(self.renderers.len(), || None);
                match frozen.get(i).and_then(Option::as_ref) {
                    Some(f) => frame.clone_from(f),
                    None => {
                        self.render(i, frame);
                        self.latched.frames[i] = Some(frame.clone());
                    }
                }
                Ok(Exposure::NOW)
            }
            kind => {
                self.render(i, frame);
                match kind {
                    FaultKind::CameraWrongSize => frame.resize(frame.width() / 2, frame.height() / 2),
                    FaultKind::CameraBlack => frame.as_bytes_mut().fill(0),
                    FaultKind::CameraSaturated => frame.as_bytes_mut().fill(255),
                    _ => {}
                }
                Ok(Exposure::NOW)
            }
        }
    }

    /// Odometry as the base reports it: [`Sim::odometry`], or what the fault in force
    /// makes of it.
    pub fn odometry_reported(&mut self) -> OdometryReading {
        let mut r = self.odometry();
        if let Some(f) = self.fault_now() {
            match f.kind {
                FaultKind::OdometryNan => r.pose.x = f64::NAN,
                FaultKind::OdometryInfinite => r.pose.y = f64::INFINITY,
                FaultKind::OdometryJump => {
                    let [x, y, deg] = f.jump.unwrap_or_default();
                    self.latched.jump.get_or_insert(Pose2::new(x, y, deg.to_radians()));
                }
                FaultKind::OdometryFrozen => r = *self.latched.odometry.get_or_insert(r),
                _ => {}
            }
        }
        if let Some(j) = self.latched.jump {
            r.pose = Pose2::new(r.pose.x + j.x, r.pose.y + j.y, r.pose.theta + j.theta);
        }
        r
    }

    /// The true pose.
    pub fn pose(&self) -> Pose2 {
        self.pose
    }

    /// Simulation time, s.
    pub fn time(&self) -> f64 {
        self.t
    }

    /// True once the robot reached the contact plates.
    pub fn docked(&self) -> bool {
        self.docked
    }

    /// The lighting of this run (to advance its session clock).
    pub fn lighting_mut(&mut self) -> &mut LightingRun {
        &mut self.light
    }

    /// Replaces the lighting programme (e.g. after imprinting under another light). The
    /// sensor's frame interval stays the loop tick.
    pub fn set_lighting(&mut self, light: LightingRun, sensor: SensorParams) {
        self.light = light;
        self.sensor = SensorParams {
            frame_interval_s: self.sensor.frame_interval_s,
            ..sensor
        };
    }

    /// Puts the robot at `pose` (a proctor placing it): stops the motors, restarts
    /// odometry and the run's clocks and counters.
    pub fn place(&mut self, pose: Pose2, inside: bool) {
        self.pose = pose;
        self.body_velocity = [0.0; 3];
        self.motion.halt();
        self.odometry = Odometry::new(self.profile.drive.model(), Pose2::default());
        self.inside = inside;
        self.docked = false;
        self.t = 0.0;
        self.path_m = 0.0;
        self.drive_changes = 0;
        self.entrance = None;
        self.pouch_lateral = 0.0;
        self.track.clear();
        self.next_track = 0.0;
        self.safe_stops = 0;
        self.stale_motion_ticks = 0;
        self.past.clear();
        self.mission_start = 0.0;
        self.releasing = false;
        self.tally = TetherTally::default();
        let last = self.motion.encoders();
        self.encoder_ref = (last.left, last.right);
        if let Some(t) = &mut self.tether {
            t.length = t.distance(&pose);
        }
    }

    /// Starts a new mission of an endurance outing where the robot is, without touching
    /// it: the clock, odometry (with its accumulated error), motors, posture, tether and
    /// cameras go on as they were; only the mission's own tallies restart (path, command
    /// changes, entrance errors, track, safe-stop ticks, the docked flag) and
    /// [`Sim::mission_time`] counts from now.
    pub fn begin_leg(&mut self) {
        self.mission_start = self.t;
        self.path_m = 0.0;
        self.drive_changes = 0;
        self.entrance = None;
        self.track.clear();
        self.next_track = self.t;
        self.safe_stops = 0;
        self.stale_motion_ticks = 0;
        self.docked = false;
        self.tally = TetherTally::default();
    }

    /// Time since the current mission began, s ([`Sim::place`] or [`Sim::begin_leg`]).
    pub fn mission_time(&self) -> f64 {
        self.t - self.mission_start
    }

    /// The dock lets a docked robot go, as the mother's latch would before the daughter
    /// departs: until the robot is clear of the dock, touching its socket neither holds
    /// it (an open dock's socket judges a robot in its mouth docked and stops it) nor
    /// catches it. A closed dock's pouch still guides it out.
    pub fn release(&mut self) {
        self.releasing = true;
    }

    /// The robot is inside a closed dock's pouch.
    pub fn inside(&self) -> bool {
        self.inside
    }

    /// A proctor carries the robot to `pose` (`inside` the pouch or not) and sets it
    /// down, stopped. Unlike [`Sim::place`] nothing else restarts: the wheels did not
    /// turn, so odometry still reads where the robot was, and the clock runs on.
    pub fn carry(&mut self, pose: Pose2, inside: bool) {
        self.pose = pose;
        self.body_velocity = [0.0; 3];
        self.motion.halt();
        self.inside = inside;
        self.docked = false;
        self.pouch_lateral = 0.0;
        self.past.clear();
        if let Some(t) = &mut self.tether {
            t.length = t.distance(&pose);
        }
    }

    fn robot_shadow(&self, light: &mut LightState) {
        let Some(f) = self.profile.fiducial.get::<crate::profile::TwoBlockSpec>().copied() else {
            return;
        };
        let (s, level) = light.sun();
        if level <= 0.0 || s.x <= 0.05 || !self.light.self_shadow_at(self.t) {
            return;
        }
        // The robot's top edge casts a horizontal shadow edge on the plane x = 0.
        let b = &self.profile.body;
        let near = [
            (-b.length_m / 2.0, -b.width_m / 2.0),
            (-b.length_m / 2.0, b.width_m / 2.0),
            (b.length_m / 2.0, 0.0),
        ]
        .map(|(a, c)| self.pose.to_world(a, c));
        let d = near.iter().map(|p| p.0).fold(f64::INFINITY, f64::min).max(0.0);
        let shift = -d * s.y / s.x;
        let y_lo = near.iter().map(|p| p.1).fold(f64::INFINITY, f64::min) + shift;
        let y_hi = near.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max) + shift;
        if y_hi < -f.width_m / 2.0 || y_lo > f.width_m / 2.0 {
            return;
        }
        let top = b.height_m + 0.1 - d * s.z / s.x;
        light.push_target_shadow(ShadowBand {
            cos: 0.0,
            sin: -1.0,
            offset: -(top - f.center_height_m) as f32,
            softness: 0.01,
            strength: 0.75,
        });
    }

    /// The run's seed.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// The profile simulated.
    pub fn profile(&self) -> &Profile {
        &self.profile
    }

    /// The world simulated.
    pub fn world(&self) -> &World {
        &self.world
    }

    /// Frames rendered so far (ticks whose cameras all rendered).
    pub fn frame_count(&self) -> u64 {
        self.frame_count
    }

    /// Renders camera `i` at the true pose into `frame`. Cameras render in order each
    /// tick: camera 0 computes the lighting of this instant, the last one counts the frame.
    pub fn render(&mut self, i: usize, frame: &mut RgbImage) {
        let Some(spec) = self.profile.cameras.get(i) else {
            return;
        };
        if i == 0 {
            self.light.fill(self.t, &mut self.light_now);
            let mut light = std::mem::replace(&mut self.light_now, LightState::uniform(0.0));
            self.robot_shadow(&mut light);
            self.light_now = light;
        }
        if i == 0 && self.fault_now().is_some_and(|f| f.kind == FaultKind::LightsOut) {
            self.light_now.lights_out();
        }
        let pose = camera_pose(&self.pose, &spec.mount);
        if self.sensor.motion_blur || self.sensor.rolling_shutter_readout_s > 0.0 {
            let motion = self.camera_motion(&pose);
            self.renderers[i].set_motion(motion);
        }
        frame.resize(spec.width_px, spec.height_px);
        let seed = self.rng.next_u64() ^ self.frame_count;
        let occluded = self.occluded_scene();
        let scene = occluded.as_deref().unwrap_or(&self.world.scene);
        self.renderers[i].render(scene, &pose, &self.light_now, &self.sensor, seed, frame);
        if i + 1 == self.profile.cameras.len() {
            self.frame_count += 1;
        }
    }

    /// The scene with the occluder in it while an `occluder` fault is in force (built
    /// when it strikes, where the first camera then looks at the target from).
    fn occluded_scene(&mut self) -> Option<Arc<super::scene::Scene>> {
        if !self.fault_now().is_some_and(|f| f.kind == FaultKind::Occluder) {
            return None;
        }
        if self.latched.scene.is_none() {
            let world = &self.world;
            let n = world.target_prims.len().max(1) as f64;
            let target = world
                .target_prims
                .iter()
                .filter_map(|&k| world.scene.prims.get(k))
                .fold(nalgebra::Point3::origin(), |c, p| c + p.shape.centre().coords / n);
            let camera = self
                .profile
                .cameras
                .first()
                .map_or(nalgebra::Point3::new(self.pose.x, self.pose.y, 0.3), |c| {
                    camera_pose(&self.pose, &c.mount).position
                });
            self.latched.scene = Some(Arc::new(faults::occluded(&world.scene, camera, target)));
        }
        self.latched.scene.clone()
    }

    /// The motion of a camera at `pose` (on the robot) during this frame, in the camera
    /// frame: the body's true yaw rate, and the optical centre's velocity (the body's
    /// velocity plus the yaw rate across the mount's lever arm).
    fn camera_motion(&self, pose: &super::render::CameraPose) -> CameraMotion {
        let [v, lateral, omega] = self.body_velocity;
        let (s, c) = self.pose.theta.sin_cos();
        let body = nalgebra::Vector3::new(c * v - s * lateral, s * v + c * lateral, 0.0);
        let arm = pose.position - nalgebra::Point3::new(self.pose.x, self.pose.y, pose.position.z);
        let w = nalgebra::Vector3::new(0.0, 0.0, omega);
        let rt = pose.rotation.transpose();
        let (wc, vc) = (rt * w, rt * (body + w.cross(&arm)));
        CameraMotion {
            omega: [wc.x as f32, wc.y as f32, wc.z as f32],
            velocity: [vc.x as f32, vc.y as f32, vc.z as f32],
        }
    }

    /// The base's odometry (integrated at the physics rate from the simulated wheels, as
    /// a motor controller would).
    pub fn odometry(&self) -> OdometryReading {
        OdometryReading {
            pose: self.odometry.pose(),
            twist: self.odometry.twist(),
        }
    }

    /// The tether's length and reel motor current (`None` without a tether).
    pub fn tether_reading(&self) -> Option<TetherReading> {
        self.tether.map(|t| t.reading())
    }

    /// The tether's largest slack, tension and reel current since the mission began
    /// (`None` without a tether).
    pub fn tether_tally(&self) -> Option<TetherTally> {
        self.tether.map(|_| self.tally)
    }

    /// Queues a drive command on the motors (counting command changes).
    pub fn command_drive(&mut self, drive: DriveCommand) {
        if drive != self.last_drive && !(drive.is_stop() && self.last_drive.is_stop()) {
            self.drive_changes += 1;
        }
        self.last_drive = drive;
        match self
            .fault_now()
            .and_then(|f| f.latency_s.filter(|_| f.kind == FaultKind::CommandLatency))
        {
            Some(latency) => self.motion.command_delayed(self.t, drive, latency),
            None => self.motion.command(self.t, drive),
        }
    }

    /// Sets the reel's command (kept until the next).
    pub fn command_reel(&mut self, reel: TetherCommand) {
        self.reel = Some(reel);
    }

    /// Changes the body's posture.
    pub fn set_posture(&mut self, posture: Posture) {
        self.posture = posture;
    }

    /// Advances the physics by one loop tick (in substeps of the scenario's `dt`); `Some`
    /// when the robot docked, caught the entrance edge or drove into an obstacle.
    pub fn advance(&mut self) -> Option<PhaseEnd> {
        let tick_dt = 1.0 / self.profile.loop_.rate_hz;
        let substeps = ((tick_dt / self.dt).round() as usize).max(1);
        let dt = tick_dt / substeps as f64;
        let (length, width) = (self.profile.body.length_m, self.profile.body.width_m);
        let (gain, reel) = match self.fault_now().map(|f| (f.kind, f.side)) {
            Some((FaultKind::TrackStall, Some(Side::Left))) => ((0.0, 1.0), self.reel),
            Some((FaultKind::TrackStall, _)) => ((1.0, 0.0), self.reel),
            Some((FaultKind::HalfSpeed, _)) => ((0.5, 0.5), self.reel),
            Some((FaultKind::ReelJam, _)) => ((1.0, 1.0), self.reel.map(|r| TetherCommand { reel_rate: 0.0, ..r })),
            _ => ((1.0, 1.0), self.reel),
        };
        if self.fault.is_some() {
            self.motion.set_side_gain(gain.0, gain.1);
        }
        if self.past.len() == PAST_CAPACITY {
            self.past.pop_front();
        }
        self.past.push_back((self.t, self.pose));
        // Seated in this tick: the run ends docked at its end, and nothing later in the
        // tick (the tether still pulling, the halted rover judged again) can undo that.
        let mut seated = false;
        for _ in 0..substeps {
            let from = self.pose;
            let mut to = self.motion.step(self.t, dt, &from, &mut self.rng);
            if let Some(t) = &mut self.tether {
                let pulled = t.step(dt, &to, reel);
                if t.arm_leads() {
                    // Dragged on free wheels, grousers on firm ground rock the rover: a yaw
                    // disturbance growing with the distance dragged (terrain's
                    // `reel_yaw_noise`; none on loose sand).
                    let noise = self.motion.slip_spec().reel_yaw_noise;
                    let dragged = pulled.distance(&to);
                    to = pulled;
                    if noise > 0.0 && dragged > 0.0 {
                        to.theta += noise * dragged.sqrt() * self.rng.normal();
                    }
                    if !seated && t.fouled(&to, length, width) {
                        self.motion.halt();
                        let psi = super::dock::Cone::arm_angle(&to);
                        let lateral = t.attach(&to).1;
                        self.entrance.get_or_insert((lateral, psi));
                        return Some(PhaseEnd::Stuck { lateral, heading: psi });
                    }
                } else {
                    to = pulled;
                }
                self.tally.observe(t, &to, self.t + dt - self.mission_start);
            }
            if let Some(obstacle) = self.world.obstacles.entered(&from, &to, length, width) {
                self.motion.halt();
                return Some(PhaseEnd::Collision { obstacle });
            }
            let lowered = self.posture == Posture::Lowered;
            match judge(&self.world.dock, self.inside, &from, &to, length, width, lowered) {
                Contact::Free => {
                    self.pose = to;
                    self.inside = false;
                    self.releasing = false;
                }
                // Released ([`Sim::release`]): the socket lets the robot drive out.
                Contact::Docked | Contact::Stuck { .. } if self.releasing => {
                    self.pose = to;
                }
                Contact::Blocked => {}
                // A cone's wall turned the rover about its axle to hold the arm's tip.
                Contact::Guided(guided) => {
                    self.pose = guided;
                    self.inside = false;
                }
                Contact::Inside => {
                    if !self.inside {
                        let arrival = (to.to_world(-length / 2.0, 0.0).1, crate::geometry::wrap_angle(to.theta));
                        self.pouch_lateral = arrival.0;
                        // The walls square the robot up at once (below). One that arrived
                        // corner first has its rear centre still a few millimetres short
                        // of the entrance, so it is outside again for a moment and
                        // re-enters squared up: that is not an arrival, and must not
                        // replace the one the judge accepted in the record.
                        self.entrance.get_or_insert(arrival);
                    }
                    self.inside = true;
                    // The pouch's walls guide the robot: it keeps its entrance offset
                    // within the clearance and moves only along the axis.
                    let clearance = (self.world.dock.entrance_half - width / 2.0).max(0.0);
                    self.pose = Pose2::new(to.x, self.pouch_lateral.clamp(-clearance, clearance), 0.0);
                }
                Contact::Docked => {
                    self.pose = to;
                    if let Some(c) = &self.world.dock.cone {
                        // A cone's "entrance": the arm's tip and angle as it seated.
                        self.entrance
                            .get_or_insert((c.tip(&to).1, super::dock::Cone::arm_angle(&to)));
                    }
                    if self.world.dock.open && self.entrance.is_none() {
                        self.entrance =
                            Some((to.to_world(-length / 2.0, 0.0).1, crate::geometry::wrap_angle(to.theta)));
                    }
                    self.docked = true;
                    seated = true;
                    self.motion.halt();
                }
                Contact::Stuck { .. } if seated => {}
                Contact::Stuck { lateral, heading } => {
                    self.entrance = Some((lateral, heading));
                    self.motion.halt();
                    return Some(PhaseEnd::Stuck { lateral, heading });
                }
            }
            // The true body velocity over this substep, in the body frame at its start.
            let (sn, cs) = from.theta.sin_cos();
            let (dx, dy) = (self.pose.x - from.x, self.pose.y - from.y);
            self.body_velocity = [
                (cs * dx + sn * dy) / dt,
                (-sn * dx + cs * dy) / dt,
                crate::geometry::wrap_angle(self.pose.theta - from.theta) / dt,
            ];
            let enc = self.motion.encoders();
            let (dl, dr) = (enc.left - self.encoder_ref.0, enc.right - self.encoder_ref.1);
            self.encoder_ref = (enc.left, enc.right);
            self.odometry.update_wheels(dl, dr, dt);
            self.path_m += self.pose.distance(&from);
            self.t += dt;
            if self.t >= self.next_track {
                self.track.push([self.t, self.pose.x, self.pose.y, self.pose.theta]);
                self.next_track += self.track_every;
            }
        }
        // The true pose each tick, for comparing a replayed run's estimates with the truth
        // (`RUST_LOG=marsupial::sim=trace marsupial dock --index N`).
        tracing::trace!(target: "marsupial::sim", t = self.t, x = self.pose.x, y = self.pose.y, theta_deg = self.pose.theta.to_degrees(), "truth");
        self.docked.then_some(PhaseEnd::Docked)
    }
}
