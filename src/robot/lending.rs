//! Lending a robot's devices to threads that may never give them back.
//!
//! The threaded runtime ([`crate::arbiter::runtime`]) polls each camera, the sensors and
//! the actuators on threads of their own. A driver that blocks inside a call (a USB camera
//! whose `capture` never returns, a motor controller stuck on a serial write) would make
//! any thread that must be joined hang the whole run, so the runtime *owns* the devices on
//! its threads: [`Robot::lend`] moves them out, and each thread hands them back when it
//! ends. A thread still blocked when the run is over is left behind; the [`Robot`] then
//! holds an [`Abandoned`] stand-in in that device's place, whose every call fails with
//! [`HardwareError::Disconnected`] naming the device, so the robot value stays usable and
//! honest. The real device is dropped by its thread if its call ever returns. Rebuild the
//! device (reopen the port) to use it again.

use super::{
    Actuation, Actuator, Camera, Drive, Exposure, HardwareError, Odometer, Robot, Sensing, Sensor, WheelEncoders,
    WheelTravel,
};
use crate::perception::RgbImage;
use crate::schemas::{DriveCommand, OdometryReading};
use serde::Serialize;
use std::fmt;

/// One device of a robot: its kind (`camera`, `drive`, `sensor`...) and, for the kinds a
/// robot can have several of, which one (profile order).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub struct DeviceId {
    /// The kind: `camera`, `encoders`, `odometer`, `sensor`, `drive` or `actuator` (the
    /// tether reel, dock switch, arm... are sensors and actuators of their profile kinds).
    pub kind: &'static str,
    /// Which one, for cameras, sensors and actuators.
    pub index: Option<usize>,
}

impl DeviceId {
    /// The one device of a kind.
    pub const fn one(kind: &'static str) -> Self {
        Self { kind, index: None }
    }
    /// Device `index` of a kind.
    pub const fn nth(kind: &'static str, index: usize) -> Self {
        Self {
            kind,
            index: Some(index),
        }
    }
}

impl fmt::Display for DeviceId {
    /// `drive`, `camera 1`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.index {
            Some(i) => write!(f, "{} {i}", self.kind),
            None => f.write_str(self.kind),
        }
    }
}

/// Stands in for a device the runtime had to leave on a blocked thread. Every call fails
/// with [`HardwareError::Disconnected`]; a camera keeps reporting its old resolution.
#[derive(Debug, Clone, Copy)]
pub struct Abandoned {
    /// The device it replaces.
    pub device: DeviceId,
    /// The replaced camera's resolution (zero for other devices).
    pub resolution: (usize, usize),
}

impl Abandoned {
    fn error(&self) -> HardwareError {
        HardwareError::Disconnected {
            device: self.device.to_string(),
            detail: "left blocked inside a call by an earlier run; rebuild the device".into(),
        }
    }
}

impl Camera for Abandoned {
    fn resolution(&self) -> (usize, usize) {
        self.resolution
    }
    fn capture(&mut self, _: &mut RgbImage) -> Result<Exposure, HardwareError> {
        Err(self.error())
    }
}
impl Drive for Abandoned {
    fn apply(&mut self, _: &DriveCommand) -> Result<(), HardwareError> {
        Err(self.error())
    }
}
impl WheelEncoders for Abandoned {
    fn read(&mut self) -> Result<WheelTravel, HardwareError> {
        Err(self.error())
    }
}
impl Odometer for Abandoned {
    fn read(&mut self) -> Result<OdometryReading, HardwareError> {
        Err(self.error())
    }
}
impl Sensor for Abandoned {
    fn read(&mut self, _: &mut Vec<f64>) -> Result<(), HardwareError> {
        Err(self.error())
    }
}
impl Actuator for Abandoned {
    fn apply(&mut self, _: &[f64]) -> Result<(), HardwareError> {
        Err(self.error())
    }
}
/// The sensing devices, owned (lent to the runtime's sensor thread).
pub struct SensingDevices {
    /// Wheel encoders.
    pub encoders: Option<Box<dyn WheelEncoders>>,
    /// The base's own odometry.
    pub odometer: Option<Box<dyn Odometer>>,
    /// `[[sensors]]`.
    pub sensors: Vec<Box<dyn Sensor>>,
}

impl SensingDevices {
    /// The devices it holds.
    pub fn ids(&self) -> Vec<DeviceId> {
        let one = |present: bool, kind| present.then_some(DeviceId::one(kind));
        [
            one(self.encoders.is_some(), "encoders"),
            one(self.odometer.is_some(), "odometer"),
        ]
        .into_iter()
        .flatten()
        .chain((0..self.sensors.len()).map(|i| DeviceId::nth("sensor", i)))
        .collect()
    }

    /// Borrows them as the [`Sensing`] side the odometry integration reads.
    pub fn sensing(&mut self) -> Sensing<'_> {
        Sensing {
            encoders: self.encoders.as_mut(),
            odometer: self.odometer.as_mut(),
            sensors: &mut self.sensors,
        }
    }
}

/// The actuation devices, owned (lent to the runtime's actuator thread).
pub struct ActuationDevices {
    /// The base.
    pub drive: Box<dyn Drive>,
    /// `[[actuators]]`.
    pub actuators: Vec<Box<dyn Actuator>>,
}

