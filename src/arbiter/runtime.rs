//! The threaded runtime: a thin, impure wrapper around [`ReactiveLoop::tick`].
//!
//! One thread per camera captures into pooled buffers and hands frames to the loop over a
//! one-slot crossbeam channel where the newest frame replaces an unread older one
//! (latest-frame-wins). One sensor thread polls the odometer (or the encoders, integrated
//! into odometry with the profile's kinematics), the dock switch and the `[[sensors]]`.
//! One actuator thread applies commands and also reads the tether reel, which is one
//! device for both. [`run_missions`] starts a robot's missions one after the other. The calling thread runs the loop at the profile's fixed rate, counting
//! overruns (ticks that started late). Stamps come from one monotonic clock started with
//! the run, so `Inputs::now − stamp` is a true age and the staleness check works.

use super::lockstep::OdometrySource;
use super::reactive_loop::{LoopStatus, ReactiveLoop, StopReason, TickOutput};
use crate::perception::RgbImage;
use crate::robot::{HardwareError, Robot};
use crate::schemas::{
    Agent, Behavior, CameraInput, CameraInputs, Inputs, Mission, MissionError, MotorOutput, OdometryReading, Outcome,
    SensorInput, SensorInputs, Stamped, TetherReading,
};
use crossbeam::channel::{Receiver, Sender, TrySendError, bounded};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Runtime settings.
#[derive(Debug, Clone, PartialEq)]
pub struct RuntimeConfig {
    /// Stop after this long even if no behavior finished (`None`: run until finished or
    /// stopped through the [`StopHandle`]).
    pub max_duration: Option<Duration>,
    /// Polling rate of encoders, tether and dock switch, Hz.
    pub sensor_rate_hz: f64,
}

