//! Stepping a robot in lockstep with the loop: sense, tick, act, on one thread, on the
//! caller's clock.
//!
//! [`Lockstep::tick`] reads every device of a [`Robot`] through the hardware traits,
//! builds this tick's [`Inputs`], ticks the [`ReactiveLoop`] and sends the command back
//! through the same traits. It reads no clock: `now` comes from the caller. The simulator
//! drives its simulated robot this way (render, decide, act, then advance the physics),
//! which is what makes a campaign reproducible bit for bit; a real robot whose drivers
//! answer immediately can be run the same way from a timer. The threaded
//! [`runtime`](super::runtime) runs the same tick against the same traits with one thread
//! per device group and a wall clock.
//!
//! A device that has nothing new ([`HardwareError::NotReady`]) keeps its last reading
//! and stamp, so a camera that stopped delivering turns stale and the loop stops the
//! robot safely; a device fault is kept in [`Lockstep::take_errors`] as well. Buffers are
//! sized once: a steady-state tick allocates nothing.

use super::reactive_loop::{LoopConfig, ReactiveLoop, TickOutput};
use crate::geometry::Pose2;
use crate::kinematics::{DriveModel, Odometry};
use crate::perception::RgbImage;
use crate::robot::{HardwareError, Robot, Sensing, WheelTravel};
use crate::schemas::{
    Behavior, CameraInput, CameraInputs, DeviceKinds, Inputs, OdometryReading, SensorInput, SensorInputs, Stamped,
};

/// A device fault seen during a tick: (loop time, device, error).
pub type DeviceFault = (f64, &'static str, HardwareError);

/// Odometry from the base's own [`Odometer`](crate::robot::Odometer), or integrated from
/// its [`WheelEncoders`](crate::robot::WheelEncoders) with the profile's kinematics.
pub(crate) struct OdometrySource {
    odo: Odometry,
    last: Option<(f64, WheelTravel)>,
}

impl OdometrySource {
    pub(crate) fn new(model: DriveModel) -> Self {
        Self {
            odo: Odometry::new(model, Pose2::default()),
            last: None,
        }
    }

    /// Reads the odometer, or the encoders (integrating the travel since the last read at
    /// time `t`); `None` when the robot has neither.
    pub(crate) fn read(&mut self, s: &mut Sensing<'_>, t: f64) -> Option<Result<OdometryReading, HardwareError>> {
        if let Some(o) = s.odometer.as_mut() {
            return Some(o.read());
        }
        let enc = s.encoders.as_mut()?;
        Some(enc.read().map(|w| {
            if let Some((t_prev, prev)) = self.last
                && t > t_prev
            {
                self.odo
                    .update_wheels(w.left - prev.left, w.right - prev.right, t - t_prev);
            }
            self.last = Some((t, w));
            OdometryReading {
                pose: self.odo.pose(),
                twist: self.odo.twist(),
            }
        }))
    }
}

/// Keeps a device's reading, or notes its fault; `NotReady` keeps the old one.
fn keep<T>(
    slot: &mut Option<Stamped<T>>,
    r: Result<T, HardwareError>,
    now: f64,
    device: &'static str,
    errors: &mut Vec<DeviceFault>,
) {
    match r {
        Ok(v) => *slot = Some(Stamped::new(now, v)),
        Err(HardwareError::NotReady) => {}
        Err(e) => errors.push((now, device, e)),
    }
}

/// One-thread driver of a robot and its loop (see the module docs).
pub struct Lockstep {
    frames: Vec<RgbImage>,
    frame_stamps: Vec<Option<f64>>,
    odometry_source: OdometrySource,
    odometry: Option<Stamped<OdometryReading>>,
    kinds: DeviceKinds,
    sensor_values: Vec<Vec<f64>>,
    sensor_stamps: Vec<Option<f64>>,
    scratch: Vec<f64>,
    errors: Vec<DeviceFault>,
}

impl Lockstep {
    /// Buffers for `robot`'s devices, with frame sizes and kinematics from `config`.
    pub fn new(robot: &Robot, config: &LoopConfig) -> Self {
        let frames = robot
            .cameras
            .iter()
            .enumerate()
            .map(|(i, c)| {
                let (w, h) = config.frame_sizes.get(i).copied().unwrap_or_else(|| c.resolution());
                RgbImage::new(w, h)
            })
            .collect::<Vec<_>>();
        let n = robot.sensors.len();
        Self {
            frame_stamps: vec![None; frames.len()],
            frames,
            odometry_source: OdometrySource::new(config.drive),
            odometry: None,
            kinds: config.devices.clone(),
            sensor_values: vec![Vec::with_capacity(64); n],
            sensor_stamps: vec![None; n],
            scratch: Vec::with_capacity(64),
            errors: Vec::new(),
        }
    }

    /// The last frame of each camera (what the loop saw this tick).
    pub fn frames(&self) -> &[RgbImage] {
        &self.frames
    }

    /// Device faults since the last call, oldest first.
    pub fn take_errors(&mut self) -> std::vec::Drain<'_, DeviceFault> {
        self.errors.drain(..)
    }

    /// Reads every device at time `now`.
    pub fn sense(&mut self, robot: &mut Robot, now: f64) {
        let (cameras, mut sensing, _) = robot.split();
        for (i, cam) in cameras.iter_mut().enumerate() {
            if let Some(frame) = self.frames.get_mut(i) {
                match cam.capture(frame) {
                    Ok(exposure) => self.frame_stamps[i] = Some(exposure.stamp(now)),
                    Err(HardwareError::NotReady) => {}
                    Err(e) => self.errors.push((now, "camera", e)),
                }
            }
        }
        if let Some(r) = self.odometry_source.read(&mut sensing, now) {
            keep(&mut self.odometry, r, now, "odometry", &mut self.errors);
        }
        for (i, s) in sensing.sensors.iter_mut().enumerate() {
            self.scratch.clear();
            match s.read(&mut self.scratch) {
                Ok(()) => {
                    std::mem::swap(&mut self.sensor_values[i], &mut self.scratch);
                    self.sensor_stamps[i] = Some(now);
                }
                Err(HardwareError::NotReady) => {}
                Err(e) => self.errors.push((now, "sensor", e)),
            }
        }
    }

    /// Senses at `now`, ticks `lp` on what was read, and sends the command to the robot.
    pub fn tick<B: Behavior + ?Sized>(&mut self, robot: &mut Robot, lp: &mut ReactiveLoop<B>, now: f64) -> TickOutput {
        self.sense(robot, now);
        let cams: CameraInputs<'_> = self
            .frames
            .iter()
            .zip(&self.frame_stamps)
            .map(|(f, s)| s.map(|stamp| CameraInput { stamp, image: f.view() }))
            .collect();
        let kinds = &self.kinds;
        let sensors: SensorInputs<'_> = self
            .sensor_values
            .iter()
            .zip(&self.sensor_stamps)
            .enumerate()
            .map(|(i, (v, s))| {
                s.map(|stamp| SensorInput {
                    kind: kinds.sensors.get(i).map_or("", String::as_str),
                    stamp,
                    values: v,
                })
            })
            .collect();
        let inputs = Inputs {
            now,
            cameras: &cams,
            odometry: self.odometry,
            sensors: &sensors,
        };
        let out = lp.tick(&inputs);
        let (_, _, mut actuation) = robot.split();
        let errors = &mut self.errors;
        actuation.apply(&out.command, &self.kinds.actuators, |device, e| {
            errors.push((now, device, e))
        });
        out
    }
}
