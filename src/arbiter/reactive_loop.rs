//! The reactive loop's pure tick: (loop state, timestamped inputs) → (loop state, command).
//!
//! [`ReactiveLoop::tick`] reads no clock, spawns nothing and draws no random number: the
//! same sequence of [`Inputs`] yields the same sequence of commands, bit for bit. Before
//! the behaviors run it checks the inputs the profile declares required; if one is
//! missing, stale, the wrong size or not finite, the loop commands a safe stop, reports
//! why in [`LoopStatus::SafeStop`], and resumes on the first tick whose inputs are good.

use super::repeats::Repeats;
use crate::kinematics::{DriveLimits, DriveModel};
use crate::robot::DeviceId;
use crate::schemas::{
    Agent, Auxiliary, Behavior, DeviceKinds, DriveCommand, Feedback, Inputs, Mission, MissionError, MotorOutput,
    Outcome, Status, TetherCommand,
};
use serde::Serialize;
use std::fmt;

/// Which input a stop reason is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum InputKind {
    /// Camera with this index (profile order).
    Camera(usize),
    /// Odometry.
    Odometry,
    /// The `[[sensors]]` entry with this index (profile order).
    Sensor(usize),
    /// The loop clock itself.
    Clock,
}

impl fmt::Display for InputKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            InputKind::Camera(i) => write!(f, "camera {i}"),
            InputKind::Odometry => f.write_str("odometry"),
            InputKind::Sensor(i) => write!(f, "sensor {i}"),
            InputKind::Clock => f.write_str("clock"),
        }
    }
}

/// Why the loop commanded a safe stop.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "reason", rename_all = "snake_case")]
pub enum StopReason {
    /// A required input has not arrived yet.
    Missing {
        /// The input.
        input: InputKind,
    },
    /// A required input is older than its staleness limit.
    Stale {
        /// The input.
        input: InputKind,
        /// Its age, s.
        age_s: f64,
        /// The limit, s.
        limit_s: f64,
    },
    /// A driver keeps re-sending one reading as new (the same frame, or odometry that
    /// reports motion with an unchanged pose) for longer than the input's staleness limit
    /// ([`Staleness::camera_repeats_stale`]).
    Frozen {
        /// The input.
        input: InputKind,
        /// How long the reading has been re-sent (since it first arrived), s.
        age_s: f64,
        /// The limit, s.
        limit_s: f64,
    },
    /// A frame does not have the size the profile declares.
    BadFrameSize {
        /// The camera.
        camera: usize,
        /// Expected (width, height).
        expected: (usize, usize),
        /// Received (width, height).
        got: (usize, usize),
    },
    /// An input holds NaN or infinity.
    NonFinite {
        /// The input.
        input: InputKind,
    },
    /// The loop time is not finite or went backwards.
    BadClock {
        /// Previous tick time.
        previous: f64,
        /// This tick's time.
        now: f64,
    },
    /// The behaviors proposed a command with NaN or infinity.
    NonFiniteCommand,
    /// The tick took longer than the tightest staleness limit, so by the time its command
    /// could be sent, the data it was computed from was stale (raised by the threaded
    /// runtime, [`crate::arbiter::runtime`], which sends a stop instead).
    Overrun {
        /// How long the tick took, s.
        tick_s: f64,
        /// The limit, s.
        limit_s: f64,
    },
    /// An actuator rejected a command (raised by the threaded runtime, which commands
    /// stops until the device has accepted commands again for a while).
    ActuatorFault {
        /// Which device.
        device: DeviceId,
    },
}

impl StopReason {
    /// The same cause as `other`: the same kind of fault on the same input, whatever the
    /// measured values (a stale input's age grows every tick; it is still one stop).
    pub fn same_cause(&self, other: &StopReason) -> bool {
        use StopReason::*;
        match (self, other) {
            (Missing { input: a }, Missing { input: b })
            | (Stale { input: a, .. }, Stale { input: b, .. })
            | (Frozen { input: a, .. }, Frozen { input: b, .. })
            | (NonFinite { input: a }, NonFinite { input: b }) => a == b,
            (BadFrameSize { camera: a, .. }, BadFrameSize { camera: b, .. }) => a == b,
            (BadClock { .. }, BadClock { .. })
            | (NonFiniteCommand, NonFiniteCommand)
            | (Overrun { .. }, Overrun { .. }) => true,
            (ActuatorFault { device: a }, ActuatorFault { device: b }) => a == b,
            _ => false,
        }
    }
}

