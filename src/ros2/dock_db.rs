//! The node's dock database: the docks a `DockRobot` goal may name by `dock_id`, and
//! what `ReloadDockDatabase` reads.
//!
//! It starts with the profile's `[[docks]]` ([`crate::profile::docks`]): each with its
//! id, its type (the profile's name unless given), its frame (the odometry frame unless
//! given) and its pose when known. A profile without `[[docks]]` has one dock, id and
//! type its name, in the odometry frame, pose unknown (the robot is taken to be within
//! sight of it). `--dock-database` at start and `ReloadDockDatabase` while running read
//! a file in the shape of Nav2's dock-database YAML, restricted to what the node can use:
//!
//! ```yaml
//! docks:
//!   home:                  # the dock's id
//!     type: bujold         # optional: the profile's type; another type is not valid
//!     frame: odom          # optional, default `map` (Nav2's); only the odometry frame resolves
//!     pose: [1.5, 0.2, 3.14]   # x, y (m), yaw (rad) of the entrance, +x out along its axis
//! ```
//!
//! Comments (`#` to the end of a line), quotes around values and blank lines are allowed;
//! any other key, a dock without a pose, a pose that is not three finite numbers, or a
//! file without `docks:` is an error naming the line and the key. Unlike Nav2's reload,
//! which replaces the database, the file's docks are added to the profile's (a dock of
//! the same id replaced), so a file cannot lose the docks the profile declares.

use crate::geometry::Pose2;
use crate::profile::Profile;
use std::path::Path;
use thiserror::Error;

/// One dock.
#[derive(Debug, Clone, PartialEq)]
pub struct Dock {
    /// Its id (`dock_id` in a goal).
    pub id: String,
    /// Its type: the behavior that docks at it (the profile's name).
    pub dock_type: String,
    /// The frame its pose is in.
    pub frame: String,
    /// Where its entrance is (+x out along its axis); `None` when not known.
    pub pose: Option<Pose2>,
}

/// Why a dock database file was refused.
#[derive(Debug, Error, PartialEq)]
pub enum DockDbError {
    /// The file could not be read.
    #[error("dock database `{path}`: {why}")]
    Read {
        /// The file.
        path: String,
        /// Why.
        why: String,
    },
    /// A line does not fit the format.
    #[error("dock database line {line}: {why}")]
    Format {
        /// 1-based.
        line: usize,
        /// What is wrong, naming the key.
        why: String,
    },
}

/// The docks the node knows.
#[derive(Debug, Clone, PartialEq)]
pub struct DockDatabase {
    /// The profile's docks first, then a file's in its order (a dock of a taken id
    /// replaced in place).
    pub docks: Vec<Dock>,
}

impl DockDatabase {
    /// The docks `profile` declares in `[[docks]]` (or its one dock, see the module
    /// docs), a frame not given being `odom_frame`.
    pub fn for_profile(profile: &Profile, odom_frame: &str) -> Self {
        let docks = if profile.docks.is_empty() {
            vec![Dock {
                id: profile.name.clone(),
                dock_type: profile.name.clone(),
                frame: odom_frame.to_owned(),
                pose: None,
            }]
        } else {
            profile
                .docks
                .iter()
                .map(|d| Dock {
                    id: d.id.clone(),
                    dock_type: d.dock_type.clone().unwrap_or_else(|| profile.name.clone()),
                    frame: d.frame.clone().unwrap_or_else(|| odom_frame.to_owned()),
                    pose: d.pose.map(|[x, y, theta]| Pose2 { x, y, theta }),
                })
                .collect()
        };
        Self { docks }
    }

    /// The dock `id`.
    pub fn get(&self, id: &str) -> Option<&Dock> {
        self.docks.iter().find(|d| d.id == id)
    }

    /// The ids, for a message naming what the database holds.
    pub fn ids(&self) -> String {
        let ids: Vec<&str> = self.docks.iter().map(|d| d.id.as_str()).collect();
        ids.join(", ")
    }

