//! The ROS 2 bridge end to end, with the simulator as a second Zenoh participant: it
//! publishes the rendered frames, odometry and the dock switch in `rmw_zenoh`'s keys and
//! CDR, applies the `cmd_vel` and `posture` it receives (Bujold declares those), and
//! calls the node's `undock_robot` and `dock_robot` actions (Nav2's `UndockRobot` and
//! `DockRobot`) and its `reload_database` service.
//!
//! Network: the node listens on `tcp/127.0.0.1:0` (a port the OS chooses) and the
//! simulator connects to exactly that locator; multicast scouting is off on both.
//!
//! Everything runs on the wall clock (the threaded runtime and the simulator's physics in
//! real time), so a docking takes about as long as the robot's.

use marsupial::behaviors::agent_for;
use marsupial::ros2::client::ActionClient;
use marsupial::ros2::interfaces;
use marsupial::ros2::keys::NodeName;
use marsupial::ros2::messages::Twist;
use marsupial::ros2::nav2::{error, state};
use marsupial::ros2::nav2_msgs::{DockFeedback, DockRobotGoal, Goal, UndockRobotGoal};

use marsupial::sim::campaign::Prepared;
use marsupial::sim::run::{Recording, docked_robot, run_one};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use zenoh::Wait;

#[path = "ros2_bridge/calls.rs"]
mod calls;
#[path = "ros2_bridge/python_peer.rs"]
mod python_peer;
#[path = "ros2_bridge/simulator.rs"]
mod simulator;
use calls::{dock_at, node, send, session, table1, undock};
use simulator::Simulator;

/// Run `index` of Table I over the bridge: undock (imprinting on the way out), be placed
/// at the run's start, dock by the profile's dock id. Returns the docking's `error_msg`
/// (its typed outcome), the feedback it sent, and whether the plates closed.
fn dock_over_the_bridge(prepared: &Prepared, index: usize, domain: u32) -> (String, Vec<DockFeedback>, bool) {
    let spec = &prepared.runs[index];
    let sim = docked_robot(prepared, spec);
    let (node, name, locator) = node(prepared, domain);
    let sess = session(&locator);
    let simulator = Simulator::start(&sess, &name, &sim, None);
    let client = ActionClient::new(&sess, name.clone());

    let out = send(&client, &undock());
    let r = client.result(&out, false, Duration::from_secs(120)).unwrap();
    assert_eq!(
        (r.error_msg.as_str(), r.success, r.status, r.error_code),
        ("completed", true, 4, 0),
        "run {index}: {r:?}"
    );

    // The proctor places the robot at the run's start.
    sim.with(|s| s.place(spec.start.pose, false));
    let feedback = Arc::new(Mutex::new(Vec::new()));
    let seen = feedback.clone();
    let _fb = client.on_feedback(move |_, f| seen.lock().unwrap().push(f)).unwrap();
    let dock_id = prepared.profile_for(spec).name;
    let dock = send(&client, &dock_at(&dock_id));
    // A second goal while one runs is rejected.
    assert!(client.send(&undock(), Duration::from_secs(2)).is_err());
    let timeout = prepared.loaded.scenario.timeout_s as f32;
    let r = client
        .result(&dock, true, Duration::from_secs_f32(timeout + 30.0))
        .unwrap();
    let docked = sim.with(|s| s.docked());
    simulator.end();
    node.shutdown();
    let fb = feedback.lock().unwrap().clone();
    (r.error_msg, fb, docked)
}

/// Held by every test that runs a simulated robot on the wall clock. One such robot, its
/// node and its renderer take about 0.7 of a core at the CI profile, so on a 2-core
/// machine two or three at once fall behind real time, and a starved loop docks late or
/// not at all: the tests would measure the machine, not the bridge.
static REAL_TIME: Mutex<()> = Mutex::new(());

fn real_time() -> std::sync::MutexGuard<'static, ()> {
    REAL_TIME.lock().unwrap_or_else(|e| e.into_inner())
}

