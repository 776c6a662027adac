//! The ROS 2 bridge end to end, with the simulator as a second Zenoh participant: it
//! publishes the rendered frames, odometry and the dock switch in `rmw_zenoh`'s keys and
//! CDR, applies the `cmd_vel` and `posture` it receives (Bujold declares those), and
//! calls the node's `undock_robot` and `dock_robot` actions.
//!
//! Network: the node listens on `tcp/127.0.0.1:0` (a port the OS chooses) and the
//! simulator connects to exactly that locator; multicast scouting is off on both.
//!
//! Everything runs on the wall clock (the threaded runtime and the simulator's physics in
//! real time), so a docking takes about as long as the robot's.

use marsupial::arbiter::runtime::StopHandle;
use marsupial::behaviors::agent_for;
use marsupial::msgs::cdr::CdrReader;
use marsupial::perception::RgbImage;
use marsupial::robot::Camera;
use marsupial::ros2::client::ActionClient;
use marsupial::ros2::devices::command_of;
use marsupial::ros2::interfaces;
use marsupial::ros2::keys::{Attachment, NodeName, gid, now_ns};
use marsupial::ros2::messages::{
    DockGoal, Goal, GoalFeedback, Twist, UndockGoal, encode_image, encode_odometry, stamp,
};
use marsupial::ros2::node::encode_bool;
use marsupial::ros2::{BridgeConfig, Ros2Node, zenoh_config};
use marsupial::schemas::{DOCK_CONTACT_KIND, DeviceCommand, DeviceReading, DockContact, POSTURE_KIND, Posture};

/// Index of the profile's device of kind `kind` (the sim robot's devices are in profile order).
fn device(kinds: &[String], kind: &str) -> usize {
    kinds.iter().position(|k| k == kind).expect("the profile declares it")
}
use marsupial::sim::campaign::{self, Prepared};
use marsupial::sim::robot::{SimCamera, SimDevices, SimRobot};
use marsupial::sim::run::{Recording, docked_robot, run_one};
use marsupial::sim::scenario::Scenario;
use std::path::Path;
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};
use zenoh::Wait;

fn table1() -> Prepared {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/bujold-table1.toml");
    campaign::prepare(Scenario::load(&path).unwrap()).unwrap()
}

