//! The hardware interface: the traits you implement to run marsupial's behaviors on a
//! real robot. The simulator implements the same traits (`sim::robot`), and its campaigns
//! drive the simulated robot through them.
//!
//! Implement [`Camera`] and [`Drive`] at least; the rest are optional and only needed by
//! behaviors that use them. Odometry comes either from [`WheelEncoders`] (the runtime
//! integrates them with the profile's kinematics) or from an [`Odometer`] (a base
//! controller that integrates its own, as ROS's `/odom`). Every other device is a
//! [`Sensor`] or an [`Actuator`] of a kind the profile declares in `[[sensors]]` and
//! `[[actuators]]` ([`crate::profile::devices`]): the tether reel, the dock contact
//! switch, the arm, lights, guides and posture as much as a user's range finder or
//! gripper, each reading or taking numbers whose meaning its kind's typed
//! [`DeviceReading`](crate::schemas::DeviceReading) or
//! [`DeviceCommand`](crate::schemas::DeviceCommand) gives (a reel is two devices, its
//! sensor and its actuator, sharing the driver). Put the parts in a [`Robot`] and
//! hand it to [`crate::arbiter::runtime::run`] (threads, wall clock) or step it with
//! [`crate::arbiter::lockstep::Lockstep`] (one thread, your clock).
//! `examples/custom_robot.rs` is a complete, runnable starting point.
//!
//! Every method returns quickly: a camera's `capture` blocks for at most about one frame
//! period and returns [`HardwareError::NotReady`] when no new frame came, so the runtime
//! can shut down promptly.

mod lending;

pub use lending::{Abandoned, ActuationDevices, DeviceId, SensingDevices};

use crate::perception::RgbImage;
use crate::schemas::{DriveCommand, MotorOutput, OdometryReading};
use std::time::Duration;
use thiserror::Error;

/// A hardware fault or a "nothing new yet".
#[derive(Debug, Clone, PartialEq, Error)]
pub enum HardwareError {
    /// No new data yet (not a fault; the runtime simply tries again).
    #[error("no new data yet")]
    NotReady,
    /// The device is disconnected or unusable.
    #[error("{device} disconnected: {detail}")]
    Disconnected {
        /// Which device.
        device: String,
        /// Details.
        detail: String,
    },
    /// The device rejected a command or returned garbage.
    #[error("{device} fault: {detail}")]
    Fault {
        /// Which device.
        device: String,
        /// Details.
        detail: String,
    },
}

/// When a captured frame was exposed, as far as its driver knows: how long before
/// [`Camera::capture`] returned. A driver that buffers frames (a V4L2 queue, a network
/// camera) knows each buffer's timestamp and reports its age, so the loop stamps the frame
/// at its exposure and a frame that sat in a buffer is caught as stale; a driver that does
/// not know returns [`Exposure::NOW`] and the frame is stamped on arrival.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Exposure {
    /// Age of the frame when `capture` returned.
    pub age: Duration,
}

impl Exposure {
    /// Exposed just now (or the driver cannot tell).
    pub const NOW: Exposure = Exposure { age: Duration::ZERO };

    /// Exposed `age` before `capture` returned.
    pub fn ago(age: Duration) -> Self {
        Self { age }
    }

    /// The loop-clock stamp of a frame that arrived at `arrival`, seconds.
    pub fn stamp(&self, arrival: f64) -> f64 {
        arrival - self.age.as_secs_f64()
    }
}

/// A camera delivering RGB frames.
pub trait Camera: Send {
    /// Frame size (width, height) in pixels; must match the profile.
    fn resolution(&self) -> (usize, usize);
    /// Captures the next frame into `frame` (already sized to `resolution()`) and says
    /// when it was exposed.
    ///
    /// # Errors
    /// [`HardwareError::NotReady`] when no frame arrived within about one frame period.
    fn capture(&mut self, frame: &mut RgbImage) -> Result<Exposure, HardwareError>;
}

/// The base's motors. Receives commands already realised for the profile's drive type
/// (a turn-or-drive base only ever gets `Turn`, `Straight` or `Stop`).
pub trait Drive: Send {
    /// Applies a command until the next one.
    ///
    /// # Errors
    /// On a motor controller fault.
    fn apply(&mut self, command: &DriveCommand) -> Result<(), HardwareError>;
}

/// Cumulative wheel (or track) travel since start, metres.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct WheelTravel {
    /// Left side, m.
    pub left: f64,
    /// Right side, m.
    pub right: f64,
}

/// Wheel encoders; the runtime integrates them into odometry with the profile's model.
pub trait WheelEncoders: Send {
    /// Reads the cumulative travel.
    ///
    /// # Errors
    /// On an encoder fault.
    fn read(&mut self) -> Result<WheelTravel, HardwareError>;
}

/// A base that integrates its own odometry (a motor controller's `/odom`).
pub trait Odometer: Send {
    /// Reads the current estimate (pose in the odometry frame, body twist).
    ///
    /// # Errors
    /// On a fault.
    fn read(&mut self) -> Result<OdometryReading, HardwareError>;
}

