//! The node's two actions and its dock database service, as the ROS 2 action protocol
//! serves them: `send_goal`, `get_result` and `cancel_goal` and the `feedback` and
//! `status` topics of `dock_robot` and `undock_robot`, and `reload_database`; and the
//! worker that runs each goal on the threaded runtime.
//!
//! A goal is accepted while no other runs (a second is rejected), then checked
//! ([`super::plan`]): a bad one ends at once, aborted with Nav2's error code and a message
//! naming its field. A good one runs as a mission; its feedback gives Nav2's state for
//! the running phase ([`super::nav2::state_of`]), and its result Nav2's error code for the
//! typed outcome ([`super::nav2::error_code`]) with the outcome's text in `error_msg`.

use super::dock_db::DockDatabase;
use super::keys::{Attachment, RmwPublisher, now_ns};
use super::latched::LatchedPublisher;
use super::messages::{
    GoalId, decode_goal_id, encode_cancel_response, encode_send_goal_response, encode_status, stamp,
};
use super::nav2::error;
use super::nav2_msgs::{
    Goal, GoalResult, decode_reload_request, decode_send_goal, encode_reload_response, encode_result,
};
use super::plan::{Plan, Resolver};
use super::progress::{Progress, result_of};
use crate::arbiter::ReactiveLoop;
use crate::arbiter::runtime::{RuntimeConfig, StopHandle, run_missions_observed};
use crate::msgs::ros::Time;
use crate::robot::Robot;
use crate::schemas::Agent;
use crossbeam::channel::{Receiver, RecvTimeoutError, Sender};
use std::collections::VecDeque;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;
use zenoh::Wait;
use zenoh::query::Query;

/// Which of the two actions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Which {
    Dock = 0,
    Undock = 1,
}

impl Which {
    /// The action's name, relative to the node's namespace.
    pub(crate) fn action(self) -> &'static str {
        match self {
            Which::Dock => "dock_robot",
            Which::Undock => "undock_robot",
        }
    }

    /// Its type.
    pub(crate) fn interface(self) -> &'static str {
        match self {
            Which::Dock => super::interfaces::DOCK_ROBOT,
            Which::Undock => super::interfaces::UNDOCK_ROBOT,
        }
    }
}

/// `action_msgs/msg/GoalStatus` codes.
pub(crate) mod status {
    pub const ACCEPTED: i8 = 1;
    pub const EXECUTING: i8 = 2;
    pub const CANCELING: i8 = 3;
    pub const SUCCEEDED: i8 = 4;
    pub const CANCELED: i8 = 5;
    pub const ABORTED: i8 = 6;
}

/// A goal handed to the worker.
pub(crate) struct Job {
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

/// The state the services, the worker and the node share.
pub(crate) struct Shared {
    goals: Mutex<Goals>,
    /// Raised when the node closes: the worker ends after the goal it runs.
    pub(crate) closing: AtomicBool,
    jobs: Sender<Job>,
    status: [LatchedPublisher; 2],
    pub(crate) feedback: RmwPublisher,
    /// The docks `dock_id` names, replaced by `reload_database`.
    docks: Mutex<DockDatabase>,
    /// The profile's dock type (its name) and the odometry frame.
    dock_type: String,
    odom_frame: String,
}

impl Shared {
    /// The shared state; `status` per action (dock, undock), `feedback` the docking's.
    pub(crate) fn new(
        jobs: Sender<Job>,
        status: [LatchedPublisher; 2],
        feedback: RmwPublisher,
        docks: DockDatabase,
        dock_type: &str,
        odom_frame: &str,
    ) -> Self {
        Self {
            goals: Mutex::new(Goals::default()),
            closing: AtomicBool::new(false),
            jobs,
            status,
            feedback,
            docks: Mutex::new(docks),
            dock_type: dock_type.to_owned(),
            odom_frame: odom_frame.to_owned(),
        }
    }

    /// Stops the running goal, if any.
    pub(crate) fn stop_active(&self) {
        if let Ok(g) = self.goals.lock()
            && let Some((_, _, stop)) = &g.active
        {
            stop.stop();
        }
    }

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

