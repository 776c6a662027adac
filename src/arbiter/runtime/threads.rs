//! The device threads: one per camera, one for the slow sensors, one for the actuators.
//!
//! Each owns its devices (lent by [`Robot::lend`](crate::robot::Robot::lend)) and hands
//! them back through a one-slot channel when it ends, so a thread stuck in a driver call
//! can be left behind instead of hanging the run. Every device call is marked on the
//! thread's [`Watch`] and runs [`guarded`], so a driver that blocks or panics is named.

use super::watchdog::{ActuatorHealth, Watch, guarded};
use super::{AbortReason, Latest, RuntimeEvent, StopHandle, send_latest, sleep_until};
use crate::arbiter::lockstep::OdometrySource;
use crate::kinematics::DriveModel;
use crate::perception::RgbImage;
use crate::robot::{ActuationDevices, Camera, DeviceId, HardwareError, SensingDevices};
use crate::schemas::{MotorOutput, OdometryReading, Stamped};
use crossbeam::channel::{Receiver, RecvTimeoutError, Sender};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// The run's monotonic clock: seconds since the run started.
#[derive(Debug, Clone, Copy)]
pub(super) struct Clock(pub(super) Instant);

impl Clock {
    pub(super) fn now(&self) -> f64 {
        self.0.elapsed().as_secs_f64()
    }
}

/// What every device thread shares with the loop.
#[derive(Clone)]
pub(super) struct Shared {
    pub(super) clock: Clock,
    /// Raised when the run is over.
    pub(super) done: StopHandle,
    pub(super) events: Sender<RuntimeEvent>,
    pub(super) watch: Arc<Watch>,
}

impl Shared {
    fn event(&self, e: RuntimeEvent) {
        let _ = self.events.send(e);
    }

    /// A fault (not a "nothing new yet") of `device`.
    fn fault(&self, device: DeviceId, error: HardwareError) {
        if error != HardwareError::NotReady {
            self.event(RuntimeEvent::HardwareError {
                t: self.clock.now(),
                device: device.kind,
                error,
            });
        }
    }

    /// A driver panicked inside a call to the device on the watch: ask the loop to end.
    fn panicked(&self, fallback: DeviceId, message: String) {
        let device = self.watch.current().unwrap_or(fallback);
        self.watch.leave();
        self.event(RuntimeEvent::Aborted {
            t: self.clock.now(),
            reason: AbortReason::DevicePanicked { device, message },
        });
    }
}

/// A camera's frames, latest-wins, from pooled buffers: `full` carries (stamp, frame) to the
/// loop; `empty` brings buffers back. Ends when the run is over or the driver panicked.
pub(super) fn camera(
    index: usize,
    mut cam: Box<dyn Camera>,
    sh: Shared,
    full: Latest<(f64, RgbImage)>,
    empty: (Sender<RgbImage>, Receiver<RgbImage>),
    back: Sender<Box<dyn Camera>>,
) {
    let id = DeviceId::nth("camera", index);
    let (w, h) = cam.resolution();
    while !sh.done.is_stopped() {
        let mut buf = empty.1.try_recv().unwrap_or_else(|_| RgbImage::new(w, h));
        buf.resize(w, h);
        sh.watch.enter(id, sh.clock.now());
        let result = guarded(|| cam.capture(&mut buf));
        match result {
            Ok(Ok(exposure)) => {
                sh.watch.leave();
                let stamp = exposure.stamp(sh.clock.now());
                if let Some((_, old)) = send_latest(&full.0, &full.1, (stamp, buf)) {
                    let _ = empty.0.try_send(old);
                }
            }
            Ok(Err(e)) => {
                sh.watch.leave();
                let _ = empty.0.try_send(buf);
                if e != HardwareError::NotReady {
                    sh.fault(id, e);
                    std::thread::sleep(Duration::from_millis(10));
                }
            }
            Err(message) => {
                sh.panicked(id, message);
                break;
            }
        }
    }
    let _ = back.send(cam);
}

