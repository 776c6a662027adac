//! The `marsupial` command-line tool's subcommands, as library functions so they can be
//! tested without spawning a process.

pub mod calibrate;
pub mod calibrate_steering;
pub mod check;
pub mod detect;
pub mod estimate;
pub mod merge;
pub mod pose_trials;
pub mod replay;
#[cfg(feature = "ros2")]
pub mod ros2;
pub mod sim_cmds;
pub mod timeline;

/// Writes `v` as one line of JSON (the `--json` output of the subcommands that print a
/// record per item).
pub(crate) fn json_line<T: serde::Serialize>(out: &mut dyn std::io::Write, v: &T) -> std::io::Result<()> {
    writeln!(out, "{}", serde_json::to_string(v).map_err(std::io::Error::other)?)
}
