//! The robot's hardware as ROS 2 topics: a [`Camera`] fed by a `sensor_msgs` image topic,
//! an [`Odometer`] fed by `nav_msgs/msg/Odometry`, and a [`Drive`] that publishes
//! `geometry_msgs/msg/Twist` on `cmd_vel`. They implement the same traits a hand-written
//! driver does, so the node runs the threaded runtime unchanged: its staleness limits,
//! safe stops, watchdog and typed outcomes are the ones every robot gets.
//!
//! Each subscription's callback (on Zenoh's threads) only stores the latest payload; the
//! device decodes it when the runtime asks, so a slow decode never backs Zenoh up. The
//! payload is kept as Zenoh's own reference-counted buffer, not copied: storing one costs
//! no allocation, and a payload that arrived in one piece (every frame that was not
//! fragmented on the wire) is decoded in place.

use super::keys::{RmwPublisher, now_ns};
use crate::kinematics::DriveCommand;
use crate::msgs::camera_frame::{CameraBytes, FrameDecoder};
use crate::msgs::cdr::{decode_compressed_image, decode_image, decode_odometry};
use crate::perception::RgbImage;
use crate::robot::{Camera, Drive, Exposure, HardwareError, Odometer};
use crate::schemas::OdometryReading;
use std::sync::{Arc, Condvar, Mutex};
use std::time::Duration;
use zenoh::Wait;
use zenoh::bytes::ZBytes;
use zenoh::pubsub::Subscriber;

/// The latest payload of a topic, and a condition to wait on for a new one.
#[derive(Default)]
pub(super) struct LatestPayload {
    slot: Mutex<Option<ZBytes>>,
    arrived: Condvar,
}

impl LatestPayload {
    /// Keeps `payload` (a reference to Zenoh's buffer: no copy, no allocation), replacing
    /// an unread one.
    pub(super) fn put(&self, payload: ZBytes) {
        if let Ok(mut s) = self.slot.lock() {
            *s = Some(payload);
            self.arrived.notify_all();
        }
    }

    /// The unread payload, waiting up to `wait` for one.
    /// Its bytes are `to_bytes()`: borrowed when the payload is one contiguous slice.
    pub(super) fn take(&self, wait: Duration) -> Option<ZBytes> {
        let s = self.slot.lock().ok()?;
        let (mut s, _) = self.arrived.wait_timeout_while(s, wait, |s| s.is_none()).ok()?;
        s.take()
    }
}

/// Subscribes `key` into a [`LatestPayload`].
///
/// # Errors
/// Zenoh's, as text.
pub(super) fn subscribe(session: &zenoh::Session, key: &str) -> Result<(Arc<LatestPayload>, Subscriber<()>), String> {
    let latest = Arc::new(LatestPayload::default());
    let sink = latest.clone();
    let sub = session
        .declare_subscriber(key.to_owned())
        .callback(move |sample| sink.put(sample.payload().clone()))
        .wait()
        .map_err(|e| e.to_string())?;
    Ok((latest, sub))
}

/// Which image message a camera topic carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageKind {
    /// `sensor_msgs/msg/Image` (`rgb8`, `bgr8`, `mono8`, `yuyv`, `uyvy`, `nv12`, Bayer …).
    Raw,
    /// `sensor_msgs/msg/CompressedImage` (JPEG, so an MJPEG camera's frames, or PNG).
    Compressed,
}

/// A camera whose frames come from a ROS 2 image topic.
pub struct TopicCamera {
    topic: String,
    kind: ImageKind,
    size: (usize, usize),
    frames: Arc<LatestPayload>,
    wait: Duration,
    trust_stamps: bool,
    decoder: FrameDecoder,
    _sub: Subscriber<()>,
}

impl TopicCamera {
    /// A camera of `size` (the profile's) on `topic`, subscribed with `frames`. Frames of
    /// another size with the profile camera's aspect ratio are rescaled to `size`
    /// ([`crate::msgs::rescale`]: the profile's intrinsics then hold).
    /// `capture` waits up to `wait` for a frame. With `trust_stamps`, a frame's age is
    /// its header stamp's distance from this machine's clock (ROS stamps in wall time, with
    /// clocks kept in sync); without, frames are stamped on arrival.
    pub(super) fn new(
        topic: String,
        kind: ImageKind,
        size: (usize, usize),
        (frames, sub): (Arc<LatestPayload>, Subscriber<()>),
        wait: Duration,
        trust_stamps: bool,
    ) -> Self {
        Self {
            topic,
            kind,
            size,
            frames,
            wait,
            trust_stamps,
            decoder: FrameDecoder::new(),
            _sub: sub,
        }
    }

    fn fault(&self, detail: String) -> HardwareError {
        fault(&self.topic, detail)
    }
}

impl Camera for TopicCamera {
    fn resolution(&self) -> (usize, usize) {
        self.size
    }