impl fmt::Display for StopReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StopReason::Missing { input } => write!(f, "{input}: no data yet"),
            StopReason::Stale { input, age_s, limit_s } => {
                write!(f, "{input}: last data {age_s:.3} s old (limit {limit_s:.3} s)")
            }
            StopReason::Frozen { input, age_s, limit_s } => {
                write!(
                    f,
                    "{input}: the same reading re-sent for {age_s:.3} s (limit {limit_s:.3} s)"
                )
            }
            StopReason::BadFrameSize { camera, expected, got } => write!(
                f,
                "camera {camera}: frame is {}×{}, profile says {}×{}",
                got.0, got.1, expected.0, expected.1
            ),
            StopReason::NonFinite { input } => write!(f, "{input}: value is not finite"),
            StopReason::BadClock { previous, now } => write!(f, "loop clock went from {previous} to {now}"),
            StopReason::NonFiniteCommand => f.write_str("behaviors proposed a non-finite command"),
            StopReason::Overrun { tick_s, limit_s } => {
                write!(
                    f,
                    "tick took {tick_s:.3} s (limit {limit_s:.3} s): its command was stale"
                )
            }
            StopReason::ActuatorFault { device } => write!(f, "{device} rejected a command"),
        }
    }
}

/// Staleness limits (s) of the required inputs; `None` means the input is optional.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Staleness {
    /// Limit for every camera.
    pub camera: Option<f64>,
    /// Limit for odometry.
    pub odometry: Option<f64>,
    /// Limit per `[[sensors]]` entry (profile order: the tether reel and the dock switch
    /// are sensors like the others).
    pub sensors: Vec<Option<f64>>,
    /// Date a frame bit-identical to its camera's last one from when that content first
    /// arrived, so a driver re-sending one frame as new turns stale like a silent camera
    /// ([`StopReason::Frozen`]). On for real cameras (sensor noise makes every exposure
    /// differ); off for noiseless synthetic cameras, whose frames of a still scene repeat.
    /// Odometry that reports motion with an unchanged pose is always dated so.
    pub camera_repeats_stale: bool,
}

/// Static configuration of a loop (built from a profile by
/// [`crate::profile::Profile::loop_config`]).
#[derive(Debug, Clone, PartialEq)]
pub struct LoopConfig {
    /// Tick rate, Hz (used by the threaded runtime and the simulator).
    pub rate_hz: f64,
    /// Required inputs and their staleness limits.
    pub staleness: Staleness,
    /// Expected frame size per camera (profile order).
    pub frame_sizes: Vec<(usize, usize)>,
    /// The base's kinematics, for command realisation.
    pub drive: DriveModel,
    /// The base's limits.
    pub limits: DriveLimits,
    /// The kinds of the profile's `[[sensors]]` and `[[actuators]]`, in order: the loop
    /// drivers ([`Lockstep`](super::Lockstep), the [`runtime`](super::runtime)) label each
    /// reading and route each command by them.
    pub devices: DeviceKinds,
}

/// The loop's status after a tick.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum LoopStatus {
    /// A behavior is running.
    Running {
        /// Its feedback.
        feedback: Feedback,
    },
    /// No behavior was released this tick; the base is stopped.
    Idle,
    /// Inputs are bad; the base is stopped until they recover.
    SafeStop {
        /// Why.
        reason: StopReason,
    },
    /// The root behavior finished; the base stays stopped.
    Finished {
        /// How it ended.
        outcome: Outcome,
    },
}

/// What a tick returns.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TickOutput {
    /// The command to send to the actuators (already realised for the drive).
    pub command: MotorOutput,
    /// The loop's status.
    pub status: LoopStatus,
}

/// The reactive loop: a root behavior (usually an arbiter, or a robot's composed
/// [`Agent`]) plus input checks.
///
/// `B` is the root's type: `dyn Behavior` by default, `dyn Agent` for a robot that takes
/// missions ([`ReactiveLoop::begin`]), or a concrete type to keep its own methods within
/// reach ([`ReactiveLoop::root_mut`]).
pub struct ReactiveLoop<B: Behavior + ?Sized = dyn Behavior> {
    root: Box<B>,
    core: LoopCore,
}

/// The loop's own state (input checks, safe-stop and finish bookkeeping) without a root
/// behavior, for callers that own the behavior themselves.
pub struct LoopCore {
    config: LoopConfig,
    repeats: Repeats,
    last_now: Option<f64>,
    finished: Option<Outcome>,
    stopped: Option<StopReason>,
    ticks: u64,
    safe_stop_ticks: u64,
}

