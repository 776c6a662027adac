//! The threaded runtime: a thin, impure wrapper around [`ReactiveLoop::tick`].
//!
//! One thread per camera captures into pooled buffers and hands frames to the loop over a
//! one-slot crossbeam channel where the newest frame replaces an unread older one
//! (latest-frame-wins). One sensor thread polls the odometer (or the encoders, integrated
//! into odometry with the profile's kinematics) and the `[[sensors]]` (the tether reel's
//! and dock switch's readings among them). One actuator thread applies commands to the
//! drive and routes each device command to the `[[actuators]]` of its kind. [`run_missions`] starts a robot's missions one after the other. The calling thread runs the loop at the profile's fixed rate, counting
//! overruns (ticks that started late). Stamps come from one monotonic clock started with
//! the run, so `Inputs::now − stamp` is a true age and the staleness check works.
//!
//! # When the robot's own parts fail
//! The loop must never drive on while it cannot see or cannot steer, and a run must end
//! however its devices misbehave:
//! * a stale or missing input stops the base until it is fresh again (the loop's own
//!   check, [`StopReason::Stale`]);
//! * a tick that takes longer than the tightest staleness limit has its command replaced
//!   by a stop ([`StopReason::Overrun`]): the data it was computed from is stale by then;
//! * an actuator that rejects a command puts the base in a safe stop for
//!   [`RuntimeConfig::actuator_hold`] ([`StopReason::ActuatorFault`]); rejections that go
//!   on for [`RuntimeConfig::device_timeout`] end the run ([`AbortReason::DeviceFailing`]);
//! * a driver call that has not returned after [`RuntimeConfig::device_timeout`]
//!   ([`AbortReason::DeviceBlocked`]) or that panicked ([`AbortReason::DevicePanicked`])
//!   ends the run.
//!
//! Every run ends by commanding a stop. The device threads own their devices (lent by
//! [`Robot::lend`]), so a thread stuck inside a driver is left behind rather than joined:
//! the run still returns, and the robot holds a [`crate::robot::Abandoned`] stand-in for
//! each device it could not get back ([`RuntimeReport::abandoned`]).

mod threads;
mod watchdog;

use super::reactive_loop::{LoopStatus, ReactiveLoop, StopReason, TickOutput};
use crate::perception::RgbImage;
use crate::robot::{DeviceId, HardwareError, Robot};
use crate::schemas::{
    Agent, Behavior, CameraInput, CameraInputs, Inputs, Mission, MissionError, MotorOutput, OdometryReading, Outcome,
    SensorInput, SensorInputs, Stamped,
};
use crossbeam::channel::{Receiver, Sender, TrySendError, bounded};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};
use threads::{Clock, SensorOutputs, Shared};
use watchdog::{ActuatorHealth, Watch};

/// Runtime settings.
#[derive(Debug, Clone, PartialEq)]
pub struct RuntimeConfig {
    /// Stop after this long even if no behavior finished (`None`: run until finished or
    /// stopped through the [`StopHandle`]).
    pub max_duration: Option<Duration>,
    /// Polling rate of the encoders (or odometer) and the `[[sensors]]`, Hz.
    pub sensor_rate_hz: f64,
    /// A driver call still running after this long is declared blocked and ends the run;
    /// actuators that keep rejecting commands this long end it too. It is also how long
    /// the run waits, at its end, for each device thread to give its devices back.
    /// Default 1 s: the hardware traits ask every call to return within about a frame
    /// period.
    pub device_timeout: Duration,
    /// After an actuator rejects a command, the base is held in a safe stop this long
    /// before the behaviors' commands are tried again. Default 0.5 s.
    pub actuator_hold: Duration,
    /// A tick that takes longer than this has its command replaced by a stop. `None` (the
    /// default) takes the tightest staleness limit of the loop's inputs, or two periods
    /// when no input has one.
    pub max_tick: Option<Duration>,
}

impl Default for RuntimeConfig {
    fn default() -> Self {
        Self {
            max_duration: None,
            sensor_rate_hz: 50.0,
            device_timeout: Duration::from_secs(1),
            actuator_hold: Duration::from_millis(500),
            max_tick: None,
        }
    }
}

