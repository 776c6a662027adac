//! The node: a robot's composed behavior on the threaded runtime, its hardware as ROS 2
//! topics ([`super::devices`]), and its missions as two ROS 2 actions.
//!
//! * **Topics.** It subscribes to one image topic per camera of the profile, to
//!   `nav_msgs/msg/Odometry` and, when the profile declares a `dock_contact` sensor, to
//!   the dock contact switch (`std_msgs/msg/Bool`); it publishes
//!   `geometry_msgs/msg/Twist` on `cmd_vel` and, for the actuators the profile declares,
//!   `posture` and `dock_guides` (`std_msgs/msg/String`: `raised`/`lowered`,
//!   `open`/`closed`) and `lights` (`std_msgs/msg/Bool`) ([`super::aux_devices`]).
//! * **Actions.** `dock_robot` (`marsupial_msgs/action/Dock`) starts a docking mission
//!   and `undock_robot` (`marsupial_msgs/action/Undock`) a departure, after Nav2's
//!   `DockRobot` and `UndockRobot`: the ROS 2 action protocol's `send_goal`,
//!   `get_result` and `cancel_goal` services and `feedback` and `status` topics, under
//!   `<action>/_action/`. Feedback carries the running behavior's phase, the time since
//!   the goal started and the retries used; the result carries the typed outcome (and
//!   Nav2's error code for it). One goal runs at a time; a goal sent while another runs is
//!   rejected. A cancel stops the robot and ends the goal `canceled`.
//! * **The run.** Each goal is [`run_missions_observed`] on the robot those topics make, so
//!   staleness limits, safe stops, the watchdog and the typed outcomes are the threaded
//!   runtime's own. The behavior persists between goals: a docking after an undocking
//!   uses the colours imprinted on the way out.

use super::aux_devices::{AuxTopic, Encode, TopicSwitch, Unbridged, guides_message, lights_message, posture_message};
pub use super::aux_devices::{encode_bool, encode_string};
use super::devices::{ImageKind, TopicCamera, TopicOdometer, TwistDrive, subscribe};
use super::interfaces::{self, Interface};
use super::keys::{Attachment, NodeName, RmwPublisher, gid, now_ns};
use super::messages::{
    Goal, GoalId, GoalResult, decode_goal_id, decode_send_goal, encode_cancel_response, encode_feedback, encode_result,
    encode_send_goal_response, encode_status, stamp,
};
use crate::arbiter::ReactiveLoop;
use crate::arbiter::reactive_loop::LoopStatus;
use crate::arbiter::runtime::{RuntimeConfig, RuntimeEvent, RuntimeReport, StopHandle, run_missions_observed};
use crate::msgs::ros::Time;
use crate::profile::Profile;
use crate::robot::{Actuator, Robot, Sensor};
use crate::schemas::{
    Agent, DOCK_CONTACT_KIND, FailureReason, GUIDES_KIND, LIGHTS_KIND, Mission, Outcome, POSTURE_KIND,
};
use crossbeam::channel::{Receiver, RecvTimeoutError, Sender, unbounded};
use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;
use thiserror::Error;
use zenoh::Wait;
use zenoh::query::Query;

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

fn zerr(e: impl std::fmt::Display) -> BridgeError {
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
    /// The runtime's settings (a goal's `max_time` overrides `max_duration`).
    pub runtime: RuntimeConfig,
}

