//! The JSON Schemas of the messages a recording holds (MCAP schema encoding
//! `jsonschema`, message encoding `json`).
//!
//! The `foxglove.*` ones are Foxglove's well-known schemas cut down to the fields this
//! recorder writes (Foxglove recognises a schema by its name; the text only has to
//! describe the messages). Bytes are base64 strings, Foxglove's convention for bytes in
//! JSON; times are `{sec, nsec}` on the simulation clock.

/// `{sec, nsec}`, as every Foxglove timestamp.
macro_rules! time_schema {
    () => {
        r#"{"type":"object","properties":{"sec":{"type":"integer","minimum":0},"nsec":{"type":"integer","minimum":0}}}"#
    };
}

/// `{x, y}` in image pixels.
macro_rules! point2_schema {
    () => {
        r#"{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"}}}"#
    };
}

/// `{r, g, b, a}` in [0, 1].
macro_rules! color_schema {
    () => {
        r#"{"type":"object","properties":{"r":{"type":"number"},"g":{"type":"number"},"b":{"type":"number"},"a":{"type":"number"}}}"#
    };
}

/// `{position:{x,y,z}, orientation:{x,y,z,w}}`.
macro_rules! pose_schema {
    () => {
        concat!(
            r#"{"type":"object","properties":{"position":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"}}},"#,
            r#""orientation":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"},"w":{"type":"number"}}}}}"#
        )
    };
}

/// `sensor_msgs/msg/Image` in ROS 2's message-definition format (`ros2msg`), with the
/// definitions it uses after it as rosbag2 writes them: the raw frames' schema. Raw
/// frames are CDR, not JSON: a JSON `foxglove.RawImage` carries its pixels as base64,
/// a third larger and encoded every frame, which was most of what recording cost.
pub const ROS2_IMAGE: &str = concat!(
    "std_msgs/Header header\nuint32 height\nuint32 width\nstring encoding\nuint8 is_bigendian\nuint32 step\nuint8[] data\n",
    "================================================================================\n",
    "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n",
    "================================================================================\n",
    "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n",
);

/// `foxglove.CompressedImage`: a JPEG frame.
pub const COMPRESSED_IMAGE: &str = concat!(
    r#"{"title":"foxglove.CompressedImage","type":"object","properties":{"timestamp":"#,
    time_schema!(),
    r#","frame_id":{"type":"string"},"data":{"type":"string","contentEncoding":"base64"},"format":{"type":"string"}}}"#
);

/// `foxglove.CameraCalibration`: pin-hole intrinsics (`plumb_bob` distortion).
pub const CAMERA_CALIBRATION: &str = concat!(
    r#"{"title":"foxglove.CameraCalibration","type":"object","properties":{"timestamp":"#,
    time_schema!(),
    r#","frame_id":{"type":"string"},"width":{"type":"integer"},"height":{"type":"integer"},"distortion_model":{"type":"string"},"#,
    r#""D":{"type":"array","items":{"type":"number"}},"K":{"type":"array","items":{"type":"number"},"minItems":9,"maxItems":9},"#,
    r#""R":{"type":"array","items":{"type":"number"},"minItems":9,"maxItems":9},"P":{"type":"array","items":{"type":"number"},"minItems":12,"maxItems":12}}}"#
);

/// `foxglove.ImageAnnotations`: circles, point sets (outlines, centroids) and texts in
/// image pixels.
pub const IMAGE_ANNOTATIONS: &str = concat!(
    r#"{"title":"foxglove.ImageAnnotations","type":"object","properties":{"#,
    r#""circles":{"type":"array","items":{"type":"object","properties":{"timestamp":"#,
    time_schema!(),
    r#","position":"#,
    point2_schema!(),
    r#","diameter":{"type":"number"},"thickness":{"type":"number"},"fill_color":"#,
    color_schema!(),
    r#","outline_color":"#,
    color_schema!(),
    r#"}}},"points":{"type":"array","items":{"type":"object","properties":{"timestamp":"#,
    time_schema!(),
    r#","type":{"type":"integer","description":"0 unknown, 1 points, 2 line loop, 3 line strip, 4 line list"},"points":{"type":"array","items":"#,
    point2_schema!(),
    r#"},"outline_color":"#,
    color_schema!(),
    r#","outline_colors":{"type":"array","items":"#,
    color_schema!(),
    r#"},"fill_color":"#,
    color_schema!(),
    r#","thickness":{"type":"number"}}}},"texts":{"type":"array","items":{"type":"object","properties":{"timestamp":"#,
    time_schema!(),
    r#","position":"#,
    point2_schema!(),
    r#","text":{"type":"string"},"font_size":{"type":"number"},"text_color":"#,
    color_schema!(),
    r#","background_color":"#,
    color_schema!(),
    r#"}}}}}"#
);

