//! The integration tests that run the command-line tool (feature `cli`), in one binary
//! (`cargo test --test cli`; one file's: `cargo test --test cli replay::`). One module
//! per file beside this one.

mod common;
// Configuration-text mutations for the loaders' no-panic tests (profile_errors, scenario_errors).
#[path = "common/mutate.rs"]
mod mutate;

mod axel_pose_campaign;
mod campaign_resume;
mod detect_cli;
mod dock_cli;
mod krawler_estimate;
mod krawler_replay;
mod lighting_random;
mod odometry_calibration;
mod profile_errors;
mod replay;
mod replay_bags;
mod scenario_errors;
mod shard_merge;
mod trials_determinism;
