//! The robot catalog: robot kinds, fiducial kinds and device kinds, by name.
//!
//! A profile names its robot kind in `[robot] kind` and its fiducial in `[fiducial] kind`;
//! a [`Catalog`] maps those names to what builds the robot. A robot kind ([`RobotKind`])
//! brings its typed tuning (the rest of `[robot]`, read strictly so a misspelt or foreign
//! field is an error naming its line), its shared memory (its perceptual schemas run once
//! per tick) and its leaves; the catalog composes them with the crate's common leaves into
//! the tree the profile's `[behavior.tree]` declares ([`Composed`]).
//!
//! [`Catalog::shipped`] holds the papers' robots (`bujold`, `raposa`, `axel`, `krawler`),
//! the crate's fiducial kinds and the `range` sensor kind. A user's crate adds its own without editing
//! marsupial, and can serve them from its own `marsupial` command
//! (`marsupial::cli::run_with`):
//!
//! ```
//! use marsupial::behaviors::catalog::{Catalog, RobotKind};
//! use marsupial::behaviors::registry::Registry;
//! use marsupial::config::{Validate, Validator};
//! use marsupial::profile::Profile;
//!
//! /// A robot kind whose tuning is one gain and whose leaves share nothing.
//! struct Toy;
//!
//! #[derive(serde::Deserialize)]
//! #[serde(deny_unknown_fields)]
//! struct ToyTuning { gain: f64 }
//!
//! impl Validate for ToyTuning {
//!     fn validate(&self, v: &mut Validator<'_>) { v.positive("robot.gain", self.gain) }
//! }
//!
//! impl RobotKind for Toy {
//!     const NAME: &'static str = "toy";
//!     type Tuning = ToyTuning;
//!     type Memory = ();
//!     fn memory(&self, _: &Profile, _: &ToyTuning) -> Result<(), String> { Ok(()) }
//!     fn leaves(&self, _registry: &mut Registry<()>) {}
//! }
//!
//! let mut catalog = Catalog::shipped();
//! catalog.register_robot(Toy);
//! assert!(catalog.robot_kinds().any(|k| k == "toy"));
//! ```

use super::agent::BuildError;
use super::composed::{Composed, SharedMemory};
use super::registry::Registry;
use crate::config::{ConfigError, Validate, Validator};
use crate::profile::{FiducialKind, FiducialKinds, Profile};
use crate::schemas::Agent;
use serde::de::DeserializeOwned;
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::{Arc, OnceLock};

/// The leaf registry a robot kind of memory `M` fills.
pub type LeafRegistry<M> = Registry<M>;

/// A kind of robot a profile's `[robot] kind` can name (see the module docs).
pub trait RobotKind: Send + Sync + 'static {
    /// The name `[robot] kind` gives (`"bujold"`).
    const NAME: &'static str;
    /// The kind's tuning: the rest of the `[robot]` table. Use
    /// `#[serde(deny_unknown_fields)]`; paths in its [`Validate`] problems start with
    /// `robot.` so they name the profile's line.
    type Tuning: DeserializeOwned + Validate;
    /// What the kind's leaves share: its perceptual schemas and the robot's memory.
    type Memory: SharedMemory;

    /// The memory of a robot of this kind just switched on, for `profile`.
    ///
    /// # Errors
    /// A message saying what the profile lacks (a camera, a `[dock]`, another fiducial).
    fn memory(&self, profile: &Profile, tuning: &Self::Tuning) -> Result<Self::Memory, String>;

    /// Registers the kind's leaves and selectors (the catalog adds the crate's common ones).
    fn leaves(&self, registry: &mut LeafRegistry<Self::Memory>);
}

/// Checks a device kind's `params` table; the error names the field.
type DeviceCheck = dyn Fn(&toml::Table) -> Result<(), String> + Send + Sync;

/// Builds one robot kind's agent (the type-erased [`RobotKind`]).
trait BuildAgent: Send + Sync {
    fn agent(&self, profile: &Profile, devices: &Devices) -> Result<Box<dyn Agent>, BuildError>;
}

