//! From a Nav2 goal to a mission: which dock, where it is, and the time limits, or the
//! Nav2 error code and a message naming the goal's field that made it unusable. Pure
//! functions of the goal and the dock database, so every bad goal is tested without a
//! network.

use super::dock_db::DockDatabase;
use super::nav2::error;
use super::nav2_msgs::{DockRobotGoal, PoseStamped, UndockRobotGoal};
use crate::geometry::Pose2;
use crate::schemas::Mission;
use std::time::Duration;

/// What a goal asks the runtime to do.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// The mission (a docking carries the dock's pose as its hint when it is known).
    pub mission: Mission,
    /// The whole goal's time limit (`max_undocking_time`); `None`: the runtime's own.
    pub max_duration: Option<Duration>,
    /// The longest the phases that drive to the staging pose may take in all
    /// (`max_staging_time`), s.
    pub max_staging_s: Option<f64>,
}

/// Why a goal was not run: Nav2's error code and a message naming the field.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct GoalError {
    /// `DOCK_NOT_IN_DB` or `DOCK_NOT_VALID`.
    pub code: u16,
    /// Names the goal's field (`dock_id`, `dock_pose.header.frame_id` …).
    pub message: String,
}

fn not_valid(message: String) -> GoalError {
    GoalError {
        code: error::DOCK_NOT_VALID,
        message,
    }
}

/// What the node can resolve and dock at.
#[derive(Debug, Clone, PartialEq)]
pub struct Resolver<'a> {
    /// The docks.
    pub db: &'a DockDatabase,
    /// The odometry frame, the only one the node can put a pose in (it has no TF).
    pub odom_frame: &'a str,
    /// The dock type the running behavior docks at (the profile's name).
    pub dock_type: &'a str,
}

impl Resolver<'_> {
    fn check_type(&self, field: &str, t: &str) -> Result<(), GoalError> {
        if t.is_empty() || t == self.dock_type {
            Ok(())
        } else {
            Err(not_valid(format!(
                "{field} `{t}` is not a type this node docks at (only `{}`)",
                self.dock_type
            )))
        }
    }

    fn check_frame(&self, field: &str, frame: &str) -> Result<(), GoalError> {
        if frame.is_empty() || frame == self.odom_frame {
            Ok(())
        } else {
            Err(not_valid(format!(
                "{field} `{frame}` cannot be resolved: the node has no transforms and knows only the odometry frame `{}`",
                self.odom_frame
            )))
        }
    }

    /// A `DockRobot` goal's plan: by `dock_id` from the database (its pose, when known,
    /// becomes the mission's dock hint), or at `dock_pose` (the hint), of `dock_type`.
    /// With `navigate_to_staging_pose` and a hint, the robot's own ballistic phase drives
    /// to the approach zone first (it has no `NavigateToPose` client); without, it starts
    /// where it is, as staged.
    ///
    /// # Errors
    /// [`GoalError`]: `DOCK_NOT_IN_DB` for an unknown `dock_id`; `DOCK_NOT_VALID` for a
    /// dock of another type, a frame other than the odometry frame, a pose that is not
    /// finite or whose quaternion is zero, or a `max_staging_time` that is not a positive
    /// number.
    pub fn docking(&self, g: &DockRobotGoal) -> Result<Plan, GoalError> {
        if !(g.max_staging_time.is_finite() && g.max_staging_time > 0.0) {
            return Err(not_valid(format!(
                "max_staging_time {} is not a positive number of seconds",
                g.max_staging_time
            )));
        }
        let hint = if g.use_dock_id {
            let Some(dock) = self.db.get(&g.dock_id) else {
                return Err(GoalError {
                    code: error::DOCK_NOT_IN_DB,
                    message: format!(
                        "dock_id `{}` is not in the dock database (it holds: {})",
                        g.dock_id,
                        self.db.ids()
                    ),
                });
            };
            self.check_type(&format!("dock `{}`'s type", dock.id), &dock.dock_type)?;
            if dock.pose.is_some() {
                self.check_frame(&format!("dock `{}`'s frame", dock.id), &dock.frame)?;
            }
            dock.pose
        } else {
            self.check_type("dock_type", &g.dock_type)?;
            self.check_frame("dock_pose.header.frame_id", &g.dock_pose.frame_id)?;
            Some(planar(&g.dock_pose)?)
        };
        Ok(Plan {
            mission: Mission::Docking {
                dock_hint: hint,
                stage: g.navigate_to_staging_pose,
            },
            max_duration: None,
            max_staging_s: Some(f64::from(g.max_staging_time)),
        })
    }

    /// An `UndockRobot` goal's plan: the departure, within `max_undocking_time`.
    ///
    /// # Errors
    /// `DOCK_NOT_VALID` for another `dock_type` or a `max_undocking_time` that is not a
    /// positive number.
    pub fn undocking(&self, g: &UndockRobotGoal) -> Result<Plan, GoalError> {
        self.check_type("dock_type", &g.dock_type)?;
        if !(g.max_undocking_time.is_finite() && g.max_undocking_time > 0.0) {
            return Err(not_valid(format!(
                "max_undocking_time {} is not a positive number of seconds",
                g.max_undocking_time
            )));
        }
        Ok(Plan {
            mission: Mission::Departure,
            max_duration: Some(Duration::from_secs_f32(g.max_undocking_time)),
            max_staging_s: None,
        })
    }
}

