//! The `marsupial` command itself: its arguments and their dispatch, served by
//! [`run`] for the crate's robots or by [`run_with`] for a crate's own (see [`Plugins`]).
//! The campaign commands need feature `sim`, `ros2` needs feature `ros2`; `check`,
//! `detect`, `calibrate-odometry` and `timeline` need neither.

use crate::behaviors::Catalog;
use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

/// Reactive vision-based docking: validate profiles, run perception, docking runs and
/// trial campaigns in the built-in simulator.
#[derive(Parser, Debug)]
#[command(name = "marsupial", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Run one docking run of a scenario in the simulator.
    ///
    /// Prints one line (or, with --json, the run record: start, outcome, time_s, path_m,
    /// entrance errors, track …). With --out DIR, writes DIR/trajectory.csv and every Nth
    /// camera frame (the scenario's [record] frames_every) to DIR/frames/. With --trace
    /// FILE, writes each tick's decision (see `timeline`).
    #[cfg(feature = "sim")]
    Dock(super::sim_cmds::DockOptions),
    /// Run a scenario's whole trial campaign in the simulator, in parallel.
    ///
    /// Prints a table per start group (success rate, mean and SD of time to dock, effective
    /// velocity, commands per metre, failures by reason). With --out DIR: DIR/runs.jsonl
    /// (one line per finished run, in run order), DIR/summary.json, DIR/trajectories.svg,
    /// DIR/success_map.svg and per-run trajectories.
    #[cfg(feature = "sim")]
    Trials(super::sim_cmds::TrialsOptions),
    /// Run a perception campaign for circle fiducials (Axel) against the simulator's truth.
    ///
    /// Renders both cameras through the campaign's sensor from a grid of rover poses
    /// (distance, α, heading, noise seeds; `[occlusion]` adds marks hidden behind panels
    /// and false marks), detects, labels and poses the module in stereo and mono, and
    /// prints per-distance tables beside the paper's figures: pose errors, reprojection,
    /// the ablations (mono without the distortion model, labelling from 4 marks) and what
    /// happened per number of visible marks. `--json` prints one record per run instead;
    /// `--out DIR` writes DIR/runs.jsonl and DIR/tables.txt. Same seed, same bytes.
    #[cfg(feature = "sim")]
    PoseTrials(super::pose_trials::PoseTrialsOptions),
    /// Join the output folders of a campaign's shards (`trials S --shard K/N --out DIR`).
    ///
    /// Checks that the folders are shards 1..N of one campaign, each complete, and writes
    /// OUT/runs.jsonl (the shards' lines in campaign order) and OUT/summary.json, equal
    /// byte for byte to an unsharded `trials --out`; with --scenario, also the plots and
    /// paper comparison.
    #[cfg(feature = "sim")]
    Merge(super::merge::MergeOptions),
    /// Validate profile and scenario files.
    ///
    /// Prints `ok FILE` for each valid file. For each invalid file prints every problem
    /// as `FILE:LINE: FIELD.PATH: what was expected`, and exits with status 1.
    Check {
        /// Files to check (TOML).
        #[arg(required = true, value_name = "FILE")]
        files: Vec<PathBuf>,
    },
    /// Fit skid-steer odometry (effective track and wheel scale) to a logged run.
    ///
    /// The log is CSV with a header and one line per sample:
    /// `t,left_m,right_m,x_m,y_m,theta_rad`: cumulative wheel travel as the encoders
    /// report it, and the true pose (motion capture, survey, or the simulator). Drive
    /// straight and turn both ways in the log. With `--profile`, also reports whether the
    /// fit lies in the profile's [d_min, d_max].
    CalibrateOdometry {
        /// The log (CSV).
        #[arg(value_name = "LOG.csv")]
        log: PathBuf,
        /// Profile to compare with.
        #[arg(long, value_name = "PROFILE")]
        profile: Option<PathBuf>,
        /// Print JSON: {"calibration": {...}, "within_profile_bounds": bool|null}.
        #[arg(long)]
        json: bool,
    },
    /// Fit the AutoKrawler's steering polynomials λ = f(x) from a sweep.
    ///
    /// Finds the eight markers in each frame of a recorded sweep (`--sweep`, CSV
    /// `image,steer_front_deg,steer_rear_deg`) or of one simulated from the profile's gear
    /// (0 → +max → −max), takes each axle's tie-rod ratio x = d(B1,A1)/d(B2,A2) after
    /// ray-plane intersection, and fits λ = c0 + c1·(x−1) + c2·(x−1)² per axle. Prints
    /// the coefficients and residuals; `--write` puts them into the profile.
    #[cfg(feature = "sim")]
    CalibrateSteering(super::calibrate_steering::CalibrateSteeringOptions),
    /// Run a profile's fiducial detection on image files: the two-block schema for a
    /// `two_block` fiducial profile, circle marks for a `circles` fiducial one.
    ///
    /// The images are processed in order as a stream, so adaptation carries from one to
    /// the next (and the fallback timeouts run on `--interval` seconds per image). With
    /// `--imprint`, those images are imprinted on first, as on departure from the dock.
    /// PNG and JPEG are read; grey and RGBA images are converted.
    ///
    /// `--json` prints one object per image: image, width, height, found, left_px,
    /// right_px, total_px, ratio, left_centroid, right_centroid, offset_px, mode
    /// (adapted / imprinted / table) and us_per_frame (median over --repeat runs).
    ///
    /// For circles (Axel) each image is camera --camera N's frame, processed on its own:
    /// detection, correspondence to the profile's layout and the monocular pose through
    /// that camera's lens model. `--json` gives found (or the reason not), each mark's
    /// id, rotation, centroid and whether it was detected or filled in, the hypothesis,
    /// reprojection error, inliers, and the module's pose with its quality figures.
    Detect(super::detect::DetectOptions),
    /// Run the AutoKrawler's state estimator over a rendered driving sequence (seed 003).
    ///
    /// Renders every frame of a sequence (built-in dataset1, dataset2, dataset3 of the
    /// paper's 82, 170 and 257 s, or a sequences/*.toml file) with a known state and
    /// sensor noise, estimates the ten degrees of freedom, and prints a table beside the
    /// paper's Table I: roll and steering MAE, the wheel drift the paper's way (the rear
    /// wheels' mean against the rear encoder) and per wheel, and the double-Ackermann
    /// odometry's drift with the estimated against the commanded steering. `--out DIR`
    /// writes frames.csv, odometry.csv, an SVG per degree of freedom and summary.json.
    #[cfg(feature = "sim")]
    Estimate(super::estimate::EstimateOptions),
    /// Run a profile's perception, or its whole behavior open-loop, on a real log.
    ///
    /// Reads ROS 2 bags in MCAP (CDR `sensor_msgs/msg/Image`, `sensor_msgs/msg/CompressedImage`,
    /// `nav_msgs/msg/Odometry`) and Foxglove-schema MCAP files (JSON `foxglove.RawImage`,
    /// `foxglove.CompressedImage`, `foxglove.PoseInFrame`, as `dock --record` writes them).
    /// Prints one line per frame (the percept, and with --behavior the command the robot
    /// would have sent), one per message that could not be used (bad CDR, 16-bit
    /// encodings, truncated JPEG…), and a summary with the skipped counts by topic and reason.
    #[cfg(feature = "sim")]
    Replay(super::replay::ReplayOptions),
    /// Run a profile's behaviors as a ROS 2 node over Zenoh (built with `--features ros2`).
    ///
    /// Speaks `rmw_zenoh`'s key expressions and CDR: subscribes to the camera image(s),
    /// odometry and the dock switch, publishes cmd_vel (and the posture, dock_guides and
    /// lights the profile declares),
    /// and serves Nav2's docking interface: the actions dock_robot
    /// (nav2_msgs/action/DockRobot) and undock_robot (nav2_msgs/action/UndockRobot) and
    /// the service reload_database (nav2_msgs/srv/ReloadDockDatabase); no ROS 2 package
    /// of ours is needed to call them. Multicast scouting is off: it talks to the
    /// endpoints given and nothing else.
    #[cfg(feature = "ros2")]
    Ros2(super::ros2::Ros2Options),
    /// Print the phase timeline of a run from its decision trace (`dock --trace`).
    ///
    /// One line per sequencer transition: mission, time, sequencer, from → to and the
    /// event that fired it; and one per mission's end with its outcome.
    Timeline {
        /// The trace (JSON lines).
        #[arg(value_name = "TRACE.jsonl")]
        trace: PathBuf,
    },
}

