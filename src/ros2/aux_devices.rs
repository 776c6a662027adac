//! The profile's `[[sensors]]` and `[[actuators]]` as ROS 2 topics: the dock contact
//! switch read from a `std_msgs/msg/Bool`, and `posture`, `dock_guides`
//! (`std_msgs/msg/String`: `raised`/`lowered`, `open`/`closed`) and `lights`
//! (`std_msgs/msg/Bool`) published. A kind with no standard message (the tether reel, the
//! arm, a user's kinds) is unbridged: it reads nothing and its commands go nowhere,
//! so a profile that requires such a sensor stays in its safe stop on the node.

use super::devices::LatestPayload;
use super::keys::RmwPublisher;
use crate::robot::{Actuator, HardwareError, Sensor};
use crate::schemas::{DeviceCommand, DeviceReading, DockContact, Guides, Lights, Posture};
use std::sync::Arc;
use std::time::Duration;

/// A `std_msgs/msg/String`.
pub fn encode_string(s: &str) -> Vec<u8> {
    let mut buf = Vec::new();
    crate::msgs::cdr::CdrWriter::new(&mut buf).string(s);
    buf
}

/// A `std_msgs/msg/Bool`.
pub fn encode_bool(b: bool) -> Vec<u8> {
    let mut buf = Vec::new();
    crate::msgs::cdr::CdrWriter::new(&mut buf).u8(u8::from(b));
    buf
}

/// The message for a posture command.
pub(super) fn posture_message(values: &[f64]) -> Option<Vec<u8>> {
    Posture::decode(values).map(|p| {
        encode_string(match p {
            Posture::Raised => "raised",
            Posture::Lowered => "lowered",
        })
    })
}

/// The message for a guides command.
pub(super) fn guides_message(values: &[f64]) -> Option<Vec<u8>> {
    Guides::decode(values).map(|g| {
        encode_string(match g {
            Guides::Open => "open",
            Guides::Closed => "closed",
        })
    })
}

/// The message for a lights command.
pub(super) fn lights_message(values: &[f64]) -> Option<Vec<u8>> {
    Lights::decode(values).map(|l| encode_bool(l.0))
}

/// Encodes a command's values as its topic's message; `None` when they are not one.
pub(super) type Encode = fn(&[f64]) -> Option<Vec<u8>>;

/// An actuator published as a topic, each command encoded by `encode`.
pub(super) struct AuxTopic {
    pub(super) publisher: RmwPublisher,
    pub(super) encode: Encode,
}

impl Actuator for AuxTopic {
    fn apply(&mut self, values: &[f64]) -> Result<(), HardwareError> {
        let payload = (self.encode)(values).ok_or_else(|| HardwareError::Fault {
            device: self.publisher.key(),
            detail: format!("not a command for this topic: {values:?}"),
        })?;
        self.publisher.put(&payload).map_err(|detail| HardwareError::Fault {
            device: self.publisher.key(),
            detail,
        })
    }
}

/// The dock switch as a `std_msgs/msg/Bool` topic. A read with no new message since the
/// last is [`HardwareError::NotReady`], so a switch that stops publishing goes stale.
pub(super) struct TopicSwitch {
    pub(super) topic: String,
    pub(super) latest: Arc<LatestPayload>,
    pub(super) _sub: zenoh::pubsub::Subscriber<()>,
}

impl Sensor for TopicSwitch {
    fn read(&mut self, values: &mut Vec<f64>) -> Result<(), HardwareError> {
        let Some(p) = self.latest.take(Duration::ZERO) else {
            return Err(HardwareError::NotReady);
        };
        let p = p.to_bytes();
        let mut r = crate::msgs::cdr::CdrReader::new(&p).map_err(|e| self.fault(e))?;
        DockContact(r.u8("data").map_err(|e| self.fault(e))? != 0).encode(values);
        Ok(())
    }
}

impl TopicSwitch {
    fn fault(&self, e: impl std::fmt::Display) -> HardwareError {
        HardwareError::Fault {
            device: format!("dock switch on {}", self.topic),
            detail: e.to_string(),
        }
    }
}

/// A declared device the bridge has no topic for: reads nothing, takes every command.
pub(super) struct Unbridged;

impl Sensor for Unbridged {
    fn read(&mut self, _values: &mut Vec<f64>) -> Result<(), HardwareError> {
        Err(HardwareError::NotReady)
    }
}

impl Actuator for Unbridged {
    fn apply(&mut self, _values: &[f64]) -> Result<(), HardwareError> {
        Ok(())
    }
}
