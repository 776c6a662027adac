//! `marsupial replay` on logs written here in ROS 2's exact layout: CDR with its 4-byte
//! encapsulation header and XCDR1 alignment, the schema text rosbag2 writes (the .msg text
//! then `====…\nMSG: pkg/Type` dependency blocks), schema encoding `ros2msg`, message
//! encoding `cdr`. The CDR here is written by this file's own encoder, not the crate's
//! decoder run backwards, and one Image and one Odometry are assembled byte by byte from
//! the specification. The frames are real photos (../shared/data/photos, cropped to the
//! Bujold camera's 256×240, some with a cyan|magenta flap painted in so percepts are
//! found); each replayed percept must equal what the perceptual schema gives on the same
//! decoded pixels. Every error the docs promise is provoked: Bayer and 16-bit encodings,
//! a missing topic, a truncated file, bad CDR, a half-readable topic, two image topics.

use crate::common;

use marsupial::cli::replay::{ReplayCliError, ReplayOptions, run};
use marsupial::msgs::cdr;
use marsupial::perception::RgbImage;
use marsupial::profile::NamedColor;
use marsupial::replay::ReplayError;
use marsupial::replay::log::LogFault;
use marsupial::replay::topics::TopicError;
use marsupial::schemas::{ObservedPercept, TwoBlockSchema};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

// ---------------------------------------------------------------- test-side CDR encoder

/// Little-endian plain CDR (XCDR1), written independently of the crate's decoder.
struct Cdr(Vec<u8>);

impl Cdr {
    fn new() -> Self {
        Cdr(vec![0x00, 0x01, 0x00, 0x00]) // CDR_LE, options 0
    }
    fn align(&mut self, n: usize) {
        while !(self.0.len() - 4).is_multiple_of(n) {
            self.0.push(0);
        }
    }
    fn u8(&mut self, v: u8) -> &mut Self {
        self.0.push(v);
        self
    }
    fn u32(&mut self, v: u32) -> &mut Self {
        self.align(4);
        self.0.extend_from_slice(&v.to_le_bytes());
        self
    }
    fn i32(&mut self, v: i32) -> &mut Self {
        self.align(4);
        self.0.extend_from_slice(&v.to_le_bytes());
        self
    }
    fn f64(&mut self, v: f64) -> &mut Self {
        self.align(8);
        self.0.extend_from_slice(&v.to_le_bytes());
        self
    }
    fn string(&mut self, s: &str) -> &mut Self {
        self.u32(s.len() as u32 + 1);
        self.0.extend_from_slice(s.as_bytes());
        self.0.push(0);
        self
    }
    fn bytes(&mut self, b: &[u8]) -> &mut Self {
        self.u32(b.len() as u32);
        self.0.extend_from_slice(b);
        self
    }
    fn header(&mut self, ns: u64, frame: &str) -> &mut Self {
        self.i32((ns / 1_000_000_000) as i32)
            .u32((ns % 1_000_000_000) as u32)
            .string(frame)
    }
}

fn image_msg(ns: u64, w: u32, h: u32, encoding: &str, step: u32, data: &[u8]) -> Vec<u8> {
    image_msg_in("camera_optical", ns, w, h, encoding, step, data)
}

fn image_msg_in(frame: &str, ns: u64, w: u32, h: u32, encoding: &str, step: u32, data: &[u8]) -> Vec<u8> {
    let mut c = Cdr::new();
    c.header(ns, frame)
        .u32(h)
        .u32(w)
        .string(encoding)
        .u8(0)
        .u32(step)
        .bytes(data);
    c.0
}

fn compressed_msg(ns: u64, format: &str, data: &[u8]) -> Vec<u8> {
    let mut c = Cdr::new();
    c.header(ns, "camera_optical").string(format).bytes(data);
    c.0
}

fn odometry_msg(ns: u64, x: f64, y: f64, yaw: f64, v: f64, w: f64) -> Vec<u8> {
    let mut c = Cdr::new();
    c.header(ns, "odom").string("base_link");
    for p in [x, y, 0.0, 0.0, 0.0, (yaw / 2.0).sin(), (yaw / 2.0).cos()] {
        c.f64(p);
    }
    (0..36).for_each(|i| {
        c.f64(if i % 7 == 0 { 0.01 } else { 0.0 });
    });
    for t in [v, 0.0, 0.0, 0.0, 0.0, w] {
        c.f64(t);
    }
    (0..36).for_each(|_| {
        c.f64(0.0);
    });
    c.0
}

// ------------------------------------------------- schema texts as rosbag2 writes them

const SEP: &str = "================================================================================\n";

const HEADER_MSG: &str = "# Standard metadata for higher-level stamped data types.\n# This is generally used to communicate timestamped data\n# in a particular coordinate frame.\n\n# Two-integer timestamp that is expressed as seconds and nanoseconds.\nbuiltin_interfaces/Time stamp\n\n# Transform frame with which this data is associated.\nstring frame_id\n";

const TIME_MSG: &str = "# This message communicates ROS Time defined here:\n# https://design.ros2.org/articles/clock_and_time.html\n\n# The seconds component, valid over all int32 values.\nint32 sec\n\n# The nanoseconds component, valid in the range [0, 1e9), to be added to the seconds component.\n# e.g.\n# The time -1.7 seconds is represented as {sec: -2, nanosec: 3e8}\n# The time 1.7 seconds is represented as {sec: 1, nanosec: 7e8}\nuint32 nanosec\n";

fn with_deps(msg: &str, deps: &[(&str, &str)]) -> String {
    let mut s = msg.to_string();
    for (name, text) in deps {
        s.push_str(SEP);
        s.push_str(&format!("MSG: {name}\n"));
        s.push_str(text);
    }
    s
}