/// `foxglove.PoseInFrame`: a pose in a named frame.
pub const POSE_IN_FRAME: &str = concat!(
    r#"{"title":"foxglove.PoseInFrame","type":"object","properties":{"timestamp":"#,
    time_schema!(),
    r#","frame_id":{"type":"string"},"pose":"#,
    pose_schema!(),
    r#"}}"#
);

/// `foxglove.FrameTransform`: a child frame's pose in its parent.
pub const FRAME_TRANSFORM: &str = concat!(
    r#"{"title":"foxglove.FrameTransform","type":"object","properties":{"timestamp":"#,
    time_schema!(),
    r#","parent_frame_id":{"type":"string"},"child_frame_id":{"type":"string"},"#,
    r#""translation":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"}}},"#,
    r#""rotation":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"},"w":{"type":"number"}}}}}"#
);

/// `foxglove.Log`: a log line (`level` 1 debug, 2 info, 3 warning, 4 error, 5 fatal).
pub const LOG: &str = concat!(
    r#"{"title":"foxglove.Log","type":"object","properties":{"timestamp":"#,
    time_schema!(),
    r#","level":{"type":"integer","minimum":0,"maximum":5},"message":{"type":"string"},"name":{"type":"string"},"file":{"type":"string"},"line":{"type":"integer","minimum":0}}}"#
);

/// `marsupial.MotorCommand`: the command sent this tick, with its equivalent twist
/// (`v`, `omega`) for plotting.
pub const MOTOR_COMMAND: &str = r#"{"title":"marsupial.MotorCommand","type":"object","properties":{"mission":{"type":"string"},"t":{"type":"number"},"v":{"type":"number","description":"m/s"},"omega":{"type":"number","description":"rad/s"},"command":{"type":"object","description":"the MotorOutput as sent"}}}"#;

/// `marsupial.TraceLine`: the decision trace of one tick (`marsupial dock --trace`'s line).
pub const TRACE_LINE: &str = r#"{"title":"marsupial.TraceLine","type":"object","properties":{"mission":{"type":"string"},"t":{"type":"number"},"status":{},"command":{"type":"object"},"nodes":{"type":"array","items":{"type":"object","properties":{"node":{"type":"string"},"strategy":{},"active":{"type":"array","items":{"type":"string"}},"proposals":{"type":"array"},"winner":{"type":["string","null"]},"transitions":{"type":"array"}}}}}}"#;

/// `marsupial.Percept`: the percept of one tick (`Observation::percept`, tagged by
/// fiducial kind) and the camera it came from.
pub const PERCEPT: &str = r#"{"title":"marsupial.Percept","type":"object","properties":{"camera":{"type":"integer"},"percept":{"type":"object","properties":{"two_block":{"type":"object"},"pyramid":{"type":"object"}}}}}"#;

/// `marsupial.ColourRanges`: the colour model's segmentation ranges (SCT or HSV boxes,
/// one per fiducial colour).
pub const COLOUR_RANGES: &str = r#"{"title":"marsupial.ColourRanges","type":"object","properties":{"sct":{"type":"array","items":{"type":"object","properties":{"a":{"type":"array","items":{"type":"number"}},"b":{"type":"array","items":{"type":"number"}},"min_l":{"type":"number"},"min_chroma":{"type":"number"}}}},"hsv":{"type":"array","items":{"type":"object","properties":{"h":{"type":"array","items":{"type":"number"}},"s":{"type":"array","items":{"type":"number"}},"v":{"type":"array","items":{"type":"number"}}}}}}}"#;

#[cfg(test)]
mod tests {
    /// The ROS 2 definition lists every type it uses, as rosbag2 writes them.
    #[test]
    fn the_image_definition_carries_its_dependencies() {
        let parts: Vec<&str> = super::ROS2_IMAGE.split(&format!("{}\n", "=".repeat(80))).collect();
        assert_eq!(parts.len(), 3);
        assert!(parts[0].starts_with("std_msgs/Header header\n") && parts[0].ends_with("uint8[] data\n"));
        assert!(parts[1].starts_with("MSG: std_msgs/Header\n"));
        assert!(parts[2].starts_with("MSG: builtin_interfaces/Time\n"));
    }

    /// Every schema is valid JSON with an object type.
    #[test]
    fn schemas_parse() {
        for s in [
            super::COMPRESSED_IMAGE,
            super::CAMERA_CALIBRATION,
            super::IMAGE_ANNOTATIONS,
            super::POSE_IN_FRAME,
            super::FRAME_TRANSFORM,
            super::LOG,
            super::MOTOR_COMMAND,
            super::TRACE_LINE,
            super::PERCEPT,
            super::COLOUR_RANGES,
        ] {
            let v: serde_json::Value = serde_json::from_str(s).unwrap_or_else(|e| panic!("{e}: {s}"));
            assert_eq!(v["type"], "object");
        }
    }
}
