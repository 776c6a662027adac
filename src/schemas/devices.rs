//! One device model: every device beyond the cameras, the drive and odometry is a kind
//! a profile declares in `[[sensors]]` or `[[actuators]]` ([`crate::profile::devices`]),
//! read and commanded as numbers, with typed readings and commands on top.
//!
//! The crate's own devices are kinds like any user's: the tether reel ([`TETHER_KIND`],
//! a sensor and an actuator), the dock contact switch ([`DOCK_CONTACT_KIND`]), the arm,
//! the lights, the dock guides and the body posture. A reading travels as the values a
//! [`Sensor`](crate::robot::Sensor) writes and a behavior reads it typed through
//! [`DeviceReading`] ([`Inputs::reading`](super::Inputs::reading), or
//! [`Inputs::tether`](super::Inputs::tether) for the reel); a command is set typed on the
//! output ([`Auxiliary::set`](super::Auxiliary::set) with a [`DeviceCommand`]) and reaches
//! every declared actuator of its kind as values. A user's crate implements the two
//! traits for its own kinds and gets the same typed access:
//!
//! ```
//! use marsupial::schemas::{Auxiliary, Command, DeviceCommand};
//!
//! /// A gripper's jaw opening, m.
//! struct Jaw(f64);
//! impl DeviceCommand for Jaw {
//!     const KIND: &'static str = "gripper";
//!     fn encode(&self) -> Command { Command::of(Self::KIND, [self.0]) }
//!     fn decode(values: &[f64]) -> Option<Self> { values.first().map(|&v| Jaw(v)) }
//! }
//!
//! let mut aux = Auxiliary::default();
//! aux.set(Jaw(0.02));
//! assert_eq!(aux.get::<Jaw>().map(|j| j.0), Some(0.02));
//! assert_eq!(aux.command("gripper").map(|c| c.values()), Some(&[0.02][..]));
//! ```

use super::inputs::TetherReading;
use super::motor_output::{Guides, Posture, TetherCommand};

/// How many devices a tick holds without allocating: the `[[sensors]]` readings of one
/// tick are inline up to this many (more are allowed and spill to the heap), and one
/// output carries commands for up to this many actuator kinds, which is why a profile
/// may declare at most this many `[[actuators]]`.
pub const INLINE_DEVICES: usize = 8;

/// Most numbers in one device command (the tether reel's: rate and free wheel).
pub const COMMAND_VALUES: usize = 2;

/// The tether reel: as a sensor it reads [`TetherReading`] (length, reel motor current);
/// as an actuator it takes [`TetherCommand`]. Declaring it needs a `[tether]` table.
pub const TETHER_KIND: &str = "tether";
/// The dock contact switch (pressure plates): reads [`DockContact`].
pub const DOCK_CONTACT_KIND: &str = "dock_contact";
/// An arm (or camera mast) with one position: takes [`ArmPosition`].
pub const ARM_KIND: &str = "arm";
/// Lights: take [`Lights`].
pub const LIGHTS_KIND: &str = "lights";
/// Dock guides: take [`Guides`].
pub const GUIDES_KIND: &str = "guides";
/// Body posture (raise or lower the body): takes [`Posture`].
pub const POSTURE_KIND: &str = "posture";

/// The sensor kinds the crate defines (with [`crate::profile::RANGE_KIND`]); none takes
/// `params`.
pub const BUILTIN_SENSOR_KINDS: [&str; 2] = [TETHER_KIND, DOCK_CONTACT_KIND];
/// The actuator kinds the crate defines; none takes `params`.
pub const BUILTIN_ACTUATOR_KINDS: [&str; 5] = [TETHER_KIND, ARM_KIND, LIGHTS_KIND, GUIDES_KIND, POSTURE_KIND];

/// A typed reading of one sensor kind: how its values read.
pub trait DeviceReading: Sized {
    /// The `[[sensors]]` kind that delivers it.
    const KIND: &'static str;
    /// The reading from a sensor's values; `None` when they do not make one.
    fn decode(values: &[f64]) -> Option<Self>;
    /// Writes the reading as values (what the device's [`Sensor`](crate::robot::Sensor)
    /// does; `out` arrives cleared).
    fn encode(&self, out: &mut Vec<f64>);
}

