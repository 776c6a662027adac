//! The calls every bridge test makes: the scenario, a node on a loopback port the OS
//! chooses, a session connected to it only, and Nav2 goals.

use marsupial::ros2::client::ActionClient;
use marsupial::ros2::keys::NodeName;
use marsupial::ros2::nav2_msgs::{DockRobotGoal, Goal, UndockRobotGoal};
use marsupial::ros2::{BridgeConfig, Ros2Node, zenoh_config};
use marsupial::sim::campaign::{self, Prepared};
use marsupial::sim::scenario::Scenario;
use std::path::Path;
use std::time::{Duration, Instant};
use zenoh::Wait;

/// Bujold's Table I scenario, prepared.
pub fn table1() -> Prepared {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/bujold-table1.toml");
    campaign::prepare(Scenario::load(&path).unwrap()).unwrap()
}

/// A node for `prepared`'s robot, listening on a loopback port the OS chooses, in its own
/// ROS domain (so tests running side by side never meet).
pub fn node(prepared: &Prepared, domain: u32) -> (Ros2Node, NodeName, String) {
    let profile = prepared.profile_for(&prepared.runs[0]);
    let mut config = BridgeConfig::for_profile(&profile);
    config.node.domain = domain;
    config.listen = vec!["tcp/127.0.0.1:0".to_owned()];
    config.connect = Vec::new();
    let name = config.node.clone();
    let node = Ros2Node::start(&profile, config).unwrap();
    let locator = node
        .locators()
        .into_iter()
        .find(|l| l.starts_with("tcp/127.0.0.1:"))
        .expect("the node listens on loopback");
    assert!(!locator.ends_with(":0"), "the OS chose a port: {locator}");
    (node, name, locator)
}

/// A Zenoh session that connects to `locator` only.
pub fn session(locator: &str) -> zenoh::Session {
    zenoh::open(zenoh_config(&[], &[locator.to_owned()]).unwrap())
        .wait()
        .unwrap()
}

/// Sends `goal`, retrying while the simulator's session is still connecting.
pub fn send(client: &ActionClient, goal: &Goal) -> [u8; 16] {
    let deadline = Instant::now() + Duration::from_secs(20);
    loop {
        match client.send(goal, Duration::from_secs(2)) {
            Ok(id) => return id,
            Err(e) if Instant::now() < deadline => {
                eprintln!("retrying the goal: {e}");
                std::thread::sleep(Duration::from_millis(200));
            }
            Err(e) => panic!("the node never took the goal: {e}"),
        }
    }
}

/// A `DockRobot` goal for the dock `id`, with Nav2's defaults otherwise.
pub fn dock_at(id: &str) -> Goal {
    Goal::Dock(DockRobotGoal {
        dock_id: id.to_owned(),
        ..DockRobotGoal::default()
    })
}

/// An `UndockRobot` goal with time for Bujold's whole departure (undock, drive out,
/// imprint).
pub fn undock() -> Goal {
    Goal::Undock(UndockRobotGoal {
        max_undocking_time: 90.0,
        ..UndockRobotGoal::default()
    })
}
