//! One simulated docking run, stepped synchronously against the pure reactive loop.
//!
//! Each loop tick: render every camera at the current true pose under the lighting of
//! this instant, hand the frames with odometry, tether and dock-switch readings to the
//! loop, queue the resulting command on the motors, then advance the physics in small
//! steps (motion with latency and slip, tether pull, contact and the docking judge). Time
//! and randomness are the run's own: the same seed reproduces the run bit for bit.

use super::camera::camera_pose;
use super::dock::{Contact, judge};
use super::lighting::{LightState, LightingRun, ShadowBand};
use super::motion::Motion;
use super::render::{Renderer, SensorParams};
use super::rng::Rng;
use super::tether::Tether;
use super::world::World;
use crate::arbiter::{LoopCore, LoopStatus};
use crate::geometry::Pose2;
use crate::kinematics::Odometry;
use crate::perception::RgbImage;
use crate::perception::camera_model::CameraModel;
use crate::profile::Profile;
use crate::schemas::{
    Behavior, CameraInput, CameraInputs, DriveCommand, Inputs, OdometryReading, Outcome, Posture, Stamped,
    TetherCommand,
};

/// How a phase of a run ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PhaseEnd {
    /// The behavior reported an outcome.
    Finished(Outcome),
    /// The robot reached the contact plates.
    Docked,
    /// The robot caught the entrance edge.
    Stuck {
        /// Lateral error, m.
        lateral: f64,
        /// Heading error, rad.
        heading: f64,
    },
    /// Time ran out.
    Timeout,
}

/// Per-frame observer (for recording frames).
pub type FrameHook<'a> = dyn FnMut(u64, f64, &[RgbImage]) + 'a;

/// A running simulation.
pub struct Sim<'w> {
    profile: &'w Profile,
    world: &'w World,
    renderers: Vec<Renderer>,
    frames: Vec<RgbImage>,
    sensor: SensorParams,
    light: LightingRun,
    motion: Motion,
    pose: Pose2,
    odometry: Odometry,
    tether: Option<Tether>,
    posture: Posture,
    inside: bool,
    docked: bool,
    rng: Rng,
    t: f64,
    dt: f64,
    frame_count: u64,
    /// Path length driven (true), m.
    pub path_m: f64,
    /// Drive command changes issued by the behaviors.
    pub drive_changes: u32,
    last_drive: DriveCommand,
    /// Entrance errors when the robot crossed the entrance (lateral m, heading rad).
    pub entrance: Option<(f64, f64)>,
    /// True pose samples (t, x, y, θ) every `track_every` s.
    pub track: Vec<[f64; 4]>,
    track_every: f64,
    /// Ticks spent in safe stop.
    pub safe_stops: u64,
    encoder_ref: (f64, f64),
}

