//! Motor outputs: what a motor schema proposes and the arbiter commands.

use super::devices::{Command, DeviceCommand, INLINE_DEVICES};
use crate::geometry::Twist;
use serde::{Deserialize, Serialize};

pub use crate::kinematics::DriveCommand;

/// Command for a tether reel.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TetherCommand {
    /// Reel rate, m/s; positive reels the tether in, negative pays it out.
    pub reel_rate: f64,
    /// Put the wheels in free rotation so the tether can pull the rover (Axel's mating).
    pub free_wheel: bool,
}

/// Position of docking guides (RAPOSA closes its guides at the end of state 6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Guides {
    /// Guides open, ready to receive the target.
    Open,
    /// Guides closed on the target.
    Closed,
}

/// Body posture for robots that change geometry (Bujold lowers herself to enter the pouch).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Posture {
    /// Normal driving geometry.
    Raised,
    /// Lowest profile.
    Lowered,
}

/// The device commands of one output, by actuator kind (see [`super::devices`]): a kind
/// with no command means "this behavior has no opinion", so several outputs can be merged
/// in priority order ([`Auxiliary::or`]). Holds up to [`INLINE_DEVICES`] kinds inline.
/// Two are equal when they command the same kinds with the same values, in any order.
#[derive(Debug, Clone, Copy, Default)]
pub struct Auxiliary {
    commands: [Option<Command>; INLINE_DEVICES],
}

impl Auxiliary {
    /// Only `command`.
    pub fn with(command: impl DeviceCommand) -> Self {
        let mut a = Self::default();
        a.set(command);
        a
    }

    /// Sets the command for `C`'s kind, replacing an earlier one.
    pub fn set<C: DeviceCommand>(&mut self, command: C) {
        self.put(command.encode());
    }

    /// Sets a command given as values (for a kind without a typed command), replacing an
    /// earlier one for its kind. With [`INLINE_DEVICES`] kinds already set a new kind is
    /// dropped (a profile declares at most that many actuators, so no declared device
    /// loses its command).
    pub fn put(&mut self, command: Command) {
        let slot = match self
            .commands
            .iter()
            .position(|c| c.is_some_and(|c| c.kind() == command.kind()))
        {
            Some(i) => Some(i),
            None => self.commands.iter().position(Option::is_none),
        };
        if let Some(i) = slot {
            self.commands[i] = Some(command);
        }
    }

    /// The command for `C`'s kind, typed.
    pub fn get<C: DeviceCommand>(&self) -> Option<C> {
        self.command(C::KIND).and_then(|c| C::decode(c.values()))
    }

    /// The command for kind `kind`.
    pub fn command(&self, kind: &str) -> Option<&Command> {
        self.commands().find(|c| c.kind() == kind)
    }

    /// Every command set, in the order first set.
    pub fn commands(&self) -> impl Iterator<Item = &Command> {
        self.commands.iter().flatten()
    }

    /// Drops the command for `kind`.
    pub fn clear(&mut self, kind: &str) {
        for c in &mut self.commands {
            if c.is_some_and(|c| c.kind() == kind) {
                *c = None;
            }
        }
    }

    /// Adds each command of `other`'s whose kind this one leaves open (self has priority).
    ///
    /// ```
    /// use marsupial::schemas::{ArmPosition, Auxiliary, Guides, Lights};
    ///
    /// let dock = Auxiliary::with(Guides::Closed);
    /// let mut carry = Auxiliary::with(ArmPosition(0.3));
    /// carry.set(Guides::Open);
    /// let merged = dock.or(carry);
    /// assert_eq!(merged.get::<Guides>(), Some(Guides::Closed));
    /// assert_eq!(merged.get::<ArmPosition>(), Some(ArmPosition(0.3)));
    /// assert_eq!(merged.get::<Lights>(), None, "nobody had an opinion");
    /// ```
    pub fn or(mut self, other: Auxiliary) -> Auxiliary {
        for c in other.commands() {
            if self.command(c.kind()).is_none() {
                self.put(*c);
            }
        }
        self
    }

    /// True when no command is set.
    pub fn is_empty(&self) -> bool {
        self.commands().next().is_none()
    }

    /// True when every number in every command is finite.
    pub fn is_finite(&self) -> bool {
        self.commands().all(|c| c.values().iter().all(|v| v.is_finite()))
    }
}

impl PartialEq for Auxiliary {
    fn eq(&self, other: &Self) -> bool {
        self.commands().count() == other.commands().count()
            && self.commands().all(|c| other.command(c.kind()) == Some(c))
    }
}

/// A map from kind to values (`{"tether": [0.0, 0.0]}`), for traces and logs.
impl Serialize for Auxiliary {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut m = s.serialize_map(None)?;
        for c in self.commands() {
            m.serialize_entry(c.kind(), c.values())?;
        }
        m.end()
    }
}

/// One motor schema's (or the arbiter's) output for one tick.
///
/// # Example
///
/// ```
/// use marsupial::geometry::Twist;
/// use marsupial::schemas::{Auxiliary, DriveCommand, MotorOutput, Posture};
///
/// let out = MotorOutput::twist(0.1, -0.2);
/// assert_eq!(out.drive, DriveCommand::Twist(Twist::new(0.1, -0.2)));
/// assert!(MotorOutput::stop().drive.is_stop());
/// // Backing in, lowered: the base reverses at 3 cm/s without turning.
/// let lowered = Auxiliary::with(Posture::Lowered);
/// let out = MotorOutput::drive(DriveCommand::Straight { v: -0.03 }).with_aux(lowered);
/// assert_eq!(out.drive.to_twist(), Twist::new(-0.03, 0.0));
/// assert_eq!(out.aux.get::<Posture>(), Some(Posture::Lowered));
/// assert!(out.is_finite());
/// assert!(!MotorOutput::drive(DriveCommand::Turn { omega: f64::NAN }).is_finite());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct MotorOutput {
    /// Base motion.
    pub drive: DriveCommand,
    /// Device commands (tether, arm, lights, guides, posture, a user's kinds).
    pub aux: Auxiliary,
}

impl MotorOutput {
    /// Stop the base; leave auxiliaries alone.
    pub fn stop() -> Self {
        Self::default()
    }

    /// A drive-only output.
    pub fn drive(drive: DriveCommand) -> Self {
        Self {
            drive,
            aux: Auxiliary::default(),
        }
    }

    /// A twist-only output.
    pub fn twist(v: f64, omega: f64) -> Self {
        Self::drive(DriveCommand::Twist(Twist::new(v, omega)))
    }

    /// Replaces the auxiliary part.
    pub fn with_aux(mut self, aux: Auxiliary) -> Self {
        self.aux = aux;
        self
    }

    /// True when every number is finite.
    pub fn is_finite(&self) -> bool {
        self.drive.is_finite() && self.aux.is_finite()
    }
}