/// A typed command of one actuator kind: how it travels as values.
pub trait DeviceCommand: Sized {
    /// The `[[actuators]]` kind it commands.
    const KIND: &'static str;
    /// The command as values addressed to [`Self::KIND`].
    fn encode(&self) -> Command;
    /// The command from its values (what the device's
    /// [`Actuator`](crate::robot::Actuator) does); `None` when they do not make one.
    fn decode(values: &[f64]) -> Option<Self>;
}

/// One device command: its kind and up to [`COMMAND_VALUES`] numbers, fixed size so an
/// output is `Copy` and a tick allocates nothing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Command {
    kind: &'static str,
    values: [f64; COMMAND_VALUES],
    len: usize,
}

impl Command {
    /// A command for kind `kind`; the length is checked when compiled.
    pub const fn of<const N: usize>(kind: &'static str, values: [f64; N]) -> Self {
        const { assert!(N <= COMMAND_VALUES, "a command carries at most COMMAND_VALUES numbers") };
        let mut v = [0.0; COMMAND_VALUES];
        let mut i = 0;
        while i < N {
            v[i] = values[i];
            i += 1;
        }
        Self {
            kind,
            values: v,
            len: N,
        }
    }

    /// A command from a slice; `None` when it has more than [`COMMAND_VALUES`] numbers.
    pub fn new(kind: &'static str, values: &[f64]) -> Option<Self> {
        let mut v = [0.0; COMMAND_VALUES];
        v.get_mut(..values.len())?.copy_from_slice(values);
        Some(Self {
            kind,
            values: v,
            len: values.len(),
        })
    }

    /// The actuator kind it addresses.
    pub fn kind(&self) -> &'static str {
        self.kind
    }

    /// Its numbers.
    pub fn values(&self) -> &[f64] {
        &self.values[..self.len]
    }
}

/// The dock contact switch's reading: closed (in the dock) or open.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DockContact(pub bool);

/// An arm's position, rad (RAPOSA's front arm; positive raises).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArmPosition(pub f64);

/// Lights on (true) or off.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Lights(pub bool);

/// A flag as a number: 1 for true, 0 for false; any other value than 0 reads true.
fn flag(b: bool) -> f64 {
    if b { 1.0 } else { 0.0 }
}

/// `[length_m, motor_current_a]`.
impl DeviceReading for TetherReading {
    const KIND: &'static str = TETHER_KIND;
    fn decode(values: &[f64]) -> Option<Self> {
        match *values {
            [length, motor_current_a] => Some(Self {
                length,
                motor_current_a,
            }),
            _ => None,
        }
    }
    fn encode(&self, out: &mut Vec<f64>) {
        out.extend([self.length, self.motor_current_a]);
    }
}

/// `[closed]`, 1 or 0.
impl DeviceReading for DockContact {
    const KIND: &'static str = DOCK_CONTACT_KIND;
    fn decode(values: &[f64]) -> Option<Self> {
        match *values {
            [c] => Some(Self(c != 0.0)),
            _ => None,
        }
    }
    fn encode(&self, out: &mut Vec<f64>) {
        out.push(flag(self.0));
    }
}

/// `[reel_rate_mps, free_wheel]`.
impl DeviceCommand for TetherCommand {
    const KIND: &'static str = TETHER_KIND;
    fn encode(&self) -> Command {
        Command::of(Self::KIND, [self.reel_rate, flag(self.free_wheel)])
    }
    fn decode(values: &[f64]) -> Option<Self> {
        match *values {
            [reel_rate, free] => Some(Self {
                reel_rate,
                free_wheel: free != 0.0,
            }),
            _ => None,
        }
    }
}

