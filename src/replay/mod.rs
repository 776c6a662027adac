//! Replaying real logs (`marsupial replay`): a robot's camera frames and odometry read from
//! an MCAP file or a rosbag2 directory of them ([`bag_dir`]), run through a profile's
//! perceptual schema or its whole behavior. Chunks stored uncompressed, or compressed with
//! zstd (libmcap's and so rosbag2's default, and Foxglove's) or lz4, are read in the
//! default build, by pure-Rust decoders ([`stream`]).
//!
//! Two kinds of log are read:
//!
//! * ROS 2 bags in MCAP, as rosbag2 writes them: schema encoding `ros2msg`, message
//!   encoding `cdr`, topics of `sensor_msgs/msg/Image`, `sensor_msgs/msg/CompressedImage`
//!   and `nav_msgs/msg/Odometry` ([`crate::msgs::cdr`], [`crate::msgs::ros`]);
//! * Foxglove-schema files with JSON messages (`foxglove.RawImage`,
//!   `foxglove.CompressedImage`, `foxglove.PoseInFrame`), as `marsupial dock --record`
//!   writes them ([`foxglove`]).
//!
//! Raw frames in the encodings cameras deliver (`rgb8`, `bgr8`, `rgba8`, `bgra8`, `mono8`,
//! YUV 4:2:2 and 4:2:0, 8-bit Bayer), and JPEG or PNG compressed frames, become RGB
//! ([`crate::msgs::pixels`]); 16-bit depth and other encodings are refused by name.
//!
//! Errors come in two sizes. A fault of the file (not MCAP, truncated, compressed with an
//! unknown codec: [`log::LogFault`]) or of a bag directory ([`ReplayError::Bag`]) or of the topics asked for
//! ([`topics::TopicError`]) stops the replay with [`ReplayError`]. A message that does not
//! decode (bad CDR, unsupported encoding: [`decode::DecodeError`]) is skipped and counted by
//! topic and reason, so a half-readable topic still replays; only a topic with no usable
//! message at all is an error ([`ReplayError::Unreadable`]).
//!
//! The decoders ([`crate::msgs::cdr::decode_image`], [`foxglove::decode_raw_image`] …)
//! are pure functions over `&[u8]` that never panic, for fuzzing.

pub mod bag_dir;
pub mod decode;
pub mod foxglove;
pub mod log;
pub mod preflight;
pub mod session;
pub mod stream;
pub mod topics;

use std::path::PathBuf;
use thiserror::Error;

/// Why a replay stopped.
#[derive(Debug, Error)]
pub enum ReplayError {
    /// The log could not be read.
    #[error("{}: cannot read: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A rosbag2 directory that cannot be replayed: its `metadata.yaml` is missing or
    /// malformed, its storage is not MCAP, or a file it names is not there.
    #[error("{}: {why}", path.display())]
    Bag {
        /// The directory's `metadata.yaml`.
        path: PathBuf,
        /// What is wrong, naming the field.
        why: String,
    },
    /// The file is not a readable MCAP file, or stops being one part-way.
    #[error("{}: {fault}", path.display())]
    Log {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        fault: log::LogFault,
    },
    /// The topics asked for are not there, or none can be chosen.
    #[error("{}: {error}", path.display())]
    Topic {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        error: topics::TopicError,
    },
    /// No message of the topic could be used.
    #[error(
        "{}: topic `{topic}`: none of its {count} messages could be used; message #{first_index}: {why}",
        path.display()
    )]
    Unreadable {
        /// The file.
        path: PathBuf,
        /// The topic.
        topic: String,
        /// Its messages.
        count: u64,
        /// The first message that failed.
        first_index: u64,
        /// Why it failed (boxed: errors stay small to pass around).
        why: Box<decode::DecodeError>,
    },
    /// The image topic has no messages.
    #[error("{}: topic `{topic}` has no messages", path.display())]
    Empty {
        /// The file.
        path: PathBuf,
        /// The topic.
        topic: String,
    },
    /// A frame's size is not the profile camera's, nor of its aspect ratio (which would be
    /// rescaled to it), and what runs needs it to be.
    #[error(
        "topic `{topic}` message #{index}: frame {}×{} but the profile's camera is {}×{}, of another aspect ratio (frames of the camera's ratio are rescaled to it); the pyramid schema and the behavior work in that camera's pixels (give a profile for this camera, or replay the two-block schema alone)",
        got.0, got.1, expected.0, expected.1
    )]
    FrameSize {
        /// The topic.
        topic: String,
        /// The message.
        index: u64,
        /// Its size.
        got: (usize, usize),
        /// The profile camera's.
        expected: (usize, usize),
    },
    /// The profile cannot be replayed as asked (no perception a replay runs, no behavior).
    #[error("{0}")]
    Setup(String),
}
