//! `marsupial ros2`: a profile's behaviors as a ROS 2 node over Zenoh (feature `ros2`).
//!
//! The node runs until interrupted (Ctrl-C) or, with `--for`, for that long; it prints
//! where it listens and each goal's end.

use crate::profile::Profile;
use crate::ros2::{BridgeConfig, BridgeError, CameraTopic, ImageKind, Ros2Node};
use std::io::Write;
use std::path::PathBuf;
use std::time::Duration;
use thiserror::Error;

/// Options of `marsupial ros2`.
#[derive(Debug, Clone, clap::Args)]
pub struct Ros2Options {
    /// The robot's profile (e.g. profiles/bujold.toml).
    #[arg(long, value_name = "PROFILE")]
    pub profile: PathBuf,
    /// ROS domain (`ROS_DOMAIN_ID`; default: that variable, or 0).
    #[arg(long)]
    pub domain: Option<u32>,
    /// The node's namespace (`/robot1`).
    #[arg(long, default_value = "")]
    pub namespace: String,
    /// The node's name: Nav2's docking server is `docking_server`, whose
    /// `reload_database` service clients then find where Nav2's is.
    #[arg(long, default_value = "docking_server")]
    pub name: String,
    /// Zenoh endpoint to connect to: the `rmw_zenoh` router (`ros2 run rmw_zenoh_cpp
    /// rmw_zenohd`) listens on tcp/127.0.0.1:7447. Repeat for several; `none` for none.
    #[arg(long, value_name = "ENDPOINT", default_values_t = ["tcp/127.0.0.1:7447".to_owned()])]
    pub connect: Vec<String>,
    /// Zenoh endpoint to listen on (e.g. tcp/127.0.0.1:0 for a port the OS chooses).
    #[arg(long, value_name = "ENDPOINT")]
    pub listen: Vec<String>,
    /// Image topic, once per camera of the profile (default camera/image_raw, or
    /// camera0/image_raw, camera1/image_raw … for several).
    #[arg(long, value_name = "TOPIC")]
    pub image_topic: Vec<String>,
    /// The image topics carry sensor_msgs/msg/CompressedImage (JPEG or PNG).
    #[arg(long)]
    pub compressed: bool,
    /// Odometry topic (nav_msgs/msg/Odometry); `none` when the robot has none.
    #[arg(long, default_value = "odom")]
    pub odom_topic: String,
    /// Dock contact switch topic (std_msgs/msg/Bool); `none` when the robot has none.
    #[arg(long, default_value = "dock_contact")]
    pub dock_topic: String,
    /// Velocity command topic (geometry_msgs/msg/Twist).
    #[arg(long, default_value = "cmd_vel")]
    pub cmd_vel_topic: String,
    /// The odometry frame: the one frame a DockRobot goal's `dock_pose` (or a dock of the
    /// database) may be in (the node has no transforms).
    #[arg(long, default_value = "odom")]
    pub odom_frame: String,
    /// A dock database to read at start (Nav2's YAML shape: `docks:`, then per dock id its
    /// `type`, `frame` and `pose: [x, y, yaw]`), beside the profile's own dock, whose id
    /// is the profile's name.
    #[arg(long, value_name = "FILE")]
    pub dock_database: Option<PathBuf>,
    /// Stamp frames on arrival instead of trusting their header stamps (for cameras
    /// whose clock is not synchronised with this machine's).
    #[arg(long)]
    pub stamp_on_arrival: bool,
    /// Exit after this many seconds (default: run until interrupted).
    #[arg(long = "for", value_name = "SECONDS")]
    pub run_for: Option<f64>,
}

