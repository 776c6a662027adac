//! The crate's built-in device kinds in the simulator: the tether reel (a sensor and an
//! actuator on one simulated reel), the dock contact switch, the body posture (the dock
//! judge admits a lowered robot into the pouch), and the arm, lights and guides, which
//! are accepted with no effect on the planar world (the simulator renders neither the
//! robot's own lights nor its arm).

use super::robot::{SimDevices, SimRobot};
use crate::robot::{Actuator, HardwareError, Sensor};
use crate::schemas::{
    ARM_KIND, DOCK_CONTACT_KIND, DeviceCommand, DeviceReading, DockContact, GUIDES_KIND, LIGHTS_KIND, POSTURE_KIND,
    Posture, TETHER_KIND, TetherCommand,
};

/// Registers the built-in kinds in `d`.
pub(super) fn register_builtin(d: &mut SimDevices) {
    d.register_sensor(TETHER_KIND, |sim, _| Ok(Box::new(SimReel(sim.clone()))));
    d.register_actuator(TETHER_KIND, |sim, _| Ok(Box::new(SimReel(sim.clone()))));
    d.register_sensor(DOCK_CONTACT_KIND, |sim, _| Ok(Box::new(SimDockSwitch(sim.clone()))));
    d.register_actuator(POSTURE_KIND, |sim, _| Ok(Box::new(SimPosture(sim.clone()))));
    for kind in [ARM_KIND, LIGHTS_KIND, GUIDES_KIND] {
        d.register_actuator(kind, |_, _| Ok(Box::new(Switch)));
    }
}

/// The values of a command of kind `C`, or a fault naming the kind.
fn decode<C: DeviceCommand>(values: &[f64]) -> Result<C, HardwareError> {
    C::decode(values).ok_or_else(|| HardwareError::Fault {
        device: C::KIND.into(),
        detail: format!("expected a {} command, got {values:?}", C::KIND),
    })
}

/// The pressure plates (or the open dock's contact).
pub struct SimDockSwitch(SimRobot);

impl Sensor for SimDockSwitch {
    fn read(&mut self, values: &mut Vec<f64>) -> Result<(), HardwareError> {
        DockContact(self.0.with(|s| s.docked())).encode(values);
        Ok(())
    }
}

/// Raising and lowering the body.
pub struct SimPosture(SimRobot);

impl Actuator for SimPosture {
    fn apply(&mut self, values: &[f64]) -> Result<(), HardwareError> {
        let posture: Posture = decode(values)?;
        self.0.with(|s| s.set_posture(posture));
        Ok(())
    }
}

/// The tether reel: reads the simulated tether's length and reel current (nothing without
/// a `[tether]`), takes reel commands.
pub struct SimReel(SimRobot);

impl Sensor for SimReel {
    fn read(&mut self, values: &mut Vec<f64>) -> Result<(), HardwareError> {
        let reading = self.0.with(|s| s.tether_reading()).ok_or(HardwareError::NotReady)?;
        reading.encode(values);
        Ok(())
    }
}

impl Actuator for SimReel {
    fn apply(&mut self, values: &[f64]) -> Result<(), HardwareError> {
        let command: TetherCommand = decode(values)?;
        self.0.with(|s| s.command_reel(command));
        Ok(())
    }
}

/// Arm, lights and guides: accepted, with no effect on the simulated world.
pub struct Switch;

impl Actuator for Switch {
    fn apply(&mut self, _values: &[f64]) -> Result<(), HardwareError> {
        Ok(())
    }
}
