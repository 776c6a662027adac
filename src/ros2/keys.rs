//! `rmw_zenoh`'s names on the wire: the key expression of a topic or service, the
//! liveliness tokens that make the node visible to `ros2 node list` and `ros2 topic
//! list`, and the attachment every message, request and reply carries.
//!
//! From `rmw_zenoh`'s design document:
//! * A topic or service is the key `<domain>/<name without its outer slashes>/<DDS type
//!   name>/<type hash>`, e.g. `0/cmd_vel/geometry_msgs::msg::dds_::Twist_/RIHS01_9c45…`.
//! * A liveliness token is `@ros2_lv/<domain>/<session id>/<node id>/<entity id>/<kind>/
//!   <enclave>/<namespace>/<node>[/<name>/<type>/<hash>/<qos>]`, each name mangled (`/`
//!   becomes `%`, an empty one is `%`); kinds `NN` node, `MP` publisher, `MS`
//!   subscription, `SS` service server, `SC` service client; the QoS part is
//!   [`Qos::keyexpr`]. The session id is written as `rmw_zenoh`'s `zid_to_str` writes it
//!   ([`zid_string`]).
//! * An entity's GID is XXH3-128 of its liveliness token, the low 64 bits then the high
//!   64 bits, each little-endian (`liveliness_utils.cpp`, `Entity::Entity`).
//! * The attachment is 33 bytes: the sequence number (`int64`, little-endian), the source
//!   timestamp (ns since the UNIX epoch, `int64`, little-endian), the GID's length (one
//!   byte, 16) and the 16-byte GID. A service reply repeats the request's sequence number
//!   and client GID.

use super::interfaces::Interface;
use super::qos::Qos;
use std::sync::atomic::{AtomicI64, Ordering};
use zenoh::Wait;
use zenoh::pubsub::Publisher;

/// Where the node's names live: the ROS domain and namespace, and the node's name.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NodeName {
    /// `ROS_DOMAIN_ID`.
    pub domain: u32,
    /// The namespace (`""` or `/robot1`).
    pub namespace: String,
    /// The node's name.
    pub name: String,
}

impl NodeName {
    /// The fully qualified name of a topic or service: a relative `name` is put in the
    /// namespace, an absolute one (`/cmd_vel`) is kept.
    pub fn qualify(&self, name: &str) -> String {
        if name.starts_with('/') {
            name.to_owned()
        } else {
            format!("{}/{name}", self.namespace.trim_end_matches('/'))
        }
    }

    /// The data key of the topic or service `name` of type `ty`.
    pub fn key(&self, name: &str, ty: &Interface) -> String {
        format!(
            "{}/{}/{}/{}",
            self.domain,
            self.qualify(name).trim_matches('/'),
            ty.dds_name(),
            ty.hash
        )
    }

    fn token_prefix(&self, session: &str, entity: u32, kind: &str) -> String {
        format!(
            "@ros2_lv/{}/{session}/0/{entity}/{kind}/%/{}/{}",
            self.domain,
            mangle(&self.namespace),
            mangle(&self.name)
        )
    }

    /// The node's own liveliness token; `session` is the Zenoh session id in hex.
    pub fn node_token(&self, session: &str) -> String {
        self.token_prefix(session, 0, "NN")
    }

    /// The liveliness token of entity number `entity` (1, 2 …) of kind `kind` (`MP`, `MS`,
    /// `SS`, `SC`) on `name`, with its QoS `qos`.
    pub fn entity_token(
        &self,
        session: &str,
        entity: u32,
        kind: &str,
        name: &str,
        ty: &Interface,
        qos: &Qos,
    ) -> String {
        format!(
            "{}/{}/{}/{}/{}",
            self.token_prefix(session, entity, kind),
            mangle(&self.qualify(name)),
            ty.dds_name(),
            ty.hash,
            qos.keyexpr()
        )
    }
}

/// A Zenoh session id as `rmw_zenoh` writes it in tokens (and as the prefix of a
/// transient-local publisher's cache): the id's 16 little-endian bytes from the most
/// significant down, each in lower-case hex *without* padding (`zid_to_str`), so a byte
/// 0x0a is `a`. `le_bytes` is `ZenohId::to_le_bytes`.
pub fn zid_string(le_bytes: [u8; 16]) -> String {
    let mut s = String::with_capacity(32);
    for b in le_bytes.iter().rev() {
        s.push_str(&format!("{b:x}"));
    }
    s
}

/// `/` → `%`; the empty name is `%`.
fn mangle(name: &str) -> String {
    if name.is_empty() {
        "%".to_owned()
    } else {
        name.replace('/', "%")
    }
}

