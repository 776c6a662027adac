//! `marsupial check FILE...`: validate profiles (and scenarios) without running anything.

use crate::behaviors::{BuildError, Catalog};
use crate::config::ConfigError;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Validates one file with the crate's catalog (see [`check_file_with`]).
///
/// # Errors
/// The file's [`ConfigError`].
pub fn check_file(path: &Path) -> Result<(), ConfigError> {
    check_file_with(path, crate::behaviors::catalog::shipped())
}

/// Validates one file, choosing its kind from its contents: a scenario names its profile
/// with a top-level `profile = "path"` (a perception campaign for `pose-trials` also has
/// a `[pose]` table); anything else is checked as a profile. A profile (a scenario's,
/// as patched) naming a robot kind is also built with `catalog`, so its robot kind's
/// tuning and its tree are checked too. Scenarios need the simulator (feature `sim`):
/// without it a scenario is refused with a problem saying so.
///
/// # Errors
/// The file's [`ConfigError`].
pub fn check_file_with(path: &Path, catalog: &Catalog) -> Result<(), ConfigError> {
    let table = std::fs::read_to_string(path)
        .ok()
        .and_then(|s| s.parse::<toml::Table>().ok());
    let is_scenario = table
        .as_ref()
        .is_some_and(|t| t.get("profile").is_some_and(|v| v.is_str()));
    if is_scenario {
        check_scenario(path, table.as_ref(), catalog)
    } else {
        catalog.check_profile(path).map(|_| ())
    }
}

/// The [`ConfigError`] a robot that does not build reads as.
#[cfg_attr(not(feature = "sim"), allow(dead_code))]
fn build_problem(profile: &crate::profile::Profile, e: BuildError) -> ConfigError {
    match e {
        BuildError::Tree(e) | BuildError::Invalid(e) => e,
        other => profile.problems(vec![("robot".into(), other.to_string())]),
    }
}

#[cfg(feature = "sim")]
fn check_scenario(path: &Path, table: Option<&toml::Table>, catalog: &Catalog) -> Result<(), ConfigError> {
    if table.is_some_and(super::pose_trials::PoseCampaign::is_campaign) {
        return super::pose_trials::PoseCampaign::load(path).map(|_| ());
    }
    let loaded = crate::sim::scenario::Scenario::load_with(path, catalog.fiducials())?;
    if loaded.profile.robot.is_none() {
        return Ok(());
    }
    catalog
        .agent(&loaded.profile)
        .map(|_| ())
        .map_err(|e| build_problem(&loaded.profile, e))
}

#[cfg(not(feature = "sim"))]
fn check_scenario(path: &Path, _table: Option<&toml::Table>, _catalog: &Catalog) -> Result<(), ConfigError> {
    Err(ConfigError::Invalid {
        file: path.to_path_buf(),
        problems: vec![crate::config::Problem {
            path: "profile".into(),
            line: None,
            message: "the file is a scenario (it names a profile); this marsupial was built without the simulator that checks scenarios (build it with feature `sim`)".into(),
        }],
    })
}

/// Checks every file with the crate's catalog (see [`run_with`]).
pub fn run(files: &[PathBuf], out: &mut dyn Write, err: &mut dyn Write) -> usize {
    run_with(files, crate::behaviors::catalog::shipped(), out, err)
}

/// Checks every file with `catalog`'s robot and fiducial kinds, printing `ok FILE` to
/// `out` for each valid one and the error to `err` for each invalid one. Returns the
/// number of invalid files.
pub fn run_with(files: &[PathBuf], catalog: &Catalog, out: &mut dyn Write, err: &mut dyn Write) -> usize {
    let mut bad = 0;
    for f in files {
        match check_file_with(f, catalog) {
            Ok(()) => {
                let _ = writeln!(out, "ok {}", f.display());
            }
            Err(e) => {
                bad += 1;
                let _ = writeln!(err, "error: {e}");
            }
        }
    }
    bad
}