pub(crate) fn image_schema() -> String {
    with_deps(
        "# This message contains an uncompressed image\n# (0, 0) is at top-left corner of image\n\nstd_msgs/Header header # Header timestamp should be acquisition time of image\n                             # Header frame_id should be optical frame of camera\n\nuint32 height                # image height, that is, number of rows\nuint32 width                 # image width, that is, number of columns\n\n# The legal values for encoding are in file include/sensor_msgs/image_encodings.hpp\n# If you want to standardize a new string format, join\n# ros-users@lists.ros.org and send an email proposing a new encoding.\n\nstring encoding       # Encoding of pixels -- channel meaning, ordering, size\n                      # taken from the list of strings in include/sensor_msgs/image_encodings.hpp\n\nuint8 is_bigendian    # is this data bigendian?\nuint32 step           # Full row length in bytes\nuint8[] data          # actual matrix data, size is (step * rows)\n",
        &[("std_msgs/Header", HEADER_MSG), ("builtin_interfaces/Time", TIME_MSG)],
    )
}

fn compressed_schema() -> String {
    with_deps(
        "# This message contains a compressed image.\n\nstd_msgs/Header header # Header timestamp should be acquisition time of image\n                             # Header frame_id should be optical frame of camera\n\nstring format                # Specifies the format of the data\n                             #   Acceptable values:\n                             #     jpeg, png, tiff\n\nuint8[] data                 # Compressed image buffer\n",
        &[("std_msgs/Header", HEADER_MSG), ("builtin_interfaces/Time", TIME_MSG)],
    )
}

fn odometry_schema() -> String {
    with_deps(
        "# This represents an estimate of a position and velocity in free space.\n# The pose in this message should be specified in the coordinate frame given by header.frame_id\n# The twist in this message should be specified in the coordinate frame given by the child_frame_id\n\n# Includes the frame id of the pose parent.\nstd_msgs/Header header\n\n# Frame id the pose points to. The twist is in this coordinate frame.\nstring child_frame_id\n\n# Estimated pose that is typically relative to a fixed world frame.\ngeometry_msgs/PoseWithCovariance pose\n\n# Estimated linear and angular velocity relative to child_frame_id.\ngeometry_msgs/TwistWithCovariance twist\n",
        &[
            ("std_msgs/Header", HEADER_MSG),
            ("builtin_interfaces/Time", TIME_MSG),
            (
                "geometry_msgs/PoseWithCovariance",
                "Pose pose\nfloat64[36] covariance\n",
            ),
            ("geometry_msgs/Pose", "Point position\nQuaternion orientation\n"),
            ("geometry_msgs/Point", "float64 x\nfloat64 y\nfloat64 z\n"),
            (
                "geometry_msgs/Quaternion",
                "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n",
            ),
            (
                "geometry_msgs/TwistWithCovariance",
                "Twist twist\nfloat64[36] covariance\n",
            ),
            ("geometry_msgs/Twist", "Vector3  linear\nVector3  angular\n"),
            ("geometry_msgs/Vector3", "float64 x\nfloat64 y\nfloat64 z\n"),
        ],
    )
}

// ------------------------------------------------------------------- the bag writer

