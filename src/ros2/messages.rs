//! CDR payloads of the messages the bridge writes and reads, beyond the camera and
//! odometry messages [`crate::msgs::cdr`] already decodes: `geometry_msgs/msg/Twist`,
//! the encoders of `sensor_msgs/msg/Image` and `nav_msgs/msg/Odometry` (for a simulator
//! or a test publishing to the node), and the action protocol's own requests, replies and
//! messages (`SendGoal`'s response, `GetResult`'s request, `CancelGoal`, the status
//! topic). Nav2's goals, results and feedback are in [`super::nav2_msgs`].
//!
//! Every decoder is total: a short or malformed payload is a [`CdrError`], never a panic.

use crate::geometry::Pose2;
use crate::msgs::cdr::{CdrError, CdrReader, CdrWriter};
use crate::msgs::ros::Time;

/// A goal's id, `unique_identifier_msgs/msg/UUID`.
pub type GoalId = [u8; 16];

/// `geometry_msgs/msg/Twist`, as a planar base uses it.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Twist {
    /// `linear.x`, m/s forward.
    pub linear_x: f64,
    /// `angular.z`, rad/s counter-clockwise.
    pub angular_z: f64,
}

impl Twist {
    /// The CDR payload (the other four components are zero).
    pub fn encode(&self, buf: &mut Vec<u8>) {
        let mut w = CdrWriter::new(buf);
        for v in [self.linear_x, 0.0, 0.0, 0.0, 0.0, self.angular_z] {
            w.f64(v);
        }
    }

    /// Reads a payload, keeping `linear.x` and `angular.z`.
    ///
    /// # Errors
    /// [`CdrError`] naming the field.
    pub fn decode(buf: &[u8]) -> Result<Self, CdrError> {
        let mut r = CdrReader::new(buf)?;
        let linear = r.f64s::<3>("linear")?;
        let angular = r.f64s::<3>("angular")?;
        Ok(Self {
            linear_x: linear[0],
            angular_z: angular[2],
        })
    }
}

/// A stamp from ns since the epoch.
pub fn stamp(ns: i64) -> Time {
    Time {
        sec: ns.div_euclid(1_000_000_000) as i32,
        nanosec: ns.rem_euclid(1_000_000_000) as u32,
    }
}

/// Writes a `sensor_msgs/msg/Image` of packed `rgb8` pixels.
pub fn encode_image(buf: &mut Vec<u8>, t: Time, frame_id: &str, width: u32, height: u32, rgb: &[u8]) {
    let mut w = CdrWriter::new(buf);
    w.header(t, frame_id);
    w.u32(height);
    w.u32(width);
    w.string("rgb8");
    w.u8(0);
    w.u32(3 * width);
    w.bytes(rgb);
}

/// Writes a `nav_msgs/msg/Odometry` of a planar pose and body twist (covariances zero).
pub fn encode_odometry(buf: &mut Vec<u8>, t: Time, pose: Pose2, v: f64, omega: f64) {
    let mut w = CdrWriter::new(buf);
    w.header(t, "odom");
    w.string("base_link");
    let (s, c) = (pose.theta / 2.0).sin_cos();
    for x in [pose.x, pose.y, 0.0, 0.0, 0.0, s, c] {
        w.f64(x);
    }
    for _ in 0..36 {
        w.f64(0.0);
    }
    for x in [v, 0.0, 0.0, 0.0, 0.0, omega] {
        w.f64(x);
    }
    for _ in 0..36 {
        w.f64(0.0);
    }
}

/// Writes a `SendGoal` response.
pub fn encode_send_goal_response(buf: &mut Vec<u8>, accepted: bool, t: Time) {
    let mut w = CdrWriter::new(buf);
    w.u8(u8::from(accepted));
    w.i32(t.sec);
    w.u32(t.nanosec);
}

/// Reads a `SendGoal` response: accepted or not.
///
/// # Errors
/// [`CdrError`].
pub fn decode_send_goal_response(buf: &[u8]) -> Result<bool, CdrError> {
    Ok(CdrReader::new(buf)?.u8("accepted")? != 0)
}

/// Reads a request that is a goal id alone (`GetResult`), or a cancel request's goal id
/// (`CancelGoal`'s `GoalInfo`, whose stamp follows and is not needed).
///
/// # Errors
/// [`CdrError`].
pub fn decode_goal_id(buf: &[u8]) -> Result<GoalId, CdrError> {
    CdrReader::new(buf)?.fixed_bytes::<16>("goal_id")
}

/// Writes a request that is a goal id alone (`GetResult`).
pub fn encode_goal_id(buf: &mut Vec<u8>, id: &GoalId) {
    CdrWriter::new(buf).fixed_bytes(id);
}

/// Writes an `action_msgs/msg/GoalStatusArray` of `(id, accepted at, status)`.
pub fn encode_status(buf: &mut Vec<u8>, goals: &[(GoalId, Time, i8)]) {
    let mut w = CdrWriter::new(buf);
    w.u32(goals.len() as u32);
    for (id, t, status) in goals {
        w.fixed_bytes(id);
        w.i32(t.sec);
        w.u32(t.nanosec);
        w.u8(*status as u8);
    }
}