    fn capture(&mut self, frame: &mut RgbImage) -> Result<Exposure, HardwareError> {
        let Some(payload) = self.frames.take(self.wait) else {
            return Err(HardwareError::NotReady);
        };
        let payload = payload.to_bytes();
        // Decoded straight into the loop's frame, or rescaled into it from the decoder's
        // buffer when the camera runs another mode of the profile camera's aspect ratio.
        // A frame that cannot be used (an encoding not read, a truncated JPEG, another
        // aspect ratio) is a fault naming the topic: the runtime reports it and the loop
        // goes on without that frame, as for a missing one.
        let stamp = match self.kind {
            ImageKind::Raw => {
                let im = decode_image(&payload).map_err(|e| self.fault(e.to_string()))?;
                let bytes = CameraBytes::Raw {
                    width: im.width,
                    height: im.height,
                    encoding: im.encoding,
                    step: im.step,
                    data: im.data,
                };
                self.decoder
                    .decode_into(bytes, frame)
                    .map_err(|e| fault(&self.topic, e.to_string()))?;
                im.header.stamp
            }
            ImageKind::Compressed => {
                let im = decode_compressed_image(&payload).map_err(|e| self.fault(e.to_string()))?;
                let bytes = CameraBytes::Compressed {
                    format: im.format,
                    data: im.data,
                };
                self.decoder
                    .decode_into(bytes, frame)
                    .map_err(|e| fault(&self.topic, e.to_string()))?;
                im.header.stamp
            }
        };
        let age = match stamp.ns() {
            Some(ns) if self.trust_stamps => {
                let age = now_ns() - ns as i64;
                Duration::from_nanos(age.max(0) as u64)
            }
            _ => Duration::ZERO,
        };
        Ok(Exposure::ago(age))
    }
}

/// A fault of the camera on `topic`.
fn fault(topic: &str, detail: String) -> HardwareError {
    HardwareError::Fault {
        device: format!("camera on {topic}"),
        detail,
    }
}

/// An odometer fed by a `nav_msgs/msg/Odometry` topic. A read with no new message since
/// the last is [`HardwareError::NotReady`], so a silent publisher goes stale.
pub struct TopicOdometer {
    topic: String,
    odometry: Arc<LatestPayload>,
    _sub: Subscriber<()>,
}

impl TopicOdometer {
    pub(super) fn new(topic: String, (odometry, sub): (Arc<LatestPayload>, Subscriber<()>)) -> Self {
        Self {
            topic,
            odometry,
            _sub: sub,
        }
    }
}

impl Odometer for TopicOdometer {
    fn read(&mut self) -> Result<OdometryReading, HardwareError> {
        let Some(payload) = self.odometry.take(Duration::ZERO) else {
            return Err(HardwareError::NotReady);
        };
        let payload = payload.to_bytes();
        let o = decode_odometry(&payload).map_err(|e| HardwareError::Fault {
            device: format!("odometry on {}", self.topic),
            detail: e.to_string(),
        })?;
        Ok(OdometryReading {
            pose: o.pose2(),
            twist: o.twist(),
        })
    }
}

/// A base driven by `geometry_msgs/msg/Twist` on `cmd_vel`.
pub struct TwistDrive {
    out: RmwPublisher,
    buf: Vec<u8>,
}

impl TwistDrive {
    pub(super) fn new(out: RmwPublisher) -> Self {
        Self {
            out,
            buf: Vec::with_capacity(64),
        }
    }
}

impl Drive for TwistDrive {
    fn apply(&mut self, command: &DriveCommand) -> Result<(), HardwareError> {
        let t = command.to_twist();
        super::messages::Twist {
            linear_x: t.v,
            angular_z: t.omega,
        }
        .encode(&mut self.buf);
        self.out.put(&self.buf).map_err(|detail| HardwareError::Fault {
            device: "cmd_vel".to_owned(),
            detail,
        })
    }
}

/// The drive command a base that receives `twist` on `cmd_vel` executes: a twist with no
/// turn is a straight drive, one with no speed a turn in place, and zero a stop, so a
/// turn-or-drive base (Bujold's) gets exactly the commands the behaviors realised.
pub fn command_of(twist: super::messages::Twist) -> DriveCommand {
    match (twist.linear_x == 0.0, twist.angular_z == 0.0) {
        (true, true) => DriveCommand::Stop,
        (true, false) => DriveCommand::Turn { omega: twist.angular_z },
        (false, true) => DriveCommand::Straight { v: twist.linear_x },
        (false, false) => DriveCommand::Twist(crate::geometry::Twist::new(twist.linear_x, twist.angular_z)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ros2::messages::Twist;

    #[test]
    fn twists_become_the_commands_they_came_from() {
        for cmd in [
            DriveCommand::Stop,
            DriveCommand::Turn { omega: -0.3 },
            DriveCommand::Straight { v: 0.2 },
            DriveCommand::Twist(crate::geometry::Twist::new(0.1, 0.4)),
        ] {
            let t = cmd.to_twist();
            assert_eq!(
                command_of(Twist {
                    linear_x: t.v,
                    angular_z: t.omega
                }),
                cmd
            );
        }
    }

    #[test]
    fn the_latest_payload_wins_and_is_taken_once() {
        let l = LatestPayload::default();
        assert!(l.take(Duration::ZERO).is_none());
        l.put(ZBytes::from(vec![1u8]));
        l.put(ZBytes::from(vec![2u8]));
        let taken = l.take(Duration::ZERO).map(|p| p.to_bytes().into_owned());
        assert_eq!(taken, Some(vec![2]));
        assert!(l.take(Duration::from_millis(1)).is_none());
    }
}