impl RuntimeConfig {
    /// The tick-duration limit for `config`'s loop, s ([`RuntimeConfig::max_tick`]).
    pub fn max_tick_s(&self, config: &super::LoopConfig) -> f64 {
        if let Some(d) = self.max_tick {
            return d.as_secs_f64();
        }
        let st = &config.staleness;
        [st.camera, st.odometry]
            .into_iter()
            .chain(st.sensors.iter().copied())
            .flatten()
            .reduce(f64::min)
            .unwrap_or(2.0 / config.rate_hz.max(1e-3))
    }
}

/// Why the runtime ended a run early.
#[derive(Debug, Clone, PartialEq)]
pub enum AbortReason {
    /// A driver panicked inside a call.
    DevicePanicked {
        /// Which device.
        device: DeviceId,
        /// The panic's message.
        message: String,
    },
    /// A driver call did not return within [`RuntimeConfig::device_timeout`].
    DeviceBlocked {
        /// Which device.
        device: DeviceId,
        /// How long the call had lasted, s.
        for_s: f64,
    },
    /// The actuators kept rejecting the behaviors' commands for
    /// [`RuntimeConfig::device_timeout`].
    DeviceFailing {
        /// The device that rejected the last command.
        device: DeviceId,
        /// How long the rejections had gone on, s.
        for_s: f64,
    },
}

impl std::fmt::Display for AbortReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            AbortReason::DevicePanicked { device, message } => write!(f, "{device} driver panicked: {message}"),
            AbortReason::DeviceBlocked { device, for_s } => {
                write!(f, "{device} blocked in a call for {for_s:.2} s")
            }
            AbortReason::DeviceFailing { device, for_s } => {
                write!(f, "{device} rejected commands for {for_s:.2} s")
            }
        }
    }
}

/// Something that happened during a run.
#[derive(Debug, Clone, PartialEq)]
pub enum RuntimeEvent {
    /// The loop entered a safe stop.
    SafeStop {
        /// Run time, s.
        t: f64,
        /// Why.
        reason: StopReason,
    },
    /// The loop left a safe stop.
    Resumed {
        /// Run time, s.
        t: f64,
    },
    /// The root behavior finished.
    Finished {
        /// Run time, s.
        t: f64,
        /// How.
        outcome: Outcome,
    },
    /// A mission started ([`run_missions`]).
    MissionStarted {
        /// Run time, s.
        t: f64,
        /// Which (`departure`, `docking`).
        mission: &'static str,
    },
    /// The robot could not start a mission ([`run_missions`]); the run ends.
    MissionRefused {
        /// Run time, s.
        t: f64,
        /// Which.
        mission: &'static str,
        /// Why.
        error: MissionError,
    },
    /// The runtime ended the run early; a stop was commanded.
    Aborted {
        /// Run time, s.
        t: f64,
        /// Why.
        reason: AbortReason,
    },
    /// A device thread was still blocked inside a driver when the run ended; the robot
    /// holds a stand-in for this device ([`crate::robot::Abandoned`]).
    Abandoned {
        /// Run time, s.
        t: f64,
        /// Which device.
        device: DeviceId,
    },
    /// A device reported a fault.
    HardwareError {
        /// Run time, s.
        t: f64,
        /// Which device.
        device: &'static str,
        /// The error.
        error: HardwareError,
    },
}

impl RuntimeEvent {
    /// When it happened, run time in s.
    pub fn time(&self) -> f64 {
        match self {
            RuntimeEvent::SafeStop { t, .. }
            | RuntimeEvent::Resumed { t }
            | RuntimeEvent::Finished { t, .. }
            | RuntimeEvent::MissionStarted { t, .. }
            | RuntimeEvent::MissionRefused { t, .. }
            | RuntimeEvent::Aborted { t, .. }
            | RuntimeEvent::Abandoned { t, .. }
            | RuntimeEvent::HardwareError { t, .. } => *t,
        }
    }
}

