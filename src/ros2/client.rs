//! Calling the node's Nav2 actions and its dock database service from Rust, as
//! `ros2 action send_goal` and `ros2 service call` would: send a goal, follow its
//! feedback and status, wait for its result, cancel it, reload the docks. The tests use
//! it; so can a mission planner written in Rust that shares the node's Zenoh network.

use super::interfaces::{self, ActionInterfaces};
use super::keys::{Attachment, NodeName, gid, now_ns};
use super::messages::{
    GoalId, decode_cancel_response, decode_send_goal_response, decode_status, encode_cancel_request, encode_goal_id,
};
use super::nav2_msgs::{
    DockFeedback, Goal, GoalResult, decode_feedback, decode_reload_response, decode_result, encode_reload_request,
    encode_send_goal,
};
use crate::msgs::ros::Time;
use std::sync::atomic::{AtomicI64, Ordering};
use std::time::Duration;
use thiserror::Error;
use zenoh::Wait;
use zenoh::query::{QueryTarget, ReplyKeyExpr};

/// One goal of a status message: its id, when it was accepted, its
/// `action_msgs/msg/GoalStatus` code.
pub type GoalStatus = (GoalId, Time, i8);

/// Why a call did not get its answer.
#[derive(Debug, Error)]
pub enum ClientError {
    /// Zenoh failed the request.
    #[error("zenoh: {0}")]
    Zenoh(String),
    /// No server answered within the timeout.
    #[error("no answer from `{0}` (is the node running, and connected to this session?)")]
    NoAnswer(String),
    /// The answer did not decode.
    #[error("`{service}` answered with a payload that does not decode: {why}")]
    Malformed {
        /// The service.
        service: String,
        /// Why.
        why: String,
    },
    /// The server rejected the goal.
    #[error("the goal was rejected (another goal is running, or the goal did not decode)")]
    Rejected,
}

/// A client of the node's `dock_robot` and `undock_robot` actions and its
/// `reload_database` service.
pub struct ActionClient {
    session: zenoh::Session,
    node: NodeName,
    gid: [u8; 16],
    sequence: AtomicI64,
}

impl ActionClient {
    /// A client on `session` for the node whose names `node` gives (its domain and
    /// namespace; the node's own name is only in `reload_database`'s key).
    pub fn new(session: &zenoh::Session, node: NodeName) -> Self {
        let gid = gid(&format!("client/{}/{}", session.zid(), now_ns()));
        Self {
            session: session.clone(),
            node,
            gid,
            sequence: AtomicI64::new(0),
        }
    }

    fn names(goal_is_dock: bool) -> (&'static str, ActionInterfaces) {
        if goal_is_dock {
            ("dock_robot", interfaces::action(interfaces::DOCK_ROBOT))
        } else {
            ("undock_robot", interfaces::action(interfaces::UNDOCK_ROBOT))
        }
    }

    /// One request-reply on the service `name` of type `ty`.
    fn call(
        &self,
        name: &str,
        ty: &interfaces::Interface,
        payload: Vec<u8>,
        timeout: Duration,
    ) -> Result<Vec<u8>, ClientError> {
        let att = Attachment {
            sequence_number: self.sequence.fetch_add(1, Ordering::SeqCst) + 1,
            source_timestamp: now_ns(),
            gid: self.gid,
        };
        let replies = self
            .session
            .get(self.node.key(name, ty))
            .payload(payload)
            .attachment(att.encode())
            .target(QueryTarget::AllComplete)
            .timeout(timeout)
            .wait()
            .map_err(|e| ClientError::Zenoh(e.to_string()))?;
        while let Ok(reply) = replies.recv() {
            if let Ok(sample) = reply.result() {
                return Ok(sample.payload().to_bytes().into_owned());
            }
        }
        Err(ClientError::NoAnswer(self.node.qualify(name)))
    }

    /// Sends `goal` and returns its id once the node accepted it.
    ///
    /// # Errors
    /// [`ClientError`]; [`ClientError::Rejected`] when the node refused the goal.
    pub fn send(&self, goal: &Goal, timeout: Duration) -> Result<GoalId, ClientError> {
        let dock = matches!(goal, Goal::Dock(_));
        let (action, ty) = Self::names(dock);
        let id = gid(&format!("goal/{}/{}", now_ns(), self.sequence.load(Ordering::SeqCst)));
        let mut buf = Vec::new();
        encode_send_goal(&mut buf, &id, goal);
        let name = format!("{action}/_action/send_goal");
        let answer = self.call(&name, &ty.send_goal, buf, timeout)?;
        let accepted = decode_send_goal_response(&answer).map_err(|e| ClientError::Malformed {
            service: name,
            why: e.to_string(),
        })?;
        if accepted { Ok(id) } else { Err(ClientError::Rejected) }
    }