/// Reads an `action_msgs/msg/GoalStatusArray` as `(id, accepted at, status)`, the
/// layout [`encode_status`] writes (what an action client's status subscriber sees).
///
/// # Errors
/// [`CdrError`] for a truncated or malformed message. A count larger than the bytes hold
/// fails when they run out, without allocating for it.
pub fn decode_status(buf: &[u8]) -> Result<Vec<(GoalId, Time, i8)>, CdrError> {
    let mut r = CdrReader::new(buf)?;
    let n = r.u32("status_list.size")?;
    let mut goals = Vec::new();
    for _ in 0..n {
        let id = r.fixed_bytes::<16>("status_list.goal_info.goal_id")?;
        let sec = r.i32("status_list.goal_info.stamp.sec")?;
        let nanosec = r.u32("status_list.goal_info.stamp.nanosec")?;
        let status = r.u8("status_list.status")? as i8;
        goals.push((id, Time { sec, nanosec }, status));
    }
    Ok(goals)
}

/// Writes an `action_msgs/srv/CancelGoal` response: return code (0 accepted, 2 unknown
/// goal, 3 terminated) and the goals now canceling.
pub fn encode_cancel_response(buf: &mut Vec<u8>, code: i8, canceling: &[(GoalId, Time)]) {
    let mut w = CdrWriter::new(buf);
    w.u8(code as u8);
    w.u32(canceling.len() as u32);
    for (id, t) in canceling {
        w.fixed_bytes(id);
        w.i32(t.sec);
        w.u32(t.nanosec);
    }
}

/// Writes a `CancelGoal` request for one goal (stamp zero).
pub fn encode_cancel_request(buf: &mut Vec<u8>, id: &GoalId) {
    let mut w = CdrWriter::new(buf);
    w.fixed_bytes(id);
    w.i32(0);
    w.u32(0);
}

/// Reads a `CancelGoal` response's return code.
///
/// # Errors
/// [`CdrError`].
pub fn decode_cancel_response(buf: &[u8]) -> Result<i8, CdrError> {
    Ok(CdrReader::new(buf)?.u8("return_code")? as i8)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::msgs::cdr::{decode_image, decode_odometry};

    #[test]
    fn goal_status_arrays_read_back() {
        let goals = [
            ([1; 16], Time { sec: 3, nanosec: 7 }, 2i8),
            ([9; 16], Time { sec: -1, nanosec: 0 }, 5i8),
        ];
        let mut b = Vec::new();
        encode_status(&mut b, &goals);
        assert_eq!(decode_status(&b).unwrap(), goals);
        // Two elements of 25 bytes, the second aligned to 4 for its stamp: 4 + 4 + 25 + 3 + 25.
        assert_eq!(b.len(), 61);
        assert!(decode_status(&b[..b.len() - 1]).is_err());
        let mut huge = b.clone();
        huge[4..8].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(decode_status(&huge).is_err());
        let mut empty = Vec::new();
        encode_status(&mut empty, &[]);
        assert_eq!(decode_status(&empty).unwrap(), []);
    }

    #[test]
    fn twist_layout_is_six_float64_after_the_header() {
        let mut b = Vec::new();
        Twist {
            linear_x: 0.25,
            angular_z: -0.5,
        }
        .encode(&mut b);
        assert_eq!(b.len(), 4 + 48);
        assert_eq!(&b[4..12], &0.25f64.to_le_bytes());
        assert_eq!(&b[44..52], &(-0.5f64).to_le_bytes());
        assert_eq!(
            Twist::decode(&b).unwrap(),
            Twist {
                linear_x: 0.25,
                angular_z: -0.5
            }
        );
        assert!(Twist::decode(&b[..40]).is_err());
    }

    #[test]
    fn image_and_odometry_encoders_match_the_replay_decoders() {
        let mut b = Vec::new();
        encode_image(&mut b, stamp(1_500_000_000), "cam0", 2, 1, &[1, 2, 3, 4, 5, 6]);
        let im = decode_image(&b).unwrap();
        assert_eq!((im.width, im.height, im.encoding, im.step), (2, 1, "rgb8", 6));
        assert_eq!(im.data, &[1, 2, 3, 4, 5, 6]);
        assert_eq!((im.header.stamp.sec, im.header.stamp.nanosec), (1, 500_000_000));
        let p = Pose2 {
            x: 1.0,
            y: -2.0,
            theta: 0.5,
        };
        encode_odometry(&mut b, stamp(3), p, 0.1, -0.2);
        let o = decode_odometry(&b).unwrap();
        let back = o.pose2();
        assert!((back.x - 1.0).abs() < 1e-12 && (back.y + 2.0).abs() < 1e-12 && (back.theta - 0.5).abs() < 1e-12);
        assert_eq!((o.linear[0], o.angular[2]), (0.1, -0.2));
    }

    #[test]
    fn the_action_protocols_own_messages_round_trip() {
        let id = [9u8; 16];
        let mut b = Vec::new();
        encode_send_goal_response(&mut b, true, stamp(5));
        assert!(decode_send_goal_response(&b).unwrap());
        encode_goal_id(&mut b, &id);
        assert_eq!(decode_goal_id(&b).unwrap(), id);
        encode_cancel_request(&mut b, &id);
        assert_eq!(decode_goal_id(&b).unwrap(), id);
        encode_cancel_response(&mut b, 0, &[(id, stamp(0))]);
        assert_eq!(decode_cancel_response(&b).unwrap(), 0);
        assert!(decode_goal_id(&b[..8]).is_err());
    }

    #[test]
    fn negative_durations_keep_their_value() {
        let t = stamp(-1);
        assert_eq!((t.sec, t.nanosec), (-1, 999_999_999));
    }
}
