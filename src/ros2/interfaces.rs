//! The ROS 2 interfaces the bridge speaks: their type descriptions (for the type hashes
//! in `rmw_zenoh`'s key expressions) and their names as DDS spells them.
//!
//! Messages: `sensor_msgs/msg/Image`, `sensor_msgs/msg/CompressedImage`,
//! `nav_msgs/msg/Odometry` (read) and `geometry_msgs/msg/Twist` (written). Requests: the
//! actions `marsupial_msgs/action/Dock` and `marsupial_msgs/action/Undock`, modelled on
//! Nav2's `DockRobot` and `UndockRobot` and shipped as a ROS 2 package in
//! `ros2/marsupial_msgs` (build it in your workspace to call them from `ros2 action`), and
//! `action_msgs`' cancel service and status topic, which every action has.

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
        TypeDescription::new("geometry_msgs/msg/Pose2D", f64s(&["x", "y", "theta"])),
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
        // The two actions' own messages (ros2/marsupial_msgs/action/*.action).
        TypeDescription::new(
            "marsupial_msgs/action/Dock_Goal",
            vec![
                field("use_dock_hint", FieldType::Bool),
                field("dock_hint", nested("geometry_msgs/msg/Pose2D")),
                field("max_time", FieldType::F32),
            ],
        ),
        TypeDescription::new("marsupial_msgs/action/Dock_Result", result_fields(true)),
        TypeDescription::new("marsupial_msgs/action/Dock_Feedback", feedback_fields()),
        TypeDescription::new(
            "marsupial_msgs/action/Undock_Goal",
            vec![field("max_time", FieldType::F32)],
        ),
        TypeDescription::new("marsupial_msgs/action/Undock_Result", result_fields(false)),
        TypeDescription::new("marsupial_msgs/action/Undock_Feedback", feedback_fields()),
    ]
}

/// A result: `bool success`, `uint16 error_code`, `string outcome`, and for docking
/// `uint16 num_retries`.
fn result_fields(retries: bool) -> Vec<Field> {
    let mut f = vec![
        field("success", FieldType::Bool),
        field("error_code", FieldType::U16),
        field("outcome", FieldType::String),
    ];
    if retries {
        f.push(field("num_retries", FieldType::U16));
    }
    f
}

/// Feedback: `string phase`, `builtin_interfaces/Duration elapsed`, `uint16 num_retries`.
fn feedback_fields() -> Vec<Field> {
    vec![
        field("phase", FieldType::String),
        field("elapsed", nested("builtin_interfaces/msg/Duration")),
        field("num_retries", FieldType::U16),
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

/// The interfaces of one action (`marsupial_msgs/action/Dock` or `…/Undock`).
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
mod tests {
    use super::*;

    #[test]
    fn twist_keeps_the_hash_ros_2_prints() {
        let t = twist();
        assert_eq!(t.dds_name(), "geometry_msgs::msg::dds_::Twist_");
        assert_eq!(
            t.hash,
            "RIHS01_9c45bf16fe0983d80e3cfe750d6835843d265a9a6c46bd2e609fcddde6fb8d2a"
        );
    }

    #[test]
    fn camera_and_odometry_keep_the_hashes_ros_2_prints() {
        assert_eq!(
            image().hash,
            "RIHS01_d31d41a9a4c4bc8eae9be757b0beed306564f7526c88ea6a4588fb9582527d47"
        );
        assert_eq!(
            odometry().hash,
            "RIHS01_3cc97dc7fb7502f8714462c526d369e35b603cfc34d946e3f2eda2766dfec6e0"
        );
        assert_eq!(
            message("std_msgs/msg/String").hash,
            "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18"
        );
    }

    #[test]
    fn action_services_are_named_as_rosidl_names_them() {
        let a = action("marsupial_msgs/action/Dock");
        assert_eq!(a.send_goal.dds_name(), "marsupial_msgs::action::dds_::Dock_SendGoal_");
        assert_eq!(a.get_result.dds_name(), "marsupial_msgs::action::dds_::Dock_GetResult_");
        assert_eq!(
            a.feedback.dds_name(),
            "marsupial_msgs::action::dds_::Dock_FeedbackMessage_"
        );
        let u = action("marsupial_msgs/action/Undock");
        assert_ne!(a.send_goal.hash, u.send_goal.hash);
        assert_eq!(cancel_goal().dds_name(), "action_msgs::srv::dds_::CancelGoal_");
    }

    /// The fields of one part (goal, result or feedback) of a shipped `.action` file, as
    /// `(type, name)`, constants and comments left out.
    fn action_part(text: &str, part: usize) -> Vec<(String, String)> {
        let section = text.split("\n---").nth(part).unwrap();
        section
            .lines()
            .map(|l| l.split('#').next().unwrap().trim())
            .filter(|l| !l.is_empty() && !l.contains('='))
            .map(|l| {
                let mut w = l.split_whitespace();
                (w.next().unwrap().to_owned(), w.next().unwrap().to_owned())
            })
            .collect()
    }

    /// The `.action` spelling of a described field's type.
    fn spelled(ty: &FieldType) -> String {
        match ty {
            FieldType::Bool => "bool".into(),
            FieldType::F32 => "float32".into(),
            FieldType::U16 => "uint16".into(),
            FieldType::String => "string".into(),
            FieldType::Nested(n) => n.replace("/msg/", "/"),
            other => format!("{other:?}"),
        }
    }

    #[test]
    fn the_shipped_action_files_match_the_hashed_descriptions() {
        let lib = library();
        for (name, text) in [
            ("Dock", include_str!("../../ros2/marsupial_msgs/action/Dock.action")),
            ("Undock", include_str!("../../ros2/marsupial_msgs/action/Undock.action")),
        ] {
            for (part, suffix) in ["Goal", "Result", "Feedback"].iter().enumerate() {
                let described = lib
                    .iter()
                    .find(|t| t.name == format!("marsupial_msgs/action/{name}_{suffix}"))
                    .unwrap();
                let got: Vec<(String, String)> = described
                    .fields
                    .iter()
                    .map(|f| (spelled(&f.ty), f.name.to_owned()))
                    .collect();
                assert_eq!(action_part(text, part), got, "{name}_{suffix}");
            }
        }
    }

    #[test]
    fn every_interface_hashes() {
        for i in [
            image(),
            compressed_image(),
            odometry(),
            twist(),
            goal_status_array(),
            cancel_goal(),
        ] {
            assert!(i.hash.starts_with("RIHS01_") && i.hash.len() == 71, "{i:?}");
        }
    }
}
