//! `marsupial check FILE...`: validate profiles (and scenarios) without running anything.

use crate::config::ConfigError;
use crate::profile::Profile;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Validates one file, choosing its kind from its contents: a scenario names its profile
/// with a top-level `profile = "path"` (a perception campaign for `pose-trials` also has
/// a `[pose]` table); anything else is checked as a profile. Scenarios need the simulator
/// (feature `sim`): without it a scenario is refused with a problem saying so.
///
/// # Errors
/// The file's [`ConfigError`].
pub fn check_file(path: &Path) -> Result<(), ConfigError> {
    let table = std::fs::read_to_string(path)
        .ok()
        .and_then(|s| s.parse::<toml::Table>().ok());
    let is_scenario = table
        .as_ref()
        .is_some_and(|t| t.get("profile").is_some_and(|v| v.is_str()));
    if is_scenario {
        check_scenario(path, table.as_ref())
    } else {
        Profile::load(path).map(|_| ())
    }
}

#[cfg(feature = "sim")]
fn check_scenario(path: &Path, table: Option<&toml::Table>) -> Result<(), ConfigError> {
    if table.is_some_and(super::pose_trials::PoseCampaign::is_campaign) {
        super::pose_trials::PoseCampaign::load(path).map(|_| ())
    } else {
        crate::sim::scenario::Scenario::load(path).map(|_| ())
    }
}

#[cfg(not(feature = "sim"))]
fn check_scenario(path: &Path, _table: Option<&toml::Table>) -> Result<(), ConfigError> {
    Err(ConfigError::Invalid {
        file: path.to_path_buf(),
        problems: vec![crate::config::Problem {
            path: "profile".into(),
            line: None,
            message: "the file is a scenario (it names a profile); this marsupial was built without the simulator that checks scenarios (build it with feature `sim`)".into(),
        }],
    })
}

/// Checks every file, printing `ok FILE` to `out` for each valid one and the error to
/// `err` for each invalid one. Returns the number of invalid files.
pub fn run(files: &[PathBuf], out: &mut dyn Write, err: &mut dyn Write) -> usize {
    let mut bad = 0;
    for f in files {
        match check_file(f) {
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