/// The metadata attached to each message, request and reply.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Attachment {
    /// Counts the sender's messages (or a client's requests) from 1.
    pub sequence_number: i64,
    /// When it was sent, ns since the UNIX epoch.
    pub source_timestamp: i64,
    /// The sender's (or, on a reply, the client's) GID.
    pub gid: [u8; 16],
}

impl Attachment {
    /// The 33 bytes on the wire.
    pub fn encode(&self) -> [u8; 33] {
        let mut b = [0u8; 33];
        b[..8].copy_from_slice(&self.sequence_number.to_le_bytes());
        b[8..16].copy_from_slice(&self.source_timestamp.to_le_bytes());
        b[16] = 16;
        b[17..].copy_from_slice(&self.gid);
        b
    }

    /// Reads an attachment; `None` when it is not 33 bytes with a GID of 16.
    pub fn decode(b: &[u8]) -> Option<Self> {
        if b.len() != 33 || b[16] != 16 {
            return None;
        }
        let i64_at = |i: usize| i64::from_le_bytes(b[i..i + 8].try_into().unwrap_or_default());
        let mut gid = [0u8; 16];
        gid.copy_from_slice(&b[17..]);
        Some(Self {
            sequence_number: i64_at(0),
            source_timestamp: i64_at(8),
            gid,
        })
    }
}

/// A publisher that sends each message with `rmw_zenoh`'s attachment: its own GID (its
/// liveliness token's) and a sequence number counting its messages from 1.
pub struct RmwPublisher {
    publisher: Publisher<'static>,
    gid: [u8; 16],
    sequence: AtomicI64,
}

impl RmwPublisher {
    /// Wraps `publisher`, whose entity's GID is `gid`.
    pub fn new(publisher: Publisher<'static>, gid: [u8; 16]) -> Self {
        Self {
            publisher,
            gid,
            sequence: AtomicI64::new(0),
        }
    }

    /// Publishes `payload` (a CDR message).
    ///
    /// # Errors
    /// Zenoh's, as text.
    pub fn put(&self, payload: &[u8]) -> Result<(), String> {
        self.put_with(payload, &self.next_attachment())
    }

    /// The attachment of the next message: the sequence number counted on, now.
    pub fn next_attachment(&self) -> Attachment {
        Attachment {
            sequence_number: self.sequence.fetch_add(1, Ordering::Relaxed) + 1,
            source_timestamp: now_ns(),
            gid: self.gid,
        }
    }

    /// Publishes `payload` with `att` (from [`RmwPublisher::next_attachment`]).
    ///
    /// # Errors
    /// Zenoh's, as text.
    pub fn put_with(&self, payload: &[u8], att: &Attachment) -> Result<(), String> {
        self.publisher
            .put(payload)
            .attachment(att.encode())
            .wait()
            .map_err(|e| e.to_string())
    }

    /// The key expression it publishes on.
    pub fn key(&self) -> String {
        self.publisher.key_expr().to_string()
    }
}

/// An entity's GID as `rmw_zenoh` makes it: XXH3-128 of its liveliness token, low 64
/// bits first, each half little-endian, which is the hash's `u128` in little-endian.
/// So the GID a ROS 2 tool reads for a publisher (`ros2 topic info --verbose`) and the
/// one in its messages' attachments are the same as a `rmw_zenoh` node's would be.
pub fn gid(token: &str) -> [u8; 16] {
    xxhash_rust::xxh3::xxh3_128(token.as_bytes()).to_le_bytes()
}

