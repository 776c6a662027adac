//! A ROS 2 bridge over Zenoh (feature `ros2`): the robot's behaviors as a ROS 2 node in
//! the key expressions and CDR payloads of `rmw_zenoh`, ROS 2's Zenoh transport.
//!
//! [`Ros2Node::start`] opens a Zenoh session with explicit endpoints and multicast
//! scouting off, subscribes to the camera image(s), odometry and the dock switch,
//! publishes `cmd_vel`, and serves Nav2's docking interface exactly:
//! `nav2_msgs/action/DockRobot` on `dock_robot`, `nav2_msgs/action/UndockRobot` on
//! `undock_robot` and `nav2_msgs/srv/ReloadDockDatabase` on `<node>/reload_database`
//! (see [`node`], [`goals`], [`nav2`]). A ROS 2 client needs no package of ours.
//! `marsupial ros2 --profile P` runs it from the command line, and
//! [`client::ActionClient`] calls its actions from Rust.
//!
//! What was checked here and what was not: the key expressions, liveliness tokens (with
//! each entity's QoS), GIDs, attachments and type hashes follow `rmw_zenoh`'s design
//! document and sources and REP-2011's hashing; the hashes are tested against published
//! values (`std_msgs/msg/String`, `geometry_msgs/msg/Twist`, `sensor_msgs/msg/Image`,
//! `nav_msgs/msg/Odometry`, `example_interfaces/srv/AddTwoInts`, and every Nav2 docking
//! interface: see [`interfaces`]); the CDR layouts against the XCDR1 rules
//! ([`crate::msgs::cdr`]). `tests/ros2_bridge.rs` docks the simulated Bujold through the
//! bridge, with the simulator as a second Zenoh participant. No live ROS 2 installation
//! was run against it.

pub mod aux_devices;
pub mod client;
pub mod config;
pub mod devices;
pub mod dock_db;
pub mod goals;
pub mod interfaces;
pub mod keys;
pub mod latched;
pub mod messages;
pub mod nav2;
pub mod nav2_msgs;
pub mod node;
pub mod plan;
pub mod progress;
pub mod qos;
pub mod type_hash;

pub use devices::ImageKind;
pub use keys::NodeName;
pub use node::{BridgeConfig, BridgeError, CameraTopic, Ros2Node, zenoh_config};