impl std::fmt::Display for RuntimeEvent {
    /// `  12.30 s  safe stop: camera 0: last data 0.612 s old (limit 0.500 s)`.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:7.2} s  ", self.time())?;
        match self {
            RuntimeEvent::SafeStop { reason, .. } => write!(f, "safe stop: {reason}"),
            RuntimeEvent::Resumed { .. } => f.write_str("resumed"),
            RuntimeEvent::Finished { outcome, .. } => write!(f, "finished: {outcome:?}"),
            RuntimeEvent::MissionStarted { mission, .. } => write!(f, "{mission} started"),
            RuntimeEvent::MissionRefused { error, .. } => write!(f, "refused: {error}"),
            RuntimeEvent::Aborted { reason, .. } => write!(f, "aborted: {reason}"),
            RuntimeEvent::Abandoned { device, .. } => write!(f, "{device} abandoned, still blocked in a call"),
            RuntimeEvent::HardwareError { device, error, .. } => write!(f, "{device}: {error}"),
        }
    }
}

/// Summary of a run.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RuntimeReport {
    /// Ticks run.
    pub ticks: u64,
    /// Ticks that started later than their slot.
    pub overruns: u64,
    /// Longest tick computation, s.
    pub max_tick_s: f64,
    /// Run time, s.
    pub elapsed_s: f64,
    /// Events in order.
    pub events: Vec<RuntimeEvent>,
    /// Outcome when the root behavior finished.
    pub outcome: Option<Outcome>,
    /// The last command sent before the final stop.
    pub last_command: Option<MotorOutput>,
    /// Why the runtime ended the run early, if it did.
    pub aborted: Option<AbortReason>,
    /// Devices left behind blocked in a call; the robot holds stand-ins for them.
    pub abandoned: Vec<DeviceId>,
}

/// Stops a running [`run`] from another thread.
#[derive(Debug, Clone, Default)]
pub struct StopHandle(Arc<AtomicBool>);

impl StopHandle {
    /// A fresh handle.
    pub fn new() -> Self {
        Self::default()
    }
    /// Asks the run to stop (it sends a stop command and returns).
    pub fn stop(&self) {
        self.0.store(true, Ordering::SeqCst);
    }
    /// True once `stop` was called.
    pub fn is_stopped(&self) -> bool {
        self.0.load(Ordering::SeqCst)
    }
}

/// Both ends of a one-slot channel: the sender keeps the receiver so that
/// [`send_latest`] can displace an unread value.
pub(super) type Latest<T> = (Sender<T>, Receiver<T>);

/// Sends `value`, replacing an unread older value (one-slot, latest wins). Returns the
/// displaced value so its buffer can be recycled.
pub(super) fn send_latest<T>(tx: &Sender<T>, rx: &Receiver<T>, value: T) -> Option<T> {
    match tx.try_send(value) {
        Ok(()) => None,
        Err(TrySendError::Full(v)) => {
            let old = rx.try_recv().ok();
            let _ = tx.try_send(v);
            old
        }
        Err(TrySendError::Disconnected(_)) => None,
    }
}

pub(super) fn sleep_until(deadline: Instant, stop: &StopHandle) {
    loop {
        let now = Instant::now();
        if now >= deadline || stop.is_stopped() {
            return;
        }
        std::thread::sleep((deadline - now).min(Duration::from_millis(20)));
    }
}

/// Runs `lp` on `robot` until its root behavior finishes, `stop` is raised, or
/// `config.max_duration` passes. Always ends by commanding a stop.
pub fn run<B: Behavior + ?Sized>(
    robot: &mut Robot,
    lp: &mut ReactiveLoop<B>,
    config: &RuntimeConfig,
    stop: &StopHandle,
) -> RuntimeReport {
    run_with(robot, lp, config, stop, &mut |_, _| {}, &mut |_, _| false)
}

/// Runs `missions` one after the other on the robot `lp` drives: each is started with
/// [`ReactiveLoop::begin`] when the one before it succeeded (a departure that completed,
/// say, before the docking). Returns when the last finishes, one fails, `stop` is raised
/// or `config.max_duration` passes; [`RuntimeEvent::MissionStarted`] marks each start.
/// A mission the robot cannot start ends the run with nothing commanded but a stop.
pub fn run_missions<B: Agent + ?Sized>(
    robot: &mut Robot,
    lp: &mut ReactiveLoop<B>,
    missions: &[Mission],
    config: &RuntimeConfig,
    stop: &StopHandle,
) -> RuntimeReport {
    run_missions_observed(robot, lp, missions, config, stop, &mut |_, _| {})
}