impl BridgeConfig {
    /// Defaults for `profile`: node `marsupial` in domain 0, no namespace, listening on
    /// nothing and connecting to a router at `tcp/127.0.0.1:7447`; `camera/image_raw`
    /// (`camera0/image_raw`, `camera1/image_raw` … for several cameras), `odom`,
    /// `dock_contact`, `cmd_vel`.
    pub fn for_profile(profile: &Profile) -> Self {
        let n = profile.cameras.len();
        Self {
            node: NodeName {
                domain: 0,
                namespace: String::new(),
                name: "marsupial".to_owned(),
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

/// Which of the two actions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Which {
    Dock = 0,
    Undock = 1,
}

impl Which {
    fn action(self) -> &'static str {
        match self {
            Which::Dock => "dock_robot",
            Which::Undock => "undock_robot",
        }
    }

    fn interface(self) -> &'static str {
        match self {
            Which::Dock => "marsupial_msgs/action/Dock",
            Which::Undock => "marsupial_msgs/action/Undock",
        }
    }
}

/// `action_msgs/msg/GoalStatus` codes.
mod status {
    pub const ACCEPTED: i8 = 1;
    pub const EXECUTING: i8 = 2;
    pub const SUCCEEDED: i8 = 4;
    pub const CANCELED: i8 = 5;
    pub const ABORTED: i8 = 6;
}

/// A goal handed to the worker.
struct Job {
    which: Which,
    id: GoalId,
    goal: Goal,
    stop: StopHandle,
}

/// What the services share with the worker.
#[derive(Default)]
struct Goals {
    /// The goal running or queued, with its stop handle.
    active: Option<(Which, GoalId, StopHandle)>,
    /// Recent goals of each action: id, accepted at, status (for the status topic).
    recent: [VecDeque<(GoalId, Time, i8)>; 2],
    /// Finished goals' results, newest last.
    results: VecDeque<(GoalId, GoalResult)>,
    /// `get_result` requests waiting for their goal to end.
    waiting: Vec<(GoalId, Which, Query, Option<Attachment>)>,
}

/// How many finished goals are remembered.
const KEEP: usize = 16;

struct Shared {
    goals: Mutex<Goals>,
    /// Raised when the node closes: the worker ends after the goal it runs.
    closing: AtomicBool,
    jobs: Sender<Job>,
    status: [RmwPublisher; 2],
    feedback: [RmwPublisher; 2],
}

impl Shared {
    fn publish_status(&self, which: Which, g: &Goals) {
        let list: Vec<_> = g.recent[which as usize].iter().copied().collect();
        let mut buf = Vec::new();
        encode_status(&mut buf, &list);
        let _ = self.status[which as usize].put(&buf);
    }

    fn set_status(&self, which: Which, id: &GoalId, code: i8) {
        let Ok(mut g) = self.goals.lock() else { return };
        let recent = &mut g.recent[which as usize];
        if let Some(e) = recent.iter_mut().find(|e| &e.0 == id) {
            e.2 = code;
        } else {
            recent.push_back((*id, stamp(now_ns()), code));
            if recent.len() > KEEP {
                recent.pop_front();
            }
        }
        self.publish_status(which, &g);
    }

    /// Records `result` for goal `id` and answers every `get_result` waiting for it.
    fn finish(&self, which: Which, id: GoalId, result: GoalResult) {
        self.set_status(which, &id, result.status);
        let Ok(mut g) = self.goals.lock() else { return };
        g.active = None;
        let waiting = std::mem::take(&mut g.waiting);
        for (wid, w, query, att) in waiting {
            if wid == id {
                reply_result(&query, att, &result, w == Which::Dock);
            } else {
                g.waiting.push((wid, w, query, att));
            }
        }
        g.results.push_back((id, result));
        if g.results.len() > KEEP {
            g.results.pop_front();
        }
    }
}

/// Replies to a service request, echoing its sequence number and client GID as
/// `rmw_zenoh` does.
fn reply(query: &Query, att: Option<Attachment>, payload: Vec<u8>) {
    let r = query.reply(query.key_expr().clone(), payload);
    let _ = match att {
        Some(a) => r
            .attachment(
                Attachment {
                    source_timestamp: now_ns(),
                    ..a
                }
                .encode(),
            )
            .wait(),
        None => r.wait(),
    };
}

fn reply_result(query: &Query, att: Option<Attachment>, result: &GoalResult, dock: bool) {
    let mut buf = Vec::new();
    encode_result(&mut buf, result, dock);
    reply(query, att, buf);
}

fn request(query: &Query) -> (Vec<u8>, Option<Attachment>) {
    let payload = query.payload().map(|p| p.to_bytes().into_owned()).unwrap_or_default();
    let att = query.attachment().and_then(|a| Attachment::decode(&a.to_bytes()));
    (payload, att)
}

/// The running node. Dropping it (or [`Ros2Node::shutdown`]) cancels the running goal,
/// waits for the robot to stop and closes the session.
pub struct Ros2Node {
    session: zenoh::Session,
    shared: Arc<Shared>,
    worker: Option<JoinHandle<()>>,
    /// Queryables, subscribers and liveliness tokens, kept alive with the node.
    _declared: Vec<Box<dyn std::any::Any + Send + Sync>>,
}

impl Ros2Node {
    /// Opens the session, declares every topic, service and token, and starts the worker
    /// that runs goals.
    ///
    /// # Errors
    /// [`BridgeError`] when the behavior cannot be built, the topics do not match the
    /// profile's cameras, or Zenoh refuses a declaration.
    pub fn start(profile: &Profile, config: BridgeConfig) -> Result<Self, BridgeError> {
        Self::start_with(profile, crate::behaviors::catalog::shipped(), config)
    }

