//! Which topics of a log a replay reads: each channel's kind from its schema name and
//! message encoding, and the choice of the image and odometry topics.

use std::collections::BTreeMap;
use thiserror::Error;

/// What a topic carries, for a replay.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TopicKind {
    /// `sensor_msgs/msg/Image`, CDR.
    RosImage,
    /// `sensor_msgs/msg/CompressedImage`, CDR.
    RosCompressedImage,
    /// `nav_msgs/msg/Odometry`, CDR.
    RosOdometry,
    /// `foxglove.RawImage`, JSON.
    FoxgloveRawImage,
    /// `foxglove.CompressedImage`, JSON.
    FoxgloveCompressedImage,
    /// `foxglove.PoseInFrame`, JSON (our recorder's `/odometry`).
    FoxglovePose,
}

impl TopicKind {
    /// Camera frames.
    pub fn is_image(self) -> bool {
        !self.is_odometry()
    }

    /// Odometry.
    pub fn is_odometry(self) -> bool {
        matches!(self, TopicKind::RosOdometry | TopicKind::FoxglovePose)
    }
}

/// A topic of the log: its schema name and message encoding, as logged.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct TopicInfo {
    /// The topic.
    pub topic: String,
    /// The schema's name (`sensor_msgs/msg/Image`), empty without a schema.
    pub schema: String,
    /// The message encoding (`cdr`, `json` …).
    pub encoding: String,
}

impl std::fmt::Display for TopicInfo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} ({}, {})", self.topic, self.schema, self.encoding)
    }
}

/// The kind of a topic with `schema` and message `encoding`: `Ok(None)` for a topic a
/// replay does not read, `Err` with why for an image or odometry topic in an encoding it
/// cannot read (ROS 1, protobuf …).
pub fn classify(schema: &str, encoding: &str) -> Result<Option<TopicKind>, String> {
    let (kind, want) = match schema {
        "sensor_msgs/msg/Image" => (TopicKind::RosImage, "cdr"),
        "sensor_msgs/msg/CompressedImage" => (TopicKind::RosCompressedImage, "cdr"),
        "nav_msgs/msg/Odometry" => (TopicKind::RosOdometry, "cdr"),
        "foxglove.RawImage" => (TopicKind::FoxgloveRawImage, "json"),
        "foxglove.CompressedImage" => (TopicKind::FoxgloveCompressedImage, "json"),
        "foxglove.PoseInFrame" => (TopicKind::FoxglovePose, "json"),
        "sensor_msgs/Image" | "sensor_msgs/CompressedImage" | "nav_msgs/Odometry" => {
            return Err(format!(
                "`{schema}` in `{encoding}` is a ROS 1 message; only ROS 2 (CDR) bags are read"
            ));
        }
        _ => return Ok(None),
    };
    if encoding == want {
        Ok(Some(kind))
    } else {
        Err(format!(
            "`{schema}` in message encoding `{encoding}`: only `{want}` is read"
        ))
    }
}

/// Why the topics asked for (or the one to pick) are not in the log.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum TopicError {
    /// `--image-topic`/`--odom-topic` names a topic the log does not have.
    #[error("no topic `{topic}` in the log; its topics: {}", list(available))]
    Missing {
        /// The topic asked for.
        topic: String,
        /// The log's topics.
        available: Vec<TopicInfo>,
    },
    /// The topic exists but is not of the kind asked for, or in an encoding not read.
    #[error("topic `{topic}` cannot be read as an {wanted} topic: {why}")]
    WrongKind {
        /// The topic.
        topic: String,
        /// `image` or `odometry`.
        wanted: &'static str,
        /// Why.
        why: String,
    },
    /// No topic of the kind, and none named.
    #[error("no {wanted} topic in the log; its topics: {}", list(available))]
    None {
        /// `image` or `odometry`.
        wanted: &'static str,
        /// The log's topics.
        available: Vec<TopicInfo>,
    },
    /// Several topics of the kind, and none named.
    #[error("several {wanted} topics, choose one with {flag}: {}", list(candidates))]
    Ambiguous {
        /// `image` or `odometry`.
        wanted: &'static str,
        /// The option that chooses.
        flag: &'static str,
        /// The candidates.
        candidates: Vec<TopicInfo>,
    },
}