/// [`run_missions`], telling `observe` each tick's run time and loop status as the
/// actuators get its command: a front end that reports progress (the ROS 2 bridge's
/// action feedback) reads the running behavior's phase and retries there. `observe` runs
/// on the loop's thread, between ticks, so it must return quickly.
pub fn run_missions_observed<B: Agent + ?Sized>(
    robot: &mut Robot,
    lp: &mut ReactiveLoop<B>,
    missions: &[Mission],
    config: &RuntimeConfig,
    stop: &StopHandle,
    observe: &mut dyn FnMut(f64, &LoopStatus),
) -> RuntimeReport {
    let Some((first, rest)) = missions.split_first() else {
        return RuntimeReport::default();
    };
    if let Err(e) = lp.begin(first) {
        return RuntimeReport {
            events: vec![RuntimeEvent::MissionRefused {
                t: 0.0,
                mission: first.name(),
                error: e,
            }],
            ..RuntimeReport::default()
        };
    }
    let mut events = vec![RuntimeEvent::MissionStarted {
        t: 0.0,
        mission: first.name(),
    }];
    let mut next = rest.iter();
    let mut report = run_with(robot, lp, config, stop, observe, &mut |lp, t| {
        let Some(m) = next.next() else { return false };
        match lp.begin(m) {
            Ok(()) => {
                events.push(RuntimeEvent::MissionStarted { t, mission: m.name() });
                true
            }
            Err(e) => {
                events.push(RuntimeEvent::MissionRefused {
                    t,
                    mission: m.name(),
                    error: e,
                });
                false
            }
        }
    });
    events.append(&mut report.events);
    // In time order; at one instant a mission's end comes before the next one's start.
    let rank = |e: &RuntimeEvent| u8::from(!matches!(e, RuntimeEvent::Finished { .. }));
    events.sort_by(|a, b| a.time().total_cmp(&b.time()).then(rank(a).cmp(&rank(b))));
    report.events = events;
    report
}

/// The safe-stop events of a run, from each tick's loop status: a stop is reported when it
/// starts and again when its cause changes (a camera that was missing and is now stale),
/// not on every tick it lasts; a resumption when the loop runs again.
#[derive(Debug, Default)]
struct StopEvents {
    /// The cause of the safe stop in force, if any.
    stopped_for: Option<StopReason>,
}

impl StopEvents {
    /// The event this tick's `status` (not `Finished`, which the caller reports) adds.
    fn observe(&mut self, now: f64, status: &LoopStatus) -> Option<RuntimeEvent> {
        match *status {
            LoopStatus::SafeStop { reason } => {
                let new = !self.stopped_for.is_some_and(|r| r.same_cause(&reason));
                self.stopped_for = Some(reason);
                new.then_some(RuntimeEvent::SafeStop { t: now, reason })
            }
            LoopStatus::Finished { .. } => None,
            _ => self.stopped_for.take().map(|_| RuntimeEvent::Resumed { t: now }),
        }
    }
}

