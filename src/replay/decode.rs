//! One logged message to what perception and the loop take: a frame (RGB pixels and
//! stamp) or an odometry reading, whatever the topic's schema.

use super::foxglove;
use super::topics::TopicKind;
use crate::geometry::Twist;
use crate::msgs::cdr;
use crate::perception::RgbImage;
use crate::schemas::OdometryReading;
use thiserror::Error;

/// Why one message could not be used.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum DecodeError {
    /// The CDR bytes do not parse.
    #[error("CDR does not parse: {0}")]
    Cdr(#[from] cdr::CdrError),
    /// The Foxglove JSON does not parse.
    #[error("{0}")]
    Foxglove(#[from] foxglove::FoxgloveError),
    /// The pixels cannot become an RGB frame.
    #[error("{0}")]
    Pixels(#[from] crate::msgs::pixels::PixelError),
    /// An odometry message handed to the frame decoder or the reverse.
    #[error("a {0:?} message is not what was asked for")]
    Kind(TopicKind),
}

impl DecodeError {
    /// A short, stable name for the reason (`cdr`, `json`, `unsupported_encoding` …), to
    /// group skipped messages by.
    pub fn reason(&self) -> &'static str {
        use crate::msgs::pixels::PixelError as P;
        match self {
            DecodeError::Cdr(_) => "cdr",
            DecodeError::Foxglove(_) => "json",
            DecodeError::Pixels(P::Unsupported { .. }) => "unsupported_encoding",
            DecodeError::Pixels(
                P::Size { .. } | P::Sides { .. } | P::Buffer { .. } | P::Frame { .. } | P::Aspect { .. },
            ) => "bad_size",
            DecodeError::Pixels(P::Decode { .. }) => "undecodable_image",
            DecodeError::Kind(_) => "kind",
        }
    }
}

/// A decoded camera frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Frame {
    /// Capture stamp from the message, ns (`None`: the message has none).
    pub stamp_ns: Option<u64>,
    /// The pixels.
    pub image: RgbImage,
}

/// A decoded odometry message.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OdomSample {
    /// Stamp from the message, ns (`None`: the message has none).
    pub stamp_ns: Option<u64>,
    /// Pose in the odometry frame and body twist (zero for a pose-only message).
    pub reading: OdometryReading,
}

/// Decodes a frame from a message of an image topic of `kind`.
///
/// # Errors
/// [`DecodeError`].
pub fn frame(kind: TopicKind, data: &[u8]) -> Result<Frame, DecodeError> {
    match kind {
        TopicKind::RosImage => {
            let m = cdr::decode_image(data)?;
            Ok(Frame {
                stamp_ns: m.header.stamp.ns(),
                image: m.to_rgb()?,
            })
        }
        TopicKind::RosCompressedImage => {
            let m = cdr::decode_compressed_image(data)?;
            Ok(Frame {
                stamp_ns: m.header.stamp.ns(),
                image: m.to_rgb()?,
            })
        }
        TopicKind::FoxgloveRawImage => {
            let m = foxglove::decode_raw_image(data)?;
            Ok(Frame {
                stamp_ns: m.timestamp.ns(),
                image: m.to_rgb()?,
            })
        }
        TopicKind::FoxgloveCompressedImage => {
            let m = foxglove::decode_compressed_image(data)?;
            Ok(Frame {
                stamp_ns: m.timestamp.ns(),
                image: m.to_rgb()?,
            })
        }
        k => Err(DecodeError::Kind(k)),
    }
}

/// Decodes an odometry reading from a message of an odometry topic of `kind`.
///
/// # Errors
/// [`DecodeError`].
pub fn odometry(kind: TopicKind, data: &[u8]) -> Result<OdomSample, DecodeError> {
    match kind {
        TopicKind::RosOdometry => {
            let m = cdr::decode_odometry(data)?;
            Ok(OdomSample {
                stamp_ns: m.header.stamp.ns(),
                reading: OdometryReading {
                    pose: m.pose2(),
                    twist: m.twist(),
                },
            })
        }
        TopicKind::FoxglovePose => {
            let m = foxglove::decode_pose_in_frame(data)?;
            Ok(OdomSample {
                stamp_ns: m.timestamp.ns(),
                reading: OdometryReading {
                    pose: m.pose2(),
                    twist: Twist::default(),
                },
            })
        }
        k => Err(DecodeError::Kind(k)),
    }
}
