//! A ROS 2 bridge over Zenoh (feature `ros2`): the robot's behaviors as a ROS 2 node in
//! the key expressions and CDR payloads of `rmw_zenoh`, ROS 2's Zenoh transport.
//!
//! [`Ros2Node::start`] opens a Zenoh session with explicit endpoints and multicast
//! scouting off, subscribes to the camera image(s), odometry and the dock switch,
//! publishes `cmd_vel`, and serves docking and undocking as ROS 2 actions
//! (`marsupial_msgs/action/Dock` and `…/Undock`, modelled on Nav2's `DockRobot` and
//! `UndockRobot`; see [`node`]). `marsupial ros2 --profile P` runs it from the command
//! line, and [`client::ActionClient`] calls its actions from Rust.
//!
//! What was checked here and what was not: the key expressions, liveliness tokens,
//! attachments and type hashes follow `rmw_zenoh`'s design document and REP-2016, and
//! the hashes are tested against those ROS 2 prints for `std_msgs/msg/String`,
//! `geometry_msgs/msg/Twist`, `sensor_msgs/msg/Image`, `nav_msgs/msg/Odometry` and the
//! service `example_interfaces/srv/AddTwoInts`; the CDR layouts against the XCDR1 rules
//! ([`crate::msgs::cdr`]). `tests/ros2_bridge.rs` docks the simulated Bujold through
//! the bridge, with the simulator as a second Zenoh participant. No live ROS 2
//! installation was run against it.

pub mod aux_devices;
pub mod client;
pub mod devices;
pub mod interfaces;
pub mod keys;
pub mod messages;
pub mod node;
pub mod type_hash;

pub use devices::ImageKind;
pub use keys::NodeName;
pub use node::{BridgeConfig, BridgeError, CameraTopic, Ros2Node, zenoh_config};
