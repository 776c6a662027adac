//! The `marsupial` command-line tool's subcommands, as library functions so they can be
//! tested without spawning a process.
//!
//! Two layers: the commands a robot runs, which need no simulator (`check`, `detect`,
//! `calibrate-odometry`, `timeline`, and `ros2` with feature `ros2`), and the campaign
//! commands, compiled only with feature `sim` (`dock`, `trials`, `merge`, `pose-trials`,
//! `estimate`, `calibrate-steering`, `replay`).

pub mod calibrate;
#[cfg(feature = "sim")]
pub mod calibrate_steering;
pub mod check;
pub mod command;
pub mod detect;
#[cfg(feature = "sim")]
pub mod estimate;
#[cfg(feature = "sim")]
mod estimate_frames;
#[cfg(feature = "sim")]
pub mod estimate_runtime;
#[cfg(feature = "sim")]
pub mod merge;
#[cfg(feature = "sim")]
pub mod pose_trials;
#[cfg(feature = "sim")]
pub mod replay;
#[cfg(feature = "ros2")]
pub mod ros2;
#[cfg(feature = "sim")]
pub mod sim_cmds;
pub mod timeline;

pub use command::{Plugins, run, run_with};

/// Writes `v` as one line of JSON (the `--json` output of the subcommands that print a
/// record per item).
pub(crate) fn json_line<T: serde::Serialize>(out: &mut dyn std::io::Write, v: &T) -> std::io::Result<()> {
    writeln!(out, "{}", serde_json::to_string(v).map_err(std::io::Error::other)?)
}