impl ActuationDevices {
    /// The devices it holds.
    pub fn ids(&self) -> Vec<DeviceId> {
        std::iter::once(DeviceId::one("drive"))
            .chain((0..self.actuators.len()).map(|i| DeviceId::nth("actuator", i)))
            .collect()
    }

    /// Borrows them as the [`Actuation`] side that applies commands.
    pub fn actuation(&mut self) -> Actuation<'_> {
        Actuation {
            drive: &mut self.drive,
            actuators: &mut self.actuators,
        }
    }
}

/// Takes an optional device out of `slot`, leaving `stand_in` if there was one.
fn take<T: ?Sized>(slot: &mut Option<Box<T>>, stand_in: Box<T>) -> Option<Box<T>> {
    let replacement = slot.is_some().then_some(stand_in);
    std::mem::replace(slot, replacement)
}

impl Robot {
    /// Moves every device out, leaving an [`Abandoned`] stand-in in each one's place until
    /// it is given back with [`Robot::return_camera`], [`Robot::return_sensing`] and
    /// [`Robot::return_actuation`].
    pub fn lend(&mut self) -> (Vec<Box<dyn Camera>>, SensingDevices, ActuationDevices) {
        let gone = |device| Abandoned {
            device,
            resolution: (0, 0),
        };
        let cameras: Vec<Box<dyn Camera>> = self
            .cameras
            .iter()
            .enumerate()
            .map(|(i, c)| {
                Box::new(Abandoned {
                    device: DeviceId::nth("camera", i),
                    resolution: c.resolution(),
                }) as Box<dyn Camera>
            })
            .collect();
        let cameras = std::mem::replace(&mut self.cameras, cameras);
        let (n_sensors, n_actuators) = (self.sensors.len(), self.actuators.len());
        let sensing = SensingDevices {
            encoders: take(&mut self.encoders, Box::new(gone(DeviceId::one("encoders")))),
            odometer: take(&mut self.odometer, Box::new(gone(DeviceId::one("odometer")))),
            sensors: std::mem::replace(
                &mut self.sensors,
                (0..n_sensors)
                    .map(|i| Box::new(gone(DeviceId::nth("sensor", i))) as Box<dyn Sensor>)
                    .collect(),
            ),
        };
        let actuation = ActuationDevices {
            drive: std::mem::replace(&mut self.drive, Box::new(gone(DeviceId::one("drive")))),
            actuators: std::mem::replace(
                &mut self.actuators,
                (0..n_actuators)
                    .map(|i| Box::new(gone(DeviceId::nth("actuator", i))) as Box<dyn Actuator>)
                    .collect(),
            ),
        };
        (cameras, sensing, actuation)
    }

    /// Gives camera `index` back (a no-op for an index the robot does not have).
    pub fn return_camera(&mut self, index: usize, camera: Box<dyn Camera>) {
        if let Some(slot) = self.cameras.get_mut(index) {
            *slot = camera;
        }
    }

    /// Gives the sensing devices back.
    pub fn return_sensing(&mut self, devices: SensingDevices) {
        self.encoders = devices.encoders;
        self.odometer = devices.odometer;
        self.sensors = devices.sensors;
    }

    /// Gives the actuation devices back.
    pub fn return_actuation(&mut self, devices: ActuationDevices) {
        self.drive = devices.drive;
        self.actuators = devices.actuators;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Cam;
    impl Camera for Cam {
        fn resolution(&self) -> (usize, usize) {
            (4, 3)
        }
        fn capture(&mut self, _: &mut RgbImage) -> Result<Exposure, HardwareError> {
            Ok(Exposure::NOW)
        }
    }
    struct Still;
    impl Drive for Still {
        fn apply(&mut self, _: &DriveCommand) -> Result<(), HardwareError> {
            Ok(())
        }
    }
    impl Actuator for Still {
        fn apply(&mut self, _: &[f64]) -> Result<(), HardwareError> {
            Ok(())
        }
    }

    #[test]
    fn lent_devices_leave_stand_ins_that_fail_by_name_until_given_back() {
        let mut robot = Robot::new(vec![Box::new(Cam), Box::new(Cam)], Box::new(Still));
        robot.actuators.push(Box::new(Still));
        let (mut cams, sensing, actuation) = robot.lend();
        assert_eq!(robot.cameras.len(), 2);
        assert_eq!(robot.cameras[1].resolution(), (4, 3));
        let mut frame = RgbImage::new(4, 3);
        match robot.cameras[1].capture(&mut frame) {
            Err(HardwareError::Disconnected { device, .. }) => assert_eq!(device, "camera 1"),
            other => panic!("{other:?}"),
        }
        assert!(robot.drive.apply(&DriveCommand::Stop).is_err());
        assert!(robot.actuators[0].apply(&[1.0]).is_err());
        assert!(robot.encoders.is_none(), "no stand-in for a device the robot never had");

        robot.return_camera(0, cams.remove(0));
        robot.return_sensing(sensing);
        robot.return_actuation(actuation);
        assert!(robot.cameras[0].capture(&mut frame).is_ok());
        assert!(
            robot.cameras[1].capture(&mut frame).is_err(),
            "camera 1 was not given back"
        );
        assert!(robot.drive.apply(&DriveCommand::Stop).is_ok());
        assert!(robot.actuators[0].apply(&[1.0]).is_ok());
    }
}
