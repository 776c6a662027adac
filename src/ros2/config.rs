//! The node's settings and its Zenoh configuration.

use super::devices::ImageKind;
use super::keys::NodeName;
use crate::arbiter::runtime::RuntimeConfig;
use crate::profile::Profile;
use std::path::PathBuf;
use thiserror::Error;

/// Why the node could not start.
#[derive(Debug, Error)]
pub enum BridgeError {
    /// Zenoh refused the configuration or a declaration.
    #[error("zenoh: {0}")]
    Zenoh(String),
    /// The profile's behavior could not be built.
    #[error("the profile's behavior: {0}")]
    Behavior(String),
    /// The configuration does not fit the profile.
    #[error("{0}")]
    Config(String),
}

pub(crate) fn zerr(e: impl std::fmt::Display) -> BridgeError {
    BridgeError::Zenoh(e.to_string())
}

/// One camera's topic.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CameraTopic {
    /// The topic (`camera/image_raw`).
    pub topic: String,
    /// Raw or compressed.
    pub kind: ImageKind,
}

/// The node's settings.
#[derive(Debug, Clone, PartialEq)]
pub struct BridgeConfig {
    /// Domain, namespace and node name.
    pub node: NodeName,
    /// Zenoh endpoints to listen on (`tcp/127.0.0.1:0`: a port the OS chooses).
    pub listen: Vec<String>,
    /// Zenoh endpoints to connect to: `rmw_zenoh`'s router is at `tcp/127.0.0.1:7447` by
    /// default.
    pub connect: Vec<String>,
    /// One per camera of the profile, in its order.
    pub cameras: Vec<CameraTopic>,
    /// `nav_msgs/msg/Odometry`, when the profile's behaviors need odometry.
    pub odometry: Option<String>,
    /// `std_msgs/msg/Bool`, the dock contact switch.
    pub dock_contact: Option<String>,
    /// `geometry_msgs/msg/Twist` out.
    pub cmd_vel: String,
    /// Read each frame's age from its header stamp (clocks in sync, as ROS assumes);
    /// otherwise frames are stamped on arrival.
    pub trust_stamps: bool,
    /// The runtime's settings (an undocking's `max_undocking_time` overrides
    /// `max_duration`).
    pub runtime: RuntimeConfig,
    /// The odometry frame: the one frame a goal's `dock_pose` (or a dock of the
    /// database) may be in, the node having no transforms.
    pub odom_frame: String,
    /// A dock database file read at start ([`super::dock_db`]), beside the profile's dock.
    pub dock_database: Option<PathBuf>,
}

impl BridgeConfig {
    /// Defaults for `profile`: node `docking_server` (Nav2's name for it) in domain 0, no
    /// namespace, listening on nothing and connecting to a router at
    /// `tcp/127.0.0.1:7447`; `camera/image_raw` (`camera0/image_raw`, `camera1/image_raw`
    /// … for several cameras), `odom`, `dock_contact`, `cmd_vel`; odometry frame `odom`;
    /// the profile's dock only.
    pub fn for_profile(profile: &Profile) -> Self {
        let n = profile.cameras.len();
        Self {
            node: NodeName {
                domain: 0,
                namespace: String::new(),
                name: "docking_server".to_owned(),
            },
            listen: Vec::new(),
            connect: vec!["tcp/127.0.0.1:7447".to_owned()],
            cameras: (0..n)
                .map(|i| CameraTopic {
                    topic: if n == 1 {
                        "camera/image_raw".to_owned()
                    } else {
                        format!("camera{i}/image_raw")
                    },
                    kind: ImageKind::Raw,
                })
                .collect(),
            odometry: Some("odom".to_owned()),
            dock_contact: Some("dock_contact".to_owned()),
            cmd_vel: "cmd_vel".to_owned(),
            trust_stamps: true,
            runtime: RuntimeConfig::default(),
            odom_frame: "odom".to_owned(),
            dock_database: None,
        }
    }
}

/// A Zenoh configuration of peer mode with exactly these endpoints and multicast
/// scouting off: the session talks only to the endpoints it is given and to the peers
/// that connect to it.
///
/// # Errors
/// [`BridgeError::Zenoh`] for an endpoint Zenoh cannot parse.
pub fn zenoh_config(listen: &[String], connect: &[String]) -> Result<zenoh::Config, BridgeError> {
    let mut c = zenoh::Config::default();
    let list = |v: &[String]| serde_json::to_string(v).unwrap_or_else(|_| "[]".to_owned());
    c.insert_json5("mode", "\"peer\"").map_err(zerr)?;
    c.insert_json5("listen/endpoints", &list(listen)).map_err(zerr)?;
    c.insert_json5("connect/endpoints", &list(connect)).map_err(zerr)?;
    c.insert_json5("scouting/multicast/enabled", "false").map_err(zerr)?;
    Ok(c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_zenoh_configuration_has_multicast_off_and_only_the_given_endpoints() {
        let c = zenoh_config(&["tcp/127.0.0.1:0".to_owned()], &[]).unwrap();
        let text = format!("{c}");
        assert!(text.contains("127.0.0.1:0"), "{text}");
        assert_eq!(c.get_json("scouting/multicast/enabled").unwrap(), "false");
        assert_eq!(c.get_json("connect/endpoints").unwrap(), "[]");
        assert!(zenoh_config(&["not an endpoint".to_owned()], &[]).is_err());
    }
}