impl<'w> Sim<'w> {
    /// A simulation of `profile` in `world`.
    pub fn new(
        profile: &'w Profile,
        world: &'w World,
        light: LightingRun,
        sensor: SensorParams,
        motion: Motion,
        dt: f64,
        seed: u64,
    ) -> Self {
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
        let frames = profile
            .cameras
            .iter()
            .map(|c| RgbImage::new(c.width_px, c.height_px))
            .collect();
        let tether = profile.tether.map(|t| {
            Tether::new(
                (0.0, 0.0),
                1.0,
                t.length_m,
                t.max_reel_rate_mps,
                profile.body.length_m / 2.0,
            )
        });
        Self {
            profile,
            world,
            renderers,
            frames,
            sensor,
            light,
            motion,
            pose: Pose2::default(),
            odometry: Odometry::new(profile.drive.model(), Pose2::default()),
            tether,
            posture: Posture::Raised,
            inside: false,
            docked: false,
            rng: Rng::new(seed),
            t: 0.0,
            dt,
            frame_count: 0,
            path_m: 0.0,
            drive_changes: 0,
            last_drive: DriveCommand::Stop,
            entrance: None,
            track: Vec::new(),
            track_every: 0.5,
            safe_stops: 0,
            encoder_ref: (0.0, 0.0),
        }
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

    /// Replaces the lighting programme (e.g. after imprinting under another light).
    pub fn set_lighting(&mut self, light: LightingRun, sensor: SensorParams) {
        self.light = light;
        self.sensor = sensor;
    }

    /// Puts the robot at `pose` (a proctor placing it): stops the motors, restarts
    /// odometry and the run's clocks and counters.
    pub fn place(&mut self, pose: Pose2, inside: bool) {
        self.pose = pose;
        self.motion.halt();
        self.odometry = Odometry::new(self.profile.drive.model(), Pose2::default());
        self.inside = inside;
        self.docked = false;
        self.t = 0.0;
        self.path_m = 0.0;
        self.drive_changes = 0;
        self.entrance = None;
        self.track.clear();
        self.safe_stops = 0;
        let last = self.motion.encoders();
        self.encoder_ref = (last.left, last.right);
        if let Some(t) = &mut self.tether {
            t.length = t.distance(&pose);
        }
    }

    fn robot_shadow(&self, light: &mut LightState) {
        let Some(f) = self.profile.fiducial.two_block else {
            return;
        };
        let (s, level) = light.sun();
        if level <= 0.0 || s.x <= 0.05 || !self.light.self_shadow() {
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

    /// Runs `behavior` from the current state until it finishes, the robot docks or gets
    /// stuck, or `max_s` of simulated time pass. `hook` sees every frame.
    pub fn run_phase(
        &mut self,
        behavior: &mut dyn Behavior,
        max_s: f64,
        mut hook: Option<&mut FrameHook<'_>>,
    ) -> PhaseEnd {
        let mut core = LoopCore::new(self.profile.loop_config());
        let tick_dt = 1.0 / self.profile.loop_.rate_hz;
        let substeps = ((tick_dt / self.dt).round() as usize).max(1);
        let dt = tick_dt / substeps as f64;
        let t_end = self.t + max_s;
        let (length, width) = (self.profile.body.length_m, self.profile.body.width_m);
        let mut next_track = self.t;
        // Refilled every tick: its shadow and flasher lists keep their allocation.
        let mut light = LightState::uniform(0.0);
        loop {
            if self.t >= t_end - 1e-9 {
                return PhaseEnd::Timeout;
            }
            // Sense.
            self.light.fill(self.t, &mut light);
            self.robot_shadow(&mut light);
            for (i, spec) in self.profile.cameras.iter().enumerate() {
                let pose = camera_pose(&self.pose, &spec.mount);
                self.renderers[i].render(
                    &self.world.scene,
                    &pose,
                    &light,
                    &self.sensor,
                    self.rng.next_u64() ^ self.frame_count,
                    &mut self.frames[i],
                );
            }
            self.frame_count += 1;
            if let Some(h) = hook.as_mut() {
                h(self.frame_count, self.t, &self.frames);
            }
            let cams: CameraInputs<'_> = self
                .frames
                .iter()
                .map(|f| {
                    Some(CameraInput {
                        stamp: self.t,
                        image: f.view(),
                    })
                })
                .collect();
            let inputs = Inputs {
                now: self.t,
                cameras: &cams,
                odometry: Some(Stamped::new(
                    self.t,
                    OdometryReading {
                        pose: self.odometry.pose(),
                        twist: self.odometry.twist(),
                    },
                )),
                tether: self.tether.map(|t| Stamped::new(self.t, t.reading())),
                dock_contact: Some(Stamped::new(self.t, self.docked)),
            };
            // Decide.
            let out = core.tick(behavior, &inputs);
            drop(cams);
            if matches!(out.status, LoopStatus::SafeStop { .. }) {
                self.safe_stops += 1;
            }
            let drive = out.command.drive;
            if drive != self.last_drive && !(drive.is_stop() && self.last_drive.is_stop()) {
                self.drive_changes += 1;
            }
            self.last_drive = drive;
            self.motion.command(self.t, drive);
            if let Some(p) = out.command.aux.posture {
                self.posture = p;
            }
            let reel: Option<TetherCommand> = out.command.aux.tether;
            if let LoopStatus::Finished { outcome } = out.status {
                return PhaseEnd::Finished(outcome);
            }
            // Act: physics.
            for _ in 0..substeps {
                let from = self.pose;
                let mut to = self.motion.step(self.t, dt, &from, &mut self.rng);
                if let Some(t) = &mut self.tether {
                    to = t.step(dt, &to, reel);
                }
                let lowered = self.posture == Posture::Lowered;
                match judge(&self.world.dock, self.inside, &from, &to, length, width, lowered) {
                    Contact::Free => {
                        self.pose = to;
                        self.inside = false;
                    }
                    Contact::Blocked => {}
                    Contact::Inside => {
                        if !self.inside {
                            self.entrance =
                                Some((to.to_world(-length / 2.0, 0.0).1, crate::geometry::wrap_angle(to.theta)));
                        }
                        self.inside = true;
                        // The pouch's walls guide the robot: it keeps its entrance offset
                        // within the clearance and moves only along the axis.
                        let (lat, _) = self.entrance.unwrap_or((0.0, 0.0));
                        let clearance = (self.world.dock.entrance_half - width / 2.0).max(0.0);
                        self.pose = Pose2::new(to.x, lat.clamp(-clearance, clearance), 0.0);
                    }
                    Contact::Docked => {
                        self.pose = to;
                        if self.world.dock.open && self.entrance.is_none() {
                            self.entrance =
                                Some((to.to_world(-length / 2.0, 0.0).1, crate::geometry::wrap_angle(to.theta)));
                        }
                        self.docked = true;
                        self.motion.halt();
                    }
                    Contact::Stuck { lateral, heading } => {
                        self.entrance = Some((lateral, heading));
                        self.motion.halt();
                        return PhaseEnd::Stuck { lateral, heading };
                    }
                }
                let enc = self.motion.encoders();
                let (dl, dr) = (enc.left - self.encoder_ref.0, enc.right - self.encoder_ref.1);
                self.encoder_ref = (enc.left, enc.right);
                self.odometry.update_wheels(dl, dr, dt);
                self.path_m += (self.pose.x - from.x).hypot(self.pose.y - from.y);
                self.t += dt;
                if self.t >= next_track {
                    self.track.push([self.t, self.pose.x, self.pose.y, self.pose.theta]);
                    next_track += self.track_every;
                }
            }
            if self.docked {
                return PhaseEnd::Docked;
            }
        }
    }
}
