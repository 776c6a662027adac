//! The harness for the independent Python peer (`tests/peer/nav2_peer.py`): a node and the
//! simulated Bujold, the robot placed at a Table I start once the peer's undocking ends.
//! Ignored by default: it needs Python with PyPI's `eclipse-zenoh`, which
//! `tests/peer/run.sh` installs in a virtual environment and names in
//! `MARSUPIAL_PY_PEER`.

use super::calls::{node, session, table1};
use super::simulator::Simulator;
use marsupial::ros2::client::ActionClient;
use marsupial::sim::run::docked_robot;
use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

#[test]
#[ignore = "needs tests/peer/run.sh (Python and eclipse-zenoh)"]
fn an_independent_python_peer_undocks_and_docks_bujold() {
    let _one_at_a_time = super::real_time();
    let python = std::env::var("MARSUPIAL_PY_PEER").expect("MARSUPIAL_PY_PEER names a Python with eclipse-zenoh");
    let prepared = table1();
    let spec = &prepared.runs[3];
    let sim = docked_robot(&prepared, spec);
    let (node, name, locator) = node(&prepared, 70);
    let sess = session(&locator);
    let simulator = Simulator::start(&sess, &name, &sim, None);
    // The proctor: when the undocking succeeds, the robot is placed at the run's start.
    let client = ActionClient::new(&sess, name.clone());
    let placed = Arc::new(AtomicBool::new(false));
    let (flag, robot, start) = (placed.clone(), sim.clone(), spec.start.pose);
    let _st = client
        .on_status(false, move |goals| {
            if goals.iter().any(|(_, _, c)| *c == 4) && !flag.swap(true, Ordering::SeqCst) {
                robot.with(|s| s.place(start, false));
            }
        })
        .unwrap();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/peer/nav2_peer.py");
    let dock_id = prepared.profile_for(spec).name;
    let out = std::process::Command::new(python)
        .arg(script)
        .args([locator.as_str(), &name.domain.to_string(), &dock_id])
        .output()
        .expect("the peer runs");
    eprintln!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    simulator.end();
    node.shutdown();
    assert!(placed.load(Ordering::SeqCst), "the undocking succeeded");
    assert!(out.status.success(), "the peer's checks failed");
}