#[test]
fn bujold_docks_over_the_bridge_from_three_starts_as_in_process() {
    let _one_at_a_time = real_time();
    let prepared = table1();
    // Table I positions 2 (0.33 m on the axis), 4 (0.5 m, 30° to the right) and 9
    // (1.33 m on the axis), first trial of each, one after another (see `REAL_TIME`).
    for (k, index) in [3usize, 9, 24].into_iter().enumerate() {
        let (outcome, feedback, docked) = dock_over_the_bridge(&prepared, index, 40 + k as u32);
        // The same run in process, on the simulator's own loop.
        let spec = &prepared.runs[index];
        let mut rec = Recording::default();
        let reference = run_one(&prepared, spec, &|p| agent_for(p), &mut rec).unwrap();
        eprintln!(
            "run {index} ({}): bridge {outcome} (plates closed: {docked}), in process {} after {:.1} s",
            spec.start.label, reference.outcome, reference.time_s
        );
        // The states the feedback named, each with the time it began (for a failure's log).
        let mut trail: Vec<(u16, f64)> = Vec::new();
        for f in &feedback {
            if trail.last().is_none_or(|(s, _)| *s != f.state) {
                trail.push((f.state, f.docking_time_ns as f64 * 1e-9));
            }
        }
        eprintln!("run {index}: over the bridge, Nav2 states {trail:?}");
        assert_eq!(outcome, "docked", "run {index}");
        assert!(docked, "run {index}: the plates closed");
        assert_eq!(
            reference.outcome, outcome,
            "run {index}: the same outcome as in process"
        );
        // Feedback came in Nav2's states, in a docking's order, with time running on: it
        // looks for the dock (or drives to the staging pose) before it controls onto it.
        assert!(feedback.len() >= 3, "run {index}: {} feedback messages", feedback.len());
        assert!(
            feedback
                .windows(2)
                .all(|w| w[0].docking_time_ns <= w[1].docking_time_ns)
        );
        assert!(
            feedback.iter().all(|f| f.state <= state::RETRY),
            "run {index}: {trail:?}"
        );
        let first = |s: u16| trail.iter().position(|(x, _)| *x == s);
        let controlling = first(state::CONTROLLING).expect("it controlled onto the dock");
        let started = trail.iter().find(|(s, _)| *s != state::NONE).map(|(s, _)| *s);
        assert!(
            matches!(started, Some(state::INITIAL_PERCEPTION | state::NAV_TO_STAGING_POSE)),
            "run {index}: began with {started:?}: {trail:?}"
        );
        assert!(
            first(state::INITIAL_PERCEPTION).is_none_or(|p| p < controlling),
            "run {index}: perceived before controlling: {trail:?}"
        );
    }
}