/// The loop, with `observe` told each tick's status and `next_mission` asked after each
/// successful finish whether to go on (it starts the next mission on the loop and
/// returns true).
fn run_with<B: Behavior + ?Sized>(
    robot: &mut Robot,
    lp: &mut ReactiveLoop<B>,
    config: &RuntimeConfig,
    stop: &StopHandle,
    observe: &mut dyn FnMut(f64, &LoopStatus),
    next_mission: &mut dyn FnMut(&mut ReactiveLoop<B>, f64) -> bool,
) -> RuntimeReport {
    let clock = Clock(Instant::now());
    let rate = lp.config().rate_hz.max(1e-3);
    let period = Duration::from_secs_f64(1.0 / rate);
    let max_tick_s = config.max_tick_s(lp.config());
    let timeout_s = config.device_timeout.as_secs_f64();
    let hold_s = config.actuator_hold.as_secs_f64();
    let (event_tx, event_rx) = crossbeam::channel::unbounded::<RuntimeEvent>();
    let done = StopHandle::new();
    let mut report = RuntimeReport::default();
    // Room for the events of a normal run (safe stops, resumptions, faults), so reporting
    // one does not allocate on the loop's thread (`tests/no_alloc_runtime.rs`).
    report.events.reserve(64);
    let (cameras, sensing, actuation) = robot.lend();
    let n_sensors = sensing.sensors.len();
    let sensing_ids = sensing.ids();
    let actuation_ids = actuation.ids();
    let shared = |watch: &Arc<Watch>| Shared {
        clock,
        done: done.clone(),
        events: event_tx.clone(),
        watch: watch.clone(),
    };
    let spawn = |name: String, f: Box<dyn FnOnce() + Send>| {
        std::thread::Builder::new()
            .name(name)
            .spawn(f)
            .expect("the OS refused to start a runtime thread");
    };

    // Cameras: latest-frame-wins with a small buffer pool.
    let mut watches = Vec::new();
    let mut frame_rx = Vec::new();
    let mut recycle_tx = Vec::new();
    let mut cameras_back = Vec::new();
    for (i, cam) in cameras.into_iter().enumerate() {
        let (full_tx, full_rx) = bounded::<(f64, RgbImage)>(1);
        let (empty_tx, empty_rx) = bounded::<RgbImage>(3);
        let (w, h) = cam.resolution();
        for _ in 0..2 {
            let _ = empty_tx.try_send(RgbImage::new(w, h));
        }
        let (back_tx, back_rx) = bounded(1);
        let watch = Arc::new(Watch::default());
        let sh = shared(&watch);
        let (full, empty) = ((full_tx, full_rx.clone()), (empty_tx.clone(), empty_rx));
        spawn(
            format!("marsupial-camera-{i}"),
            Box::new(move || threads::camera(i, cam, sh, full, empty, back_tx)),
        );
        watches.push(watch);
        frame_rx.push(full_rx);
        recycle_tx.push(empty_tx);
        cameras_back.push(back_rx);
    }

    // Slow sensors: odometry and the [[sensors]] (their value buffers come
    // back through `values_back` to be reused). The buffer pool is filled up front and used
    // in turn (the channel is FIFO), so every buffer has grown to its sensor's size within
    // the first readings; a reading the loop has no room for gives its buffer back to the
    // pool instead of dropping it. Steady state then allocates nothing, even after the loop
    // falls behind.
    let (odo_tx, odo_rx) = bounded::<Stamped<OdometryReading>>(1);
    let pool = 4 * n_sensors.max(1);
    let (values_tx, values_rx) = bounded::<(usize, f64, Vec<f64>)>(pool);
    let (values_back_tx, values_back_rx) = bounded::<Vec<f64>>(pool);
    for _ in 0..pool {
        let _ = values_back_tx.try_send(Vec::new());
    }
    let (sensing_back_tx, sensing_back) = bounded(1);
    {
        let watch = Arc::new(Watch::default());
        let sh = shared(&watch);
        let out = SensorOutputs {
            odometry: (odo_tx, odo_rx.clone()),
            values: values_tx,
            values_back: (values_back_tx.clone(), values_back_rx),
        };
        let drive_model = lp.config().drive;
        let sensor_period = Duration::from_secs_f64(1.0 / config.sensor_rate_hz.max(1e-3));
        spawn(
            "marsupial-sensors".into(),
            Box::new(move || threads::sensors(sensing, drive_model, sensor_period, sh, out, sensing_back_tx)),
        );
        watches.push(watch);
    }

    // Actuators, each routed its kind's command. Commands are latest-wins too, so a stuck
    // actuator never blocks the loop.
    let (cmd_tx, cmd_rx) = bounded::<(MotorOutput, bool)>(1);
    let health = Arc::new(ActuatorHealth::default());
    let (actuation_back_tx, actuation_back) = bounded(1);
    {
        let watch = Arc::new(Watch::default());
        let sh = shared(&watch);
        let (health, cmd_rx, kinds) = (health.clone(), cmd_rx.clone(), lp.config().devices.actuators.clone());
        spawn(
            "marsupial-actuators".into(),
            Box::new(move || threads::actuators(actuation, &kinds, sh, health, cmd_rx, actuation_back_tx)),
        );
        watches.push(watch);
    }
    drop(event_tx);
    // A behavior that panics still leaves the base commanded to stop and the threads ended.
    let guard = StopOnUnwind {
        done: done.clone(),
        commands: (cmd_tx.clone(), cmd_rx.clone()),
    };

    // The loop itself, on this thread.
    let mut frames: Vec<Option<(f64, RgbImage)>> = (0..frame_rx.len()).map(|_| None).collect();
    let mut sensor_values: Vec<Option<(f64, Vec<f64>)>> = (0..n_sensors).map(|_| None).collect();
    let mut odometry = None;
    let sensor_kinds = lp.config().devices.sensors.clone();
    let mut stops = StopEvents::default();
    let mut next = Instant::now();
    loop {
        if stop.is_stopped() || config.max_duration.is_some_and(|d| clock.0.elapsed() >= d) {
            break;
        }
        for (slot, (rx, recycle)) in frames.iter_mut().zip(frame_rx.iter().zip(&recycle_tx)) {
            while let Ok(f) = rx.try_recv() {
                if let Some((_, old)) = slot.replace(f) {
                    let _ = recycle.try_send(old);
                }
            }
        }
        while let Ok((i, t, v)) = values_rx.try_recv() {
            if let Some((_, old)) = sensor_values[i].replace((t, v)) {
                let _ = values_back_tx.try_send(old);
            }
        }
        while let Ok(o) = odo_rx.try_recv() {
            odometry = Some(o);
        }
        let cams: CameraInputs<'_> = frames
            .iter()
            .map(|f| {
                f.as_ref().map(|(stamp, im)| CameraInput {
                    stamp: *stamp,
                    image: im.view(),
                })
            })
            .collect();
        let sensors: SensorInputs<'_> = sensor_values
            .iter()
            .enumerate()
            .map(|(i, v)| {
                v.as_ref().map(|(stamp, values)| SensorInput {
                    kind: sensor_kinds.get(i).map_or("", String::as_str),
                    stamp: *stamp,
                    values,
                })
            })
            .collect();
        let now = clock.now();
        let inputs = Inputs {
            now,
            cameras: &cams,
            odometry,
            sensors: &sensors,
        };
        let started = Instant::now();
        let TickOutput {
            mut command,
            mut status,
        } = lp.tick(&inputs);
        let tick_s = started.elapsed().as_secs_f64();
        report.max_tick_s = report.max_tick_s.max(tick_s);
        report.ticks += 1;

        // The runtime's own safe stops, over a tick that would move the base.
        let health = health.get();
        let mut abort = watches
            .iter()
            .find_map(|w| w.stuck(now, timeout_s))
            .map(|(device, for_s)| AbortReason::DeviceBlocked { device, for_s });
        if let (Some(since), Some((device, _))) = (health.episode_since, health.last_error)
            && now - since >= timeout_s
        {
            abort.get_or_insert(AbortReason::DeviceFailing {
                device,
                for_s: now - since,
            });
        }
        let moving = matches!(status, LoopStatus::Running { .. } | LoopStatus::Idle);
        let mut from_behaviors = true;
        if moving && tick_s > max_tick_s {
            status = LoopStatus::SafeStop {
                reason: StopReason::Overrun {
                    tick_s,
                    limit_s: max_tick_s,
                },
            };
        } else if let Some((device, t)) = health.last_error
            && moving
            && now - t < hold_s
        {
            status = LoopStatus::SafeStop {
                reason: StopReason::ActuatorFault { device },
            };
        }
        if matches!(status, LoopStatus::SafeStop { .. }) && moving {
            command = MotorOutput::stop();
            from_behaviors = false;
        }
        send_latest(&cmd_tx, &cmd_rx, (command, from_behaviors));
        report.last_command = Some(command);
        observe(now, &status);
        if let LoopStatus::Finished { outcome } = status {
            report.events.push(RuntimeEvent::Finished { t: now, outcome });
            report.outcome = Some(outcome);
            if !(outcome.is_success() && next_mission(lp, now)) {
                break;
            }
        } else if let Some(e) = stops.observe(now, &status) {
            report.events.push(e);
        }
        while let Ok(e) = event_rx.try_recv() {
            if let RuntimeEvent::Aborted { reason, .. } = &e {
                abort.get_or_insert_with(|| reason.clone());
            }
            report.events.push(e);
        }
        if let Some(reason) = abort {
            if !report.events.iter().any(|e| matches!(e, RuntimeEvent::Aborted { .. })) {
                report.events.push(RuntimeEvent::Aborted {
                    t: now,
                    reason: reason.clone(),
                });
            }
            report.aborted = Some(reason);
            break;
        }
        next += period;
        if Instant::now() > next {
            report.overruns += 1;
            next = Instant::now();
        } else {
            sleep_until(next, stop);
        }
    }
    send_latest(&cmd_tx, &cmd_rx, (MotorOutput::stop(), false));
    // The actuator thread applies that stop and ends once every sender is gone.
    drop(guard);
    drop(cmd_tx);
    done.stop();

    // Take the devices back; a thread still inside a driver call is left behind.
    let deadline = Instant::now() + config.device_timeout;
    let mut abandoned = Vec::new();
    for (i, back) in cameras_back.iter().enumerate() {
        match back.recv_deadline(deadline) {
            Ok(cam) => robot.return_camera(i, cam),
            Err(_) => abandoned.push(DeviceId::nth("camera", i)),
        }
    }
    match sensing_back.recv_deadline(deadline) {
        Ok(devices) => robot.return_sensing(devices),
        Err(_) => abandoned.extend(sensing_ids),
    }
    match actuation_back.recv_deadline(deadline) {
        Ok(devices) => robot.return_actuation(devices),
        Err(_) => abandoned.extend(actuation_ids),
    }
    while let Ok(e) = event_rx.try_recv() {
        report.events.push(e);
    }
    let t_end = clock.now();
    report.events.extend(
        abandoned
            .iter()
            .map(|&device| RuntimeEvent::Abandoned { t: t_end, device }),
    );
    report.abandoned = abandoned;
    report.elapsed_s = t_end;
    report
}

