//! CDR payloads of Nav2's docking interface, as `nav2_msgs` defines it (Jazzy, Kilted,
//! Rolling): the `DockRobot` and `UndockRobot` goals, results and feedback inside the
//! action protocol's messages, and `ReloadDockDatabase`'s request and response. The field
//! order, types and default values are those of `nav2_msgs/action/DockRobot.action`,
//! `UndockRobot.action` and `srv/ReloadDockDatabase.srv`.
//!
//! Every decoder is total: a short or malformed payload is a [`CdrError`] naming the
//! field, never a panic.

use super::messages::{GoalId, stamp};
use crate::msgs::cdr::{CdrError, CdrReader, CdrWriter};
use crate::msgs::ros::Time;

/// `geometry_msgs/msg/PoseStamped`.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseStamped {
    /// `header.stamp`.
    pub stamp: Time,
    /// `header.frame_id`: the frame the pose is in.
    pub frame_id: String,
    /// `pose.position` (x, y, z), m.
    pub position: [f64; 3],
    /// `pose.orientation` (x, y, z, w).
    pub orientation: [f64; 4],
}

impl Default for PoseStamped {
    /// At the origin, identity orientation (`Quaternion`'s `w` defaults to 1), no frame.
    fn default() -> Self {
        Self {
            stamp: Time::default(),
            frame_id: String::new(),
            position: [0.0; 3],
            orientation: [0.0, 0.0, 0.0, 1.0],
        }
    }
}

/// `nav2_msgs/action/DockRobot_Goal`.
#[derive(Debug, Clone, PartialEq)]
pub struct DockRobotGoal {
    /// Dock at the dock named `dock_id` (true) or at `dock_pose` (false).
    pub use_dock_id: bool,
    /// A dock of the dock database.
    pub dock_id: String,
    /// The dock's pose, when `use_dock_id` is false.
    pub dock_pose: PoseStamped,
    /// The dock's type (its plugin, in Nav2); empty when there is one type.
    pub dock_type: String,
    /// The longest the drive to the staging pose may take, s.
    pub max_staging_time: f32,
    /// Drive to the staging pose first (true), or start from where the robot is.
    pub navigate_to_staging_pose: bool,
}

impl Default for DockRobotGoal {
    /// The `.action` file's defaults: `use_dock_id` true, `max_staging_time` 1000 s,
    /// `navigate_to_staging_pose` true.
    fn default() -> Self {
        Self {
            use_dock_id: true,
            dock_id: String::new(),
            dock_pose: PoseStamped::default(),
            dock_type: String::new(),
            max_staging_time: 1000.0,
            navigate_to_staging_pose: true,
        }
    }
}

/// `nav2_msgs/action/UndockRobot_Goal`.
#[derive(Debug, Clone, PartialEq)]
pub struct UndockRobotGoal {
    /// The dock's type; empty when there is one type.
    pub dock_type: String,
    /// The longest the undocking may take, s.
    pub max_undocking_time: f32,
}

impl Default for UndockRobotGoal {
    /// The `.action` file's default: `max_undocking_time` 30 s.
    fn default() -> Self {
        Self {
            dock_type: String::new(),
            max_undocking_time: 30.0,
        }
    }
}

/// Either goal.
#[derive(Debug, Clone, PartialEq)]
pub enum Goal {
    /// `DockRobot`.
    Dock(DockRobotGoal),
    /// `UndockRobot`.
    Undock(UndockRobotGoal),
}

/// Reads a `SendGoal` request: the goal id, then the goal of the action `dock` says.
///
/// # Errors
/// [`CdrError`] naming the field.
pub fn decode_send_goal(buf: &[u8], dock: bool) -> Result<(GoalId, Goal), CdrError> {
    let mut r = CdrReader::new(buf)?;
    let id = r.fixed_bytes::<16>("goal_id")?;
    let goal = if dock {
        let use_dock_id = r.u8("goal.use_dock_id")? != 0;
        let dock_id = r.string("goal.dock_id")?.to_owned();
        let sec = r.i32("goal.dock_pose.header.stamp.sec")?;
        let nanosec = r.u32("goal.dock_pose.header.stamp.nanosec")?;
        let frame_id = r.string("goal.dock_pose.header.frame_id")?.to_owned();
        let position = r.f64s::<3>("goal.dock_pose.pose.position")?;
        let orientation = r.f64s::<4>("goal.dock_pose.pose.orientation")?;
        Goal::Dock(DockRobotGoal {
            use_dock_id,
            dock_id,
            dock_pose: PoseStamped {
                stamp: Time { sec, nanosec },
                frame_id,
                position,
                orientation,
            },
            dock_type: r.string("goal.dock_type")?.to_owned(),
            max_staging_time: r.f32("goal.max_staging_time")?,
            navigate_to_staging_pose: r.u8("goal.navigate_to_staging_pose")? != 0,
        })
    } else {
        Goal::Undock(UndockRobotGoal {
            dock_type: r.string("goal.dock_type")?.to_owned(),
            max_undocking_time: r.f32("goal.max_undocking_time")?,
        })
    };
    Ok((id, goal))
}

