//! `[robot]`: which registered robot kind runs this platform, and that kind's tuning.
//!
//! ```toml
//! [robot]
//! kind = "bujold"               # a kind registered in the catalog
//! approach = "ratio_steering"   # the rest of the table is the kind's own tuning
//! [robot.ratio_steering]
//! dead_band = 0.06
//! ```
//!
//! The generic profile keeps the table as written; the robot kind reads it into its own
//! typed tuning when the robot is built ([`RobotSpec::tuning`]), strictly, so a misspelt
//! or foreign field is an error naming its line (`behaviors::catalog`). A profile without
//! `[robot]` describes a platform that runs no behavior (perception only).

use super::fiducial::{parse_table, take_kind};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

/// The `[robot]` table (see the module docs).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RobotSpec {
    /// The robot kind's registered name.
    pub kind: String,
    /// The table as written, less `kind`: the kind's tuning.
    pub tuning: toml::Table,
}

impl RobotSpec {
    /// The kind's tuning as its type `T`.
    ///
    /// # Errors
    /// The field path (from the profile's root, `robot.ratio_steering.dead_band`) and the
    /// deserializer's message.
    pub fn tuning<T: DeserializeOwned>(&self) -> Result<T, (String, String)> {
        parse_table(&self.tuning).map_err(|(path, message)| {
            let path = if path.is_empty() {
                "robot".to_string()
            } else {
                format!("robot.{path}")
            };
            (path, message)
        })
    }
}

impl Serialize for RobotSpec {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut t = toml::Table::new();
        t.insert("kind".into(), toml::Value::String(self.kind.clone()));
        t.extend(self.tuning.clone());
        t.serialize(s)
    }
}

impl<'de> Deserialize<'de> for RobotSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let mut tuning = toml::Table::deserialize(d)?;
        let kind = take_kind(&mut tuning, "the robot kind (one a catalog registers)")?;
        Ok(Self { kind, tuning })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Deserialize, PartialEq)]
    #[serde(deny_unknown_fields)]
    struct Gains {
        gain: f64,
    }

    #[test]
    fn the_tuning_is_read_strictly_with_its_path() {
        let spec: RobotSpec = "kind = 'toy'\ngain = 2.0"
            .parse::<toml::Table>()
            .unwrap()
            .try_into()
            .unwrap();
        assert_eq!(spec.kind, "toy");
        assert_eq!(spec.tuning::<Gains>().unwrap(), Gains { gain: 2.0 });
        let bad: RobotSpec = "kind = 'toy'\ngian = 2.0"
            .parse::<toml::Table>()
            .unwrap()
            .try_into()
            .unwrap();
        let (path, message) = bad.tuning::<Gains>().unwrap_err();
        assert_eq!(path, "robot.gian", "the path names the field, so its line is found");
        assert!(message.contains("gian"), "{message}");
    }
}
