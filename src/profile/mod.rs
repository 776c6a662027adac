//! Robot profiles: one TOML file describes one platform.
//!
//! A profile holds the drive (kinematics and limits), the cameras (model, resolution,
//! field of view or intrinsics, mounting), the body, dock and fiducial geometry, the
//! behavior selection with its gains, loop timing, and success tolerances. Unknown fields
//! are rejected and every value is range-checked; see [`crate::config`] for the errors.
//!
//! ```
//! let p = marsupial::profile::Profile::load("profiles/bujold.toml".as_ref()).unwrap();
//! assert_eq!(p.cameras[0].width_px, 256);
//! ```

pub mod adapters;
pub mod behavior;
pub mod camera;
pub mod devices;
pub mod docks;
pub mod drive;
pub mod fiducial;
pub mod geometry;
pub mod paint;
pub mod perception;
pub mod pyramid_perception;
pub mod robot;
pub mod tree;

pub use behavior::{BehaviorSpec, LoopSpec};
pub use camera::{CameraModelKind, CameraSpec, FisheyeSpec, Intrinsics, Mount};
pub use devices::{ActuatorSpec, RANGE_KIND, RangeParams, SensorSpec};
pub use docks::DockEntry;
pub use drive::{DriveKind, DriveSpec};
pub use fiducial::{
    CirclePlacement, CirclesSpec, FiducialKind, FiducialKinds, FiducialSpec, MarkersSpec, NamedColor, PyramidSpec,
    SteeringCoeffs, TwoBlockSpec,
};
pub use geometry::{BodySpec, ConeSpec, DockSpec, SuccessSpec, TetherSpec};
pub use perception::{ImprintSpec, PerceptionSpec, SegmentationMode};
pub use pyramid_perception::{HsvBand, PyramidPerceptionSpec};
pub use robot::RobotSpec;
pub use tree::{NodeSpec, TreeSpec};

use crate::arbiter::{LoopConfig, Staleness};
use crate::config::{self, ConfigError, Validate, Validator};
use crate::schemas::DeviceKinds;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Where a loaded profile came from, for messages about it after loading.
#[derive(Debug, Clone, PartialEq)]
pub struct ProfileSource {
    /// The file (or the name shown for text parsed from elsewhere).
    pub file: std::path::PathBuf,
    /// Its text.
    pub text: String,
}

/// A platform profile.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Profile {
    /// Short name (`"bujold"`).
    pub name: String,
    /// One-line description.
    #[serde(default)]
    pub description: String,
    /// Base kinematics and limits.
    pub drive: DriveSpec,
    /// Footprint.
    pub body: BodySpec,
    /// Cameras, in the order the robot interface delivers them.
    pub cameras: Vec<CameraSpec>,
    /// Dock geometry (absent for profiles that do not dock).
    #[serde(default)]
    pub dock: Option<DockSpec>,
    /// The docks a goal may name, by id, with their poses (`[[docks]]`; none: the one
    /// dock named after the profile, see [`docks`]).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub docks: Vec<DockEntry>,
    /// The robot kind that runs this platform, and its tuning (absent: a platform that
    /// runs no behavior, only perception).
    #[serde(default)]
    pub robot: Option<RobotSpec>,
    /// Visual target: a registered kind and its fields.
    pub fiducial: FiducialSpec,
    /// Colour perception settings (defaults: the paper's values, see
    /// [`PerceptionSpec::default`]).
    #[serde(default)]
    pub perception: PerceptionSpec,
    /// Tether (absent for untethered robots).
    #[serde(default)]
    pub tether: Option<TetherSpec>,
    /// Sensors beyond cameras and odometry: the tether reel, the dock switch, a range
    /// finder, a user's kinds (see [`devices`]).
    #[serde(default)]
    pub sensors: Vec<SensorSpec>,
    /// Actuators beyond the drive: the tether reel, arm, lights, guides, posture, a user's
    /// kinds (see [`devices`]).
    #[serde(default)]
    pub actuators: Vec<ActuatorSpec>,
    /// The behavior tree and the limits its leaves share.
    #[serde(default)]
    pub behavior: BehaviorSpec,
    /// Loop timing.
    #[serde(rename = "loop")]
    pub loop_: LoopSpec,
    /// Success tolerances.
    pub success: SuccessSpec,
    /// The file and text it was loaded from (`None` for a profile built in code).
    #[serde(skip)]
    pub source: Option<std::sync::Arc<ProfileSource>>,
}