/// Writes a `SendGoal` request (what a client sends).
pub fn encode_send_goal(buf: &mut Vec<u8>, id: &GoalId, goal: &Goal) {
    let mut w = CdrWriter::new(buf);
    w.fixed_bytes(id);
    match goal {
        Goal::Dock(g) => {
            w.u8(u8::from(g.use_dock_id));
            w.string(&g.dock_id);
            w.header(g.dock_pose.stamp, &g.dock_pose.frame_id);
            for v in g.dock_pose.position.iter().chain(&g.dock_pose.orientation) {
                w.f64(*v);
            }
            w.string(&g.dock_type);
            w.f32(g.max_staging_time);
            w.u8(u8::from(g.navigate_to_staging_pose));
        }
        Goal::Undock(g) => {
            w.string(&g.dock_type);
            w.f32(g.max_undocking_time);
        }
    }
}

/// How a goal ended: the `GetResult` response's status and the action's result.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct GoalResult {
    /// `action_msgs/msg/GoalStatus` code: 4 succeeded, 5 canceled, 6 aborted.
    pub status: i8,
    /// Docked, or undocked.
    pub success: bool,
    /// Nav2's error code ([`super::nav2`]); 0 on success.
    pub error_code: u16,
    /// Retries used (`DockRobot` only; not on the wire for `UndockRobot`).
    pub num_retries: u16,
    /// The typed outcome as text (`docked`, `completed`, `target_lost`, `canceled` …),
    /// or why the goal was bad, naming its field.
    pub error_msg: String,
}

/// Writes a `GetResult` response for the action `dock` says.
pub fn encode_result(buf: &mut Vec<u8>, r: &GoalResult, dock: bool) {
    let mut w = CdrWriter::new(buf);
    w.u8(r.status as u8);
    w.u8(u8::from(r.success));
    w.u16(r.error_code);
    if dock {
        w.u16(r.num_retries);
    }
    w.string(&r.error_msg);
}

/// Reads a `GetResult` response.
///
/// # Errors
/// [`CdrError`] naming the field.
pub fn decode_result(buf: &[u8], dock: bool) -> Result<GoalResult, CdrError> {
    let mut r = CdrReader::new(buf)?;
    let status = r.u8("status")? as i8;
    let success = r.u8("result.success")? != 0;
    let error_code = r.u16("result.error_code")?;
    let num_retries = if dock { r.u16("result.num_retries")? } else { 0 };
    let error_msg = r.string("result.error_msg")?.to_owned();
    Ok(GoalResult {
        status,
        success,
        error_code,
        num_retries,
        error_msg,
    })
}

/// `nav2_msgs/action/DockRobot_Feedback`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DockFeedback {
    /// Nav2's docking state ([`super::nav2::state`]).
    pub state: u16,
    /// `docking_time`: since the goal started, ns.
    pub docking_time_ns: i64,
    /// Retries used so far.
    pub num_retries: u16,
}

/// Writes a `DockRobot_FeedbackMessage`: the goal id and the feedback.
pub fn encode_feedback(buf: &mut Vec<u8>, id: &GoalId, f: &DockFeedback) {
    let mut w = CdrWriter::new(buf);
    w.fixed_bytes(id);
    w.u16(f.state);
    let d = stamp(f.docking_time_ns);
    w.i32(d.sec);
    w.u32(d.nanosec);
    w.u16(f.num_retries);
}

