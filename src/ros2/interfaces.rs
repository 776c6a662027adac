//! The ROS 2 interfaces the bridge speaks: their type descriptions (for the type hashes
//! in `rmw_zenoh`'s key expressions) and their names as DDS spells them.
//!
//! Messages: `sensor_msgs/msg/Image`, `sensor_msgs/msg/CompressedImage`,
//! `nav_msgs/msg/Odometry` (read) and `geometry_msgs/msg/Twist` (written). Requests:
//! Nav2's own `nav2_msgs/action/DockRobot` and `nav2_msgs/action/UndockRobot` and the
//! service `nav2_msgs/srv/ReloadDockDatabase`, so Nav2's behavior-tree nodes,
//! `nav2_simple_commander` and `ros2 action send_goal` call the node with no package of
//! ours built, and `action_msgs`' cancel service and status topic, which every action has.
//!
//! Which hashes were checked against a published value (the tests below): every Nav2
//! docking hash (`DockRobot_SendGoal`, `_GetResult`, `_FeedbackMessage`, the three of
//! `UndockRobot`, `ReloadDockDatabase`, and their goals, results and feedback), compared
//! with the `hash_string`s `rosidl_generator_type_description` wrote into a public Nav2
//! build's `share/nav2_msgs/*/*.json`, whose type descriptions carry today's fields; and
//! the messages those reference (`geometry_msgs/msg/PoseStamped`, `std_msgs/msg/Header`,
//! `builtin_interfaces/msg/Time` and `Duration`, `unique_identifier_msgs/msg/UUID`,
//! `service_msgs/msg/ServiceEventInfo`) from the same files. Computed only (no published
//! value found): `action_msgs/msg/GoalStatusArray` and `action_msgs/srv/CancelGoal`, which
//! a second implementation of the algorithm, the Python peer's, computes alike.

use super::type_hash::{Field, FieldType, TypeDescription, field, service_hash, time, type_hash};

/// A message or service type: its ROS name and its type hash.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Interface {
    /// `package/msg/Name`, `package/srv/Name` or `package/action/Name_SendGoal`.
    pub name: String,
    /// `RIHS01_…`.
    pub hash: String,
}

impl Interface {
    /// The name as DDS spells it, which `rmw_zenoh` puts in key expressions:
    /// `geometry_msgs/msg/Twist` → `geometry_msgs::msg::dds_::Twist_`.
    pub fn dds_name(&self) -> String {
        let mut parts: Vec<&str> = self.name.split('/').collect();
        let last = parts.pop().unwrap_or_default();
        format!("{}::dds_::{last}_", parts.join("::"))
    }
}

fn nested(name: &str) -> FieldType {
    FieldType::nested(name)
}