/// Commands a stop and ends the device threads if the loop's thread unwinds (a behavior
/// that panicked); a normal end does the same explicitly first.
struct StopOnUnwind {
    done: StopHandle,
    commands: Latest<(MotorOutput, bool)>,
}

impl Drop for StopOnUnwind {
    fn drop(&mut self) {
        if std::thread::panicking() {
            send_latest(&self.commands.0, &self.commands.1, (MotorOutput::stop(), false));
            self.done.stop();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::arbiter::InputKind;

    #[test]
    fn a_stop_is_reported_when_it_starts_and_when_its_cause_changes() {
        let stop = |reason| LoopStatus::SafeStop { reason };
        let stale = |age_s| StopReason::Stale {
            input: InputKind::Camera(0),
            age_s,
            limit_s: 0.25,
        };
        let missing = StopReason::Missing {
            input: InputKind::Camera(0),
        };
        let mut e = StopEvents::default();
        let events: Vec<_> = [
            (0.0, stop(missing)),
            (0.1, stop(missing)),
            (0.2, stop(stale(1.0))),
            (0.3, stop(stale(1.1))),
            (0.4, LoopStatus::Idle),
            (0.5, LoopStatus::Idle),
            (0.6, stop(stale(0.3))),
        ]
        .iter()
        .filter_map(|(t, s)| e.observe(*t, s))
        .collect();
        assert_eq!(
            events,
            vec![
                RuntimeEvent::SafeStop {
                    t: 0.0,
                    reason: missing
                },
                RuntimeEvent::SafeStop {
                    t: 0.2,
                    reason: stale(1.0)
                },
                RuntimeEvent::Resumed { t: 0.4 },
                RuntimeEvent::SafeStop {
                    t: 0.6,
                    reason: stale(0.3)
                },
            ]
        );
    }
}