/// A sensor declared in the profile's `[[sensors]]` (the tether reel's length, the dock
/// switch, a range finder, an IMU...).
pub trait Sensor: Send {
    /// Writes its latest reading into `values` (cleared before the call); what the values
    /// mean is the sensor's kind's business (a built-in kind's typed reading writes them
    /// with [`DeviceReading::encode`](crate::schemas::DeviceReading::encode)).
    ///
    /// # Errors
    /// [`HardwareError::NotReady`] when nothing new came; a fault otherwise.
    fn read(&mut self, values: &mut Vec<f64>) -> Result<(), HardwareError>;
}

/// An actuator declared in the profile's `[[actuators]]` (the tether reel, an arm, lights,
/// guides, posture, a gripper...), commanded by the values of its kind's command each
/// tick an output has one ([`Auxiliary::set`](crate::schemas::Auxiliary::set)).
pub trait Actuator: Send {
    /// Applies a command until the next one; a built-in kind's typed command reads it with
    /// [`DeviceCommand::decode`](crate::schemas::DeviceCommand::decode).
    ///
    /// # Errors
    /// On a fault, or values the device cannot take.
    fn apply(&mut self, values: &[f64]) -> Result<(), HardwareError>;
}

/// All of one robot's hardware.
pub struct Robot {
    /// Cameras, in the profile's `[[cameras]]` order.
    pub cameras: Vec<Box<dyn Camera>>,
    /// The base.
    pub drive: Box<dyn Drive>,
    /// Wheel encoders (integrated into odometry when there is no [`Odometer`]).
    pub encoders: Option<Box<dyn WheelEncoders>>,
    /// The base's own odometry (preferred over the encoders when both are given).
    pub odometer: Option<Box<dyn Odometer>>,
    /// The profile's `[[sensors]]`, in order.
    pub sensors: Vec<Box<dyn Sensor>>,
    /// The profile's `[[actuators]]`, in order.
    pub actuators: Vec<Box<dyn Actuator>>,
}

/// The robot's sensing side, borrowed apart from its actuation (the threaded runtime
/// polls it on its own thread).
pub struct Sensing<'a> {
    /// Wheel encoders.
    pub encoders: Option<&'a mut Box<dyn WheelEncoders>>,
    /// The base's own odometry.
    pub odometer: Option<&'a mut Box<dyn Odometer>>,
    /// `[[sensors]]`.
    pub sensors: &'a mut [Box<dyn Sensor>],
}

/// The robot's actuation side.
pub struct Actuation<'a> {
    /// The base.
    pub drive: &'a mut Box<dyn Drive>,
    /// `[[actuators]]`.
    pub actuators: &'a mut [Box<dyn Actuator>],
}

impl Actuation<'_> {
    /// Sends `command` to every device it has an opinion for: the drive always; actuator
    /// `i`, of kind `kinds[i]` (the profile's `[[actuators]]` order), only when the
    /// command has one for its kind, so no command leaves the device as it is. `report`
    /// hears each device that failed, by kind.
    pub fn apply<K: AsRef<str>>(
        &mut self,
        command: &MotorOutput,
        kinds: &[K],
        mut report: impl FnMut(&'static str, HardwareError),
    ) {
        self.apply_watched(command, kinds, |_| {}, |device, e| report(device.kind, e));
    }

    /// [`Actuation::apply`], telling `enter` which device it is about to call before each
    /// call, so a watchdog can name the device a blocked call is stuck in.
    pub fn apply_watched<K: AsRef<str>>(
        &mut self,
        command: &MotorOutput,
        kinds: &[K],
        mut enter: impl FnMut(DeviceId),
        mut report: impl FnMut(DeviceId, HardwareError),
    ) {
        let mut call = |device: DeviceId, f: &mut dyn FnMut() -> Result<(), HardwareError>| {
            enter(device);
            if let Err(e) = f() {
                report(device, e);
            }
        };
        call(DeviceId::one("drive"), &mut || self.drive.apply(&command.drive));
        for (i, (a, kind)) in self.actuators.iter_mut().zip(kinds).enumerate() {
            if let Some(c) = command.aux.command(kind.as_ref()) {
                call(DeviceId::nth("actuator", i), &mut || a.apply(c.values()));
            }
        }
    }
}

impl Robot {
    /// A robot with cameras and a drive only.
    pub fn new(cameras: Vec<Box<dyn Camera>>, drive: Box<dyn Drive>) -> Self {
        Self {
            cameras,
            drive,
            encoders: None,
            odometer: None,
            sensors: Vec::new(),
            actuators: Vec::new(),
        }
    }

    /// Borrows the cameras, the sensing side and the actuation side apart.
    pub fn split(&mut self) -> (&mut [Box<dyn Camera>], Sensing<'_>, Actuation<'_>) {
        (
            &mut self.cameras,
            Sensing {
                encoders: self.encoders.as_mut(),
                odometer: self.odometer.as_mut(),
                sensors: &mut self.sensors,
            },
            Actuation {
                drive: &mut self.drive,
                actuators: &mut self.actuators,
            },
        )
    }
}
