//! `marsupial check FILE...`: validate profiles (and scenarios) without running anything.

use crate::config::ConfigError;
use crate::profile::Profile;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Validates one file, choosing its kind from its contents: a scenario names its profile
/// with a top-level `profile = "path"` (a perception campaign for `pose-trials` also has
/// a `[pose]` table); anything else is checked as a profile.
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
    if is_scenario
        && table
            .as_ref()
            .is_some_and(super::pose_trials::PoseCampaign::is_campaign)
    {
        super::pose_trials::PoseCampaign::load(path).map(|_| ())
    } else if is_scenario {
        crate::sim::scenario::Scenario::load(path).map(|_| ())
    } else {
        Profile::load(path).map(|_| ())
    }
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