impl Validate for Profile {
    fn validate(&self, v: &mut Validator<'_>) {
        v.require(!self.name.trim().is_empty(), "name", || {
            "expected a non-empty profile name".into()
        });
        self.drive.validate(v);
        geometry::validate_body(&self.body, v);
        v.require(!self.cameras.is_empty(), "cameras", || {
            "expected at least one [[cameras]] entry".into()
        });
        for (i, c) in self.cameras.iter().enumerate() {
            c.validate_at(v, &format!("cameras[{i}]"));
        }
        if let Some(d) = &self.dock {
            geometry::validate_dock(d, &self.body, self.fiducial.kind() == PyramidSpec::KIND, v);
            geometry::validate_cone_arm(d, self.tether.as_ref(), &self.body, v);
        }
        docks::validate_docks(&self.docks, v);
        perception::validate_perception(&self.perception, v);
        if let Some(t) = &self.tether {
            geometry::validate_tether(t, v);
        }
        devices::validate_devices(self, v);
        behavior::validate_behavior(&self.behavior, v);
        behavior::validate_loop(&self.loop_, v);
        geometry::validate_success(&self.success, v);
    }
}

impl Profile {
    /// Loads and validates a profile file whose fiducial is one of the crate's kinds
    /// ([`FiducialKinds::builtin`]).
    ///
    /// # Errors
    /// [`ConfigError`] naming the file, field path, line and expectation.
    pub fn load(path: &Path) -> Result<Self, ConfigError> {
        Self::load_with(path, &FiducialKinds::builtin())
    }

    /// Loads and validates a profile file whose fiducial is one of `kinds`.
    ///
    /// # Errors
    /// As [`Profile::load`].
    pub fn load_with(path: &Path, kinds: &FiducialKinds) -> Result<Self, ConfigError> {
        Self::parse_with(&config::read_source(path)?, path, kinds)
    }

    /// Parses and validates profile text (the crate's fiducial kinds); `file` is used in
    /// messages.
    ///
    /// # Errors
    /// As [`Profile::load`].
    pub fn parse(src: &str, file: &Path) -> Result<Self, ConfigError> {
        Self::parse_with(src, file, &FiducialKinds::builtin())
    }

    /// Parses and validates profile text whose fiducial is one of `kinds`.
    ///
    /// # Errors
    /// As [`Profile::load`]; the fiducial's own problems (an unknown kind, a field of
    /// another kind, a value out of range) are listed with the others.
    pub fn parse_with(src: &str, file: &Path, kinds: &FiducialKinds) -> Result<Self, ConfigError> {
        let mut p: Self = config::parse_str(src, file)?;
        p.source = Some(std::sync::Arc::new(ProfileSource {
            file: file.to_path_buf(),
            text: src.to_string(),
        }));
        let problems = p.checked(|p, v| kinds.resolve(&mut p.fiducial, v));
        if problems.is_empty() {
            Ok(p)
        } else {
            Err(p.problems(problems))
        }
    }

    /// Runs `check` with a validator over this profile's source (so problems it reports
    /// name their lines), and returns what it found as (path, message) pairs.
    fn checked(&mut self, check: impl FnOnce(&mut Self, &mut Validator<'_>)) -> Vec<(String, String)> {
        let source = self.source.clone();
        let text = source.as_ref().map_or("", |s| s.text.as_str());
        let doc = toml::de::DeTable::parse(text).ok();
        let mut v = Validator::new(text, doc.as_ref().map(|d| d.get_ref()));
        check(self, &mut v);
        v.into_problems().into_iter().map(|p| (p.path, p.message)).collect()
    }

    /// Reports problems found after loading (when a behavior tree is built) the way
    /// loading does: naming the file, the line of each field path, and what was expected.
    pub fn problems(&self, problems: Vec<(String, String)>) -> ConfigError {
        let (file, text) = match &self.source {
            Some(s) => (s.file.clone(), s.text.as_str()),
            None => (std::path::PathBuf::from(format!("profile `{}`", self.name)), ""),
        };
        let doc = toml::de::DeTable::parse(text).ok();
        let v = config::Validator::new(text, doc.as_ref().map(|d| d.get_ref()));
        let mut problems: Vec<config::Problem> = problems
            .into_iter()
            .map(|(path, message)| config::Problem {
                line: v.line_of(&path),
                path,
                message,
            })
            .collect();
        // In file order, so a reader fixes them top to bottom.
        problems.sort_by_key(|p| p.line.unwrap_or(usize::MAX));
        ConfigError::Invalid { file, problems }
    }

    /// The reactive loop's configuration for this platform.
    pub fn loop_config(&self) -> LoopConfig {
        LoopConfig {
            rate_hz: self.loop_.rate_hz,
            staleness: Staleness {
                camera: self.loop_.camera_stale_s,
                odometry: self.loop_.odometry_stale_s,
                sensors: self.sensors.iter().map(|s| s.stale_s).collect(),
                camera_repeats_stale: self.loop_.camera_repeats_stale,
            },
            frame_sizes: self.cameras.iter().map(|c| (c.width_px, c.height_px)).collect(),
            drive: self.drive.model(),
            limits: self.drive.limits(),
            devices: DeviceKinds {
                sensors: self.sensors.iter().map(|s| s.kind.clone()).collect(),
                actuators: self.actuators.iter().map(|a| a.kind.clone()).collect(),
            },
        }
    }
}