fn list(t: &[TopicInfo]) -> String {
    if t.is_empty() {
        return "none".into();
    }
    t.iter().map(ToString::to_string).collect::<Vec<_>>().join(", ")
}

/// The log's topics by name (sorted, so listings are stable).
pub type Topics = BTreeMap<String, TopicInfo>;

/// Picks the topic to read: `named` if given (it must exist and be of the kind), else the
/// only topic of the kind. With `optional`, no topic of the kind is `Ok(None)`.
///
/// # Errors
/// [`TopicError`].
pub fn choose(
    topics: &Topics,
    named: Option<&str>,
    odometry: bool,
    optional: bool,
) -> Result<Option<(String, TopicKind)>, TopicError> {
    let (wanted, flag) = if odometry {
        ("odometry", "--odom-topic")
    } else {
        ("image", "--image-topic")
    };
    let fits = |k: TopicKind| if odometry { k.is_odometry() } else { k.is_image() };
    let available = || topics.values().cloned().collect::<Vec<_>>();
    if let Some(name) = named {
        let Some(info) = topics.get(name) else {
            return Err(TopicError::Missing {
                topic: name.to_string(),
                available: available(),
            });
        };
        let wrong = |why: String| TopicError::WrongKind {
            topic: name.to_string(),
            wanted,
            why,
        };
        return match classify(&info.schema, &info.encoding) {
            Ok(Some(k)) if fits(k) => Ok(Some((name.to_string(), k))),
            Ok(_) => Err(wrong(format!("its schema is `{}`", info.schema))),
            Err(why) => Err(wrong(why)),
        };
    }
    let candidates: Vec<(&TopicInfo, TopicKind)> = topics
        .values()
        .filter_map(|t| match classify(&t.schema, &t.encoding) {
            Ok(Some(k)) if fits(k) => Some((t, k)),
            _ => None,
        })
        .collect();
    match candidates.as_slice() {
        [(t, k)] => Ok(Some((t.topic.clone(), *k))),
        [] if optional => Ok(None),
        [] => Err(TopicError::None {
            wanted,
            available: available(),
        }),
        _ => Err(TopicError::Ambiguous {
            wanted,
            flag,
            candidates: candidates.iter().map(|(t, _)| (*t).clone()).collect(),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn topics(list: &[(&str, &str, &str)]) -> Topics {
        list.iter()
            .map(|(t, s, e)| {
                (
                    t.to_string(),
                    TopicInfo {
                        topic: t.to_string(),
                        schema: s.to_string(),
                        encoding: e.to_string(),
                    },
                )
            })
            .collect()
    }

    #[test]
    fn picks_the_only_image_topic_or_lists_candidates() {
        let one = topics(&[
            ("/cam", "sensor_msgs/msg/Image", "cdr"),
            ("/odom", "nav_msgs/msg/Odometry", "cdr"),
        ]);
        assert_eq!(choose(&one, None, false, false).unwrap().unwrap().0, "/cam");
        assert_eq!(choose(&one, None, true, true).unwrap().unwrap().0, "/odom");
        let two = topics(&[
            ("/a", "sensor_msgs/msg/Image", "cdr"),
            ("/b", "sensor_msgs/msg/CompressedImage", "cdr"),
        ]);
        let e = choose(&two, None, false, false).unwrap_err();
        assert!(e.to_string().contains("/a (") && e.to_string().contains("/b ("), "{e}");
        assert_eq!(choose(&two, None, true, true), Ok(None));
        assert!(matches!(
            choose(&two, Some("/c"), false, false),
            Err(TopicError::Missing { .. })
        ));
        assert!(matches!(
            choose(&one, Some("/odom"), false, false),
            Err(TopicError::WrongKind { .. })
        ));
        let pb = topics(&[("/cam", "foxglove.RawImage", "protobuf")]);
        let e = choose(&pb, Some("/cam"), false, false).unwrap_err();
        assert!(e.to_string().contains("protobuf"), "{e}");
    }
}