    /// The goal's plan, against the dock database as it is now.
    fn plan(&self, goal: &Goal) -> Result<Plan, super::plan::GoalError> {
        let db = self
            .docks
            .lock()
            .map(|d| d.clone())
            .unwrap_or_else(|e| e.into_inner().clone());
        let r = Resolver {
            db: &db,
            odom_frame: &self.odom_frame,
            dock_type: &self.dock_type,
        };
        match goal {
            Goal::Dock(g) => r.docking(g),
            Goal::Undock(g) => r.undocking(g),
        }
    }
}

/// Replies to a service request, echoing its sequence number and client GID as
/// `rmw_zenoh` does.
pub(crate) fn reply(query: &Query, att: Option<Attachment>, payload: Vec<u8>) {
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

/// `send_goal`: accepts the goal when none runs.
pub(crate) fn on_send_goal(sh: &Shared, which: Which, query: &Query) {
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

/// `get_result`: answers now for a finished goal, when it ends for the running one.
pub(crate) fn on_get_result(sh: &Shared, which: Which, query: Query) {
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
        error_code: error::UNKNOWN,
        num_retries: 0,
        error_msg: "unknown goal".to_owned(),
    }
}

/// `cancel_goal`: stops the running goal (an all-zero id cancels every goal).
pub(crate) fn on_cancel(sh: &Shared, which: Which, query: &Query) {
    let (payload, att) = request(query);
    let id = decode_goal_id(&payload).unwrap_or_default();
    let mut buf = Vec::new();
    let Ok(g) = sh.goals.lock() else { return };
    match &g.active {
        Some((w, a, stop)) if *w == which && (*a == id || id == [0; 16]) => {
            stop.stop();
            let a = *a;
            drop(g);
            sh.set_status(which, &a, status::CANCELING);
            encode_cancel_response(&mut buf, 0, &[(a, stamp(now_ns()))]);
        }
        _ => {
            let known = g.results.iter().any(|(r, _)| *r == id);
            encode_cancel_response(&mut buf, if known { 3 } else { 2 }, &[]);
        }
    }
    reply(query, att, buf);
}

/// `reload_database`: adds the docks of the file `filepath` ([`super::dock_db`]); false,
/// with the database unchanged and the reason logged, when the file does not read.
pub(crate) fn on_reload(sh: &Shared, query: &Query) {
    let (payload, att) = request(query);
    let ok = match decode_reload_request(&payload) {
        Ok(path) => {
            let Ok(mut db) = sh.docks.lock() else { return };
            match db.reloaded(std::path::Path::new(&path), &sh.dock_type) {
                Ok(new) => {
                    tracing::info!(target: "marsupial::ros2", docks = %new.ids(), "dock database reloaded from {path}");
                    *db = new;
                    true
                }
                Err(e) => {
                    tracing::warn!(target: "marsupial::ros2", "dock database not reloaded: {e}");
                    false
                }
            }
        }
        Err(e) => {
            tracing::warn!(target: "marsupial::ros2", "reload_database request: {e}");
            false
        }
    };
    let mut buf = Vec::new();
    encode_reload_response(&mut buf, ok);
    reply(query, att, buf);
}

/// Runs each goal as it comes, until the node closes.
pub(crate) fn run_goals(
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
        let dock = job.which == Which::Dock;
        sh.set_status(job.which, &job.id, status::EXECUTING);
        let plan = match sh.plan(&job.goal) {
            Ok(plan) => plan,
            Err(e) => {
                tracing::warn!(target: "marsupial::ros2", action = job.which.action(), code = e.code, "goal aborted: {}", e.message);
                let result = GoalResult {
                    status: status::ABORTED,
                    success: false,
                    error_code: e.code,
                    num_retries: 0,
                    error_msg: e.message,
                };
                sh.finish(job.which, job.id, result);
                continue;
            }
        };
        let mut config = runtime.clone();
        if plan.max_duration.is_some() {
            config.max_duration = plan.max_duration;
        }
        let mut progress = Progress::new(job.id, dock, job.stop.clone(), plan.max_staging_s);
        let report = run_missions_observed(
            &mut robot,
            &mut lp,
            std::slice::from_ref(&plan.mission),
            &config,
            &job.stop,
            &mut |t, s| progress.observe(sh, t, s),
        );
        let result = result_of(&report, job.stop.is_stopped(), &progress, dock);
        tracing::info!(target: "marsupial::ros2", action = job.which.action(), code = result.error_code, outcome = %result.error_msg, "goal finished");
        sh.finish(job.which, job.id, result);
    }
}
