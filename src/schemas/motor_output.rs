//! Motor outputs: what a motor schema proposes and the arbiter commands.

use crate::geometry::Twist;
use serde::{Deserialize, Serialize};

pub use crate::kinematics::DriveCommand;

/// Most `[[actuators]]` a profile may declare: their commands travel in a fixed array,
/// so a tick's output never allocates.
pub const MAX_ACTUATORS: usize = 4;

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

/// Auxiliary actuators; `None` means "this behavior has no opinion", so several outputs
/// can be merged in priority order.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Auxiliary {
    /// Tether reel command.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tether: Option<TetherCommand>,
    /// Arm position, radians (RAPOSA's front arm; positive raises).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub arm: Option<f64>,
    /// Lights on or off.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lights: Option<bool>,
    /// Dock guides.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub guides: Option<Guides>,
    /// Body posture.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub posture: Option<Posture>,
    /// Commands for the profile's `[[actuators]]`, by index (a gripper's position, a
    /// beacon's power...): what a value means is the actuator's kind's business.
    #[serde(default, skip_serializing_if = "no_commands")]
    pub actuators: [Option<f64>; MAX_ACTUATORS],
}

fn no_commands(a: &[Option<f64>; MAX_ACTUATORS]) -> bool {
    a.iter().all(Option::is_none)
}

impl Auxiliary {
    /// Fills each field this one leaves open with `other`'s value (self has priority).
    ///
    /// ```
    /// use marsupial::schemas::{Auxiliary, Guides};
    ///
    /// let dock = Auxiliary { guides: Some(Guides::Closed), ..Default::default() };
    /// let carry = Auxiliary { arm: Some(0.3), guides: Some(Guides::Open), ..Default::default() };
    /// let merged = dock.or(carry);
    /// assert_eq!((merged.guides, merged.arm), (Some(Guides::Closed), Some(0.3)));
    /// assert_eq!(merged.lights, None, "nobody had an opinion");
    /// ```
    pub fn or(self, other: Auxiliary) -> Auxiliary {
        Auxiliary {
            tether: self.tether.or(other.tether),
            arm: self.arm.or(other.arm),
            lights: self.lights.or(other.lights),
            guides: self.guides.or(other.guides),
            posture: self.posture.or(other.posture),
            actuators: std::array::from_fn(|i| self.actuators[i].or(other.actuators[i])),
        }
    }

    /// True when every number in the command is finite.
    pub fn is_finite(&self) -> bool {
        self.tether.is_none_or(|t| t.reel_rate.is_finite())
            && self.arm.is_none_or(f64::is_finite)
            && self.actuators.iter().all(|a| a.is_none_or(f64::is_finite))
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
/// let lowered = Auxiliary { posture: Some(Posture::Lowered), ..Default::default() };
/// let out = MotorOutput::drive(DriveCommand::Straight { v: -0.03 }).with_aux(lowered);
/// assert_eq!(out.drive.to_twist(), Twist::new(-0.03, 0.0));
/// assert_eq!(out.aux.posture, Some(Posture::Lowered));
/// assert!(out.is_finite());
/// assert!(!MotorOutput::drive(DriveCommand::Turn { omega: f64::NAN }).is_finite());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct MotorOutput {
    /// Base motion.
    pub drive: DriveCommand,
    /// Auxiliary actuators.
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
