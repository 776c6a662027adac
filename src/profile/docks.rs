//! `[[docks]]`: the docks a robot may be sent to, the profile's part of its dock database.
//!
//! Each entry is a Nav2 dock-database entry (an id, a type, a frame and a pose), so a
//! `DockRobot` goal can name a dock by `dock_id` and the robot starts from its pose:
//!
//! ```toml
//! [[docks]]
//! id = "home"              # what a goal's dock_id names
//! type = "bujold"          # optional: the profile's name (the behavior that docks here)
//! frame = "odom"           # optional: the odometry frame
//! pose = [1.5, 0.2, 3.14]  # optional: x, y (m), yaw (rad) of the entrance, +x out along its axis
//! ```
//!
//! A profile without `[[docks]]` has one dock, its own, whose id and type are the
//! profile's name and whose pose is unknown (the robot is taken to be within sight of
//! it). The ROS 2 node adds the docks of a Nav2 dock-database file to these
//! (`marsupial::ros2::dock_db`).

use crate::config::Validator;
use serde::{Deserialize, Serialize};

/// One `[[docks]]` entry (see the module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DockEntry {
    /// The dock's id, unique in the profile (a goal's `dock_id`).
    pub id: String,
    /// The dock's type: the behavior that docks at it; absent, the profile's name.
    #[serde(rename = "type", default, skip_serializing_if = "Option::is_none")]
    pub dock_type: Option<String>,
    /// The frame of `pose`; absent, the odometry frame.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frame: Option<String>,
    /// The entrance's pose `[x, y, yaw]` (m, m, rad), +x out along the dock's axis;
    /// absent when not known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pose: Option<[f64; 3]>,
}

/// Checks `[[docks]]`: ids present and unique, names not blank, poses finite.
pub(super) fn validate_docks(docks: &[DockEntry], v: &mut Validator<'_>) {
    for (i, d) in docks.iter().enumerate() {
        let at = |field: &str| format!("docks[{i}].{field}");
        v.require(!d.id.trim().is_empty(), &at("id"), || {
            "expected a non-empty dock id".into()
        });
        if let Some(first) = docks[..i].iter().position(|o| o.id == d.id) {
            v.problem(&at("id"), format!("dock id `{}` is already docks[{first}]'s", d.id));
        }
        for (field, value) in [("type", &d.dock_type), ("frame", &d.frame)] {
            if let Some(s) = value {
                v.require(!s.trim().is_empty(), &at(field), || {
                    format!("expected a non-empty {field}, or no `{field}` for the default")
                });
            }
        }
        if let Some(p) = d.pose {
            v.require(p.iter().all(|x| x.is_finite()), &at("pose"), || {
                format!("expected three finite numbers [x, y, yaw], got {p:?}")
            });
        }
    }
}