/// One message to write: topic, log time (ns), CDR bytes.
pub(crate) type Msg = (&'static str, u64, Vec<u8>);

/// Writes a rosbag2-style MCAP: profile `ros2`, one `ros2msg` schema and one `cdr`
/// channel per topic (with rosbag2's QoS metadata), chunked as rosbag2 does.
pub(crate) fn write_bag(path: &Path, topics: &[(&'static str, &str)], msgs: &[Msg]) {
    let mut w = mcap::WriteOptions::new()
        .profile("ros2")
        .chunk_size(Some(200_000))
        .compression(None)
        .create(std::io::BufWriter::new(std::fs::File::create(path).unwrap()))
        .unwrap();
    let mut ids = BTreeMap::new();
    for (topic, ty) in topics {
        let text = match *ty {
            "sensor_msgs/msg/Image" => image_schema(),
            "sensor_msgs/msg/CompressedImage" => compressed_schema(),
            "nav_msgs/msg/Odometry" => odometry_schema(),
            other => panic!("{other}"),
        };
        let schema = w.add_schema(ty, "ros2msg", text.as_bytes()).unwrap();
        let meta = BTreeMap::from([(
            "offered_qos_profiles".to_string(),
            "- history: 3\n  depth: 0\n  reliability: 1\n  durability: 2\n".to_string(),
        )]);
        ids.insert(*topic, w.add_channel(schema, topic, "cdr", &meta).unwrap());
    }
    for (seq, (topic, ns, data)) in msgs.iter().enumerate() {
        let header = mcap::records::MessageHeader {
            channel_id: ids[topic],
            sequence: seq as u32,
            log_time: *ns,
            publish_time: *ns,
        };
        w.write_to_known_channel(&header, data).unwrap();
    }
    w.finish().unwrap();
}

// ----------------------------------------------------------------------- the frames

pub(crate) fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("marsupial-replay-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A 256×240 crop of a real photo, with the flap painted in (image-left magenta, right
/// cyan: Bujold's camera is upside down) when `flap`.
fn frame(dir: &Path, name: &str, flap: bool) -> RgbImage {
    let im = marsupial::image_io::load_rgb(&dir.join(name)).unwrap();
    let mut out = RgbImage::new(256, 240);
    for y in 0..240 {
        for x in 0..256 {
            out.put(x, y, im.view().get(x + 20, y + 20).unwrap());
        }
    }
    if flap {
        let (l, r) = (NamedColor::Magenta.paint_srgb(), NamedColor::Cyan.paint_srgb());
        for y in 100..140 {
            (96..128).for_each(|x| out.put(x, y, l));
            (128..160).for_each(|x| out.put(x, y, r));
        }
    }
    out
}

const PHOTOS: [(&str, bool); 4] = [
    ("backgrounds/home.jpg", true),
    ("backgrounds/building.jpg", false),
    ("color/fruits.jpg", true),
    ("backgrounds/stuff.jpg", true),
];

fn bgr(im: &RgbImage) -> Vec<u8> {
    im.as_bytes().chunks(3).flat_map(|p| [p[2], p[1], p[0]]).collect()
}

fn jpeg(im: &RgbImage) -> Vec<u8> {
    let mut out = Vec::new();
    image::codecs::jpeg::JpegEncoder::new_with_quality(&mut out, 92)
        .encode(im.as_bytes(), 256, 240, image::ExtendedColorType::Rgb8)
        .unwrap();
    out
}

pub(crate) const T0: u64 = 1_700_000_000_000_000_000;
pub(crate) const DT: u64 = 100_000_000;

/// A bag with the photos as raw frames (rgb8 and bgr8 alternating, rows padded to 800
/// bytes), as JPEG, and odometry between frames. Returns the frames and the JPEG bytes.
pub(crate) fn photo_bag(path: &Path, dir: &Path) -> (Vec<RgbImage>, Vec<Vec<u8>>) {
    let frames: Vec<RgbImage> = PHOTOS.iter().map(|(n, f)| frame(dir, n, *f)).collect();
    let jpegs: Vec<Vec<u8>> = frames.iter().map(jpeg).collect();
    let mut msgs: Vec<Msg> = Vec::new();
    for (k, im) in frames.iter().enumerate() {
        let ns = T0 + k as u64 * DT;
        let (enc, px) = if k % 2 == 0 {
            ("rgb8", im.as_bytes().to_vec())
        } else {
            ("bgr8", bgr(im))
        };
        let mut padded = Vec::new();
        for row in px.chunks(256 * 3) {
            padded.extend_from_slice(row);
            padded.extend_from_slice(&[0xAA; 800 - 768]);
        }
        msgs.push(("/camera/image_raw", ns, image_msg(ns, 256, 240, enc, 800, &padded)));
        msgs.push((
            "/camera/image_raw/compressed",
            ns,
            compressed_msg(ns, "rgb8; jpeg compressed bgr8", &jpegs[k]),
        ));
        let o = ns + DT / 2;
        msgs.push((
            "/odom",
            o,
            odometry_msg(o, 0.1 * k as f64, 0.0, 0.05 * k as f64, 0.02, 0.01),
        ));
    }
    write_bag(
        path,
        &[
            ("/camera/image_raw", "sensor_msgs/msg/Image"),
            ("/camera/image_raw/compressed", "sensor_msgs/msg/CompressedImage"),
            ("/odom", "nav_msgs/msg/Odometry"),
        ],
        &msgs,
    );
    (frames, jpegs)
}

pub(crate) fn opts(log: &Path) -> ReplayOptions {
    ReplayOptions {
        log: log.to_path_buf(),
        profile: Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/bujold.toml"),
        image_topic: None,
        odom_topic: None,
        behavior: false,
        json: true,
        record: None,
    }
}

/// Runs a replay; the output lines parsed, and the result.
pub(crate) fn replay(o: &ReplayOptions) -> (Vec<serde_json::Value>, Result<(), ReplayCliError>) {
    let mut out = Vec::new();
    let r = run(o, &mut out).map(|_| ());
    let lines = String::from_utf8(out)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    (lines, r)
}

pub(crate) fn of_kind<'a>(lines: &'a [serde_json::Value], kind: &str) -> Vec<&'a serde_json::Value> {
    lines.iter().filter(|l| l["kind"] == kind).collect()
}

/// The `index` of each line (the message each frame or skip names).
fn indices(lines: &[&serde_json::Value]) -> Vec<u64> {
    lines.iter().map(|l| l["index"].as_u64().unwrap()).collect()
}

/// The percepts the schema gives on `frames` at 0, 0.1, 0.2 … s, as JSON.
pub(crate) fn expected(frames: &[RgbImage]) -> Vec<serde_json::Value> {
    let p = common::shipped_profile("bujold");
    let mut s = TwoBlockSchema::from_profile(&p, 0).unwrap();
    frames
        .iter()
        .enumerate()
        .map(|(k, im)| {
            let t = (k as u64 * DT) as f64 / 1e9;
            let pc = s.process(&im.view(), t).unwrap();
            serde_json::to_value(ObservedPercept::TwoBlock(pc)).unwrap()
        })
        .collect()
}

// ------------------------------------------------------------------------ the tests

#[test]
fn a_ros2_bag_of_real_photos_replays_as_the_schema_sees_them() {
    let Some(dir) = common::photos() else { return };
    let d = tmp("photos");
    let bag = d.join("photos.mcap");
    let (frames, jpegs) = photo_bag(&bag, &dir);

    // Two image topics: no guessing.
    let (_, r) = replay(&opts(&bag));
    let e = r.unwrap_err().to_string();
    assert!(
        e.contains("--image-topic") && e.contains("/camera/image_raw (sensor_msgs/msg/Image, cdr)"),
        "{e}"
    );
    assert!(
        e.contains("/camera/image_raw/compressed (sensor_msgs/msg/CompressedImage, cdr)"),
        "{e}"
    );

    // Raw rgb8 / bgr8: the percepts are the schema's on the very pixels.
    let mut o = opts(&bag);
    o.image_topic = Some("/camera/image_raw".into());
    let (lines, r) = replay(&o);
    r.unwrap();
    let got: Vec<_> = of_kind(&lines, "frame").iter().map(|l| l["percept"].clone()).collect();
    assert_eq!(got, expected(&frames));
    let found: Vec<bool> = of_kind(&lines, "frame").iter().map(|l| l["found"] == true).collect();
    assert!(
        found[2] && !found[1],
        "a painted flap is found, the bare photo gives nothing: {found:?}"
    );
    let summary = of_kind(&lines, "summary")[0];
    assert_eq!(summary["frames"], 4);
    assert_eq!(summary["odometry"], 4, "the only odometry topic is picked");
    assert_eq!(summary["odom_topic"], "/odom");
    assert_eq!(summary["skipped"].as_array().unwrap().len(), 0);
    let t: Vec<f64> = of_kind(&lines, "frame")
        .iter()
        .map(|l| l["t"].as_f64().unwrap())
        .collect();
    for (k, tk) in t.iter().enumerate() {
        assert!(
            (tk - k as f64 * 0.1).abs() < 1e-9,
            "header stamps give the clock: {t:?}"
        );
    }

    // JPEG: the schema on the JPEG decoded independently.
    o.image_topic = Some("/camera/image_raw/compressed".into());
    let (lines, r) = replay(&o);
    r.unwrap();
    let decoded: Vec<RgbImage> = jpegs
        .iter()
        .map(|j| {
            let im = image::load_from_memory(j).unwrap().to_rgb8();
            RgbImage::from_raw(256, 240, im.into_raw()).unwrap()
        })
        .collect();
    let got: Vec<_> = of_kind(&lines, "frame").iter().map(|l| l["percept"].clone()).collect();
    assert_eq!(got, expected(&decoded));
    assert!(of_kind(&lines, "frame").iter().any(|l| l["found"] == true));
}

#[test]
fn the_behavior_runs_open_loop_and_the_record_replays_the_same() {
    let Some(dir) = common::photos() else { return };
    let d = tmp("behavior");
    let bag = d.join("photos.mcap");
    let (frames, _) = photo_bag(&bag, &dir);
    let mut o = opts(&bag);
    o.image_topic = Some("/camera/image_raw".into());
    o.behavior = true;
    o.record = Some(d.join("out.mcap"));
    let (lines, r) = replay(&o);
    r.unwrap();
    let fl = of_kind(&lines, "frame");
    assert_eq!(fl.len(), 4);
    // Frame 0 comes before any odometry: the loop stops the robot, as on the robot.
    assert_eq!(fl[0]["status"]["status"], "safe_stop", "{}", fl[0]);
    assert_eq!(fl[0]["status"]["reason"]["input"], "odometry", "{}", fl[0]);
    assert_eq!((fl[0]["v"].as_f64(), fl[0]["omega"].as_f64()), (Some(0.0), Some(0.0)));
    for l in &fl[1..] {
        assert!(
            l["v"].as_f64().unwrap().is_finite() && l["omega"].as_f64().unwrap().is_finite(),
            "{l}"
        );
        assert_eq!(l["status"]["status"], "running", "{l}");
        assert!(!l["percept"].is_null(), "the agent exposes its percept: {l}");
    }
    assert!(
        fl.iter().any(|l| l["found"] == true),
        "the agent's own schema sees the painted flap"
    );

    // The recording holds the frames, percepts and commands …
    let bytes = std::fs::read(d.join("out.mcap")).unwrap();
    let mut counts = BTreeMap::<String, usize>::new();
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        *counts.entry(m.unwrap().channel.topic.clone()).or_default() += 1;
    }
    assert_eq!(counts["/cam0/image"], 4);
    assert_eq!(counts["/percept"], 3, "none in the safe stop of frame 0");
    assert_eq!(counts["/command"], 4);
    assert_eq!(counts["/odometry"], 4);

    // … and replaying it (frames as ROS 2 CDR, poses as Foxglove JSON) gives the schema's
    // percepts again.
    // Its /ground_truth is a pose too: the odometry topic must be named.
    let mut o2 = opts(&d.join("out.mcap"));
    let e = run(&o2, &mut Vec::new()).unwrap_err().to_string();
    assert!(
        e.contains("several odometry topics") && e.contains("/ground_truth ("),
        "{e}"
    );
    o2.odom_topic = Some("/odometry".into());
    let (lines, r) = replay(&o2);
    r.unwrap();
    assert_eq!(of_kind(&lines, "summary")[0]["odometry"], 4);
    let got: Vec<_> = of_kind(&lines, "frame").iter().map(|l| l["percept"].clone()).collect();
    // The recording's clock starts at its first frame, as the bag's did.
    assert_eq!(got, expected(&frames));
    assert_eq!(of_kind(&lines, "summary")[0]["image_kind"], "ros_image");
}

/// `sensor_msgs/msg/Image`, 2×1 rgb8, assembled byte by byte (offsets from the start of
/// the message; alignment counts from the end of the 4-byte encapsulation header).
const IMAGE_FIXTURE: [u8; 54] = [
    0x00, 0x01, 0x00, 0x00, // 0: encapsulation CDR_LE, options 0
    0x01, 0x00, 0x00, 0x00, // 4: header.stamp.sec = 1
    0xf4, 0x01, 0x00, 0x00, // 8: header.stamp.nanosec = 500
    0x04, 0x00, 0x00, 0x00, // 12: header.frame_id length 4 (NUL counted)
    b'c', b'a', b'm', 0x00, // 16: "cam\0"
    0x01, 0x00, 0x00, 0x00, // 20: height = 1
    0x02, 0x00, 0x00, 0x00, // 24: width = 2
    0x05, 0x00, 0x00, 0x00, // 28: encoding length 5
    b'r', b'g', b'b', b'8', 0x00, // 32: "rgb8\0"
    0x00, // 37: is_bigendian = 0
    0x00, 0x00, // 38: padding: step is a uint32, body offset 34 → 36
    0x06, 0x00, 0x00, 0x00, // 40: step = 6
    0x06, 0x00, 0x00, 0x00, // 44: data length 6
    0x0a, 0x14, 0x1e, 0x28, 0x32, 0x3c, // 48: data: (10,20,30) (40,50,60)
];

/// `nav_msgs/msg/Odometry`, assembled field by field: the strings byte by byte, the
/// float64s as their little-endian bytes, every offset checked.
fn odometry_fixture() -> Vec<u8> {
    let mut b: Vec<u8> = vec![
        0x00, 0x01, 0x00, 0x00, // 0: encapsulation CDR_LE
        0x02, 0x00, 0x00, 0x00, // 4: stamp.sec = 2
        0x00, 0xe1, 0xf5, 0x05, // 8: stamp.nanosec = 100_000_000
        0x05, 0x00, 0x00, 0x00, // 12: frame_id length 5
        b'o', b'd', b'o', b'm', 0x00, // 16: "odom\0"
        0x00, 0x00, 0x00, // 21: padding to body offset 20 (uint32)
        0x0a, 0x00, 0x00, 0x00, // 24: child_frame_id length 10
        b'b', b'a', b's', b'e', b'_', b'l', b'i', b'n', b'k', 0x00, // 28: "base_link\0"
        0x00, 0x00, 0x00, 0x00, 0x00, 0x00, // 38: padding: body offset 34 → 40 (float64)
    ];
    assert_eq!(b.len(), 44, "pose.pose.position.x starts at 44");
    let f = |b: &mut Vec<u8>, v: f64| b.extend_from_slice(&v.to_le_bytes());
    // 44: position (1.5, -0.25, 0); 68: orientation (0, 0, sin 0.25, cos 0.25) = yaw 0.5
    for v in [1.5, -0.25, 0.0, 0.0, 0.0, 0.25f64.sin(), 0.25f64.cos()] {
        f(&mut b, v);
    }
    assert_eq!(b.len(), 100);
    // 100: pose covariance, 36 float64: 0, 1, 2 …
    (0..36).for_each(|i| f(&mut b, i as f64));
    assert_eq!(b.len(), 388);
    // 388: linear (0.2, 0, 0); 412: angular (0, 0, -0.1)
    for v in [0.2, 0.0, 0.0, 0.0, 0.0, -0.1] {
        f(&mut b, v);
    }
    assert_eq!(b.len(), 436);
    // 436: twist covariance, 36 float64: −0, −1 …
    (0..36).for_each(|i| f(&mut b, -(i as f64)));
    assert_eq!(b.len(), 724);
    b
}

#[test]
fn hand_assembled_messages_decode_exactly() {
    let im = cdr::decode_image(&IMAGE_FIXTURE).unwrap();
    assert_eq!((im.header.stamp.sec, im.header.stamp.nanosec), (1, 500));
    assert_eq!(im.header.frame_id, "cam");
    assert_eq!(
        (im.width, im.height, im.encoding, im.is_bigendian, im.step),
        (2, 1, "rgb8", 0, 6)
    );
    assert_eq!(im.data, &[10, 20, 30, 40, 50, 60]);
    assert_eq!(im.to_rgb().unwrap().as_bytes(), &[10, 20, 30, 40, 50, 60]);
    // The test encoder writes the same bytes, so the bags below are real CDR.
    assert_eq!(
        IMAGE_FIXTURE.to_vec(),
        image_msg_in("cam", 1_000_000_500, 2, 1, "rgb8", 6, &[10, 20, 30, 40, 50, 60])
    );

    // One byte short anywhere is an error naming the field, never a panic.
    for n in 0..IMAGE_FIXTURE.len() {
        assert!(cdr::decode_image(&IMAGE_FIXTURE[..n]).is_err(), "{n} bytes");
    }
    let e = cdr::decode_image(&IMAGE_FIXTURE[..50]).unwrap_err();
    assert_eq!(
        e,
        cdr::CdrError::Truncated {
            offset: 48,
            field: "data",
            need: 6,
            left: 2
        }
    );

    let b = odometry_fixture();
    let o = cdr::decode_odometry(&b).unwrap();
    assert_eq!((o.header.stamp.sec, o.header.stamp.nanosec), (2, 100_000_000));
    assert_eq!((o.header.frame_id, o.child_frame_id), ("odom", "base_link"));
    assert_eq!(o.position, [1.5, -0.25, 0.0]);
    assert_eq!(o.orientation, [0.0, 0.0, 0.25f64.sin(), 0.25f64.cos()]);
    assert_eq!(o.pose_covariance[35], 35.0);
    assert_eq!((o.linear, o.angular), ([0.2, 0.0, 0.0], [0.0, 0.0, -0.1]));
    assert_eq!(o.twist_covariance[1], -1.0);
    let p = o.pose2();
    assert!((p.theta - 0.5).abs() < 1e-12, "{p:?}");
    // The test encoder writes the same bytes, so the bags below are real CDR.
    assert_eq!(b, odometry_msg_fixture_check());
}

/// The test encoder gives the fixture's bytes too (so the bag tests write real CDR).
fn odometry_msg_fixture_check() -> Vec<u8> {
    let mut c = Cdr::new();
    c.header(2_100_000_000, "odom").string("base_link");
    for v in [1.5, -0.25, 0.0, 0.0, 0.0, 0.25f64.sin(), 0.25f64.cos()] {
        c.f64(v);
    }
    (0..36).for_each(|i| {
        c.f64(i as f64);
    });
    for v in [0.2, 0.0, 0.0, 0.0, 0.0, -0.1] {
        c.f64(v);
    }
    (0..36).for_each(|i| {
        c.f64(-(i as f64));
    });
    c.0
}

/// A one-topic bag of small frames, some good, some not.
pub(crate) fn small_bag(path: &Path, msgs: Vec<Vec<u8>>) {
    let msgs: Vec<Msg> = msgs
        .into_iter()
        .enumerate()
        .map(|(k, m)| ("/cam", T0 + k as u64 * DT, m))
        .collect();
    write_bag(path, &[("/cam", "sensor_msgs/msg/Image")], &msgs);
}

pub(crate) fn good(k: u64) -> Vec<u8> {
    image_msg(T0 + k * DT, 32, 24, "rgb8", 96, &[90; 96 * 24])
}

pub(crate) fn replay_err(path: &Path) -> (Vec<serde_json::Value>, ReplayError) {
    replay_err_with(&opts(path))
}

#[test]
fn sixteen_bit_frames_are_refused_by_name_and_index() {
    let d = tmp("encodings");
    for (enc, bpp) in [("bayer_rggb16", 2), ("16UC1", 2), ("mono16", 2), ("nv24", 2)] {
        let bag = d.join(format!("{enc}.mcap"));
        let m = image_msg(T0, 32, 24, enc, 32 * bpp, &vec![7; 32 * 24 * bpp as usize]);
        small_bag(&bag, vec![m]);
        let (_, e) = replay_err(&bag);
        let text = e.to_string();
        assert!(
            matches!(&e, ReplayError::Unreadable { topic, count: 1, first_index: 0, .. } if topic == "/cam"),
            "{e:?}"
        );
        assert!(
            text.contains(enc) && text.contains("`/cam`") && text.contains("#0"),
            "{text}"
        );
    }
}

/// A 32×24 frame of `encoding`, `bytes_per_px` bytes a pixel and `rows_x2 / 2` rows of
/// data a frame row, every byte `v`.
fn flat(k: u64, encoding: &str, bytes_per_px: u32, rows_x2: usize, v: u8) -> Vec<u8> {
    let step = 32 * bytes_per_px;
    image_msg(
        T0 + k * DT,
        32,
        24,
        encoding,
        step,
        &vec![v; step as usize * 24 * rows_x2 / 2],
    )
}

#[test]
fn camera_encodings_replay_like_rgb() {
    let d = tmp("camera_encodings");
    let bag = d.join("cam.mcap");
    // Y′ = Cb = Cr = 128: grey 130 in BT.601 limited range; a flat mosaic is grey too.
    let msgs = vec![
        flat(0, "yuyv", 2, 2, 128),
        flat(1, "yuv422", 2, 2, 128),
        flat(2, "nv12", 1, 3, 128),
        flat(3, "bayer_rggb8", 1, 2, 130),
        image_msg(T0 + 4 * DT, 32, 24, "rgb8", 96, &[130; 96 * 24]),
    ];
    small_bag(&bag, msgs);
    let (lines, r) = replay(&opts(&bag));
    r.unwrap();
    let frames = of_kind(&lines, "frame");
    assert_eq!(frames.len(), 5, "{lines:?}");
    assert!(of_kind(&lines, "skipped").is_empty());
    // The same grey, so the same percept every time (but for its stamp).
    let percept = |f: &serde_json::Value| {
        let mut p = f["percept"]["two_block"].clone();
        p.as_object_mut().unwrap().remove("stamp");
        p
    };
    assert!(frames.iter().all(|f| percept(f) == percept(frames[4])), "{frames:?}");
}

#[test]
fn a_truncated_or_corrupt_jpeg_frame_is_skipped_as_missing() {
    let d = tmp("bad_jpeg");
    let bag = d.join("jpeg.mcap");
    let mut im = RgbImage::new(256, 240);
    im.fill([40, 160, 90]);
    let good_jpeg = jpeg(&im);
    let mut corrupt = good_jpeg.clone();
    corrupt[2..64].fill(0x5A);
    let msgs: Vec<Msg> = [&good_jpeg[..], &good_jpeg[..20], &good_jpeg[..], &corrupt[..]]
        .iter()
        .enumerate()
        .map(|(k, data)| {
            let ns = T0 + k as u64 * DT;
            ("/cam/compressed", ns, compressed_msg(ns, "jpeg", data))
        })
        .collect();
    write_bag(&bag, &[("/cam/compressed", "sensor_msgs/msg/CompressedImage")], &msgs);
    let (lines, r) = replay(&opts(&bag));
    r.unwrap();
    let frames = indices(&of_kind(&lines, "frame"));
    assert_eq!(frames, [0, 2]);
    let skipped = of_kind(&lines, "skipped");
    let indices = indices(&skipped);
    assert_eq!(indices, [1, 3]);
    for l in skipped {
        assert_eq!(l["reason"], "undecodable_image", "{l}");
        assert_eq!(l["topic"], "/cam/compressed", "{l}");
    }
}

#[test]
fn a_missing_topic_lists_the_topics() {
    let d = tmp("missing");
    let bag = d.join("one.mcap");
    small_bag(&bag, vec![good(0)]);
    let mut o = opts(&bag);
    o.image_topic = Some("/front/image".into());
    let Err(ReplayCliError::Replay(ReplayError::Topic {
        error: TopicError::Missing { topic, available },
        ..
    })) = run(&o, &mut Vec::new())
    else {
        panic!("expected a missing topic");
    };
    assert_eq!(topic, "/front/image");
    assert_eq!(available.len(), 1);
    assert_eq!(available[0].topic, "/cam");
    o.image_topic = None;
    o.odom_topic = Some("/odom".into());
    let e = run(&o, &mut Vec::new()).unwrap_err().to_string();
    assert!(
        e.contains("no topic `/odom`") && e.contains("/cam (sensor_msgs/msg/Image, cdr)"),
        "{e}"
    );
}

#[test]
fn a_truncated_file_gives_its_frames_then_names_where_it_broke() {
    let d = tmp("truncated");
    let bag = d.join("full.mcap");
    // 12 frames of 2.3 kB in 10 kB chunks: several chunks; cut in the middle.
    let msgs: Vec<Msg> = (0..12).map(|k| ("/cam", T0 + k * DT, good(k))).collect();
    let mut w = mcap::WriteOptions::new()
        .profile("ros2")
        .chunk_size(Some(10_000))
        .compression(None)
        .create(std::io::BufWriter::new(std::fs::File::create(&bag).unwrap()))
        .unwrap();
    let s = w
        .add_schema("sensor_msgs/msg/Image", "ros2msg", image_schema().as_bytes())
        .unwrap();
    let c = w.add_channel(s, "/cam", "cdr", &BTreeMap::new()).unwrap();
    for (k, (_, ns, m)) in msgs.iter().enumerate() {
        let h = mcap::records::MessageHeader {
            channel_id: c,
            sequence: k as u32,
            log_time: *ns,
            publish_time: *ns,
        };
        w.write_to_known_channel(&h, m).unwrap();
    }
    w.finish().unwrap();
    let bytes = std::fs::read(&bag).unwrap();
    let cut = d.join("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let (lines, e) = replay_err(&cut);
    let frames = of_kind(&lines, "frame").len() as u64;
    assert!(frames > 0 && frames < 12, "{frames} frames before the cut");
    match &e {
        ReplayError::Log {
            fault: LogFault::Truncated { after: Some((t, i)) },
            ..
        } => assert_eq!((t.as_str(), *i), ("/cam", frames - 1)),
        other => panic!("{other:?}"),
    }
    let text = e.to_string();
    assert!(
        text.contains("truncated") && text.contains(&format!("#{}", frames - 1)),
        "{text}"
    );
    assert_eq!(
        of_kind(&lines, "summary")[0]["frames"],
        frames,
        "the summary still comes"
    );

    // Cut inside the magic: not MCAP at all.
    std::fs::write(&cut, &bytes[..5]).unwrap();
    let (_, e) = replay_err(&cut);
    assert!(
        matches!(
            e,
            ReplayError::Log {
                fault: LogFault::NotMcap { .. },
                ..
            }
        ),
        "{e:?}"
    );
}

#[test]
fn bad_cdr_is_named_by_topic_and_index() {
    let d = tmp("badcdr");
    let bag = d.join("bad.mcap");
    let mut m = good(0);
    m.truncate(40); // inside the encoding string
    small_bag(&bag, vec![m]);
    let (lines, e) = replay_err(&bag);
    let text = e.to_string();
    assert!(
        text.contains("`/cam`") && text.contains("#0") && text.contains("CDR"),
        "{text}"
    );
    let skipped = of_kind(&lines, "skipped");
    assert_eq!(skipped.len(), 1);
    assert_eq!(skipped[0]["reason"], "cdr");
    assert_eq!(skipped[0]["index"], 0);
}

#[test]
fn a_half_readable_topic_reports_what_was_skipped_and_goes_on() {
    let d = tmp("half");
    let bag = d.join("half.mcap");
    let mut xcdr2 = good(3);
    xcdr2[1] = 0x07; // CDR2_LE encapsulation
    let nv24 = image_msg(T0, 32, 24, "nv24", 32, &[1; 32 * 24]);
    small_bag(&bag, vec![good(0), nv24.clone(), good(2), xcdr2, nv24, good(5)]);
    let (lines, r) = replay(&opts(&bag));
    r.unwrap();
    let frames = indices(&of_kind(&lines, "frame"));
    assert_eq!(frames, [0, 2, 5]);
    let s = &of_kind(&lines, "summary")[0]["skipped"];
    assert_eq!(s[0]["reason"], "cdr");
    assert_eq!(
        (s[0]["count"].as_u64(), s[0]["first_index"].as_u64()),
        (Some(1), Some(3))
    );
    assert!(s[0]["first_why"].as_str().unwrap().contains("0x0007"), "{s}");
    assert_eq!(s[1]["reason"], "unsupported_encoding");
    assert_eq!(
        (s[1]["count"].as_u64(), s[1]["first_index"].as_u64()),
        (Some(2), Some(1))
    );
    assert!(s[1]["first_why"].as_str().unwrap().contains("nv24"), "{s}");

    // The table says the same in words.
    let mut o = opts(&bag);
    o.json = false;
    let mut out = Vec::new();
    run(&o, &mut out).unwrap();
    let text = String::from_utf8(out).unwrap();
    assert!(
        text.contains("skipped 2 messages of /cam (unsupported_encoding), first #1"),
        "{text}"
    );
    assert!(text.contains("skipped 1 messages of /cam (cdr), first #3"), "{text}");
    assert!(text.contains("3 frames from /cam"), "{text}");
}

#[test]
fn a_frame_of_another_size_stops_the_behavior() {
    let d = tmp("size");
    let bag = d.join("size.mcap");
    small_bag(&bag, vec![good(0)]);
    let mut o = opts(&bag);
    o.behavior = true;
    let e = run(&o, &mut Vec::new()).unwrap_err();
    assert!(
        matches!(
            &e,
            ReplayCliError::Replay(ReplayError::FrameSize {
                index: 0,
                got: (32, 24),
                expected: (256, 240),
                ..
            })
        ),
        "{e:?}"
    );
}

/// A rosbag2-style log of three 32×24 frames (`good(0..3)` on `/cam`) in zstd-compressed
/// chunks, written once by the `mcap` crate with its C zstd encoder, as libmcap writes
/// (`tests/fixtures/replay/zstd.mcap`).
pub(crate) fn zstd_fixture() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/replay/zstd.mcap")
}

#[test]
fn a_zstd_bag_from_a_c_encoder_replays_in_the_default_build() {
    let bytes = std::fs::read(zstd_fixture()).unwrap();
    let raw: usize = (0..3).map(|k| good(k).len()).sum();
    assert!(bytes.len() < raw, "the chunks are compressed");
    let (lines, r) = replay(&opts(&zstd_fixture()));
    r.unwrap();
    let d = tmp("zstd-twin");
    let twin = d.join("plain.mcap");
    small_bag(&twin, (0..3).map(good).collect());
    let (plain, r) = replay(&opts(&twin));
    r.unwrap();
    assert_eq!(of_kind(&lines, "frame").len(), 3);
    assert_eq!(of_kind(&lines, "frame"), of_kind(&plain, "frame"));
}

proptest::proptest! {
    /// The decoders are total: any bytes (here the fixtures with bytes overwritten and
    /// cut short) give a value or an error, never a panic, and a decoded image converts
    /// or refuses without one either.
    #[test]
    fn decoders_never_panic(
        edits in proptest::collection::vec((0usize..724, proptest::prelude::any::<u8>()), 0..8),
        cut in 0usize..800,
    ) {
        let mut img = IMAGE_FIXTURE.to_vec();
        let mut odo = odometry_fixture();
        for (at, b) in &edits {
            if let Some(x) = img.get_mut(*at) { *x = *b; }
            if let Some(x) = odo.get_mut(*at) { *x = *b; }
        }
        img.truncate(cut);
        odo.truncate(cut);
        if let Ok(m) = cdr::decode_image(&img) {
            let _ = m.to_rgb();
        }
        if let Ok(m) = cdr::decode_compressed_image(&img) {
            let _ = m.to_rgb();
        }
        let _ = cdr::decode_odometry(&odo);
        let _ = cdr::decode_image(&odo);
        let _ = marsupial::replay::foxglove::decode_raw_image(&img);
        let _ = marsupial::replay::foxglove::decode_pose_in_frame(&odo);
    }
}

#[test]
fn the_pyramid_schema_replays_raposa_frames_and_needs_its_camera_aspect() {
    let Some(dir) = common::photos() else { return };
    let d = tmp("raposa");
    let bag = d.join("raposa.mcap");
    // 160×120 crops of real fruit (orange among them), as bgr8.
    let crop = |name: &str, x0: usize, y0: usize| {
        let im = marsupial::image_io::load_rgb(&dir.join(name)).unwrap();
        let mut out = RgbImage::new(160, 120);
        for y in 0..120 {
            for x in 0..160 {
                out.put(x, y, im.view().get(x0 + x, y0 + y).unwrap());
            }
        }
        out
    };
    let frames = [crop("color/orange.jpg", 40, 40), crop("color/fruits.jpg", 100, 60)];
    let msgs: Vec<Msg> = frames
        .iter()
        .enumerate()
        .map(|(k, im)| {
            let ns = T0 + k as u64 * DT;
            ("/rear/image", ns, image_msg(ns, 160, 120, "bgr8", 480, &bgr(im)))
        })
        .collect();
    write_bag(&bag, &[("/rear/image", "sensor_msgs/msg/Image")], &msgs);
    let mut o = opts(&bag);
    o.profile = Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/raposa.toml");
    let (lines, r) = replay(&o);
    r.unwrap();
    let mut s = marsupial::schemas::PyramidSchema::from_profile(&common::shipped_profile("raposa"), 0).unwrap();
    let want: Vec<_> = frames
        .iter()
        .enumerate()
        .map(|(k, im)| {
            let p = s.process(&im.view(), (k as u64 * DT) as f64 / 1e9).unwrap();
            serde_json::to_value(ObservedPercept::Pyramid(p)).unwrap()
        })
        .collect();
    let got: Vec<_> = of_kind(&lines, "frame").iter().map(|l| l["percept"].clone()).collect();
    assert_eq!(got, want);
    assert!(got[0]["pyramid"].is_object(), "{}", got[0]);

    // Frames of another size with the camera's aspect ratio are rescaled to it (32×24
    // to 160×120, `marsupial::msgs::rescale`) ...
    small_bag(&bag, vec![good(0)]);
    let (lines, r) = replay(&o);
    r.unwrap();
    let frames = of_kind(&lines, "frame");
    assert_eq!(frames.len(), 1);
    assert_eq!(
        (frames[0]["width"].as_u64(), frames[0]["height"].as_u64()),
        (Some(32), Some(24))
    );
    // ... and of another ratio refused, not stretched.
    small_bag(&bag, vec![image_msg(T0, 32, 20, "rgb8", 96, &[90; 96 * 20])]);
    let (_, e) = replay_err_with(&o);
    assert!(e.to_string().contains("another aspect ratio"), "{e}");
    assert!(
        matches!(
            &e,
            ReplayError::FrameSize {
                got: (32, 20),
                expected: (160, 120),
                ..
            }
        ),
        "{e:?}"
    );
}

pub(crate) fn replay_err_with(o: &ReplayOptions) -> (Vec<serde_json::Value>, ReplayError) {
    let (lines, r) = replay(o);
    match r {
        Err(ReplayCliError::Replay(e)) => (lines, e),
        other => panic!("expected a replay error, got {other:?}"),
    }
}

#[test]
fn a_directory_an_empty_file_and_a_pipe_are_read_not_mapped() {
    // The log is mapped into memory; what cannot be mapped is read, and refused by name
    // when it is not a log.
    let d = tmp("unmappable");
    // A directory is a rosbag2 bag: without its metadata.yaml it is refused by that name.
    let (_, e) = replay_err(&d);
    assert!(
        matches!(&e, ReplayError::Bag { path, .. } if path == &d.join("metadata.yaml")),
        "{e:?}"
    );
    let empty = d.join("empty.mcap");
    std::fs::write(&empty, b"").unwrap();
    let (_, e) = replay_err(&empty);
    assert!(e.to_string().contains("not an MCAP file"), "{e}");
    // A bag through a pipe (a FIFO cannot be mapped) replays as the file does.
    let bag = d.join("one.mcap");
    small_bag(&bag, vec![good(0), good(1)]);
    let fifo = d.join("fifo.mcap");
    let _ = std::fs::remove_file(&fifo);
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    if !made.is_ok_and(|s| s.success()) {
        eprintln!("no mkfifo here; the pipe case is skipped");
        return;
    }
    let bytes = std::fs::read(&bag).unwrap();
    let writer = std::thread::spawn({
        let fifo = fifo.clone();
        move || std::fs::write(fifo, bytes).unwrap()
    });
    let (piped, r) = replay(&opts(&fifo));
    writer.join().unwrap();
    assert!(r.is_ok(), "{r:?}");
    let (direct, r) = replay(&opts(&bag));
    assert!(r.is_ok(), "{r:?}");
    assert_eq!(of_kind(&piped, "frame"), of_kind(&direct, "frame"));
    assert_eq!(of_kind(&direct, "frame").len(), 2);
}
