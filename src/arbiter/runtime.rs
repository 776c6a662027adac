//! The threaded runtime: a thin, impure wrapper around [`ReactiveLoop::tick`].
//!
//! One thread per camera captures into pooled buffers and hands frames to the loop over a
//! one-slot crossbeam channel where the newest frame replaces an unread older one
//! (latest-frame-wins). One sensor thread polls the encoders (integrated into odometry with
//! the profile's kinematics) and the dock switch. One actuator thread applies commands and
//! also reads the tether reel, which is one device for both. The calling thread runs the loop at the profile's fixed rate, counting
//! overruns (ticks that started late). Stamps come from one monotonic clock started with
//! the run, so `Inputs::now − stamp` is a true age and the staleness check works.

use super::reactive_loop::{LoopStatus, ReactiveLoop, StopReason, TickOutput};
use crate::geometry::Pose2;
use crate::kinematics::Odometry;
use crate::perception::RgbImage;
use crate::robot::{HardwareError, Robot, WheelTravel};
use crate::schemas::{
    Behavior, CameraInput, CameraInputs, Inputs, MotorOutput, OdometryReading, Outcome, Stamped, TetherReading,
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
    let t0 = Instant::now();
    let clock = move || t0.elapsed().as_secs_f64();
    let rate = lp.config().rate_hz.max(1e-3);
    let period = Duration::from_secs_f64(1.0 / rate);
    let drive_model = lp.config().drive;
    let (event_tx, event_rx) = crossbeam::channel::unbounded::<RuntimeEvent>();
    let done = StopHandle::new();
    let mut report = RuntimeReport::default();

    std::thread::scope(|s| {
        // Cameras: latest-frame-wins with a small buffer pool.
        let mut frame_rx = Vec::new();
        let mut recycle_tx = Vec::new();
        for cam in robot.cameras.iter_mut() {
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
                        Ok(()) => {
                            let stamp = clock();
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

        // Slow sensors.
        let (odo_tx, odo_rx) = bounded::<Stamped<OdometryReading>>(1);
        let (teth_tx, teth_rx) = bounded::<Stamped<TetherReading>>(1);
        let (dock_tx, dock_rx) = bounded::<Stamped<bool>>(1);
        {
            let encoders = robot.encoders.as_mut();
            let dock = robot.dock_sensor.as_mut();
            let done = done.clone();
            let events = event_tx.clone();
            let sensor_period = Duration::from_secs_f64(1.0 / config.sensor_rate_hz.max(1e-3));
            let (odo_rx2, dock_rx2) = (odo_rx.clone(), dock_rx.clone());
            // The tether reel is shared with the actuator thread; it is read there.
            s.spawn(move || {
                let mut encoders = encoders;
                let mut dock = dock;
                let mut odo = Odometry::new(drive_model, Pose2::default());
                let mut last: Option<(f64, WheelTravel)> = None;
                let mut next = Instant::now();
                while !done.is_stopped() {
                    let t = clock();
                    if let Some(enc) = encoders.as_mut() {
                        match enc.read() {
                            Ok(w) => {
                                if let Some((t_prev, prev)) = last
                                    && t > t_prev
                                {
                                    odo.update_wheels(w.left - prev.left, w.right - prev.right, t - t_prev);
                                }
                                last = Some((t, w));
                                let reading = OdometryReading {
                                    pose: odo.pose(),
                                    twist: odo.twist(),
                                };
                                send_latest(&odo_tx, &odo_rx2, Stamped::new(t, reading));
                            }
                            Err(HardwareError::NotReady) => {}
                            Err(error) => {
                                let _ = events.send(RuntimeEvent::HardwareError {
                                    t,
                                    device: "encoders",
                                    error,
                                });
                            }
                        }
                    }
                    if let Some(d) = dock.as_mut() {
                        match d.in_contact() {
                            Ok(c) => {
                                send_latest(&dock_tx, &dock_rx2, Stamped::new(t, c));
                            }
                            Err(HardwareError::NotReady) => {}
                            Err(error) => {
                                let _ = events.send(RuntimeEvent::HardwareError {
                                    t,
                                    device: "dock_sensor",
                                    error,
                                });
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
            let drive = &mut robot.drive;
            let mut tether = robot.tether.as_mut();
            let mut arm = robot.arm.as_mut();
            let mut lights = robot.lights.as_mut();
            let mut guides = robot.guides.as_mut();
            let mut posture = robot.posture.as_mut();
            let events = event_tx.clone();
            let teth_rx2 = teth_rx.clone();
            s.spawn(move || {
                let report = |device: &'static str, r: Result<(), HardwareError>| {
                    if let Err(error) = r {
                        let _ = events.send(RuntimeEvent::HardwareError {
                            t: clock(),
                            device,
                            error,
                        });
                    }
                };
                loop {
                    match cmd_rx.recv_timeout(Duration::from_millis(20)) {
                        Ok(cmd) => {
                            report("drive", drive.apply(&cmd.drive));
                            if let (Some(t), Some(c)) = (tether.as_mut(), cmd.aux.tether) {
                                report("tether", t.command(&c));
                            }
                            if let (Some(a), Some(p)) = (arm.as_mut(), cmd.aux.arm) {
                                report("arm", a.set_position(p));
                            }
                            if let (Some(l), Some(on)) = (lights.as_mut(), cmd.aux.lights) {
                                report("lights", l.set(on));
                            }
                            if let (Some(g), Some(gc)) = (guides.as_mut(), cmd.aux.guides) {
                                report("guides", g.set(gc));
                            }
                            if let (Some(p), Some(pc)) = (posture.as_mut(), cmd.aux.posture) {
                                report("posture", p.set(pc));
                            }
                        }
                        Err(crossbeam::channel::RecvTimeoutError::Timeout) => {}
                        Err(crossbeam::channel::RecvTimeoutError::Disconnected) => break,
                    }
                    if let Some(t) = tether.as_mut() {
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
        let mut odometry = None;
        let mut tether = None;
        let mut dock_contact = None;
        let mut was_stopped = false;
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
            let now = clock();
            let inputs = Inputs {
                now,
                cameras: &cams,
                odometry,
                tether,
                dock_contact,
            };
            let started = Instant::now();
            let TickOutput { command, status } = lp.tick(&inputs);
            report.max_tick_s = report.max_tick_s.max(started.elapsed().as_secs_f64());
            report.ticks += 1;
            let _ = cmd_tx.send(command);
            report.last_command = Some(command);
            match status {
                LoopStatus::SafeStop { reason } => {
                    if !was_stopped {
                        report.events.push(RuntimeEvent::SafeStop { t: now, reason });
                    }
                    was_stopped = true;
                }
                LoopStatus::Finished { outcome } => {
                    report.events.push(RuntimeEvent::Finished { t: now, outcome });
                    report.outcome = Some(outcome);
                    break;
                }
                _ => {
                    if was_stopped {
                        report.events.push(RuntimeEvent::Resumed { t: now });
                    }
                    was_stopped = false;
                }
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