impl Default for RuntimeConfig {
    fn default() -> Self {
        Self {
            max_duration: None,
            sensor_rate_hz: 50.0,
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

/// Sends `value`, replacing an unread older value (one-slot, latest wins). Returns the
/// displaced value so its buffer can be recycled.
fn send_latest<T>(tx: &Sender<T>, rx: &Receiver<T>, value: T) -> Option<T> {
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

fn sleep_until(deadline: Instant, stop: &StopHandle) {
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
    run_with(robot, lp, config, stop, &mut |_, _| false)
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
    let mut report = run_with(robot, lp, config, stop, &mut |lp, t| {
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

/// The loop, with `next_mission` asked after each successful finish whether to go on
/// (it starts the next mission on the loop and returns true).
fn run_with<B: Behavior + ?Sized>(
    robot: &mut Robot,
    lp: &mut ReactiveLoop<B>,
    config: &RuntimeConfig,
    stop: &StopHandle,
    next_mission: &mut dyn FnMut(&mut ReactiveLoop<B>, f64) -> bool,
) -> RuntimeReport {
    let t0 = Instant::now();
    let clock = move || t0.elapsed().as_secs_f64();
    let rate = lp.config().rate_hz.max(1e-3);
    let period = Duration::from_secs_f64(1.0 / rate);
    let drive_model = lp.config().drive;
    let (event_tx, event_rx) = crossbeam::channel::unbounded::<RuntimeEvent>();
    let done = StopHandle::new();
    let mut report = RuntimeReport::default();
    // Room for the events of a normal run (safe stops, resumptions, faults), so reporting
    // one does not allocate on the loop's thread (`tests/no_alloc_runtime.rs`).
    report.events.reserve(64);
    let (cameras, sensing, mut actuation) = robot.split();
    let n_sensors = sensing.sensors.len();

    std::thread::scope(|s| {
        // Cameras: latest-frame-wins with a small buffer pool.
        let mut frame_rx = Vec::new();
        let mut recycle_tx = Vec::new();
        for cam in cameras.iter_mut() {
            let (full_tx, full_rx) = bounded::<(f64, RgbImage)>(1);
            let (empty_tx, empty_rx) = bounded::<RgbImage>(3);
            let (w, h) = cam.resolution();
            for _ in 0..2 {
                let _ = empty_tx.try_send(RgbImage::new(w, h));
            }
            let rx_for_drop = full_rx.clone();
            let recycle = empty_tx.clone();
            let done = done.clone();
            let events = event_tx.clone();
            s.spawn(move || {
                while !done.is_stopped() {
                    let mut buf = empty_rx.try_recv().unwrap_or_else(|_| RgbImage::new(w, h));
                    buf.resize(w, h);
                    match cam.capture(&mut buf) {
                        Ok(exposure) => {
                            let stamp = exposure.stamp(clock());
                            if let Some((_, old)) = send_latest(&full_tx, &rx_for_drop, (stamp, buf)) {
                                let _ = recycle.try_send(old);
                            }
                        }
                        Err(e) => {
                            let _ = recycle.try_send(buf);
                            if e != HardwareError::NotReady {
                                let _ = events.send(RuntimeEvent::HardwareError {
                                    t: clock(),
                                    device: "camera",
                                    error: e,
                                });
                                std::thread::sleep(Duration::from_millis(10));
                            }
                        }
                    }
                }
            });
            frame_rx.push(full_rx);
            recycle_tx.push(empty_tx);
        }

        // Slow sensors: odometry, dock switch and the [[sensors]] (their value buffers
        // come back through `values_back` to be reused).
        let (odo_tx, odo_rx) = bounded::<Stamped<OdometryReading>>(1);
        let (teth_tx, teth_rx) = bounded::<Stamped<TetherReading>>(1);
        let (dock_tx, dock_rx) = bounded::<Stamped<bool>>(1);
        let pool = 4 * n_sensors.max(1);
        let (values_tx, values_rx) = bounded::<(usize, f64, Vec<f64>)>(pool);
        let (values_back_tx, values_back_rx) = bounded::<Vec<f64>>(pool);
        // The buffer pool is filled up front and used in turn (the channel is FIFO), so
        // every buffer has grown to its sensor's size within the first readings; a reading
        // the loop has no room for gives its buffer back to the pool instead of dropping
        // it. Steady state then allocates nothing, even after the loop falls behind.
        for _ in 0..pool {
            let _ = values_back_tx.try_send(Vec::new());
        }
        {
            let values_back_tx = values_back_tx.clone();
            let mut sensing = sensing;
            let done = done.clone();
            let events = event_tx.clone();
            let sensor_period = Duration::from_secs_f64(1.0 / config.sensor_rate_hz.max(1e-3));
            let (odo_rx2, dock_rx2) = (odo_rx.clone(), dock_rx.clone());
            s.spawn(move || {
                let mut odometry = OdometrySource::new(drive_model);
                let mut next = Instant::now();
                let fault = |t: f64, device: &'static str, error: HardwareError| {
                    if error != HardwareError::NotReady {
                        let _ = events.send(RuntimeEvent::HardwareError { t, device, error });
                    }
                };
                while !done.is_stopped() {
                    let t = clock();
                    match odometry.read(&mut sensing, t) {
                        Some(Ok(reading)) => {
                            send_latest(&odo_tx, &odo_rx2, Stamped::new(t, reading));
                        }
                        Some(Err(e)) => fault(t, "odometry", e),
                        None => {}
                    }
                    if let Some(d) = sensing.dock_sensor.as_mut() {
                        match d.in_contact() {
                            Ok(c) => {
                                send_latest(&dock_tx, &dock_rx2, Stamped::new(t, c));
                            }
                            Err(e) => fault(t, "dock_sensor", e),
                        }
                    }
                    for (i, sensor) in sensing.sensors.iter_mut().enumerate() {
                        let mut buf = values_back_rx.try_recv().unwrap_or_default();
                        buf.clear();
                        match sensor.read(&mut buf) {
                            Ok(()) => {
                                if let Err(full) = values_tx.try_send((i, t, buf)) {
                                    let _ = values_back_tx.try_send(full.into_inner().2);
                                }
                            }
                            Err(e) => {
                                let _ = values_back_tx.try_send(buf);
                                fault(t, "sensor", e);
                            }
                        }
                    }
                    next += sensor_period;
                    sleep_until(next, &done);
                }
            });
        }

        // Actuators (and the tether reel's sensor, which shares the device).
        let (cmd_tx, cmd_rx) = bounded::<MotorOutput>(4);
        {
            let events = event_tx.clone();
            let teth_rx2 = teth_rx.clone();
            s.spawn(move || {
                loop {
                    match cmd_rx.recv_timeout(Duration::from_millis(20)) {
                        Ok(cmd) => actuation.apply(&cmd, |device, error| {
                            let _ = events.send(RuntimeEvent::HardwareError {
                                t: clock(),
                                device,
                                error,
                            });
                        }),
                        Err(crossbeam::channel::RecvTimeoutError::Timeout) => {}
                        Err(crossbeam::channel::RecvTimeoutError::Disconnected) => break,
                    }
                    if let Some(t) = actuation.tether.as_mut() {
                        match t.read() {
                            Ok(r) => {
                                send_latest(&teth_tx, &teth_rx2, Stamped::new(clock(), r));
                            }
                            Err(HardwareError::NotReady) => {}
                            Err(error) => {
                                let _ = events.send(RuntimeEvent::HardwareError {
                                    t: clock(),
                                    device: "tether",
                                    error,
                                });
                            }
                        }
                    }
                }
            });
        }

        // The loop itself, on this thread.
        let mut frames: Vec<Option<(f64, RgbImage)>> = (0..frame_rx.len()).map(|_| None).collect();
        let mut sensor_values: Vec<Option<(f64, Vec<f64>)>> = (0..n_sensors).map(|_| None).collect();
        let mut odometry = None;
        let mut tether = None;
        let mut dock_contact = None;
        let mut stops = StopEvents::default();
        let mut next = Instant::now();
        loop {
            if stop.is_stopped() || config.max_duration.is_some_and(|d| t0.elapsed() >= d) {
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
            while let Ok(t) = teth_rx.try_recv() {
                tether = Some(t);
            }
            while let Ok(d) = dock_rx.try_recv() {
                dock_contact = Some(d);
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
                .map(|v| v.as_ref().map(|(stamp, values)| SensorInput { stamp: *stamp, values }))
                .collect();
            let now = clock();
            let inputs = Inputs {
                now,
                cameras: &cams,
                odometry,
                tether,
                dock_contact,
                sensors: &sensors,
            };
            let started = Instant::now();
            let TickOutput { command, status } = lp.tick(&inputs);
            report.max_tick_s = report.max_tick_s.max(started.elapsed().as_secs_f64());
            report.ticks += 1;
            let _ = cmd_tx.send(command);
            report.last_command = Some(command);
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
                report.events.push(e);
            }
            next += period;
            if Instant::now() > next {
                report.overruns += 1;
                next = Instant::now();
            } else {
                sleep_until(next, stop);
            }
        }
        let _ = cmd_tx.send(MotorOutput::stop());
        drop(cmd_tx);
        done.stop();
    });
    while let Ok(e) = event_rx.try_recv() {
        report.events.push(e);
    }
    report.elapsed_s = t0.elapsed().as_secs_f64();
    report
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
