//! The AutoKrawler (seed 003) as a robot kind, `[robot] kind = "krawler"`: its state
//! estimator runs as the memory's perceptual schema on every tick ([`KrawlerMemory`]),
//! and its tree's leaves act on the estimate: `krawler.traverse` drives and says what it
//! commanded, `krawler.slip_monitor` compares the optical wheel rotation with the
//! commanded one (the paper's future work: "with two independent representations of
//! motion, rover slip can also be detected"), `krawler.halt` stops on a slip.
//!
//! ```toml
//! [robot]
//! kind = "krawler"
//! [robot.gear]                  # the gear's dimensions (defaults: our estimates)
//! tread_width_m = 0.08
//! ```

mod memory;
pub mod slip;
pub mod traverse;

pub use memory::{KrawlerMemory, Observer};
pub use slip::SlipReading;

use super::agent::BuildError;
use super::catalog::{LeafRegistry, RobotKind};
use super::registry::LeafArgs;
use crate::config::{Validate, Validator};
use crate::perception::{GearSpec, KrawlerParams};
use crate::profile::Profile;
use crate::schemas::KrawlerSchema;
use serde::{Deserialize, Serialize};

/// The `krawler` kind's `[robot]` table (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KrawlerRobot {
    /// The gear's dimensions (`[robot.gear]`; every field defaults to its estimate).
    #[serde(default)]
    pub gear: GearSpec,
    /// Compensate the camera's vibration on its mount (default true; off reads every
    /// frame with the nominal mount, as the paper does).
    #[serde(default = "yes")]
    pub mount_compensation: bool,
    /// Seed of the estimator's RANSAC draws (default 0): the same seed and frames give
    /// the same estimates bit for bit.
    #[serde(default)]
    pub ransac_seed: u64,
}

fn yes() -> bool {
    true
}

impl Validate for KrawlerRobot {
    fn validate(&self, v: &mut Validator<'_>) {
        let g = &self.gear;
        v.positive("robot.gear.tread_width_m", g.tread_width_m);
        v.positive("robot.gear.hub_below_plate_m", g.hub_below_plate_m);
        v.positive("robot.gear.plate_marker_y_m", g.plate_marker_y_m);
        v.positive("robot.gear.steering_arm_m", g.steering_arm_m);
    }
}

/// The gear's dimensions of `profile`: its `[robot.gear]` when its robot kind is
/// `krawler`, read and checked strictly; the defaults for a profile without `[robot]`
/// (perception only).
///
/// # Errors
/// [`BuildError::Invalid`] naming the line of a field the table refuses;
/// [`BuildError::Profile`] when `[robot]` names another kind (which has no gear).
pub fn gear_spec(profile: &Profile) -> Result<GearSpec, BuildError> {
    match &profile.robot {
        None => Ok(GearSpec::default()),
        Some(r) if r.kind == Krawler::NAME => Ok(super::catalog::tuning::<Krawler>(profile)?.gear),
        Some(r) => Err(BuildError::Profile {
            profile: profile.name.clone(),
            what: format!(
                "robot kind `{}` has no AutoKrawler gear (that is robot kind `krawler`'s [robot.gear])",
                r.kind
            ),
        }),
    }
}

/// The estimator of `profile` as `tuning` sets it up.
fn schema_with(profile: &Profile, tuning: &KrawlerRobot) -> Result<KrawlerSchema, String> {
    let mut params = KrawlerParams::default();
    params.mount.enabled = tuning.mount_compensation;
    KrawlerSchema::from_profile(profile, tuning.gear, params, tuning.ransac_seed).map_err(|e| e.to_string())
}

/// The state estimator of an AutoKrawler `profile` alone, as its robot runs it (its
/// `[robot]` tuning, or the defaults for a profile without `[robot]`): what a replay of
/// its perception runs.
///
/// # Errors
/// As [`gear_spec`], and [`BuildError::Profile`] for what the estimator lacks (a camera,
/// the `markers` fiducial's steering calibration).
pub fn schema(profile: &Profile) -> Result<KrawlerSchema, BuildError> {
    let tuning = match &profile.robot {
        None => KrawlerRobot {
            gear: GearSpec::default(),
            mount_compensation: true,
            ransac_seed: 0,
        },
        Some(_) => {
            gear_spec(profile)?;
            super::catalog::tuning::<Krawler>(profile)?
        }
    };
    schema_with(profile, &tuning).map_err(|what| BuildError::Profile {
        profile: profile.name.clone(),
        what,
    })
}

/// The AutoKrawler's robot kind (see the module docs).
#[derive(Debug, Clone, Copy, Default)]
pub struct Krawler;

impl RobotKind for Krawler {
    const NAME: &'static str = "krawler";
    type Tuning = KrawlerRobot;
    type Memory = KrawlerMemory;

    fn memory(&self, profile: &Profile, tuning: &KrawlerRobot) -> Result<KrawlerMemory, String> {
        let radius = profile
            .drive
            .wheel_radius_m
            .ok_or("needs drive.wheel_radius_m (the commanded wheel rotation is the speed over it)")?;
        Ok(KrawlerMemory::new(schema_with(profile, tuning)?, radius))
    }

    fn leaves(&self, registry: &mut LeafRegistry<KrawlerMemory>) {
        registry
            .register("krawler.traverse", |_: &KrawlerMemory, a: &LeafArgs<'_>| {
                Ok(Box::new(traverse::Traverse::new(a.params()?)?))
            })
            .register("krawler.slip_monitor", |_: &KrawlerMemory, a: &LeafArgs<'_>| {
                Ok(Box::new(slip::SlipMonitor::new(a.params()?)?))
            })
            .register("krawler.halt", |_: &KrawlerMemory, a: &LeafArgs<'_>| {
                a.no_params()?;
                Ok(Box::new(traverse::Halt))
            });
    }
}