    /// [`Ros2Node::start`], the agent built from `catalog` (a crate's own robot kinds).
    ///
    /// # Errors
    /// As [`Ros2Node::start`].
    pub fn start_with(
        profile: &Profile,
        catalog: &crate::behaviors::Catalog,
        config: BridgeConfig,
    ) -> Result<Self, BridgeError> {
        if config.cameras.len() != profile.cameras.len() {
            return Err(BridgeError::Config(format!(
                "the profile has {} camera(s) but {} image topic(s) were given",
                profile.cameras.len(),
                config.cameras.len()
            )));
        }
        let agent = catalog
            .agent(profile)
            .map_err(|e| BridgeError::Behavior(e.to_string()))?;
        let lp: ReactiveLoop<dyn Agent> = ReactiveLoop::new(agent, profile.loop_config());
        let session = zenoh::open(zenoh_config(&config.listen, &config.connect)?)
            .wait()
            .map_err(zerr)?;
        let zid = session.zid().to_string();
        let node = &config.node;
        let mut declared: Vec<Box<dyn std::any::Any + Send + Sync>> = Vec::new();
        let mut entity = 0u32;
        let mut token = |declared: &mut Vec<Box<dyn std::any::Any + Send + Sync>>,
                         kind: &str,
                         name: &str,
                         ty: &Interface|
         -> Result<[u8; 16], BridgeError> {
            entity += 1;
            let t = node.entity_token(&zid, entity, kind, name, ty);
            let g = gid(&t);
            declared.push(Box::new(session.liveliness().declare_token(t).wait().map_err(zerr)?));
            Ok(g)
        };
        declared.push(Box::new(
            session
                .liveliness()
                .declare_token(node.node_token(&zid))
                .wait()
                .map_err(zerr)?,
        ));

        // The robot's devices.
        let wait = Duration::from_secs_f64((2.0 / profile.loop_.rate_hz.max(1.0)).min(0.5));
        let mut cameras: Vec<Box<dyn crate::robot::Camera>> = Vec::new();
        for (cam, spec) in config.cameras.iter().zip(&profile.cameras) {
            let ty = match cam.kind {
                ImageKind::Raw => interfaces::image(),
                ImageKind::Compressed => interfaces::compressed_image(),
            };
            token(&mut declared, "MS", &cam.topic, &ty)?;
            let sub = subscribe(&session, &node.key(&cam.topic, &ty)).map_err(BridgeError::Zenoh)?;
            cameras.push(Box::new(TopicCamera::new(
                node.qualify(&cam.topic),
                cam.kind,
                (spec.width_px, spec.height_px),
                sub,
                wait,
                config.trust_stamps,
            )));
        }
        let twist = interfaces::twist();
        let drive_gid = token(&mut declared, "MP", &config.cmd_vel, &twist)?;
        let cmd = session
            .declare_publisher(node.key(&config.cmd_vel, &twist))
            .wait()
            .map_err(zerr)?;
        let mut robot = Robot::new(cameras, Box::new(TwistDrive::new(RmwPublisher::new(cmd, drive_gid))));
        if let Some(topic) = &config.odometry {
            let ty = interfaces::odometry();
            token(&mut declared, "MS", topic, &ty)?;
            let sub = subscribe(&session, &node.key(topic, &ty)).map_err(BridgeError::Zenoh)?;
            robot.odometer = Some(Box::new(TopicOdometer::new(node.qualify(topic), sub)));
        }
        let boolean = interfaces::message("std_msgs/msg/Bool");
        let string = interfaces::message("std_msgs/msg/String");
        for spec in &profile.sensors {
            let device: Box<dyn Sensor> = match (spec.kind.as_str(), &config.dock_contact) {
                (DOCK_CONTACT_KIND, Some(topic)) => {
                    token(&mut declared, "MS", topic, &boolean)?;
                    let (latest, sub) = subscribe(&session, &node.key(topic, &boolean)).map_err(BridgeError::Zenoh)?;
                    Box::new(TopicSwitch {
                        topic: node.qualify(topic),
                        latest,
                        _sub: sub,
                    })
                }
                _ => Box::new(Unbridged),
            };
            robot.sensors.push(device);
        }
        for spec in &profile.actuators {
            let topic: Option<(&str, &Interface, Encode)> = match spec.kind.as_str() {
                POSTURE_KIND => Some(("posture", &string, posture_message)),
                GUIDES_KIND => Some(("dock_guides", &string, guides_message)),
                LIGHTS_KIND => Some(("lights", &boolean, lights_message)),
                _ => None,
            };
            let device: Box<dyn Actuator> = match topic {
                Some((name, ty, encode)) => {
                    let g = token(&mut declared, "MP", name, ty)?;
                    let p = session.declare_publisher(node.key(name, ty)).wait().map_err(zerr)?;
                    Box::new(AuxTopic {
                        publisher: RmwPublisher::new(p, g),
                        encode,
                    })
                }
                None => Box::new(Unbridged),
            };
            robot.actuators.push(device);
        }

        // The two actions.
        let cancel = interfaces::cancel_goal();
        let status_ty = interfaces::goal_status_array();
        let mut status = Vec::new();
        let mut feedback = Vec::new();
        for which in [Which::Dock, Which::Undock] {
            let a = interfaces::action(which.interface());
            let base = format!("{}/_action", which.action());
            let fb_name = format!("{base}/feedback");
            let st_name = format!("{base}/status");
            let fb_gid = token(&mut declared, "MP", &fb_name, &a.feedback)?;
            let st_gid = token(&mut declared, "MP", &st_name, &status_ty)?;
            let publisher =
                |name: &str, ty: &Interface| session.declare_publisher(node.key(name, ty)).wait().map_err(zerr);
            feedback.push(RmwPublisher::new(publisher(&fb_name, &a.feedback)?, fb_gid));
            status.push(RmwPublisher::new(publisher(&st_name, &status_ty)?, st_gid));
        }
        let (jobs_tx, jobs_rx) = unbounded();
        let shared = Arc::new(Shared {
            goals: Mutex::new(Goals::default()),
            closing: AtomicBool::new(false),
            jobs: jobs_tx,
            status: to_pair(status),
            feedback: to_pair(feedback),
        });
        for which in [Which::Dock, Which::Undock] {
            let a = interfaces::action(which.interface());
            let base = format!("{}/_action", which.action());
            for (service, ty) in [
                ("send_goal", &a.send_goal),
                ("get_result", &a.get_result),
                ("cancel_goal", &cancel),
            ] {
                let name = format!("{base}/{service}");
                token(&mut declared, "SS", &name, ty)?;
                let sh = shared.clone();
                let q = session
                    .declare_queryable(node.key(&name, ty))
                    .complete(true)
                    .callback(move |query| match service {
                        "send_goal" => on_send_goal(&sh, which, &query),
                        "get_result" => on_get_result(&sh, which, query),
                        _ => on_cancel(&sh, which, &query),
                    })
                    .wait()
                    .map_err(zerr)?;
                declared.push(Box::new(q));
            }
        }

        let sh = shared.clone();
        let runtime = config.runtime.clone();
        let worker = std::thread::Builder::new()
            .name("marsupial-ros2-goals".to_owned())
            .spawn(move || run_goals(robot, lp, &jobs_rx, &sh, &runtime))
            .map_err(|e| BridgeError::Config(format!("could not start the goal thread: {e}")))?;
        Ok(Self {
            session,
            shared,
            worker: Some(worker),
            _declared: declared,
        })
    }

