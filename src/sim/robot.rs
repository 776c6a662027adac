//! The simulated robot behind the same hardware traits a real one implements.
//!
//! [`SimRobot`] shares one [`Sim`] between its devices: [`SimRobot::robot`] hands out a
//! [`Robot`] whose cameras render the simulated world, whose drive queues commands on the
//! simulated motors, whose odometer reads the wheels' integrated odometry, and so on. The
//! campaign steps that `Robot` in lockstep with the reactive loop
//! ([`Lockstep`](crate::arbiter::Lockstep)) and advances the physics between ticks; the
//! threaded runtime can drive it too, with [`SimRobot::run_physics`] advancing the world
//! on the wall clock (`examples/bujold_on_threads.rs`).
//!
//! The robot has the devices its profile declares in `[[sensors]]` and `[[actuators]]`,
//! built by kind from a [`SimDevices`] table: the `range` kind casts its beams against the
//! world's obstacles and the dock ([`super::range`]); the tether reel, dock switch and
//! posture act on the simulated world, the arm, lights and guides are accepted with no
//! effect on it ([`super::devices`]); a user's crate adds simulated devices for its own
//! kinds.

use super::engine::{PhaseEnd, Sim};
use super::rng::Rng;
use crate::perception::RgbImage;
use crate::profile::{ActuatorSpec, RANGE_KIND, RangeParams, SensorSpec};
use crate::robot::{Actuator, Camera, Drive, Exposure, HardwareError, Odometer, Robot, Sensor};
use crate::schemas::{DriveCommand, OdometryReading};
use std::collections::BTreeMap;
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

/// A simulation shared by the devices of one simulated robot.
#[derive(Clone)]
pub struct SimRobot(Arc<Mutex<Sim>>);

/// Builds the simulated device for a `[[sensors]]` entry.
pub type SensorFactory = dyn Fn(&SimRobot, &SensorSpec) -> Result<Box<dyn Sensor>, String> + Send + Sync;

/// Builds the simulated device for an `[[actuators]]` entry.
pub type ActuatorFactory = dyn Fn(&SimRobot, &ActuatorSpec) -> Result<Box<dyn Actuator>, String> + Send + Sync;

/// Simulated devices by kind (see the module docs).
#[derive(Clone)]
pub struct SimDevices {
    sensors: BTreeMap<String, Arc<SensorFactory>>,
    actuators: BTreeMap<String, Arc<ActuatorFactory>>,
}

impl Default for SimDevices {
    /// The kinds the simulator ships: the `range` finder and the crate's built-in kinds
    /// ([`super::devices`]).
    fn default() -> Self {
        let mut d = Self {
            sensors: BTreeMap::new(),
            actuators: BTreeMap::new(),
        };
        super::devices::register_builtin(&mut d);
        d.register_sensor(RANGE_KIND, |sim, spec| {
            let params = RangeParams::from_table(&spec.params)?;
            // Each range finder draws its noise from its own stream, named by the sensor.
            let rng = Rng::named(sim.with(|s| s.seed()), &spec.name);
            Ok(Box::new(super::range::SimRange::new(sim.clone(), params, rng)))
        });
        d
    }
}

impl SimDevices {
    /// Registers (or replaces) how the simulator simulates sensor kind `kind`.
    pub fn register_sensor(
        &mut self,
        kind: impl Into<String>,
        factory: impl Fn(&SimRobot, &SensorSpec) -> Result<Box<dyn Sensor>, String> + Send + Sync + 'static,
    ) -> &mut Self {
        self.sensors.insert(kind.into(), Arc::new(factory));
        self
    }

    /// Registers (or replaces) how the simulator simulates actuator kind `kind`.
    pub fn register_actuator(
        &mut self,
        kind: impl Into<String>,
        factory: impl Fn(&SimRobot, &ActuatorSpec) -> Result<Box<dyn Actuator>, String> + Send + Sync + 'static,
    ) -> &mut Self {
        self.actuators.insert(kind.into(), Arc::new(factory));
        self
    }
}

/// Builds a simulated device of type `D` from its entry `S`.
type Factory<S, D> = dyn Fn(&SimRobot, &S) -> Result<Box<D>, String> + Send + Sync;

/// Builds each of `specs` (named `what[i]` in errors) with the factory of its kind.
fn build_all<S, D: ?Sized>(
    sim: &SimRobot,
    what: &str,
    specs: &[S],
    kind_name: impl Fn(&S) -> (&str, &str),
    factories: &BTreeMap<String, Arc<Factory<S, D>>>,
) -> Result<Vec<Box<D>>, String> {
    specs
        .iter()
        .enumerate()
        .map(|(i, spec)| {
            let (kind, name) = kind_name(spec);
            let factory = factories.get(kind).ok_or_else(|| {
                let known: Vec<&str> = factories.keys().map(String::as_str).collect();
                format!(
                    "{what}[{i}] `{name}`: the simulator cannot simulate kind `{kind}` (it simulates: {})",
                    known.join(", ")
                )
            })?;
            factory(sim, spec).map_err(|e| format!("{what}[{i}] `{name}`: {e}"))
        })
        .collect()
}

fn lock(sim: &Arc<Mutex<Sim>>) -> MutexGuard<'_, Sim> {
    // A device that panicked mid-update leaves the world as it was; go on with it.
    sim.lock().unwrap_or_else(|p| p.into_inner())
}

