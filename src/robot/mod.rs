//! The hardware interface: the traits you implement to run marsupial's behaviors on a
//! real robot. The simulator implements the same traits (`sim::robot`), and its campaigns
//! drive the simulated robot through them.
//!
//! Implement [`Camera`] and [`Drive`] at least; the rest are optional and only needed by
//! behaviors that use them. Odometry comes either from [`WheelEncoders`] (the runtime
//! integrates them with the profile's kinematics) or from an [`Odometer`] (a base
//! controller that integrates its own, as ROS's `/odom`). Devices the crate has no field
//! for are [`Sensor`]s and [`Actuator`]s declared by kind in the profile's `[[sensors]]`
//! and `[[actuators]]` ([`crate::profile::devices`]). Put the parts in a [`Robot`] and
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
use crate::schemas::{DriveCommand, Guides, MotorOutput, OdometryReading, Posture, TetherCommand, TetherReading};
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

/// A sensor declared in the profile's `[[sensors]]` (a range finder, an IMU...).
pub trait Sensor: Send {
    /// Writes its latest reading into `values` (cleared before the call); what the values
    /// mean is the sensor's kind's business.
    ///
    /// # Errors
    /// [`HardwareError::NotReady`] when nothing new came; a fault otherwise.
    fn read(&mut self, values: &mut Vec<f64>) -> Result<(), HardwareError>;
}

/// An actuator declared in the profile's `[[actuators]]` (a gripper, a beacon...),
/// commanded by one number per tick
/// ([`Auxiliary::actuators`](crate::schemas::Auxiliary::actuators)).
pub trait Actuator: Send {
    /// Applies a command until the next one.
    ///
    /// # Errors
    /// On a fault.
    fn apply(&mut self, value: f64) -> Result<(), HardwareError>;
}

/// A tether reel.
pub trait TetherReel: Send {
    /// Sets reel rate and wheel free rotation.
    ///
    /// # Errors
    /// On a reel fault.
    fn command(&mut self, command: &TetherCommand) -> Result<(), HardwareError>;
    /// Reads length and the reel motor's current (no tension: see [`TetherReading`]).
    ///
    /// # Errors
    /// On a sensor fault.
    fn read(&mut self) -> Result<TetherReading, HardwareError>;
}

/// An arm (or camera mast) with one position.
pub trait Arm: Send {
    /// Moves to `position` rad.
    ///
    /// # Errors
    /// On a fault.
    fn set_position(&mut self, position: f64) -> Result<(), HardwareError>;
}

/// Lights.
pub trait Lights: Send {
    /// Switches the lights.
    ///
    /// # Errors
    /// On a fault.
    fn set(&mut self, on: bool) -> Result<(), HardwareError>;
}

/// Dock guides.
pub trait DockGuides: Send {
    /// Opens or closes the guides.
    ///
    /// # Errors
    /// On a fault.
    fn set(&mut self, guides: Guides) -> Result<(), HardwareError>;
}

/// Geometry changes (raise or lower the body).
pub trait BodyPosture: Send {
    /// Changes posture.
    ///
    /// # Errors
    /// On a fault.
    fn set(&mut self, posture: Posture) -> Result<(), HardwareError>;
}

/// A dock contact sensor (pressure plates).
pub trait DockSensor: Send {
    /// True when the robot is in the dock.
    ///
    /// # Errors
    /// On a fault.
    fn in_contact(&mut self) -> Result<bool, HardwareError>;
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
    /// Tether reel.
    pub tether: Option<Box<dyn TetherReel>>,
    /// Arm.
    pub arm: Option<Box<dyn Arm>>,
    /// Lights.
    pub lights: Option<Box<dyn Lights>>,
    /// Dock guides.
    pub guides: Option<Box<dyn DockGuides>>,
    /// Posture actuator.
    pub posture: Option<Box<dyn BodyPosture>>,
    /// Dock contact sensor.
    pub dock_sensor: Option<Box<dyn DockSensor>>,
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
    /// Dock contact sensor.
    pub dock_sensor: Option<&'a mut Box<dyn DockSensor>>,
    /// `[[sensors]]`.
    pub sensors: &'a mut [Box<dyn Sensor>],
}

/// The robot's actuation side (and the tether reel, which is one device for reading and
/// commanding).
pub struct Actuation<'a> {
    /// The base.
    pub drive: &'a mut Box<dyn Drive>,
    /// Tether reel.
    pub tether: Option<&'a mut Box<dyn TetherReel>>,
    /// Arm.
    pub arm: Option<&'a mut Box<dyn Arm>>,
    /// Lights.
    pub lights: Option<&'a mut Box<dyn Lights>>,
    /// Dock guides.
    pub guides: Option<&'a mut Box<dyn DockGuides>>,
    /// Posture actuator.
    pub posture: Option<&'a mut Box<dyn BodyPosture>>,
    /// `[[actuators]]`.
    pub actuators: &'a mut [Box<dyn Actuator>],
}

impl Actuation<'_> {
    /// Sends `command` to every device it has an opinion for (the drive always; an
    /// auxiliary only when the command sets it, so `None` leaves the device as it is).
    /// `report` hears each device that failed, by name.
    pub fn apply(&mut self, command: &MotorOutput, mut report: impl FnMut(&'static str, HardwareError)) {
        self.apply_watched(command, |_| {}, |device, e| report(device.kind, e));
    }

    /// [`Actuation::apply`], telling `enter` which device it is about to call before each
    /// call, so a watchdog can name the device a blocked call is stuck in.
    pub fn apply_watched(
        &mut self,
        command: &MotorOutput,
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
        let aux = &command.aux;
        if let (Some(t), Some(c)) = (self.tether.as_mut(), aux.tether) {
            call(DeviceId::one("tether"), &mut || t.command(&c));
        }
        if let (Some(a), Some(p)) = (self.arm.as_mut(), aux.arm) {
            call(DeviceId::one("arm"), &mut || a.set_position(p));
        }
        if let (Some(l), Some(on)) = (self.lights.as_mut(), aux.lights) {
            call(DeviceId::one("lights"), &mut || l.set(on));
        }
        if let (Some(g), Some(gc)) = (self.guides.as_mut(), aux.guides) {
            call(DeviceId::one("guides"), &mut || g.set(gc));
        }
        if let (Some(p), Some(pc)) = (self.posture.as_mut(), aux.posture) {
            call(DeviceId::one("posture"), &mut || p.set(pc));
        }
        for (i, (a, v)) in self.actuators.iter_mut().zip(aux.actuators).enumerate() {
            if let Some(v) = v {
                call(DeviceId::nth("actuator", i), &mut || a.apply(v));
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
            tether: None,
            arm: None,
            lights: None,
            guides: None,
            posture: None,
            dock_sensor: None,
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
                dock_sensor: self.dock_sensor.as_mut(),
                sensors: &mut self.sensors,
            },
            Actuation {
                drive: &mut self.drive,
                tether: self.tether.as_mut(),
                arm: self.arm.as_mut(),
                lights: self.lights.as_mut(),
                guides: self.guides.as_mut(),
                posture: self.posture.as_mut(),
                actuators: &mut self.actuators,
            },
        )
    }
}