/// Reads a `DockRobot_FeedbackMessage`.
///
/// # Errors
/// [`CdrError`] naming the field.
pub fn decode_feedback(buf: &[u8]) -> Result<(GoalId, DockFeedback), CdrError> {
    let mut r = CdrReader::new(buf)?;
    let id = r.fixed_bytes::<16>("goal_id")?;
    let state = r.u16("feedback.state")?;
    let sec = r.i32("feedback.docking_time.sec")?;
    let nanosec = r.u32("feedback.docking_time.nanosec")?;
    let num_retries = r.u16("feedback.num_retries")?;
    Ok((
        id,
        DockFeedback {
            state,
            docking_time_ns: i64::from(sec) * 1_000_000_000 + i64::from(nanosec),
            num_retries,
        },
    ))
}

/// Reads a `ReloadDockDatabase` request: its `filepath`.
///
/// # Errors
/// [`CdrError`].
pub fn decode_reload_request(buf: &[u8]) -> Result<String, CdrError> {
    Ok(CdrReader::new(buf)?.string("filepath")?.to_owned())
}

/// Writes a `ReloadDockDatabase` request.
pub fn encode_reload_request(buf: &mut Vec<u8>, filepath: &str) {
    CdrWriter::new(buf).string(filepath);
}

/// Writes a `ReloadDockDatabase` response.
pub fn encode_reload_response(buf: &mut Vec<u8>, success: bool) {
    CdrWriter::new(buf).u8(u8::from(success));
}

/// Reads a `ReloadDockDatabase` response.
///
/// # Errors
/// [`CdrError`].
pub fn decode_reload_response(buf: &[u8]) -> Result<bool, CdrError> {
    Ok(CdrReader::new(buf)?.u8("success")? != 0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dock_robot_goals_round_trip_in_nav2s_field_order() {
        let id = [7u8; 16];
        let goal = Goal::Dock(DockRobotGoal {
            use_dock_id: false,
            dock_id: "home".into(),
            dock_pose: PoseStamped {
                stamp: Time { sec: 3, nanosec: 9 },
                frame_id: "odom".into(),
                position: [1.0, -2.0, 0.0],
                orientation: [0.0, 0.0, 0.5f64.sin(), 0.5f64.cos()],
            },
            dock_type: "bujold".into(),
            max_staging_time: 12.5,
            navigate_to_staging_pose: false,
        });
        let mut b = Vec::new();
        encode_send_goal(&mut b, &id, &goal);
        assert_eq!(decode_send_goal(&b, true).unwrap(), (id, goal));
        // Header 4, UUID 16, bool 1 + pad 3, "home\0" 4 + 5 + pad 3, stamp 8, "odom\0"
        // 4 + 5 + pad 7 (to a multiple of 8 for the doubles), 7 doubles 56, "bujold\0"
        // 4 + 7 + pad 1, float32 4, bool 1.
        assert_eq!(b.len(), 4 + 16 + 4 + 12 + 8 + 16 + 56 + 12 + 4 + 1);
        for cut in [0, 10, 30, b.len() - 1] {
            assert!(decode_send_goal(&b[..cut], true).is_err(), "cut at {cut}");
        }
        let undock = Goal::Undock(UndockRobotGoal::default());
        encode_send_goal(&mut b, &id, &undock);
        assert_eq!(decode_send_goal(&b, false).unwrap(), (id, undock));
    }

    #[test]
    fn results_feedback_and_reloads_round_trip() {
        let r = GoalResult {
            status: 6,
            success: false,
            error_code: 901,
            num_retries: 2,
            error_msg: "dock_id `x` is not in the dock database".into(),
        };
        let mut b = Vec::new();
        for dock in [true, false] {
            encode_result(&mut b, &r, dock);
            let back = decode_result(&b, dock).unwrap();
            assert_eq!(back.num_retries, if dock { 2 } else { 0 });
            assert_eq!((back.error_code, back.error_msg.as_str()), (901, r.error_msg.as_str()));
        }
        let f = DockFeedback {
            state: 3,
            docking_time_ns: 12_300_000_000,
            num_retries: 1,
        };
        encode_feedback(&mut b, &[1; 16], &f);
        assert_eq!(decode_feedback(&b).unwrap(), ([1; 16], f));
        encode_reload_request(&mut b, "/tmp/docks.yaml");
        assert_eq!(decode_reload_request(&b).unwrap(), "/tmp/docks.yaml");
        encode_reload_response(&mut b, true);
        assert!(decode_reload_response(&b).unwrap());
    }
}