/// A node for `prepared`'s robot, listening on a loopback port the OS chooses, in its own
/// ROS domain (so tests running side by side never meet).
fn node(prepared: &Prepared, domain: u32) -> (Ros2Node, NodeName, String) {
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
fn session(locator: &str) -> zenoh::Session {
    zenoh::open(zenoh_config(&[], &[locator.to_owned()]).unwrap())
        .wait()
        .unwrap()
}

/// What the simulator does with a payload the node sent.
type OnPayload = Box<dyn Fn(&[u8]) + Send + Sync>;

/// The simulator's side of the wire.
struct Simulator {
    stop: StopHandle,
    threads: Vec<JoinHandle<()>>,
    _subs: Vec<zenoh::pubsub::Subscriber<()>>,
    /// Frames published.
    frames: Arc<Mutex<u64>>,
}

impl Simulator {
    /// Publishes `sim`'s camera at the loop's rate and its odometry and dock switch at
    /// 50 Hz, runs its physics in real time, and applies what the node commands. With
    /// `camera_stops_after`, the camera falls silent after that many frames.
    fn start(session: &zenoh::Session, node: &NodeName, sim: &SimRobot, camera_stops_after: Option<u64>) -> Self {
        let stop = StopHandle::new();
        let mut threads = Vec::new();
        let frames = Arc::new(Mutex::new(0));
        let mut robot = sim.robot(&SimDevices::default()).unwrap();
        let kinds = sim.with(|s| s.profile().loop_config().devices);
        let rate = sim.with(|s| s.profile().loop_.rate_hz);
        let publisher = |name: &str, ty: &interfaces::Interface| {
            let key = node.key(name, ty);
            (session.declare_publisher(key.clone()).wait().unwrap(), gid(&key))
        };
        let put = |p: &zenoh::pubsub::Publisher<'static>, g: [u8; 16], seq: i64, buf: &[u8]| {
            let att = Attachment {
                sequence_number: seq,
                source_timestamp: now_ns(),
                gid: g,
            };
            // A put after the test closed the session fails, and does not matter.
            let _ = p.put(buf.to_vec()).attachment(att.encode()).wait();
        };

        // Physics on the wall clock.
        {
            let (sim, stop) = (sim.clone(), stop.clone());
            threads.push(std::thread::spawn(move || {
                while !stop.is_stopped() {
                    if sim.run_physics(|| stop.is_stopped()).is_some() {
                        // Docked or caught: hold until the test places the robot again.
                        std::thread::sleep(Duration::from_millis(20));
                    }
                }
            }));
        }
        // The camera, rendered at the loop's rate.
        {
            let (image, g) = publisher("camera/image_raw", &interfaces::image());
            let mut camera = SimCamera::new(sim.clone(), 0);
            let (stop, frames) = (stop.clone(), frames.clone());
            threads.push(std::thread::spawn(move || {
                let (w, h) = camera.resolution();
                let mut frame = RgbImage::new(w, h);
                let mut buf = Vec::new();
                let period = Duration::from_secs_f64(1.0 / rate);
                let mut next = Instant::now();
                let mut n = 0;
                while !stop.is_stopped() {
                    if camera_stops_after.is_none_or(|k| n < k) && camera.capture(&mut frame).is_ok() {
                        encode_image(
                            &mut buf,
                            stamp(now_ns()),
                            "camera",
                            w as u32,
                            h as u32,
                            frame.as_bytes(),
                        );
                        n += 1;
                        put(&image, g, n as i64, &buf);
                        *frames.lock().unwrap() = n;
                    }
                    next += period;
                    if let Some(d) = next.checked_duration_since(Instant::now()) {
                        std::thread::sleep(d);
                    }
                }
            }));
        }
        // Odometry and the dock switch.
        {
            let (odom, go) = publisher("odom", &interfaces::odometry());
            let (switch, gs) = publisher("dock_contact", &interfaces::message("std_msgs/msg/Bool"));
            let mut odometer = robot.odometer.take().unwrap();
            let mut plates = robot.sensors.swap_remove(device(&kinds.sensors, DOCK_CONTACT_KIND));
            let stop = stop.clone();
            threads.push(std::thread::spawn(move || {
                let mut buf = Vec::new();
                let mut seq = 0;
                while !stop.is_stopped() {
                    seq += 1;
                    if let Ok(o) = odometer.read() {
                        encode_odometry(&mut buf, stamp(now_ns()), o.pose, o.twist.v, o.twist.omega);
                        put(&odom, go, seq, &buf);
                    }
                    let mut v = Vec::new();
                    if let Some(c) = plates.read(&mut v).ok().and_then(|()| DockContact::decode(&v)) {
                        put(&switch, gs, seq, &encode_bool(c.0));
                    }
                    std::thread::sleep(Duration::from_millis(20));
                }
            }));
        }
        // What the node commands.
        let drive = Arc::new(Mutex::new(robot.drive));
        // Bujold's actuators: her posture (she has no guides: the node publishes none).
        let posture = robot.actuators.swap_remove(device(&kinds.actuators, POSTURE_KIND));
        let posture = Arc::new(Mutex::new(posture));
        let subscribe = |name: &str, ty: &interfaces::Interface, f: OnPayload| {
            session
                .declare_subscriber(node.key(name, ty))
                .callback(move |s| f(&s.payload().to_bytes()))
                .wait()
                .unwrap()
        };
        let string = interfaces::message("std_msgs/msg/String");
        let text = |b: &[u8]| CdrReader::new(b).and_then(|mut r| r.string("data").map(str::to_owned));
        let subs = vec![
            subscribe(
                "cmd_vel",
                &interfaces::twist(),
                Box::new(move |b| {
                    let t = Twist::decode(b).expect("cmd_vel decodes");
                    drive.lock().unwrap().apply(&command_of(t)).unwrap();
                }),
            ),
            subscribe(
                "posture",
                &string,
                Box::new(move |b| {
                    let p = match text(b).unwrap().as_str() {
                        "lowered" => Posture::Lowered,
                        _ => Posture::Raised,
                    };
                    posture.lock().unwrap().apply(p.encode().values()).unwrap();
                }),
            ),
        ];
        Self {
            stop,
            threads,
            _subs: subs,
            frames,
        }
    }

    fn end(self) {
        self.stop.stop();
        for t in self.threads {
            t.join().unwrap();
        }
    }
}