    /// Waits up to `timeout` for goal `id`'s result (`dock`: of the docking action).
    ///
    /// # Errors
    /// [`ClientError`].
    pub fn result(&self, id: &GoalId, dock: bool, timeout: Duration) -> Result<GoalResult, ClientError> {
        let (action, ty) = Self::names(dock);
        let mut buf = Vec::new();
        encode_goal_id(&mut buf, id);
        let name = format!("{action}/_action/get_result");
        let answer = self.call(&name, &ty.get_result, buf, timeout)?;
        decode_result(&answer, dock).map_err(|e| ClientError::Malformed {
            service: name,
            why: e.to_string(),
        })
    }

    /// Asks the node to cancel goal `id`; returns `action_msgs/srv/CancelGoal`'s return
    /// code (0 accepted, 2 unknown goal, 3 already terminated).
    ///
    /// # Errors
    /// [`ClientError`].
    pub fn cancel(&self, id: &GoalId, dock: bool, timeout: Duration) -> Result<i8, ClientError> {
        let (action, _) = Self::names(dock);
        let mut buf = Vec::new();
        encode_cancel_request(&mut buf, id);
        let name = format!("{action}/_action/cancel_goal");
        let answer = self.call(&name, &interfaces::cancel_goal(), buf, timeout)?;
        decode_cancel_response(&answer).map_err(|e| ClientError::Malformed {
            service: name,
            why: e.to_string(),
        })
    }

    /// Calls `ReloadDockDatabase` with `filepath`; returns its `success`.
    ///
    /// # Errors
    /// [`ClientError`].
    pub fn reload_docks(&self, filepath: &str, timeout: Duration) -> Result<bool, ClientError> {
        let mut buf = Vec::new();
        encode_reload_request(&mut buf, filepath);
        let name = format!("{}/reload_database", self.node.name);
        let answer = self.call(&name, &interfaces::reload_dock_database(), buf, timeout)?;
        decode_reload_response(&answer).map_err(|e| ClientError::Malformed {
            service: name,
            why: e.to_string(),
        })
    }

    /// Calls `f` with each `DockRobot` feedback message until the returned subscriber is
    /// dropped (`UndockRobot`'s feedback is empty and never sent).
    ///
    /// # Errors
    /// [`ClientError::Zenoh`].
    pub fn on_feedback(
        &self,
        f: impl Fn(GoalId, DockFeedback) + Send + Sync + 'static,
    ) -> Result<zenoh::pubsub::Subscriber<()>, ClientError> {
        let (action, ty) = Self::names(true);
        self.session
            .declare_subscriber(self.node.key(&format!("{action}/_action/feedback"), &ty.feedback))
            .callback(move |s| {
                if let Ok((id, fb)) = decode_feedback(&s.payload().to_bytes()) {
                    f(id, fb);
                }
            })
            .wait()
            .map_err(|e| ClientError::Zenoh(e.to_string()))
    }

    /// Calls `f` with each status message of the action (`dock`: docking): every recent
    /// goal's id, acceptance time and `action_msgs/msg/GoalStatus` code, until the
    /// returned subscriber is dropped. A message that does not parse is skipped.
    ///
    /// # Errors
    /// [`ClientError::Zenoh`].
    pub fn on_status(
        &self,
        dock: bool,
        f: impl Fn(Vec<GoalStatus>) + Send + Sync + 'static,
    ) -> Result<zenoh::pubsub::Subscriber<()>, ClientError> {
        let (action, _) = Self::names(dock);
        self.session
            .declare_subscriber(
                self.node
                    .key(&format!("{action}/_action/status"), &interfaces::goal_status_array()),
            )
            .callback(move |s| {
                if let Ok(goals) = decode_status(&s.payload().to_bytes()) {
                    f(goals);
                }
            })
            .wait()
            .map_err(|e| ClientError::Zenoh(e.to_string()))
    }

    /// The last status message of the action (`dock`: docking), as a transient-local
    /// subscriber that joins late gets it: a query of `*/<status key>` that accepts
    /// replies on any key, answered by the node's cache ([`super::latched`]). `None`
    /// when nothing answered within `timeout`.
    ///
    /// # Errors
    /// [`ClientError::Zenoh`].
    pub fn latest_status(&self, dock: bool, timeout: Duration) -> Result<Option<Vec<GoalStatus>>, ClientError> {
        let (action, _) = Self::names(dock);
        let key = self
            .node
            .key(&format!("{action}/_action/status"), &interfaces::goal_status_array());
        let replies = self
            .session
            .get(format!("*/{key}"))
            .accept_replies(ReplyKeyExpr::Any)
            .target(QueryTarget::All)
            .timeout(timeout)
            .wait()
            .map_err(|e| ClientError::Zenoh(e.to_string()))?;
        while let Ok(reply) = replies.recv() {
            if let Ok(sample) = reply.result()
                && sample.key_expr().as_str() == key
                && let Ok(goals) = decode_status(&sample.payload().to_bytes())
            {
                return Ok(Some(goals));
            }
        }
        Ok(None)
    }
}