/// One number per command, read by `from`.
macro_rules! single {
    ($ty:ty, $kind:expr, $doc:literal, |$s:ident| $to:expr, |$v:ident| $from:expr) => {
        #[doc = $doc]
        impl DeviceCommand for $ty {
            const KIND: &'static str = $kind;
            fn encode(&self) -> Command {
                let $s = self;
                Command::of(Self::KIND, [$to])
            }
            fn decode(values: &[f64]) -> Option<Self> {
                match *values {
                    [$v] => Some($from),
                    _ => None,
                }
            }
        }
    };
}

single!(ArmPosition, ARM_KIND, "`[position_rad]`.", |s| s.0, |v| ArmPosition(v));
single!(Lights, LIGHTS_KIND, "`[on]`, 1 or 0.", |s| flag(s.0), |v| Lights(
    v != 0.0
));
single!(
    Guides,
    GUIDES_KIND,
    "`[closed]`, 1 or 0.",
    |s| flag(*s == Guides::Closed),
    |v| if v != 0.0 { Guides::Closed } else { Guides::Open }
);
single!(
    Posture,
    POSTURE_KIND,
    "`[lowered]`, 1 or 0.",
    |s| flag(*s == Posture::Lowered),
    |v| if v != 0.0 { Posture::Lowered } else { Posture::Raised }
);

/// The kinds of a profile's devices, in `[[sensors]]` and `[[actuators]]` order: how the
/// loop drivers label each reading and route each command (a robot's
/// [`sensors`](crate::robot::Robot::sensors) and
/// [`actuators`](crate::robot::Robot::actuators) are in the same order).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct DeviceKinds {
    /// Kind of each `[[sensors]]` entry.
    pub sensors: Vec<String>,
    /// Kind of each `[[actuators]]` entry.
    pub actuators: Vec<String>,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn round_trip<C: DeviceCommand + PartialEq + std::fmt::Debug>(c: C) {
        let cmd = c.encode();
        assert_eq!(cmd.kind(), C::KIND);
        assert_eq!(C::decode(cmd.values()), Some(c));
    }

    #[test]
    fn typed_commands_and_readings_survive_their_values_exactly() {
        round_trip(TetherCommand {
            reel_rate: -0.1 / 3.0,
            free_wheel: true,
        });
        round_trip(ArmPosition(0.3));
        round_trip(Lights(true));
        round_trip(Guides::Closed);
        round_trip(Guides::Open);
        round_trip(Posture::Lowered);
        let r = TetherReading {
            length: 1.0 / 3.0,
            motor_current_a: 0.7,
        };
        let mut v = Vec::new();
        r.encode(&mut v);
        assert_eq!(TetherReading::decode(&v), Some(r));
        assert_eq!(DockContact::decode(&[1.0]), Some(DockContact(true)));
        assert_eq!(DockContact::decode(&[1.0, 0.0]), None, "the wrong size reads nothing");
        assert!(Command::new("x", &[1.0, 2.0, 3.0]).is_none());
    }

    #[test]
    fn outputs_keep_one_command_per_kind_and_compare_regardless_of_order() {
        use crate::schemas::Auxiliary;
        let mut a = Auxiliary::with(Lights(true));
        a.set(Guides::Open);
        a.set(Lights(false));
        let mut b = Auxiliary::with(Guides::Open);
        b.set(Lights(false));
        assert_eq!(a, b);
        assert_eq!(a.commands().count(), 2, "a later command replaces its kind's");
        b.clear(LIGHTS_KIND);
        assert_ne!(a, b);
        assert_eq!(b.get::<Lights>(), None);
        let mut full = Auxiliary::default();
        for (i, kind) in ["k0", "k1", "k2", "k3", "k4", "k5", "k6", "k7", "k8"]
            .into_iter()
            .enumerate()
        {
            full.put(Command::of(kind, [i as f64]));
        }
        assert_eq!(
            full.commands().count(),
            INLINE_DEVICES,
            "a kind beyond the room is dropped, not a panic"
        );
        assert!(full.is_finite() && !Auxiliary::with(ArmPosition(f64::NAN)).is_finite());
    }
}
