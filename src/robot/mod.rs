//! The hardware interface: the traits you implement to run marsupial's behaviors on a
//! real robot (the simulator implements the same traits).
//!
//! Implement [`Camera`] and [`Drive`] at least; the rest are optional and only needed by
//! behaviors that use them. Put the parts in a [`Robot`] and hand it to
//! [`crate::arbiter::runtime::run`]. `examples/custom_robot.rs` is a complete, runnable
//! starting point.
//!
//! Every method returns quickly: a camera's `capture` blocks for at most about one frame
//! period and returns [`HardwareError::NotReady`] when no new frame came, so the runtime
//! can shut down promptly.

use crate::perception::RgbImage;
use crate::schemas::{DriveCommand, Guides, Posture, TetherCommand, TetherReading};
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

/// A camera delivering RGB frames.
pub trait Camera: Send {
    /// Frame size (width, height) in pixels; must match the profile.
    fn resolution(&self) -> (usize, usize);
    /// Captures the next frame into `frame` (already sized to `resolution()`).
    ///
    /// # Errors
    /// [`HardwareError::NotReady`] when no frame arrived within about one frame period.
    fn capture(&mut self, frame: &mut RgbImage) -> Result<(), HardwareError>;
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

/// A tether reel.
pub trait TetherReel: Send {
    /// Sets reel rate and wheel free rotation.
    ///
    /// # Errors
    /// On a reel fault.
    fn command(&mut self, command: &TetherCommand) -> Result<(), HardwareError>;
    /// Reads length and tension.
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
    /// Wheel encoders.
    pub encoders: Option<Box<dyn WheelEncoders>>,
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
}

impl Robot {
    /// A robot with cameras and a drive only.
    pub fn new(cameras: Vec<Box<dyn Camera>>, drive: Box<dyn Drive>) -> Self {
        Self {
            cameras,
            drive,
            encoders: None,
            tether: None,
            arm: None,
            lights: None,
            guides: None,
            posture: None,
            dock_sensor: None,
        }
    }
}