/// A [`RobotKind`] behind [`BuildAgent`].
struct Kind<K>(K);

/// Reads and checks `profile`'s `[robot]` tuning as robot kind `K`'s.
///
/// # Errors
/// [`BuildError::Profile`] without `[robot]`; [`BuildError::Invalid`] naming the line of
/// a field the kind refuses or a value out of range.
pub fn tuning<K: RobotKind>(profile: &Profile) -> Result<K::Tuning, BuildError> {
    let spec = profile.robot.as_ref().ok_or_else(|| BuildError::Profile {
        profile: profile.name.clone(),
        what: format!("has no [robot] table (robot kind `{}`)", K::NAME),
    })?;
    let tuning: K::Tuning = spec
        .tuning()
        .map_err(|problem| BuildError::Invalid(profile.problems(vec![problem])))?;
    let problems = checked(profile, |v| tuning.validate(v));
    if problems.is_empty() {
        Ok(tuning)
    } else {
        Err(BuildError::Invalid(profile.problems(problems)))
    }
}

/// Builds robot kind `K`'s memory for `profile`.
///
/// # Errors
/// As [`tuning`], and [`BuildError::Profile`] with what the kind says the profile lacks.
pub fn memory<K: RobotKind>(kind: &K, profile: &Profile) -> Result<K::Memory, BuildError> {
    let tuning = tuning::<K>(profile)?;
    kind.memory(profile, &tuning).map_err(|what| BuildError::Profile {
        profile: profile.name.clone(),
        what,
    })
}

impl<K: RobotKind> BuildAgent for Kind<K> {
    fn agent(&self, profile: &Profile, devices: &Devices) -> Result<Box<dyn Agent>, BuildError> {
        Ok(Box::new(compose(&self.0, profile, devices, |_| {})?))
    }
}

/// Robot kind `kind`'s robot for `profile`: its memory, and a registry of the device
/// kinds, the common leaves, the kind's own and then whatever `extend` adds (so a
/// caller's leaf of a taken name replaces the shipped one).
fn compose<K: RobotKind>(
    kind: &K,
    profile: &Profile,
    devices: &Devices,
    extend: impl FnOnce(&mut LeafRegistry<K::Memory>),
) -> Result<Composed<K::Memory>, BuildError> {
    let memory = memory(kind, profile)?;
    let mut registry = LeafRegistry::new();
    devices.install(&mut registry);
    super::common::register(&mut registry);
    kind.leaves(&mut registry);
    extend(&mut registry);
    Composed::build(profile, &registry, memory)
}

/// Runs `check` with a validator over `profile`'s source, returning its problems as
/// (path, message) pairs.
fn checked(profile: &Profile, check: impl FnOnce(&mut Validator<'_>)) -> Vec<(String, String)> {
    let text = profile.source.as_ref().map_or("", |s| s.text.as_str());
    let doc = toml::de::DeTable::parse(text).ok();
    let mut v = Validator::new(text, doc.as_ref().map(|d| d.get_ref()));
    check(&mut v);
    v.into_problems().into_iter().map(|p| (p.path, p.message)).collect()
}

/// The device kinds every robot's registry knows.
#[derive(Clone, Default)]
struct Devices {
    sensors: BTreeMap<String, Arc<DeviceCheck>>,
    actuators: BTreeMap<String, Arc<DeviceCheck>>,
}

impl Devices {
    fn install<M: 'static>(&self, registry: &mut Registry<M>) {
        for (kind, check) in &self.sensors {
            let check = Arc::clone(check);
            registry.register_sensor_kind(kind.clone(), move |t| check(t));
        }
        for (kind, check) in &self.actuators {
            let check = Arc::clone(check);
            registry.register_actuator_kind(kind.clone(), move |t| check(t));
        }
    }
}

/// Robot kinds, fiducial kinds and device kinds by name (see the module docs).
#[derive(Clone)]
pub struct Catalog {
    robots: BTreeMap<&'static str, Arc<dyn BuildAgent>>,
    fiducials: FiducialKinds,
    devices: Devices,
}