    /// This database with the docks of the file at `path` added (a dock of the same id
    /// replaced); a dock without `type` gets `default_type`.
    ///
    /// # Errors
    /// [`DockDbError`]; the database is then unchanged.
    pub fn reloaded(&self, path: &Path, default_type: &str) -> Result<Self, DockDbError> {
        let text = std::fs::read_to_string(path).map_err(|e| DockDbError::Read {
            path: path.display().to_string(),
            why: e.to_string(),
        })?;
        let mut db = self.clone();
        for dock in parse(&text, default_type)? {
            match db.docks.iter_mut().find(|d| d.id == dock.id) {
                Some(d) => *d = dock,
                None => db.docks.push(dock),
            }
        }
        Ok(db)
    }
}

fn unquote(v: &str) -> &str {
    let v = v.trim();
    v.strip_prefix('"')
        .and_then(|x| x.strip_suffix('"'))
        .or_else(|| v.strip_prefix('\'').and_then(|x| x.strip_suffix('\'')))
        .unwrap_or(v)
}

fn pose(line: usize, v: &str) -> Result<Pose2, DockDbError> {
    let bad = |why: String| DockDbError::Format { line, why };
    let inner = v
        .trim()
        .strip_prefix('[')
        .and_then(|x| x.strip_suffix(']'))
        .ok_or_else(|| bad(format!("`pose` must be [x, y, yaw], not `{v}`")))?;
    let n: Vec<f64> = inner
        .split(',')
        .map(|x| x.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad(format!("`pose` `{v}` is not three numbers")))?;
    match n[..] {
        [x, y, theta] if n.iter().all(|x| x.is_finite()) => Ok(Pose2 { x, y, theta }),
        _ => Err(bad(format!("`pose` `{v}` is not three finite numbers [x, y, yaw]"))),
    }
}