/// Why `marsupial ros2` failed.
#[derive(Debug, Error)]
pub enum Ros2CliError {
    /// Bad profile.
    #[error(transparent)]
    Profile(#[from] crate::config::ConfigError),
    /// The node did not start.
    #[error(transparent)]
    Bridge(#[from] BridgeError),
    /// Bad option.
    #[error("{0}")]
    Option(String),
    /// Writing the output failed.
    #[error(transparent)]
    Io(#[from] std::io::Error),
}

fn optional(topic: &str) -> Option<String> {
    (topic != "none" && !topic.is_empty()).then(|| topic.to_owned())
}

/// The node's configuration from the options.
///
/// # Errors
/// [`Ros2CliError::Option`] for a domain that is not a number or an image topic count
/// that does not match the profile's cameras.
pub fn config(opts: &Ros2Options, profile: &Profile) -> Result<BridgeConfig, Ros2CliError> {
    let mut c = BridgeConfig::for_profile(profile);
    c.node.domain = match opts.domain {
        Some(d) => d,
        None => match std::env::var("ROS_DOMAIN_ID") {
            Ok(v) if !v.trim().is_empty() => v
                .trim()
                .parse()
                .map_err(|_| Ros2CliError::Option(format!("ROS_DOMAIN_ID `{v}` is not a number")))?,
            _ => 0,
        },
    };
    c.node.namespace = opts.namespace.clone();
    c.node.name = opts.name.clone();
    c.connect = opts.connect.iter().filter(|e| e.as_str() != "none").cloned().collect();
    c.listen = opts.listen.clone();
    if !opts.image_topic.is_empty() {
        if opts.image_topic.len() != profile.cameras.len() {
            return Err(Ros2CliError::Option(format!(
                "{} --image-topic given for a profile with {} camera(s)",
                opts.image_topic.len(),
                profile.cameras.len()
            )));
        }
        c.cameras = opts
            .image_topic
            .iter()
            .map(|t| CameraTopic {
                topic: t.clone(),
                kind: ImageKind::Raw,
            })
            .collect();
    }
    if opts.compressed {
        for cam in &mut c.cameras {
            cam.kind = ImageKind::Compressed;
        }
    }
    c.odometry = optional(&opts.odom_topic);
    c.dock_contact = optional(&opts.dock_topic);
    c.cmd_vel = opts.cmd_vel_topic.clone();
    c.trust_stamps = !opts.stamp_on_arrival;
    c.odom_frame = opts.odom_frame.clone();
    c.dock_database = opts.dock_database.clone();
    Ok(c)
}

/// Runs the node.
///
/// # Errors
/// [`Ros2CliError`].
pub fn run(opts: &Ros2Options, out: &mut dyn Write) -> Result<(), Ros2CliError> {
    run_with(opts, crate::behaviors::catalog::shipped(), out)
}

/// [`run`] with the robot built from `catalog` (a crate's own robot kinds).
///
/// # Errors
/// As [`run`].
pub fn run_with(
    opts: &Ros2Options,
    catalog: &crate::behaviors::Catalog,
    out: &mut dyn Write,
) -> Result<(), Ros2CliError> {
    let profile = catalog.load_profile(&opts.profile)?;
    let config = config(opts, &profile)?;
    let node = Ros2Node::start_with(&profile, catalog, config.clone())?;
    writeln!(
        out,
        "node `{}` of `{}` in domain {}; listening on [{}], connecting to [{}]",
        config.node.qualify(&config.node.name),
        profile.name,
        config.node.domain,
        node.locators().join(", "),
        config.connect.join(", ")
    )?;
    writeln!(
        out,
        "actions: {} (nav2_msgs/action/DockRobot, dock_id `{}`) and {} (UndockRobot); service {}",
        config.node.qualify("dock_robot"),
        profile.name,
        config.node.qualify("undock_robot"),
        config.node.qualify(&format!("{}/reload_database", config.node.name))
    )?;
    out.flush()?;
    match opts.run_for {
        Some(s) if s.is_finite() && s >= 0.0 => std::thread::sleep(Duration::from_secs_f64(s)),
        Some(s) => return Err(Ros2CliError::Option(format!("--for {s}: not a duration"))),
        None => loop {
            std::thread::sleep(Duration::from_secs(3600));
        },
    }
    node.shutdown();
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        opts: Ros2Options,
    }

    fn profile() -> Profile {
        Profile::load(&std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/bujold.toml")).unwrap()
    }

    #[test]
    fn defaults_follow_ros_2_conventions() {
        let cli = Cli::parse_from(["x", "--profile", "p.toml", "--domain", "3"]);
        let c = config(&cli.opts, &profile()).unwrap();
        assert_eq!(c.node.domain, 3);
        assert_eq!(c.connect, ["tcp/127.0.0.1:7447"]);
        assert_eq!(c.cameras[0].topic, "camera/image_raw");
        assert_eq!((c.odometry.as_deref(), c.cmd_vel.as_str()), (Some("odom"), "cmd_vel"));
        assert_eq!(
            (c.node.name.as_str(), c.odom_frame.as_str()),
            ("docking_server", "odom")
        );
        assert_eq!(c.dock_database, None);
    }

    #[test]
    fn topics_and_endpoints_can_be_changed_or_dropped() {
        let cli = Cli::parse_from([
            "x",
            "--profile",
            "p.toml",
            "--domain",
            "0",
            "--connect",
            "none",
            "--listen",
            "tcp/127.0.0.1:0",
            "--image-topic",
            "front/image_raw/compressed",
            "--compressed",
            "--odom-topic",
            "none",
        ]);
        let c = config(&cli.opts, &profile()).unwrap();
        assert!(c.connect.is_empty());
        assert_eq!(c.listen, ["tcp/127.0.0.1:0"]);
        assert_eq!(c.cameras[0].kind, ImageKind::Compressed);
        assert_eq!(c.odometry, None);
    }

    #[test]
    fn a_topic_per_camera_is_required() {
        let cli = Cli::parse_from([
            "x",
            "--profile",
            "p",
            "--domain",
            "0",
            "--image-topic",
            "a",
            "--image-topic",
            "b",
        ]);
        let e = config(&cli.opts, &profile()).unwrap_err();
        assert!(
            e.to_string()
                .contains("2 --image-topic given for a profile with 1 camera"),
            "{e}"
        );
    }
}