/// Sends `goal`, retrying while the simulator's session is still connecting.
fn send(client: &ActionClient, goal: &Goal) -> [u8; 16] {
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

/// Run `index` of Table I over the bridge: undock (imprinting on the way out), be placed
/// at the run's start, dock. Returns the docking's outcome and the phases its feedback
/// named.
fn dock_over_the_bridge(prepared: &Prepared, index: usize, domain: u32) -> (String, Vec<GoalFeedback>, bool) {
    let spec = &prepared.runs[index];
    let sim = docked_robot(prepared, spec);
    let (node, name, locator) = node(prepared, domain);
    let sess = session(&locator);
    let simulator = Simulator::start(&sess, &name, &sim, None);
    let client = ActionClient::new(&sess, name.clone());

    let undock = send(&client, &Goal::Undock(UndockGoal { max_time: 90.0 }));
    let r = client.result(&undock, false, Duration::from_secs(120)).unwrap();
    assert_eq!(
        (r.outcome.as_str(), r.success, r.status),
        ("completed", true, 4),
        "run {index}: {r:?}"
    );

    // The proctor places the robot at the run's start.
    sim.with(|s| s.place(spec.start.pose, false));
    let feedback = Arc::new(Mutex::new(Vec::new()));
    let seen = feedback.clone();
    let _fb = client
        .on_feedback(true, move |_, f| seen.lock().unwrap().push(f))
        .unwrap();
    let timeout = prepared.loaded.scenario.timeout_s as f32;
    let dock = send(
        &client,
        &Goal::Dock(DockGoal {
            dock_hint: None,
            max_time: timeout,
        }),
    );
    // A second goal while one runs is rejected.
    assert!(
        client
            .send(&Goal::Undock(UndockGoal::default()), Duration::from_secs(2))
            .is_err()
    );
    let r = client
        .result(&dock, true, Duration::from_secs_f32(timeout + 30.0))
        .unwrap();
    let docked = sim.with(|s| s.docked());
    simulator.end();
    node.shutdown();
    let fb = feedback.lock().unwrap().clone();
    (r.outcome, fb, docked)
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
        // The phases the feedback named, each with the time it began (for a failure's log).
        let mut trail: Vec<String> = Vec::new();
        let mut last = "";
        for f in &feedback {
            if f.phase != last {
                last = &f.phase;
                trail.push(format!("{:.1} s {last}", f.elapsed_ns as f64 * 1e-9));
            }
        }
        eprintln!("run {index}: over the bridge {}", trail.join(", "));
        assert_eq!(outcome, "docked", "run {index}");
        assert!(docked, "run {index}: the plates closed");
        assert_eq!(
            reference.outcome, outcome,
            "run {index}: the same outcome as in process"
        );
        // Feedback named the docking's phases, with time running on.
        assert!(feedback.len() >= 3, "run {index}: {} feedback messages", feedback.len());
        assert!(feedback.windows(2).all(|w| w[0].elapsed_ns <= w[1].elapsed_ns));
        let phases: std::collections::BTreeSet<&str> = feedback.iter().map(|f| f.phase.as_str()).collect();
        assert!(phases.len() >= 2, "run {index}: phases {phases:?}");
    }
}

/// A camera that falls silent puts the robot in a safe stop (the runtime's staleness
/// limit), reported in the feedback; a cancel then ends the goal `canceled`, the status
/// topic follows it there, and the last command on `cmd_vel` is a stop.
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
    let _fb = client
        .on_feedback(true, move |_, f| fb.lock().unwrap().push(f))
        .unwrap();
    let statuses = Arc::new(Mutex::new(Vec::new()));
    let st = statuses.clone();
    let _st = client
        .on_status(true, move |goals| st.lock().unwrap().push(goals))
        .unwrap();
    let id = send(&client, &Goal::Dock(DockGoal::default()));
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
            .any(|f| f.phase == "safe_stop")
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
            .any(|f| f.phase != "safe_stop"),
        "the behavior ran while frames came: {:?}",
        feedback.lock().unwrap()
    );
    assert_eq!(client.cancel(&id, true, Duration::from_secs(5)).unwrap(), 0);
    let r = client.result(&id, true, Duration::from_secs(10)).unwrap();
    assert_eq!((r.status, r.success, r.outcome.as_str()), (5, false, "canceled"));
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
    // A finished goal cannot be canceled, and an unknown one has no result.
    assert_eq!(client.cancel(&id, true, Duration::from_secs(5)).unwrap(), 3);
    let unknown = client.result(&[7; 16], true, Duration::from_secs(5)).unwrap();
    assert_eq!((unknown.status, unknown.success), (0, false));
    simulator.end();
    node.shutdown();
}

/// The keys the node declares are the ones `rmw_zenoh` would use for the same names, and
/// nothing answers outside its domain.
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
    let other = NodeName {
        domain: 62,
        ..name.clone()
    };
    let stranger = ActionClient::new(&sess, other);
    let err = stranger
        .send(&Goal::Undock(UndockGoal::default()), Duration::from_millis(500))
        .unwrap_err();
    assert!(err.to_string().contains("no answer"), "{err}");
    node.shutdown();
}