/// The planar pose of a `PoseStamped`: x, y and the yaw of its quaternion.
fn planar(p: &PoseStamped) -> Result<Pose2, GoalError> {
    let [x, y, _] = p.position;
    let [qx, qy, qz, qw] = p.orientation;
    let norm = (qx * qx + qy * qy + qz * qz + qw * qw).sqrt();
    if !(p.position.iter().chain(&p.orientation).all(|v| v.is_finite()) && norm > 1e-9) {
        return Err(not_valid(format!(
            "dock_pose.pose is not a pose (position {:?}, orientation {:?})",
            p.position, p.orientation
        )));
    }
    let theta = (2.0 * (qw * qz + qx * qy)).atan2(1.0 - 2.0 * (qy * qy + qz * qz));
    Ok(Pose2 { x, y, theta })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn db() -> DockDatabase {
        let mut db = DockDatabase::for_profile(&super::super::dock_db::tests::bujold(""), "odom");
        db.docks.push(super::super::dock_db::Dock {
            id: "far".into(),
            dock_type: "bujold".into(),
            frame: "map".into(),
            pose: Some(Pose2::default()),
        });
        db
    }

    fn resolver(db: &DockDatabase) -> Resolver<'_> {
        Resolver {
            db,
            odom_frame: "odom",
            dock_type: "bujold",
        }
    }

    #[test]
    fn a_dock_by_id_or_by_pose_becomes_the_mission() {
        let db = db();
        let r = resolver(&db);
        let by_id = DockRobotGoal {
            dock_id: "bujold".into(),
            ..DockRobotGoal::default()
        };
        let p = r.docking(&by_id).unwrap();
        assert_eq!(p.mission, Mission::docking());
        assert_eq!(p.max_staging_s, Some(1000.0));
        let half = std::f64::consts::FRAC_PI_4;
        let by_pose = DockRobotGoal {
            use_dock_id: false,
            dock_pose: PoseStamped {
                frame_id: "odom".into(),
                position: [1.0, 2.0, 0.0],
                orientation: [0.0, 0.0, half.sin(), half.cos()],
                ..PoseStamped::default()
            },
            ..DockRobotGoal::default()
        };
        let Mission::Docking {
            dock_hint: Some(h),
            stage: true,
        } = r.docking(&by_pose).unwrap().mission
        else {
            panic!("a hint")
        };
        assert!((h.x - 1.0).abs() < 1e-12 && (h.y - 2.0).abs() < 1e-12);
        assert!((h.theta - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        let staged = DockRobotGoal {
            navigate_to_staging_pose: false,
            ..by_pose
        };
        let Mission::Docking { stage: false, .. } = r.docking(&staged).unwrap().mission else {
            panic!("navigate_to_staging_pose = false: already staged")
        };
    }

    #[test]
    fn bad_goals_get_nav2_codes_and_name_the_field() {
        let db = db();
        let r = resolver(&db);
        let e = r
            .docking(&DockRobotGoal {
                dock_id: "kitchen".into(),
                ..DockRobotGoal::default()
            })
            .unwrap_err();
        assert_eq!(e.code, error::DOCK_NOT_IN_DB);
        assert!(
            e.message.contains("dock_id `kitchen`") && e.message.contains("bujold, far"),
            "{}",
            e.message
        );
        let e = r
            .docking(&DockRobotGoal {
                dock_id: "far".into(),
                ..DockRobotGoal::default()
            })
            .unwrap_err();
        assert!(
            e.code == error::DOCK_NOT_VALID && e.message.contains("frame `map`"),
            "{e:?}"
        );
        let mut g = DockRobotGoal {
            use_dock_id: false,
            ..DockRobotGoal::default()
        };
        g.dock_pose.frame_id = "map".into();
        let e = r.docking(&g).unwrap_err();
        assert!(e.message.contains("dock_pose.header.frame_id `map`"), "{e:?}");
        g.dock_pose.frame_id = "odom".into();
        g.dock_pose.position[0] = f64::NAN;
        assert!(r.docking(&g).unwrap_err().message.contains("dock_pose.pose"));
        g.dock_pose.position[0] = 0.0;
        g.dock_type = "charger".into();
        assert!(r.docking(&g).unwrap_err().message.contains("dock_type `charger`"));
        g.dock_type.clear();
        g.max_staging_time = f32::NAN;
        assert!(r.docking(&g).unwrap_err().message.contains("max_staging_time"));
        let u = UndockRobotGoal {
            max_undocking_time: -1.0,
            ..UndockRobotGoal::default()
        };
        assert!(r.undocking(&u).unwrap_err().message.contains("max_undocking_time"));
        let ok = r.undocking(&UndockRobotGoal::default()).unwrap();
        assert_eq!(ok.max_duration, Some(Duration::from_secs(30)));
    }
}
