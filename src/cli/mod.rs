//! The `marsupial` command-line tool's subcommands, as library functions so they can be
//! tested without spawning a process.

pub mod calibrate;
pub mod calibrate_steering;
pub mod check;
pub mod detect;
pub mod estimate;
pub mod merge;
pub mod replay;
pub mod sim_cmds;
pub mod timeline;