impl Default for Catalog {
    fn default() -> Self {
        Self::shipped()
    }
}

impl Catalog {
    /// A catalog with no robot kinds, knowing the crate's fiducial kinds
    /// ([`FiducialKinds::builtin`]) and its device kinds ([`crate::profile::devices`]).
    pub fn new() -> Self {
        let mut c = Self {
            robots: BTreeMap::new(),
            fiducials: FiducialKinds::builtin(),
            devices: Devices::default(),
        };
        for (kind, check) in crate::profile::devices::builtin_sensor_kinds() {
            c.register_sensor_kind(kind, check);
        }
        for (kind, check) in crate::profile::devices::builtin_actuator_kinds() {
            c.register_actuator_kind(kind, check);
        }
        c
    }

    /// The crate's catalog: [`Catalog::new`] with the papers' robot kinds (`bujold`,
    /// `raposa`, `axel`, `krawler`).
    pub fn shipped() -> Self {
        let mut c = Self::new();
        c.register_robot(super::bujold::Bujold)
            .register_robot(super::raposa::Raposa)
            .register_robot(super::axel::Axel)
            .register_robot(super::krawler::Krawler);
        c
    }

    /// Registers (or replaces) robot kind `K` under [`RobotKind::NAME`].
    pub fn register_robot<K: RobotKind>(&mut self, kind: K) -> &mut Self {
        self.robots.insert(K::NAME, Arc::new(Kind(kind)));
        self
    }

    /// Registers (or replaces) fiducial kind `F` under [`FiducialKind::KIND`].
    pub fn register_fiducial<F: FiducialKind>(&mut self) -> &mut Self {
        self.fiducials.register::<F>();
        self
    }

    /// Registers (or replaces) a sensor kind a profile's `[[sensors]]` may declare, with
    /// the check of its `params`.
    pub fn register_sensor_kind(
        &mut self,
        kind: impl Into<String>,
        check: impl Fn(&toml::Table) -> Result<(), String> + Send + Sync + 'static,
    ) -> &mut Self {
        self.devices.sensors.insert(kind.into(), Arc::new(check));
        self
    }

    /// Registers (or replaces) an actuator kind a profile's `[[actuators]]` may declare,
    /// with the check of its `params`.
    pub fn register_actuator_kind(
        &mut self,
        kind: impl Into<String>,
        check: impl Fn(&toml::Table) -> Result<(), String> + Send + Sync + 'static,
    ) -> &mut Self {
        self.devices.actuators.insert(kind.into(), Arc::new(check));
        self
    }

    /// The registered robot kinds, sorted.
    pub fn robot_kinds(&self) -> impl Iterator<Item = &'static str> + '_ {
        self.robots.keys().copied()
    }

    /// The registered fiducial kinds.
    pub fn fiducials(&self) -> &FiducialKinds {
        &self.fiducials
    }

    /// Loads a profile whose fiducial is one of this catalog's kinds.
    ///
    /// # Errors
    /// As [`Profile::load_with`].
    pub fn load_profile(&self, path: &Path) -> Result<Profile, ConfigError> {
        Profile::load_with(path, &self.fiducials)
    }

    /// Loads a profile and builds its robot, so every problem the profile has (its
    /// fields, its fiducial, its robot kind's tuning, its tree) is reported; a profile
    /// without `[robot]` is only loaded.
    ///
    /// # Errors
    /// [`ConfigError`] naming the file, the lines and what was expected.
    pub fn check_profile(&self, path: &Path) -> Result<Profile, ConfigError> {
        let profile = self.load_profile(path)?;
        if profile.robot.is_none() {
            return Ok(profile);
        }
        match self.agent(&profile) {
            Ok(_) => Ok(profile),
            Err(BuildError::Tree(e) | BuildError::Invalid(e)) => Err(e),
            Err(e) => Err(profile.problems(vec![("robot".into(), e.to_string())])),
        }
    }