fn f64s(names: &[&'static str]) -> Vec<Field> {
    names.iter().map(|n| field(n, FieldType::F64)).collect()
}

/// Every message type the interfaces below reference.
fn library() -> Vec<TypeDescription> {
    let uuid = "unique_identifier_msgs/msg/UUID";
    vec![
        time(),
        TypeDescription::new(
            "builtin_interfaces/msg/Duration",
            vec![field("sec", FieldType::I32), field("nanosec", FieldType::U32)],
        ),
        TypeDescription::new(
            "std_msgs/msg/Header",
            vec![
                field("stamp", nested("builtin_interfaces/msg/Time")),
                field("frame_id", FieldType::String),
            ],
        ),
        TypeDescription::new("std_msgs/msg/Bool", vec![field("data", FieldType::Bool)]),
        TypeDescription::new("std_msgs/msg/String", vec![field("data", FieldType::String)]),
        TypeDescription::new("geometry_msgs/msg/Vector3", f64s(&["x", "y", "z"])),
        TypeDescription::new("geometry_msgs/msg/Point", f64s(&["x", "y", "z"])),
        TypeDescription::new("geometry_msgs/msg/Quaternion", f64s(&["x", "y", "z", "w"])),
        TypeDescription::new(
            "geometry_msgs/msg/Pose",
            vec![
                field("position", nested("geometry_msgs/msg/Point")),
                field("orientation", nested("geometry_msgs/msg/Quaternion")),
            ],
        ),
        TypeDescription::new(
            "geometry_msgs/msg/Twist",
            vec![
                field("linear", nested("geometry_msgs/msg/Vector3")),
                field("angular", nested("geometry_msgs/msg/Vector3")),
            ],
        ),
        TypeDescription::new(
            "geometry_msgs/msg/PoseWithCovariance",
            vec![
                field("pose", nested("geometry_msgs/msg/Pose")),
                field("covariance", FieldType::array(FieldType::F64, 36)),
            ],
        ),
        TypeDescription::new(
            "geometry_msgs/msg/TwistWithCovariance",
            vec![
                field("twist", nested("geometry_msgs/msg/Twist")),
                field("covariance", FieldType::array(FieldType::F64, 36)),
            ],
        ),
        TypeDescription::new(uuid, vec![field("uuid", FieldType::array(FieldType::U8, 16))]),
        TypeDescription::new(
            "action_msgs/msg/GoalInfo",
            vec![
                field("goal_id", nested(uuid)),
                field("stamp", nested("builtin_interfaces/msg/Time")),
            ],
        ),
        TypeDescription::new(
            "action_msgs/msg/GoalStatus",
            vec![
                field("goal_info", nested("action_msgs/msg/GoalInfo")),
                field("status", FieldType::I8),
            ],
        ),
        TypeDescription::new(
            "geometry_msgs/msg/PoseStamped",
            vec![
                field("header", nested("std_msgs/msg/Header")),
                field("pose", nested("geometry_msgs/msg/Pose")),
            ],
        ),
        // Nav2's docking actions (nav2_msgs/action/DockRobot.action, UndockRobot.action):
        // fields in order; constants and default values are not hashed.
        TypeDescription::new(
            "nav2_msgs/action/DockRobot_Goal",
            vec![
                field("use_dock_id", FieldType::Bool),
                field("dock_id", FieldType::String),
                field("dock_pose", nested("geometry_msgs/msg/PoseStamped")),
                field("dock_type", FieldType::String),
                field("max_staging_time", FieldType::F32),
                field("navigate_to_staging_pose", FieldType::Bool),
            ],
        ),
        TypeDescription::new(
            "nav2_msgs/action/DockRobot_Result",
            vec![
                field("success", FieldType::Bool),
                field("error_code", FieldType::U16),
                field("num_retries", FieldType::U16),
                field("error_msg", FieldType::String),
            ],
        ),
        TypeDescription::new(
            "nav2_msgs/action/DockRobot_Feedback",
            vec![
                field("state", FieldType::U16),
                field("docking_time", nested("builtin_interfaces/msg/Duration")),
                field("num_retries", FieldType::U16),
            ],
        ),
        TypeDescription::new(
            "nav2_msgs/action/UndockRobot_Goal",
            vec![
                field("dock_type", FieldType::String),
                field("max_undocking_time", FieldType::F32),
            ],
        ),
        TypeDescription::new(
            "nav2_msgs/action/UndockRobot_Result",
            vec![
                field("success", FieldType::Bool),
                field("error_code", FieldType::U16),
                field("error_msg", FieldType::String),
            ],
        ),
        // An empty feedback: rosidl gives every empty structure this one member.
        TypeDescription::new(
            "nav2_msgs/action/UndockRobot_Feedback",
            vec![field("structure_needs_at_least_one_member", FieldType::U8)],
        ),
    ]
}

/// The message type `name`, hashed.
///
/// # Panics
/// When `name` is not one of the messages this module describes (a bug in the crate).
pub fn message(name: &str) -> Interface {
    let lib = library();
    let top = lib
        .iter()
        .find(|t| t.name == name)
        .unwrap_or_else(|| panic!("`{name}` is not a message the bridge describes"));
    Interface {
        name: name.to_owned(),
        hash: type_hash(top, &lib),
    }
}

/// `sensor_msgs/msg/Image`.
pub fn image() -> Interface {
    with(TypeDescription::new(
        "sensor_msgs/msg/Image",
        vec![
            field("header", nested("std_msgs/msg/Header")),
            field("height", FieldType::U32),
            field("width", FieldType::U32),
            field("encoding", FieldType::String),
            field("is_bigendian", FieldType::U8),
            field("step", FieldType::U32),
            field("data", FieldType::sequence(FieldType::U8)),
        ],
    ))
}

/// `sensor_msgs/msg/CompressedImage`.
pub fn compressed_image() -> Interface {
    with(TypeDescription::new(
        "sensor_msgs/msg/CompressedImage",
        vec![
            field("header", nested("std_msgs/msg/Header")),
            field("format", FieldType::String),
            field("data", FieldType::sequence(FieldType::U8)),
        ],
    ))
}

/// `nav_msgs/msg/Odometry`.
pub fn odometry() -> Interface {
    with(TypeDescription::new(
        "nav_msgs/msg/Odometry",
        vec![
            field("header", nested("std_msgs/msg/Header")),
            field("child_frame_id", FieldType::String),
            field("pose", nested("geometry_msgs/msg/PoseWithCovariance")),
            field("twist", nested("geometry_msgs/msg/TwistWithCovariance")),
        ],
    ))
}

/// `geometry_msgs/msg/Twist`.
pub fn twist() -> Interface {
    message("geometry_msgs/msg/Twist")
}

/// `action_msgs/msg/GoalStatusArray`.
pub fn goal_status_array() -> Interface {
    with(TypeDescription::new(
        "action_msgs/msg/GoalStatusArray",
        vec![field(
            "status_list",
            FieldType::sequence(nested("action_msgs/msg/GoalStatus")),
        )],
    ))
}

/// `action_msgs/srv/CancelGoal`.
pub fn cancel_goal() -> Interface {
    let name = "action_msgs/srv/CancelGoal";
    Interface {
        name: name.to_owned(),
        hash: service_hash(
            name,
            vec![field("goal_info", nested("action_msgs/msg/GoalInfo"))],
            vec![
                field("return_code", FieldType::I8),
                field(
                    "goals_canceling",
                    FieldType::sequence(nested("action_msgs/msg/GoalInfo")),
                ),
            ],
            &library(),
        ),
    }
}

/// `nav2_msgs/srv/ReloadDockDatabase`: `string filepath` → `bool success`.
pub fn reload_dock_database() -> Interface {
    let name = "nav2_msgs/srv/ReloadDockDatabase";
    Interface {
        name: name.to_owned(),
        hash: service_hash(
            name,
            vec![field("filepath", FieldType::String)],
            vec![field("success", FieldType::Bool)],
            &library(),
        ),
    }
}

/// `nav2_msgs/action/DockRobot`.
pub const DOCK_ROBOT: &str = "nav2_msgs/action/DockRobot";
/// `nav2_msgs/action/UndockRobot`.
pub const UNDOCK_ROBOT: &str = "nav2_msgs/action/UndockRobot";

/// The interfaces of one action (`nav2_msgs/action/DockRobot` or `…/UndockRobot`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ActionInterfaces {
    /// `<action>_SendGoal`, a service.
    pub send_goal: Interface,
    /// `<action>_GetResult`, a service.
    pub get_result: Interface,
    /// `<action>_FeedbackMessage`, a message.
    pub feedback: Interface,
}