/// Where the sensor thread delivers: odometry latest-wins; each `[[sensors]]` reading
/// (the tether reel and dock switch among them) as (index, stamp, values) with its buffer
/// recycled through `values_back`.
pub(super) struct SensorOutputs {
    pub(super) odometry: Latest<Stamped<OdometryReading>>,
    pub(super) values: Sender<(usize, f64, Vec<f64>)>,
    pub(super) values_back: (Sender<Vec<f64>>, Receiver<Vec<f64>>),
}

/// Polls odometry (or integrates the encoders) and the `[[sensors]]` at
/// `period` until the run is over.
pub(super) fn sensors(
    mut devices: SensingDevices,
    drive_model: DriveModel,
    period: Duration,
    sh: Shared,
    out: SensorOutputs,
    back: Sender<SensingDevices>,
) {
    let mut odometry = OdometrySource::new(drive_model);
    let mut next = Instant::now();
    while !sh.done.is_stopped() {
        let t = sh.clock.now();
        let round = guarded(|| {
            let mut sensing = devices.sensing();
            let kind = if sensing.odometer.is_some() {
                "odometer"
            } else {
                "encoders"
            };
            sh.watch.enter(DeviceId::one(kind), t);
            match odometry.read(&mut sensing, t) {
                Some(Ok(reading)) => {
                    send_latest(&out.odometry.0, &out.odometry.1, Stamped::new(t, reading));
                }
                Some(Err(e)) => sh.fault(DeviceId::one(kind), e),
                None => {}
            }
            for (i, sensor) in sensing.sensors.iter_mut().enumerate() {
                let mut buf = out.values_back.1.try_recv().unwrap_or_default();
                buf.clear();
                sh.watch.enter(DeviceId::nth("sensor", i), t);
                match sensor.read(&mut buf) {
                    Ok(()) => {
                        if let Err(full) = out.values.try_send((i, t, buf)) {
                            let _ = out.values_back.0.try_send(full.into_inner().2);
                        }
                    }
                    Err(e) => {
                        let _ = out.values_back.0.try_send(buf);
                        sh.fault(DeviceId::nth("sensor", i), e);
                    }
                }
            }
            sh.watch.leave();
        });
        if let Err(message) = round {
            sh.panicked(DeviceId::one("sensor"), message);
            break;
        }
        next += period;
        sleep_until(next, &sh.done);
    }
    let _ = back.send(devices);
}

/// Applies each command (latest wins; `true` when it came from the behaviors rather than
/// the runtime's own safe stop) to the drive and the actuators of `kinds` (profile
/// order), until the loop hangs up.
pub(super) fn actuators(
    mut devices: ActuationDevices,
    kinds: &[String],
    sh: Shared,
    health: Arc<ActuatorHealth>,
    commands: Receiver<(MotorOutput, bool)>,
    back: Sender<ActuationDevices>,
) {
    loop {
        let cmd = match commands.recv_timeout(Duration::from_millis(20)) {
            Ok(cmd) => Some(cmd),
            Err(RecvTimeoutError::Timeout) => None,
            Err(RecvTimeoutError::Disconnected) => break,
        };
        let round = guarded(|| {
            if let Some((command, from_behaviors)) = cmd {
                let mut rejected_by = None;
                devices.actuation().apply_watched(
                    &command,
                    kinds,
                    |device| sh.watch.enter(device, sh.clock.now()),
                    |device, error| {
                        rejected_by.get_or_insert(device);
                        sh.fault(device, error);
                    },
                );
                sh.watch.leave();
                health.record(sh.clock.now(), rejected_by, from_behaviors);
            }
        });
        if let Err(message) = round {
            // Keep serving: the loop ends the run and its final stop still comes this way.
            sh.panicked(DeviceId::one("drive"), message);
        }
    }
    let _ = back.send(devices);
}