    /// Builds the robot `profile` describes: its `[robot] kind`'s memory and leaves, in
    /// the tree of `[behavior.tree]`.
    ///
    /// # Errors
    /// [`BuildError::Invalid`] for an unknown robot kind (naming the registered ones) or
    /// tuning the kind refuses, [`BuildError::Profile`] for a profile without `[robot]`
    /// or lacking what the kind needs, [`BuildError::Tree`] for a tree that does not
    /// build; each names the profile's line where it can.
    pub fn agent(&self, profile: &Profile) -> Result<Box<dyn Agent>, BuildError> {
        let spec = profile.robot.as_ref().ok_or_else(|| BuildError::Profile {
            profile: profile.name.clone(),
            what: "runs no behavior: it has no [robot] table naming a robot kind".into(),
        })?;
        let Some(kind) = self.robots.get(spec.kind.as_str()) else {
            let known: Vec<&str> = self.robot_kinds().collect();
            return Err(BuildError::Invalid(profile.problems(vec![(
                "robot.kind".into(),
                format!("unknown robot kind `{}` (registered: {})", spec.kind, known.join(", ")),
            )])));
        };
        kind.agent(profile, &self.devices)
    }

    /// Builds robot kind `kind`'s robot for `profile`, typed: as [`Catalog::agent`] does
    /// for the kind `[robot] kind` names, but with the memory reachable
    /// ([`Composed::memory`], [`Composed::memory_mut`]), which the boxed agent hides.
    ///
    /// # Errors
    /// As [`Catalog::agent`].
    pub fn compose<K: RobotKind>(&self, kind: &K, profile: &Profile) -> Result<Composed<K::Memory>, BuildError> {
        compose(kind, profile, &self.devices, |_| {})
    }

    /// [`Catalog::compose`] with leaves, selectors or device kinds of the caller's added
    /// to the registry last (a caller's leaf of a taken name replaces the shipped one).
    ///
    /// # Errors
    /// As [`Catalog::agent`].
    pub fn compose_with<K: RobotKind>(
        &self,
        kind: &K,
        profile: &Profile,
        extend: impl FnOnce(&mut LeafRegistry<K::Memory>),
    ) -> Result<Composed<K::Memory>, BuildError> {
        compose(kind, profile, &self.devices, extend)
    }
}

/// The crate's catalog ([`Catalog::shipped`]), built once.
pub fn shipped() -> &'static Catalog {
    static SHIPPED: OnceLock<Catalog> = OnceLock::new();
    SHIPPED.get_or_init(Catalog::shipped)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn profile(robot: &str) -> Profile {
        let src = std::fs::read_to_string("profiles/bujold.toml").unwrap();
        let src = src.replace("kind = \"bujold\"", robot);
        Profile::parse(&src, Path::new("bujold.toml")).unwrap()
    }

    #[test]
    fn an_unknown_robot_kind_names_its_line_and_the_registered_kinds() {
        let p = profile("kind = \"bujlod\"");
        let Err(BuildError::Invalid(e)) = Catalog::shipped().agent(&p) else {
            panic!("must not build")
        };
        let problem = &e.problems()[0];
        assert_eq!(problem.path, "robot.kind");
        assert!(problem.line.is_some());
        assert!(
            problem.message.contains("registered: axel, bujold, krawler, raposa"),
            "{}",
            problem.message
        );
    }

    #[test]
    fn another_kinds_tuning_is_refused_by_name() {
        // RAPOSA's kind on Bujold's tuning: `ratio_steering` is no field of RAPOSA's.
        let p = profile("kind = \"raposa\"");
        let Err(BuildError::Invalid(e)) = Catalog::shipped().agent(&p) else {
            panic!("must not build")
        };
        let problem = &e.problems()[0];
        assert!(problem.path.starts_with("robot"), "{problem}");
        assert!(problem.line.is_some(), "{problem}");
    }

    #[test]
    fn the_shipped_catalog_builds_the_shipped_robots() {
        for f in ["bujold", "raposa", "axel", "bujold-raposa", "bujold-avoid"] {
            let p = Profile::load(format!("profiles/{f}.toml").as_ref()).unwrap();
            assert!(shipped().agent(&p).is_ok(), "{f}");
        }
    }
}
