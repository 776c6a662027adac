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
//!   subscription, `SS` service server.
//! * The attachment is 33 bytes: the sequence number (`int64`, little-endian), the source
//!   timestamp (ns since the UNIX epoch, `int64`, little-endian), the GID's length (one
//!   byte, 16) and the 16-byte GID. A service reply repeats the request's sequence number
//!   and client GID.

use super::interfaces::Interface;
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
    /// `SS`) on `name`, with the default QoS.
    pub fn entity_token(&self, session: &str, entity: u32, kind: &str, name: &str, ty: &Interface) -> String {
        format!(
            "{}/{}/{}/{}/{DEFAULT_QOS}",
            self.token_prefix(session, entity, kind),
            mangle(&self.qualify(name)),
            ty.dds_name(),
            ty.hash
        )
    }
}

/// The QoS part of a token when every policy is `rmw_zenoh`'s default.
const DEFAULT_QOS: &str = "::,:,:,:,,";

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
        let att = Attachment {
            sequence_number: self.sequence.fetch_add(1, Ordering::Relaxed) + 1,
            source_timestamp: now_ns(),
            gid: self.gid,
        };
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

/// A GID for an entity: its liveliness token hashed (FNV-1a, 128 bits). `rmw_zenoh` uses
/// XXH3 for the same purpose; a GID only has to be unique and stable, not equal to
/// theirs.
pub fn gid(token: &str) -> [u8; 16] {
    let mut h: u128 = 0x6c62272e07bb014262b821756295c58d;
    for b in token.bytes() {
        h ^= u128::from(b);
        h = h.wrapping_mul(0x0000000001000000000000000000013B);
    }
    h.to_le_bytes()
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
    }

    #[test]
    fn tokens_follow_rmw_zenoh() {
        let n = node("");
        assert_eq!(n.node_token("abc"), "@ros2_lv/2/abc/0/0/NN/%/%/marsupial");
        let t = n.entity_token("abc", 3, "MS", "odom", &interfaces::odometry());
        assert!(t.starts_with("@ros2_lv/2/abc/0/3/MS/%/%/marsupial/%odom/nav_msgs::msg::dds_::Odometry_/RIHS01_"));
        assert!(t.ends_with("/::,:,:,:,,"));
        let r = node("/robot1").entity_token("abc", 1, "MP", "cmd_vel", &interfaces::twist());
        assert!(r.contains("/%robot1/marsupial/%robot1%cmd_vel/"));
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

    #[test]
    fn gids_differ_per_token() {
        assert_ne!(gid("a"), gid("b"));
        assert_eq!(gid("a"), gid("a"));
    }
}