impl SimRobot {
    /// Shares `sim` between devices.
    pub fn new(sim: Sim) -> Self {
        Self(Arc::new(Mutex::new(sim)))
    }

    /// Runs `f` on the simulation (the proctor's hand: placing the robot, reading the
    /// ground truth).
    pub fn with<R>(&self, f: impl FnOnce(&mut Sim) -> R) -> R {
        f(&mut lock(&self.0))
    }

    /// Advances the physics by one loop tick (see [`Sim::advance`]).
    pub fn advance(&self) -> Option<PhaseEnd> {
        self.with(Sim::advance)
    }

    /// The robot's hardware: cameras, drive, odometer, and the profile's `[[sensors]]`
    /// and `[[actuators]]` built by `devices`.
    ///
    /// # Errors
    /// A message naming a device whose kind `devices` cannot simulate, or whose params it
    /// refuses.
    pub fn robot(&self, devices: &SimDevices) -> Result<Robot, String> {
        self.build_robot(devices, false)
    }

    /// As [`SimRobot::robot`], with cameras that deliver a frame only once the simulated
    /// clock has moved on since their last (for the threaded runtime with
    /// [`SimRobot::run_physics`], where a camera thread would otherwise render the same
    /// instant over and over).
    ///
    /// # Errors
    /// As [`SimRobot::robot`].
    pub fn realtime_robot(&self, devices: &SimDevices) -> Result<Robot, String> {
        self.build_robot(devices, true)
    }

    fn build_robot(&self, devices: &SimDevices, paced: bool) -> Result<Robot, String> {
        let (cameras, sensors, actuators) = self.with(|s| {
            let p = s.profile();
            (p.cameras.len(), p.sensors.clone(), p.actuators.clone())
        });
        let mut robot = Robot::new(
            (0..cameras)
                .map(|i| {
                    Box::new(if paced {
                        SimCamera::paced(self.clone(), i)
                    } else {
                        SimCamera::new(self.clone(), i)
                    }) as Box<dyn Camera>
                })
                .collect(),
            Box::new(SimDrive(self.clone())),
        );
        robot.odometer = Some(Box::new(SimOdometer(self.clone())));
        robot.sensors = build_all(self, "sensors", &sensors, |s| (&s.kind, &s.name), &devices.sensors)?;
        robot.actuators = build_all(
            self,
            "actuators",
            &actuators,
            |a| (&a.kind, &a.name),
            &devices.actuators,
        )?;
        Ok(robot)
    }

    /// Advances the physics on the wall clock, one loop tick per tick period, until
    /// `until` says stop or the robot docks or catches the entrance edge (returned), so
    /// the threaded runtime can drive the simulated robot in real time.
    pub fn run_physics(&self, until: impl Fn() -> bool) -> Option<PhaseEnd> {
        let period = Duration::from_secs_f64(self.with(|s| 1.0 / s.profile().loop_.rate_hz));
        let mut next = Instant::now();
        while !until() {
            if let Some(end) = self.advance() {
                return Some(end);
            }
            next += period;
            if let Some(wait) = next.checked_duration_since(Instant::now()) {
                std::thread::sleep(wait);
            }
        }
        None
    }
}

/// A simulated camera: renders the world at the robot's true pose.
pub struct SimCamera {
    sim: SimRobot,
    index: usize,
    /// With `paced`, the simulated time of the last frame: a capture waits for the clock
    /// to move on (real time), as a real camera waits for its next exposure.
    last: Option<f64>,
    paced: bool,
}

impl SimCamera {
    /// Camera `index` of the profile.
    pub fn new(sim: SimRobot, index: usize) -> Self {
        Self {
            sim,
            index,
            last: None,
            paced: false,
        }
    }

    /// A camera that delivers a new frame only after the simulated clock has moved on (for
    /// the threaded runtime with [`SimRobot::run_physics`]).
    pub fn paced(sim: SimRobot, index: usize) -> Self {
        Self {
            paced: true,
            ..Self::new(sim, index)
        }
    }
}

impl Camera for SimCamera {
    fn resolution(&self) -> (usize, usize) {
        self.sim.with(|s| {
            s.profile()
                .cameras
                .get(self.index)
                .map_or((0, 0), |c| (c.width_px, c.height_px))
        })
    }

    fn capture(&mut self, frame: &mut RgbImage) -> Result<Exposure, HardwareError> {
        if self.paced {
            let t = self.sim.with(|s| s.time());
            if self.last.is_some_and(|last| t <= last) {
                std::thread::sleep(Duration::from_millis(5));
                return Err(HardwareError::NotReady);
            }
            self.last = Some(t);
        }
        let i = self.index;
        self.sim.with(|s| s.capture(i, frame))
    }
}

/// The simulated motors.
pub struct SimDrive(SimRobot);

impl Drive for SimDrive {
    fn apply(&mut self, command: &DriveCommand) -> Result<(), HardwareError> {
        self.0.with(|s| s.command_drive(*command));
        Ok(())
    }
}

/// The simulated base's odometry (integrated from the simulated wheels at the physics
/// rate, as a motor controller does).
pub struct SimOdometer(SimRobot);

impl Odometer for SimOdometer {
    fn read(&mut self) -> Result<OdometryReading, HardwareError> {
        Ok(self.0.with(|s| s.odometry_reported()))
    }
}