/// A camera that falls silent puts the robot in a safe stop (the runtime's staleness
/// limit), reported in the feedback as Nav2's `NONE` state; a cancel then ends the goal
/// `canceled`, the status topic follows it there (and a late subscriber still reads
/// it), and the last command on `cmd_vel` is a stop.
#[test]
fn a_silent_camera_safe_stops_and_a_cancel_ends_the_goal() {
    let _one_at_a_time = real_time();
    let prepared = table1();
    let spec = &prepared.runs[0];
    let sim = docked_robot(&prepared, spec);
    sim.with(|s| s.place(spec.start.pose, false));
    let (node, name, locator) = node(&prepared, 60);
    let sess = session(&locator);
    let simulator = Simulator::start(&sess, &name, &sim, Some(15));
    let last_cmd = Arc::new(Mutex::new(None));
    let seen = last_cmd.clone();
    let _cmd = sess
        .declare_subscriber(name.key("cmd_vel", &interfaces::twist()))
        .callback(move |s| *seen.lock().unwrap() = Some(Twist::decode(&s.payload().to_bytes()).unwrap()))
        .wait()
        .unwrap();
    let client = ActionClient::new(&sess, name.clone());
    let feedback = Arc::new(Mutex::new(Vec::new()));
    let fb = feedback.clone();
    let _fb = client.on_feedback(move |_, f| fb.lock().unwrap().push(f)).unwrap();
    let statuses = Arc::new(Mutex::new(Vec::new()));
    let st = statuses.clone();
    let _st = client
        .on_status(true, move |goals| st.lock().unwrap().push(goals))
        .unwrap();
    let id = send(&client, &dock_at(&prepared.profile_for(spec).name));
    // The behavior runs while frames come, then the camera falls silent and the safe stop
    // is reported.
    let deadline = Instant::now() + Duration::from_secs(20);
    while *simulator.frames.lock().unwrap() < 15 {
        assert!(Instant::now() < deadline, "the camera never sent its frames");
        std::thread::sleep(Duration::from_millis(20));
    }
    let silent_from = feedback.lock().unwrap().len();
    let stopped = || {
        feedback.lock().unwrap()[silent_from..]
            .iter()
            .any(|f| f.state == state::NONE)
    };
    while !stopped() {
        assert!(
            Instant::now() < deadline,
            "no safe stop reported: {:?}",
            feedback.lock().unwrap()
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    assert!(
        feedback.lock().unwrap()[..silent_from]
            .iter()
            .any(|f| f.state != state::NONE),
        "the behavior ran while frames came: {:?}",
        feedback.lock().unwrap()
    );
    assert_eq!(client.cancel(&id, true, Duration::from_secs(5)).unwrap(), 0);
    let r = client.result(&id, true, Duration::from_secs(10)).unwrap();
    assert_eq!((r.status, r.success, r.error_msg.as_str()), (5, false, "canceled"));
    std::thread::sleep(Duration::from_millis(200));
    assert_eq!(
        *last_cmd.lock().unwrap(),
        Some(Twist::default()),
        "the robot was left stopped"
    );
    // The status topic followed the goal: executing, canceling, canceled (2, 3, 5 in
    // action_msgs/msg/GoalStatus), in that order, and no other goal appeared.
    let mut codes: Vec<i8> = Vec::new();
    for goals in statuses.lock().unwrap().iter() {
        assert!(goals.iter().all(|(g, _, _)| *g == id), "{goals:?}");
        if let Some(&(_, _, c)) = goals.iter().find(|(g, _, _)| *g == id)
            && codes.last() != Some(&c)
        {
            codes.push(c);
        }
    }
    let at = |c: i8| codes.iter().position(|&x| x == c);
    assert!(
        at(2) < at(3) && at(3) < at(5) && at(2).is_some() && codes.last() == Some(&5),
        "status codes {codes:?}"
    );
    // The status is transient-local: a subscriber joining now still reads the goal's end.
    let late = client.latest_status(true, Duration::from_secs(5)).unwrap();
    assert!(
        late.is_some_and(|g| g.iter().any(|(g, _, c)| *g == id && *c == 5)),
        "the cached status"
    );
    // A finished goal cannot be canceled, and an unknown one has no result.
    assert_eq!(client.cancel(&id, true, Duration::from_secs(5)).unwrap(), 3);
    let unknown = client.result(&[7; 16], true, Duration::from_secs(5)).unwrap();
    assert_eq!((unknown.status, unknown.success), (0, false));
    simulator.end();
    node.shutdown();
}

/// The keys the node declares are the ones `rmw_zenoh` would use for the same names, its
/// liveliness tokens carry each entity's QoS, and nothing answers outside its domain.
#[test]
fn the_node_answers_in_its_own_domain_only() {
    let prepared = table1();
    let (node, name, locator) = node(&prepared, 61);
    let sess = session(&locator);
    // The test's own session listens nowhere: it only connects to the node's locator.
    assert_eq!(
        sess.info().locators().wait(),
        Vec::new(),
        "the client session listens on nothing"
    );
    let tokens: Vec<String> = sess
        .liveliness()
        .get("@ros2_lv/61/**")
        .timeout(Duration::from_secs(5))
        .wait()
        .unwrap()
        .iter()
        .filter_map(|r| r.result().ok().map(|s| s.key_expr().to_string()))
        .collect();
    let token = |part: &str| {
        tokens
            .iter()
            .find(|t| t.contains(part))
            .unwrap_or_else(|| panic!("no token with `{part}` in {tokens:#?}"))
            .clone()
    };
    let dock = interfaces::action(interfaces::DOCK_ROBOT);
    let status = token("/MP/%/%/docking_server/%dock_robot%_action%status/");
    assert!(status.ends_with("/::,1:,:,:,,"), "transient-local, depth 1: {status}");
    let send_goal = token("/SS/%/%/docking_server/%dock_robot%_action%send_goal/");
    assert!(
        send_goal.ends_with(&format!(
            "/nav2_msgs::action::dds_::DockRobot_SendGoal_/{}/:2:,10:,:,:,,",
            dock.send_goal.hash
        )),
        "{send_goal}"
    );
    let feedback = token("%dock_robot%_action%feedback/");
    assert!(feedback.ends_with("/:2:,10:,:,:,,"), "{feedback}");
    let reload = token("/SS/%/%/docking_server/%docking_server%reload_database/");
    assert!(
        reload.contains(&format!(
            "/nav2_msgs::srv::dds_::ReloadDockDatabase_/{}/",
            interfaces::reload_dock_database().hash
        )),
        "{reload}"
    );
    assert!(token("%undock_robot%_action%get_result/").contains("UndockRobot_GetResult_"));
    let other = NodeName {
        domain: 62,
        ..name.clone()
    };
    let stranger = ActionClient::new(&sess, other);
    let err = stranger.send(&undock(), Duration::from_millis(500)).unwrap_err();
    assert!(err.to_string().contains("no answer"), "{err}");
    node.shutdown();
}

/// Bad goals end at once with Nav2's error code and a message naming the field, and
/// `reload_database` adds a file's docks (or refuses a malformed file, changing nothing).
#[test]
fn bad_goals_get_nav2_codes_and_reloads_read_the_file() {
    let prepared = table1();
    let (node, name, locator) = node(&prepared, 63);
    let sess = session(&locator);
    let client = ActionClient::new(&sess, name);
    let unknown = send(&client, &dock_at("kitchen"));
    let r = client.result(&unknown, true, Duration::from_secs(10)).unwrap();
    assert_eq!(
        (r.status, r.success, r.error_code),
        (6, false, error::DOCK_NOT_IN_DB),
        "{r:?}"
    );
    assert!(r.error_msg.contains("dock_id `kitchen`"), "{}", r.error_msg);
    let mut by_pose = DockRobotGoal {
        use_dock_id: false,
        ..DockRobotGoal::default()
    };
    by_pose.dock_pose.frame_id = "map".into();
    let id = send(&client, &Goal::Dock(by_pose));
    let r = client.result(&id, true, Duration::from_secs(10)).unwrap();
    assert_eq!(r.error_code, error::DOCK_NOT_VALID, "{r:?}");
    assert!(
        r.error_msg.contains("dock_pose.header.frame_id `map`"),
        "{}",
        r.error_msg
    );
    // The status topic's cache holds the aborted goal for a late subscriber.
    let late = client.latest_status(true, Duration::from_secs(5)).unwrap();
    assert!(late.is_some_and(|g| g.iter().any(|(g, _, c)| *g == id && *c == 6)));

    let dir = std::env::temp_dir().join(format!("marsupial-ros2-docks-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let good = dir.join("docks.yaml");
    std::fs::write(&good, "docks:\n  shed:\n    frame: map\n    pose: [4.0, 1.0, 0.0]\n").unwrap();
    let bad = dir.join("bad.yaml");
    std::fs::write(&bad, "docks:\n  barn:\n    pose: [4.0]\n").unwrap();
    assert!(
        client
            .reload_docks(good.to_str().unwrap(), Duration::from_secs(5))
            .unwrap()
    );
    assert!(
        !client
            .reload_docks(bad.to_str().unwrap(), Duration::from_secs(5))
            .unwrap()
    );
    assert!(
        !client
            .reload_docks("/nonexistent/docks.yaml", Duration::from_secs(5))
            .unwrap()
    );
    // `shed` is now known (but in a frame the node cannot resolve); `barn` never came.
    let r = client
        .result(&send(&client, &dock_at("shed")), true, Duration::from_secs(10))
        .unwrap();
    assert_eq!(r.error_code, error::DOCK_NOT_VALID, "{r:?}");
    assert!(r.error_msg.contains("dock `shed`'s frame `map`"), "{}", r.error_msg);
    let r = client
        .result(&send(&client, &dock_at("barn")), true, Duration::from_secs(10))
        .unwrap();
    assert_eq!(r.error_code, error::DOCK_NOT_IN_DB, "{r:?}");
    // An undocking of another dock type is not valid.
    let other = Goal::Undock(UndockRobotGoal {
        dock_type: "charger".into(),
        ..UndockRobotGoal::default()
    });
    let r = client
        .result(&send(&client, &other), false, Duration::from_secs(10))
        .unwrap();
    assert_eq!(r.error_code, error::DOCK_NOT_VALID, "{r:?}");
    assert!(r.error_msg.contains("dock_type `charger`"), "{}", r.error_msg);
    std::fs::remove_dir_all(&dir).unwrap();
    node.shutdown();
}