/// The stop an input stamped `stamp` calls for at `now`, if any: [`StopReason::Stale`]
/// when the reading itself is too old, [`StopReason::Frozen`] when it is new but repeats
/// content that arrived at `since`, too long ago.
fn aged(input: InputKind, now: f64, stamp: f64, since: f64, limit: f64) -> Option<StopReason> {
    if !is_fresh(now - stamp, limit) {
        return Some(StopReason::Stale {
            input,
            age_s: now - stamp,
            limit_s: limit,
        });
    }
    (!is_fresh(now - since, limit)).then_some(StopReason::Frozen {
        input,
        age_s: now - since,
        limit_s: limit,
    })
}

/// True when an input of age `age` (s) is within `limit`; NaN ages are never fresh.
fn is_fresh(age: f64, limit: f64) -> bool {
    age.is_finite() && age <= limit
}

/// The command every safe stop sends: base stopped, reel stopped (not free-wheeling),
/// other auxiliaries held.
pub fn safe_stop_command() -> MotorOutput {
    MotorOutput {
        drive: DriveCommand::Stop,
        aux: Auxiliary::with(TetherCommand {
            reel_rate: 0.0,
            free_wheel: false,
        }),
    }
}

impl<B: Behavior + ?Sized> ReactiveLoop<B> {
    /// Builds a loop around `root`.
    pub fn new(root: Box<B>, config: LoopConfig) -> Self {
        Self {
            root,
            core: LoopCore::new(config),
        }
    }

    /// The configuration.
    pub fn config(&self) -> &LoopConfig {
        &self.core.config
    }

    /// Ticks so far.
    pub fn ticks(&self) -> u64 {
        self.core.ticks
    }

    /// Ticks spent in safe stop so far.
    pub fn safe_stop_ticks(&self) -> u64 {
        self.core.safe_stop_ticks
    }

    /// The outcome, once the root behavior has finished.
    pub fn outcome(&self) -> Option<Outcome> {
        self.core.finished
    }

    /// The root behavior.
    pub fn root(&self) -> &B {
        &self.root
    }

    /// The root behavior, to retune it between ticks.
    pub fn root_mut(&mut self) -> &mut B {
        &mut self.root
    }

    /// Runs one tick.
    pub fn tick(&mut self, inputs: &Inputs<'_>) -> TickOutput {
        self.core.tick(&mut *self.root, inputs)
    }
}

impl<B: Agent + ?Sized> ReactiveLoop<B> {
    /// Starts `mission` on the root robot at the next tick. A loop whose previous mission
    /// finished runs again; its clock may restart (a simulator placing the robot anew).
    ///
    /// # Errors
    /// [`MissionError`] when the robot cannot do the mission; the loop is then unchanged.
    pub fn begin(&mut self, mission: &Mission) -> Result<(), MissionError> {
        self.root.begin(mission)?;
        self.core.restart();
        Ok(())
    }
}

impl LoopCore {
    /// Fresh loop state.
    pub fn new(config: LoopConfig) -> Self {
        Self {
            repeats: Repeats::new(config.frame_sizes.len()),
            config,
            last_now: None,
            finished: None,
            stopped: None,
            ticks: 0,
            safe_stop_ticks: 0,
        }
    }

    /// The configuration.
    pub fn config(&self) -> &LoopConfig {
        &self.config
    }

    /// Forgets the finished outcome and the clock, for a new mission (counters are kept).
    pub fn restart(&mut self) {
        self.finished = None;
        self.last_now = None;
        self.repeats.clear();
    }

    /// Ticks so far.
    pub fn ticks(&self) -> u64 {
        self.ticks
    }

    /// Ticks spent in safe stop so far.
    pub fn safe_stop_ticks(&self) -> u64 {
        self.safe_stop_ticks
    }

    /// The outcome, once the root behavior has finished.
    pub fn outcome(&self) -> Option<Outcome> {
        self.finished
    }