/// The docks of a file in the format above.
///
/// # Errors
/// [`DockDbError::Format`] naming the line and the key.
pub fn parse(text: &str, default_type: &str) -> Result<Vec<Dock>, DockDbError> {
    let mut docks: Vec<(usize, Dock, bool)> = Vec::new();
    let mut in_docks: Option<usize> = None; // the indentation of `docks:`
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        let bad = |why: String| DockDbError::Format { line, why };
        let content = raw.split(" #").next().unwrap_or("");
        if content.trim().is_empty() || content.trim_start().starts_with('#') {
            continue;
        }
        let indent = content.len() - content.trim_start().len();
        let (key, value) = content
            .trim()
            .split_once(':')
            .ok_or_else(|| bad(format!("`{}` is not `key: value`", content.trim())))?;
        let (key, value) = (unquote(key), value.trim());
        match in_docks {
            None if key == "docks" && value.is_empty() => in_docks = Some(indent),
            None => return Err(bad(format!("`{key}` before `docks:`"))),
            Some(top) if indent <= top => return Err(bad(format!("`{key}` outside `docks:`"))),
            Some(_) if value.is_empty() => {
                if docks.iter().any(|(_, d, _)| d.id == key) {
                    return Err(bad(format!("dock `{key}` given twice")));
                }
                let dock = Dock {
                    id: key.to_owned(),
                    dock_type: default_type.to_owned(),
                    frame: "map".to_owned(),
                    pose: None,
                };
                docks.push((line, dock, false));
            }
            Some(_) => {
                let Some((_, dock, has_pose)) = docks.last_mut() else {
                    return Err(bad(format!("`{key}` before a dock's id")));
                };
                match key {
                    "type" => dock.dock_type = unquote(value).to_owned(),
                    "frame" => dock.frame = unquote(value).to_owned(),
                    "pose" => {
                        dock.pose = Some(pose(line, value)?);
                        *has_pose = true;
                    }
                    // Nav2's `id` (a detector's id for the dock) has no use here.
                    "id" => {}
                    other => return Err(bad(format!("dock `{}`: unknown key `{other}`", dock.id))),
                }
            }
        }
    }
    if in_docks.is_none() {
        return Err(DockDbError::Format {
            line: 1,
            why: "no `docks:`".to_owned(),
        });
    }
    docks
        .into_iter()
        .map(|(line, d, has_pose)| {
            if has_pose {
                Ok(d)
            } else {
                Err(DockDbError::Format {
                    line,
                    why: format!("dock `{}` has no `pose`", d.id),
                })
            }
        })
        .collect()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The shipped Bujold profile with `extra` appended.
    pub(crate) fn bujold(extra: &str) -> Profile {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/profiles/bujold.toml");
        let src = std::fs::read_to_string(path).unwrap();
        Profile::parse(&format!("{src}\n{extra}"), Path::new(path)).unwrap()
    }

    #[test]
    fn the_profiles_docks_start_the_database() {
        let own = DockDatabase::for_profile(&bujold(""), "odom");
        assert_eq!(
            own.docks,
            vec![Dock {
                id: "bujold".into(),
                dock_type: "bujold".into(),
                frame: "odom".into(),
                pose: None,
            }]
        );
        let p = bujold(
            "[[docks]]\nid = \"home\"\npose = [1.0, 2.0, 0.5]\n[[docks]]\nid = \"shed\"\ntype = \"charger\"\nframe = \"map\"\n",
        );
        let db = DockDatabase::for_profile(&p, "odom");
        assert_eq!(db.ids(), "home, shed");
        let home = db.get("home").unwrap();
        assert_eq!((home.dock_type.as_str(), home.frame.as_str()), ("bujold", "odom"));
        assert_eq!(
            home.pose,
            Some(Pose2 {
                x: 1.0,
                y: 2.0,
                theta: 0.5
            })
        );
        let shed = db.get("shed").unwrap();
        assert_eq!(
            (shed.dock_type.as_str(), shed.frame.as_str(), shed.pose),
            ("charger", "map", None)
        );
    }

    #[test]
    fn a_nav2_shaped_file_reads() {
        let text = "# docks\ndocks:\n  home:\n    type: \"bujold\"  # the only type\n    frame: odom\n    pose: [1.5, -0.25, 3.0]\n  shed:\n    pose: [0, 0, 0]\n";
        let docks = parse(text, "bujold").unwrap();
        assert_eq!(docks.len(), 2);
        assert_eq!(
            docks[0],
            Dock {
                id: "home".into(),
                dock_type: "bujold".into(),
                frame: "odom".into(),
                pose: Some(Pose2 {
                    x: 1.5,
                    y: -0.25,
                    theta: 3.0
                }),
            }
        );
        assert_eq!(
            (docks[1].frame.as_str(), docks[1].dock_type.as_str()),
            ("map", "bujold")
        );
    }

    #[test]
    fn malformed_files_name_the_line_and_key() {
        let err = |t: &str| parse(t, "b").unwrap_err().to_string();
        assert!(err("docks:\n  a:\n    pose: [1, 2]\n").contains("line 3: `pose`"));
        assert!(err("docks:\n  a:\n    pose: [1, nan, 2]\n").contains("finite"));
        assert!(err("docks:\n  a:\n    colour: red\n").contains("unknown key `colour`"));
        assert!(err("docks:\n  a:\n    type: b\n").contains("line 2: dock `a` has no `pose`"));
        assert!(err("stations:\n  a:\n").contains("before `docks:`"));
        assert!(err("").contains("no `docks:`"));
        assert!(err("docks:\n  a:\n    pose: [0,0,0]\n  a:\n").contains("given twice"));
    }

    #[test]
    fn a_reload_keeps_the_profiles_dock_and_refuses_a_missing_file() {
        let db = DockDatabase::for_profile(&bujold(""), "odom");
        let dir = std::env::temp_dir().join(format!("marsupial-dockdb-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("docks.yaml");
        std::fs::write(&file, "docks:\n  home:\n    frame: odom\n    pose: [1, 2, 0]\n").unwrap();
        let r = db.reloaded(&file, "bujold").unwrap();
        assert_eq!(r.ids(), "bujold, home");
        assert!(r.get("home").unwrap().pose.is_some());
        assert!(matches!(
            db.reloaded(&dir.join("none.yaml"), "bujold"),
            Err(DockDbError::Read { .. })
        ));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