/// Now, ns since the UNIX epoch.
pub fn now_ns() -> i64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos() as i64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ros2::interfaces;

    fn node(ns: &str) -> NodeName {
        NodeName {
            domain: 2,
            namespace: ns.to_owned(),
            name: "marsupial".to_owned(),
        }
    }

    #[test]
    fn keys_follow_rmw_zenoh() {
        let twist = interfaces::twist();
        assert_eq!(
            node("").key("cmd_vel", &twist),
            "2/cmd_vel/geometry_msgs::msg::dds_::Twist_/RIHS01_9c45bf16fe0983d80e3cfe750d6835843d265a9a6c46bd2e609fcddde6fb8d2a"
        );
        assert!(
            node("/robot1")
                .key("camera/image_raw", &twist)
                .starts_with("2/robot1/camera/image_raw/")
        );
        assert!(node("/robot1").key("/cmd_vel", &twist).starts_with("2/cmd_vel/"));
        // Nav2's action and service, with the hashes a Nav2 build publishes.
        let dock = interfaces::action(interfaces::DOCK_ROBOT);
        assert_eq!(
            node("").key("dock_robot/_action/send_goal", &dock.send_goal),
            "2/dock_robot/_action/send_goal/nav2_msgs::action::dds_::DockRobot_SendGoal_/\
             RIHS01_9e60155a1fb741109942c5c7dc21ae0e0db771eaf55d0cfc768bae57a95f3454"
        );
        assert_eq!(
            node("/robot1").key("docking_server/reload_database", &interfaces::reload_dock_database()),
            "2/robot1/docking_server/reload_database/nav2_msgs::srv::dds_::ReloadDockDatabase_/\
             RIHS01_3fa9aa056bcc0dfcd10dbd1f61a215f600c82db832dccfdd98e55cf27ad502e6"
        );
    }

    #[test]
    fn tokens_follow_rmw_zenoh() {
        let n = node("");
        assert_eq!(n.node_token("abc"), "@ros2_lv/2/abc/0/0/NN/%/%/marsupial");
        let t = n.entity_token("abc", 3, "MS", "odom", &interfaces::odometry(), &Qos::DEFAULT);
        assert!(t.starts_with("@ros2_lv/2/abc/0/3/MS/%/%/marsupial/%odom/nav_msgs::msg::dds_::Odometry_/RIHS01_"));
        assert!(t.ends_with("/:2:,10:,:,:,,"), "{t}");
        let r = node("/robot1").entity_token("abc", 1, "MP", "cmd_vel", &interfaces::twist(), &Qos::DEFAULT);
        assert!(r.contains("/%robot1/marsupial/%robot1%cmd_vel/"));
        let s = n.entity_token(
            "abc",
            4,
            "MP",
            "dock_robot/_action/status",
            &interfaces::goal_status_array(),
            &Qos::ACTION_STATUS,
        );
        assert!(
            s.contains("/%dock_robot%_action%status/action_msgs::msg::dds_::GoalStatusArray_/RIHS01_"),
            "{s}"
        );
        assert!(s.ends_with("/::,1:,:,:,,"), "{s}");
    }

    #[test]
    fn session_ids_are_written_as_rmw_zenoh_writes_them() {
        // Most significant byte first, each byte unpadded: 0x0a is `a`, 0x00 is `0`.
        let mut le = [0u8; 16];
        le[15] = 0x1f;
        le[14] = 0x0a;
        le[0] = 0x03;
        assert_eq!(zid_string(le), format!("1fa{}3", "0".repeat(13)));
    }

    #[test]
    fn attachments_round_trip_and_refuse_other_layouts() {
        let a = Attachment {
            sequence_number: 7,
            source_timestamp: -5,
            gid: [3; 16],
        };
        let b = a.encode();
        assert_eq!(&b[..8], &7i64.to_le_bytes());
        assert_eq!(b[16], 16);
        assert_eq!(Attachment::decode(&b), Some(a));
        assert_eq!(Attachment::decode(&b[..32]), None);
        let mut bad = b;
        bad[16] = 8;
        assert_eq!(Attachment::decode(&bad), None);
    }

    /// The expected values are XXH3-128 of the same bytes by the reference C library
    /// (xxHash 0.8.4, through PyPI's `xxhash` 4.1.0: `xxh3_128_hexdigest`, which prints the
    /// high 64 bits first), one of them a status topic's full token (221 bytes:
    /// XXH3's 129–240-byte path, where most tokens fall).
    #[test]
    fn gids_are_xxh3_128_of_the_token_as_rmw_zenoh_makes_them() {
        let le = |hex: &str| u128::from_str_radix(hex, 16).unwrap().to_le_bytes();
        assert_eq!(gid(""), le("99aa06d3014798d86001c324468d497f"));
        assert_eq!(gid("a"), le("a96faf705af16834e6c632b61e964e1f"));
        assert_eq!(
            gid("@ros2_lv/0/1a2b/0/0/NN/%/%/marsupial"),
            le("ea394436cfb1cffcc387d67e73a143df")
        );
        let status = "@ros2_lv/0/a1b2c3d4e5f60718293a4b5c6d7e8f90/0/5/MP/%/%/docking_server/\
            %dock_robot%_action%status/action_msgs::msg::dds_::GoalStatusArray_/\
            RIHS01_6c1684b00f177d37438febe6e709fc4e2b0d4248dca4854946f9ed8b30cda83e/::,1:,:,:,,";
        assert_eq!(status.len(), 221);
        assert_eq!(gid(status), le("d959a502211a189294b6fbb87dd9d536"));
        // Low half first: the first byte is the hash's least significant.
        assert_eq!(gid("")[0], 0x7f);
        assert_eq!(gid("")[8], 0xd8);
    }
}