    fn check_inputs(&self, inputs: &Inputs<'_>) -> Option<StopReason> {
        let now = inputs.now;
        let previous = self.last_now.unwrap_or(f64::NEG_INFINITY);
        if !now.is_finite() || now < previous {
            return Some(StopReason::BadClock { previous, now });
        }
        for (i, &expected) in self.config.frame_sizes.iter().enumerate() {
            match inputs.camera(i) {
                None => {
                    if self.config.staleness.camera.is_some() {
                        return Some(StopReason::Missing {
                            input: InputKind::Camera(i),
                        });
                    }
                }
                Some(c) => {
                    let got = (c.image.width(), c.image.height());
                    if got != expected {
                        return Some(StopReason::BadFrameSize {
                            camera: i,
                            expected,
                            got,
                        });
                    }
                    if let Some(limit) = self.config.staleness.camera {
                        let since = self.repeats.camera_since(i).unwrap_or(c.stamp);
                        if let Some(reason) = aged(InputKind::Camera(i), now, c.stamp, since, limit) {
                            return Some(reason);
                        }
                    }
                }
            }
        }
        if let Some(o) = inputs.odometry
            && !(o.value.pose.is_finite() && o.value.twist.is_finite() && o.stamp.is_finite())
        {
            return Some(StopReason::NonFinite {
                input: InputKind::Odometry,
            });
        }
        let checks = [(
            InputKind::Odometry,
            self.config.staleness.odometry,
            inputs
                .odometry
                .map(|o| (o.stamp, self.repeats.odometry_since().unwrap_or(o.stamp))),
        )];
        for (i, limit) in self.config.staleness.sensors.iter().enumerate() {
            let input = InputKind::Sensor(i);
            match (inputs.sensor(i), limit) {
                (Some(s), _) if !(s.stamp.is_finite() && s.values.iter().all(|x| x.is_finite())) => {
                    return Some(StopReason::NonFinite { input });
                }
                (None, Some(_)) => return Some(StopReason::Missing { input }),
                (Some(s), Some(limit)) if !is_fresh(now - s.stamp, *limit) => {
                    return Some(StopReason::Stale {
                        input,
                        age_s: now - s.stamp,
                        limit_s: *limit,
                    });
                }
                _ => {}
            }
        }
        for (input, limit, stamp) in checks {
            if let Some(limit) = limit {
                match stamp {
                    None => return Some(StopReason::Missing { input }),
                    Some((stamp, since)) => {
                        if let Some(reason) = aged(input, now, stamp, since, limit) {
                            return Some(reason);
                        }
                    }
                }
            }
        }
        None
    }

    fn enter_stop(&mut self, reason: StopReason, now: f64) -> TickOutput {
        if self.stopped.is_none() {
            tracing::warn!(target: "marsupial::loop", now, %reason, "safe stop");
        }
        self.stopped = Some(reason);
        self.safe_stop_ticks += 1;
        TickOutput {
            command: safe_stop_command(),
            status: LoopStatus::SafeStop { reason },
        }
    }

    /// Runs one tick of `root`.
    pub fn tick<B: Behavior + ?Sized>(&mut self, root: &mut B, inputs: &Inputs<'_>) -> TickOutput {
        self.ticks += 1;
        if let Some(outcome) = self.finished {
            return TickOutput {
                command: MotorOutput::stop(),
                status: LoopStatus::Finished { outcome },
            };
        }
        // Frames are fingerprinted only where a repeat could stop the robot.
        let frames = self.config.staleness.camera_repeats_stale && self.config.staleness.camera.is_some();
        self.repeats.observe(inputs, frames);
        if let Some(reason) = self.check_inputs(inputs) {
            return self.enter_stop(reason, inputs.now);
        }
        self.last_now = Some(inputs.now);
        if let Some(reason) = self.stopped.take() {
            tracing::info!(target: "marsupial::loop", now = inputs.now, %reason, "inputs recovered, resuming");
        }
        let Some(step) = root.tick(&mut (), inputs) else {
            return TickOutput {
                command: MotorOutput::stop(),
                status: LoopStatus::Idle,
            };
        };
        if !step.output.is_finite() {
            return self.enter_stop(StopReason::NonFiniteCommand, inputs.now);
        }
        let drive = self.config.drive.realise(&step.output.drive, &self.config.limits);
        match step.status {
            Status::Running | Status::Event(_) => TickOutput {
                command: MotorOutput {
                    drive,
                    aux: step.output.aux,
                },
                status: LoopStatus::Running {
                    feedback: step.feedback,
                },
            },
            Status::Done(outcome) => {
                tracing::info!(target: "marsupial::loop", now = inputs.now, ?outcome, "behavior finished");
                self.finished = Some(outcome);
                TickOutput {
                    command: MotorOutput {
                        drive: DriveCommand::Stop,
                        aux: step.output.aux,
                    },
                    status: LoopStatus::Finished { outcome },
                }
            }
        }
    }
}