    /// The endpoints the session listens on, as Zenoh resolved them (with the port the OS
    /// chose for `tcp/127.0.0.1:0`), for a peer to connect to.
    pub fn locators(&self) -> Vec<String> {
        self.session
            .info()
            .locators()
            .wait()
            .into_iter()
            .map(|l| l.to_string())
            .collect()
    }

    /// Cancels the running goal, waits until the robot has stopped, and closes the
    /// session.
    pub fn shutdown(mut self) {
        self.stop_worker();
    }

    fn stop_worker(&mut self) {
        self.shared.closing.store(true, Ordering::SeqCst);
        if let Ok(g) = self.shared.goals.lock()
            && let Some((_, _, stop)) = &g.active
        {
            stop.stop();
        }
        if let Some(w) = self.worker.take() {
            let _ = w.join();
        }
        let _ = self.session.close().wait();
    }
}

impl Drop for Ros2Node {
    fn drop(&mut self) {
        if self.worker.is_some() {
            self.stop_worker();
        }
    }
}

fn to_pair<T>(v: Vec<T>) -> [T; 2] {
    let mut it = v.into_iter();
    match (it.next(), it.next()) {
        (Some(a), Some(b)) => [a, b],
        _ => unreachable!("two actions are declared"),
    }
}

fn on_send_goal(sh: &Shared, which: Which, query: &Query) {
    let (payload, att) = request(query);
    let mut buf = Vec::new();
    let accepted = match decode_send_goal(&payload, which == Which::Dock) {
        Ok((id, goal)) => {
            let Ok(mut g) = sh.goals.lock() else { return };
            if g.active.is_some() {
                tracing::warn!(target: "marsupial::ros2", action = which.action(), "goal rejected: another goal is running");
                false
            } else {
                let stop = StopHandle::new();
                g.active = Some((which, id, stop.clone()));
                drop(g);
                sh.set_status(which, &id, status::ACCEPTED);
                let _ = sh.jobs.send(Job { which, id, goal, stop });
                true
            }
        }
        Err(e) => {
            tracing::warn!(target: "marsupial::ros2", action = which.action(), "goal rejected: {e}");
            false
        }
    };
    encode_send_goal_response(&mut buf, accepted, stamp(now_ns()));
    reply(query, att, buf);
}

fn on_get_result(sh: &Shared, which: Which, query: Query) {
    let (payload, att) = request(&query);
    let Ok(id) = decode_goal_id(&payload) else {
        reply_result(&query, att, &unknown_goal(), which == Which::Dock);
        return;
    };
    let Ok(mut g) = sh.goals.lock() else { return };
    if let Some((_, r)) = g.results.iter().rev().find(|(gid, _)| *gid == id) {
        let r = r.clone();
        drop(g);
        reply_result(&query, att, &r, which == Which::Dock);
    } else if g.active.as_ref().is_some_and(|(_, a, _)| *a == id) {
        g.waiting.push((id, which, query, att));
    } else {
        drop(g);
        reply_result(&query, att, &unknown_goal(), which == Which::Dock);
    }
}

fn unknown_goal() -> GoalResult {
    GoalResult {
        status: 0,
        success: false,
        error_code: 999,
        outcome: "unknown goal".to_owned(),
        num_retries: 0,
    }
}

fn on_cancel(sh: &Shared, which: Which, query: &Query) {
    let (payload, att) = request(query);
    let id = decode_goal_id(&payload).unwrap_or_default();
    let mut buf = Vec::new();
    let Ok(g) = sh.goals.lock() else { return };
    match &g.active {
        // An all-zero id cancels every goal, as the action protocol says.
        Some((w, a, stop)) if *w == which && (*a == id || id == [0; 16]) => {
            stop.stop();
            let a = *a;
            drop(g);
            sh.set_status(which, &a, 3); // CANCELING
            encode_cancel_response(&mut buf, 0, &[(a, stamp(now_ns()))]);
        }
        _ => {
            let known = g.results.iter().any(|(r, _)| *r == id);
            encode_cancel_response(&mut buf, if known { 3 } else { 2 }, &[]);
        }
    }
    reply(query, att, buf);
}

/// Runs each goal as it comes, until the node closes.
fn run_goals(
    mut robot: Robot,
    mut lp: ReactiveLoop<dyn Agent>,
    jobs: &Receiver<Job>,
    sh: &Shared,
    runtime: &RuntimeConfig,
) {
    while !sh.closing.load(Ordering::SeqCst) {
        let job = match jobs.recv_timeout(Duration::from_millis(100)) {
            Ok(job) => job,
            Err(RecvTimeoutError::Timeout) => continue,
            Err(RecvTimeoutError::Disconnected) => break,
        };
        sh.set_status(job.which, &job.id, status::EXECUTING);
        let (mission, max_time) = match job.goal {
            Goal::Dock(g) => (Mission::Docking { dock_hint: g.dock_hint }, g.max_time),
            Goal::Undock(g) => (Mission::Departure, g.max_time),
        };
        let mut config = runtime.clone();
        if max_time > 0.0 && max_time.is_finite() {
            config.max_duration = Some(Duration::from_secs_f32(max_time));
        }
        let mut progress = Progress::new(job.which, job.id);
        let report = run_missions_observed(&mut robot, &mut lp, &[mission], &config, &job.stop, &mut |t, s| {
            progress.observe(sh, t, s);
        });
        let result = result_of(
            &report,
            job.stop.is_stopped(),
            progress.retries,
            job.which == Which::Dock,
        );
        tracing::info!(target: "marsupial::ros2", action = job.which.action(), outcome = %result.outcome, "goal finished");
        sh.finish(job.which, job.id, result);
    }
}

/// Publishes a goal's feedback: when the phase changes, and twice a second.
struct Progress {
    which: Which,
    id: GoalId,
    last: Option<(&'static str, f64)>,
    retries: u16,
    buf: Vec<u8>,
}

impl Progress {
    fn new(which: Which, id: GoalId) -> Self {
        Self {
            which,
            id,
            last: None,
            retries: 0,
            buf: Vec::with_capacity(128),
        }
    }