/// Exit status of a subcommand: success, or the error on stderr and status 1.
fn exit_code<T, E: std::fmt::Display>(result: Result<T, E>) -> ExitCode {
    match result {
        Ok(_) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// What a `marsupial` command serves: the robot catalog (robot kinds, fiducial kinds,
/// device kinds) and, with the simulator, how it draws each fiducial kind's dock and
/// simulates each device kind. [`Plugins::default`] is the crate's own; a crate adds its
/// kinds to both and builds its own command with [`run_with`]
/// (`examples/plugin_robot.rs`).
#[derive(Clone, Default)]
pub struct Plugins {
    /// Robot, fiducial and device kinds by name.
    pub catalog: Catalog,
    /// Dock painters and device simulations by kind.
    #[cfg(feature = "sim")]
    pub sim: crate::sim::kinds::SimKinds,
}

/// Runs the `marsupial` command for the crate's own robots: parses the process's
/// arguments, runs the subcommand, returns its exit status.
pub fn run() -> ExitCode {
    run_with(Plugins::default())
}

/// Runs the `marsupial` command serving `plugins` (see [`Plugins`]): `check`, `dock`,
/// `trials`, `replay` and `ros2` know its robot and fiducial kinds as they know the
/// crate's.
pub fn run_with(plugins: Plugins) -> ExitCode {
    // Logs (decisions, phase changes, colour-model switches, safe stops) go to stderr when
    // RUST_LOG asks for them, e.g. RUST_LOG=marsupial=debug.
    let _ = tracing_subscriber::fmt()
        .with_env_filter(tracing_subscriber::EnvFilter::from_default_env())
        .with_writer(std::io::stderr)
        .try_init();
    let cli = Cli::parse();
    match cli.command {
        Command::CalibrateOdometry { log, profile, json } => exit_code(super::calibrate::run(
            &log,
            profile.as_deref(),
            json,
            &mut std::io::stdout(),
        )),
        #[cfg(feature = "sim")]
        Command::CalibrateSteering(opts) => exit_code(super::calibrate_steering::run(&opts, &mut std::io::stdout())),
        Command::Check { files } => {
            let bad = super::check::run_with(&files, &plugins.catalog, &mut std::io::stdout(), &mut std::io::stderr());
            if bad == 0 { ExitCode::SUCCESS } else { ExitCode::FAILURE }
        }
        #[cfg(feature = "sim")]
        Command::Dock(opts) => exit_code(super::sim_cmds::dock_with(&opts, &plugins, &mut std::io::stdout())),
        #[cfg(feature = "sim")]
        Command::Trials(mut opts) => {
            opts.progress = if std::io::IsTerminal::is_terminal(&std::io::stderr()) {
                crate::sim::campaign::Progress::Bar
            } else {
                crate::sim::campaign::Progress::Lines
            };
            exit_code(super::sim_cmds::trials_with(&opts, &plugins, &mut std::io::stdout()))
        }
        #[cfg(feature = "sim")]
        Command::PoseTrials(opts) => exit_code(super::pose_trials::run(&opts, &mut std::io::stdout())),
        #[cfg(feature = "sim")]
        Command::Merge(opts) => exit_code(super::merge::run(&opts, &mut std::io::stdout())),
        Command::Detect(opts) => exit_code(super::detect::run(&opts, &mut std::io::stdout())),
        #[cfg(feature = "sim")]
        Command::Estimate(opts) => exit_code(super::estimate::run(&opts, &mut std::io::stdout())),
        #[cfg(feature = "sim")]
        Command::Replay(opts) => exit_code(super::replay::run_with(&opts, &plugins.catalog, &mut std::io::stdout())),
        #[cfg(feature = "ros2")]
        Command::Ros2(opts) => exit_code(super::ros2::run_with(&opts, &plugins.catalog, &mut std::io::stdout())),
        Command::Timeline { trace } => exit_code(super::timeline::run(&trace, &mut std::io::stdout())),
    }
}