/// The interfaces of the action `package/action/Name`, whose goal, result and feedback
/// are described in this module.
pub fn action(name: &str) -> ActionInterfaces {
    let lib = library();
    let uuid = || field("goal_id", nested("unique_identifier_msgs/msg/UUID"));
    let send = format!("{name}_SendGoal");
    let get = format!("{name}_GetResult");
    let feedback = TypeDescription::new(
        format!("{name}_FeedbackMessage"),
        vec![uuid(), field("feedback", nested(&format!("{name}_Feedback")))],
    );
    ActionInterfaces {
        send_goal: Interface {
            hash: service_hash(
                &send,
                vec![uuid(), field("goal", nested(&format!("{name}_Goal")))],
                vec![
                    field("accepted", FieldType::Bool),
                    field("stamp", nested("builtin_interfaces/msg/Time")),
                ],
                &lib,
            ),
            name: send,
        },
        get_result: Interface {
            hash: service_hash(
                &get,
                vec![uuid()],
                vec![
                    field("status", FieldType::I8),
                    field("result", nested(&format!("{name}_Result"))),
                ],
                &lib,
            ),
            name: get,
        },
        feedback: Interface {
            hash: type_hash(&feedback, &lib),
            name: feedback.name,
        },
    }
}

fn with(top: TypeDescription) -> Interface {
    Interface {
        hash: type_hash(&top, &library()),
        name: top.name,
    }
}

#[cfg(test)]
#[path = "interfaces_tests.rs"]
mod tests;