    fn observe(&mut self, sh: &Shared, t: f64, status: &LoopStatus) {
        let (phase, retries) = match status {
            LoopStatus::Running { feedback } => (feedback.phase, feedback.retries),
            LoopStatus::SafeStop { .. } => ("safe_stop", u32::from(self.retries)),
            LoopStatus::Idle => ("idle", u32::from(self.retries)),
            LoopStatus::Finished { .. } => return,
        };
        self.retries = retries.min(u32::from(u16::MAX)) as u16;
        if self.last.is_some_and(|(p, at)| p == phase && t - at < 0.5) {
            return;
        }
        self.last = Some((phase, t));
        encode_feedback(&mut self.buf, &self.id, phase, (t * 1e9) as i64, self.retries);
        let _ = sh.feedback[self.which as usize].put(&self.buf);
    }
}

/// The result of a goal's run: the typed outcome, with Nav2's `DockRobot` error code
/// for it (`UndockRobot` uses the same numbers).
fn result_of(report: &RuntimeReport, stopped: bool, retries: u16, dock: bool) -> GoalResult {
    let refused = report.events.iter().find_map(|e| match e {
        RuntimeEvent::MissionRefused { error, .. } => Some(error.to_string()),
        _ => None,
    });
    let (status, error_code, outcome) = match (&report.outcome, &report.aborted, refused) {
        (_, _, Some(why)) => (status::ABORTED, 902, format!("refused: {why}")),
        (_, Some(reason), _) => (status::ABORTED, 999, format!("aborted: {reason}")),
        (Some(Outcome::Docked), _, _) => (status::SUCCEEDED, 0, "docked".to_owned()),
        (Some(Outcome::Completed), _, _) => (status::SUCCEEDED, 0, "completed".to_owned()),
        (Some(Outcome::Failed(r)), _, _) => (status::ABORTED, error_code(*r, dock), r.as_str().to_owned()),
        (None, None, None) if stopped => (status::CANCELED, 0, "canceled".to_owned()),
        (None, None, None) => (status::ABORTED, 907, "timeout".to_owned()),
    };
    GoalResult {
        status,
        success: status == status::SUCCEEDED,
        error_code,
        outcome,
        num_retries: retries,
    }
}

/// Nav2's code for a failure: 904 `FAILED_TO_DETECT_DOCK`, 905 `FAILED_TO_CONTROL`, 907
/// `TIMEOUT` (an undocking has only 905 and 999).
fn error_code(r: FailureReason, dock: bool) -> u16 {
    match r {
        FailureReason::TargetNeverDetected | FailureReason::TargetLost if dock => 904,
        FailureReason::Timeout if dock => 907,
        _ => 905,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn report(outcome: Option<Outcome>) -> RuntimeReport {
        RuntimeReport {
            outcome,
            ..RuntimeReport::default()
        }
    }

    #[test]
    fn results_carry_the_typed_outcome_and_nav2_codes() {
        let r = result_of(&report(Some(Outcome::Docked)), false, 1, true);
        assert_eq!(
            (r.status, r.success, r.error_code, r.outcome.as_str()),
            (4, true, 0, "docked")
        );
        assert_eq!(r.num_retries, 1);
        let r = result_of(
            &report(Some(Outcome::Failed(FailureReason::TargetLost))),
            false,
            0,
            true,
        );
        assert_eq!((r.status, r.error_code, r.outcome.as_str()), (6, 904, "target_lost"));
        let r = result_of(
            &report(Some(Outcome::Failed(FailureReason::StuckContact))),
            false,
            0,
            true,
        );
        assert_eq!(r.error_code, 905);
        let r = result_of(
            &report(Some(Outcome::Failed(FailureReason::TargetLost))),
            false,
            0,
            false,
        );
        assert_eq!(r.error_code, 905);
        let r = result_of(&report(None), true, 0, true);
        assert_eq!((r.status, r.outcome.as_str()), (5, "canceled"));
        let r = result_of(&report(None), false, 0, true);
        assert_eq!((r.status, r.error_code, r.outcome.as_str()), (6, 907, "timeout"));
    }

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
