//! The interfaces' names and hashes, against the values ROS 2 and Nav2 publish.

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
    let a = action(DOCK_ROBOT);
    assert_eq!(a.send_goal.dds_name(), "nav2_msgs::action::dds_::DockRobot_SendGoal_");
    assert_eq!(a.get_result.dds_name(), "nav2_msgs::action::dds_::DockRobot_GetResult_");
    assert_eq!(
        a.feedback.dds_name(),
        "nav2_msgs::action::dds_::DockRobot_FeedbackMessage_"
    );
    assert_eq!(cancel_goal().dds_name(), "action_msgs::srv::dds_::CancelGoal_");
    assert_eq!(
        reload_dock_database().dds_name(),
        "nav2_msgs::srv::dds_::ReloadDockDatabase_"
    );
}

/// The `hash_string`s `rosidl_generator_type_description` wrote for a public Nav2
/// build (`install/nav2_msgs/share/nav2_msgs/action/DockRobot.json`, `UndockRobot.json`
/// and `srv/ReloadDockDatabase.json` of the repository `thomasankara/hive_ws2`), whose
/// type descriptions list exactly the fields of today's Jazzy/Kilted/Rolling
/// `.action` files. Verified against a published value, not only computed.
#[test]
fn nav2_docking_hashes_match_a_published_nav2_build() {
    let d = action(DOCK_ROBOT);
    assert_eq!(
        d.send_goal.hash,
        "RIHS01_9e60155a1fb741109942c5c7dc21ae0e0db771eaf55d0cfc768bae57a95f3454"
    );
    assert_eq!(
        d.get_result.hash,
        "RIHS01_3e83e8a6eefb3ebe244cd0384418f43d22ffb1f3263fd7b978af8164591c50b3"
    );
    assert_eq!(
        d.feedback.hash,
        "RIHS01_16db0109537f6d74013ed7e6fa51f21c6dcc0a0355cef3be4db4401e971bbe81"
    );
    let u = action(UNDOCK_ROBOT);
    assert_eq!(
        u.send_goal.hash,
        "RIHS01_9c412dec37b7dad67b754dd860cdb03787c0924f01d4cd2b5c16506726b17dc3"
    );
    assert_eq!(
        u.get_result.hash,
        "RIHS01_116641408dd0a5bbb7f0cb61d4519061884c7fcc70ca78b0f89779459cf04263"
    );
    assert_eq!(
        u.feedback.hash,
        "RIHS01_e2204b39a6cd5f0563392b37a5945130d186c5df1c457fcb23ba72b3ff02eed1"
    );
    assert_eq!(
        reload_dock_database().hash,
        "RIHS01_3fa9aa056bcc0dfcd10dbd1f61a215f600c82db832dccfdd98e55cf27ad502e6"
    );
    for (name, hash) in [
        (
            "nav2_msgs/action/DockRobot_Goal",
            "RIHS01_771fae864909c42683a444d493e806a2e709af4678a21091e64edbe16e3223bc",
        ),
        (
            "nav2_msgs/action/DockRobot_Result",
            "RIHS01_09208d89bb7477854fc834f4ceced1e963890614c5e0821121b2a97ddb7be5eb",
        ),
        (
            "nav2_msgs/action/DockRobot_Feedback",
            "RIHS01_b23f877ad7013aae4ad83a1330e83a62a1397594839126331a843a8852dcc8e8",
        ),
        (
            "nav2_msgs/action/UndockRobot_Goal",
            "RIHS01_4161041de8368e5140d3a4af41d24a8756e30e42249e022e258a30a0e1781ccb",
        ),
        (
            "nav2_msgs/action/UndockRobot_Result",
            "RIHS01_df25b55a44a1b73a03fe7f32c7ba0984dd077e5315cad6f25c7354ff5de6b310",
        ),
        (
            "nav2_msgs/action/UndockRobot_Feedback",
            "RIHS01_cafb11296f8495bfdf9a773d2cdc226a906a67b466c1670a23e645334aa85996",
        ),
    ] {
        assert_eq!(message(name).hash, hash, "{name}");
    }
}

/// The referenced messages' hashes, from the same published files.
#[test]
fn referenced_messages_match_the_published_hashes() {
    for (name, hash) in [
        (
            "geometry_msgs/msg/PoseStamped",
            "RIHS01_10f3786d7d40fd2b54367835614bff85d4ad3b5dab62bf8bca0cc232d73b4cd8",
        ),
        (
            "geometry_msgs/msg/Pose",
            "RIHS01_d501954e9476cea2996984e812054b68026ae0bfae789d9a10b23daf35cc90fa",
        ),
        (
            "std_msgs/msg/Header",
            "RIHS01_f49fb3ae2cf070f793645ff749683ac6b06203e41c891e17701b1cb597ce6a01",
        ),
        (
            "builtin_interfaces/msg/Time",
            "RIHS01_b106235e25a4c5ed35098aa0a61a3ee9c9b18d197f398b0e4206cea9acf9c197",
        ),
        (
            "builtin_interfaces/msg/Duration",
            "RIHS01_e8d009f659816f758b75334ee1a9ca5b5c0b859843261f14c7f937349599d93b",
        ),
        (
            "unique_identifier_msgs/msg/UUID",
            "RIHS01_1b8e8aca958cbea28fe6ef60bf6c19b683c97a9ef60bb34752067d0f2f7ab437",
        ),
    ] {
        assert_eq!(message(name).hash, hash, "{name}");
    }
    let lib = [time(), super::super::type_hash::service_event_info()];
    assert_eq!(
        type_hash(&lib[1], &lib),
        "RIHS01_41bcbbe07a75c9b52bc96bfd5c24d7f0fc0a08c0cb7921b3373c5732345a6f45"
    );
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
        reload_dock_database(),
    ] {
        assert!(i.hash.starts_with("RIHS01_") && i.hash.len() == 71, "{i:?}");
    }
}

/// Computed only (no published value was found): pinned so a change shows, and the same
/// values come out of the Python peer's own implementation of REP-2011's hashing
/// (`tests/peer/nav2_peer.py`, `type_hash`), whose cancel call the node answers only when
/// they agree.
#[test]
fn action_msgs_hashes_are_pinned() {
    assert_eq!(
        cancel_goal().hash,
        "RIHS01_573d8b0a534451d7bc2ac8c5ffde8ac14b8593b7001175d0cd6516dcbeb8689a"
    );
    assert_eq!(
        goal_status_array().hash,
        "RIHS01_6c1684b00f177d37438febe6e709fc4e2b0d4248dca4854946f9ed8b30cda83e"
    );
}
