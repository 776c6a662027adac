//! MCAP recordings of runs (`marsupial dock --record`, `trials --record-dir`): the
//! channels and schemas a run's file holds, one message per tick (per camera) where
//! there should be, a frame that decodes to the simulator's own frame byte for byte, the
//! same file for the same run, an unchanged run record, and `--record-failed` keeping only
//! the failed runs' files.

use crate::common;

use base64::Engine as _;
use marsupial::behaviors::agent_for;
use marsupial::sim::campaign::{self, CampaignOptions, RecordRuns, Recording};
use marsupial::sim::record::RecordOptions;
use marsupial::sim::scenario::Scenario;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("marsupial-mcap-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Bujold 0.7 m out on the dock's axis, no departure, 4 s of docking (40 ticks).
const SHORT: &str = "seed = 11\ntrials = 1\ntimeout_s = 4.0\n[imprint]\nenabled = false\n[starts]\npoints = [ { x_m = 0.7, y_m = 0.0, heading_deg = 0.0 } ]\n";

/// Every message of a recording: topic → (schema name, message encoding, payloads).
type Topics = BTreeMap<String, (String, String, Vec<Vec<u8>>)>;

fn read(path: &Path) -> Topics {
    let bytes = std::fs::read(path).unwrap();
    let mut topics = Topics::new();
    let mut last = 0;
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        assert!(
            m.log_time >= last || m.channel.topic == "/log",
            "time goes back on {}",
            m.channel.topic
        );
        last = last.max(m.log_time);
        let schema = m.channel.schema.as_ref().unwrap();
        // Raw frames are ROS 2 CDR; everything else is JSON.
        let expected = if schema.name == "sensor_msgs/msg/Image" {
            "ros2msg"
        } else {
            "jsonschema"
        };
        assert_eq!(schema.encoding, expected);
        let e = topics
            .entry(m.channel.topic.clone())
            .or_insert_with(|| (schema.name.clone(), m.channel.message_encoding.clone(), Vec::new()));
        e.2.push(m.data.into_owned());
    }
    topics
}

fn json(b: &[u8]) -> serde_json::Value {
    serde_json::from_slice(b).unwrap()
}

/// Runs the short dock, recording to `file` (and every frame as PNG to `frames`).
fn short_run(d: &Path, file: &Path, frames: Option<&Path>, opts: RecordOptions) -> campaign::RunRecord {
    let s = common::scenario_file(d, "short", "bujold.toml", SHORT);
    let p = campaign::prepare(Scenario::load(&s).unwrap()).unwrap();
    let mut rec = Recording {
        frames: frames.map(|f| (f, 1)),
        trace: None,
        mcap: Some((file, opts)),
    };
    campaign::run_one(&p, &p.runs[0], &agent_for, &mut rec).unwrap()
}

#[test]
fn a_run_records_every_channel_and_the_frames_byte_for_byte() {
    let d = dir("run");
    let frames = d.join("frames");
    std::fs::create_dir_all(&frames).unwrap();
    let file = d.join("run.mcap");
    let record = short_run(&d, &file, Some(&frames), RecordOptions::default());
    let topics = read(&file);
    let names: Vec<(&str, &str)> = topics.iter().map(|(t, (s, _, _))| (t.as_str(), s.as_str())).collect();
    assert_eq!(
        names,
        [
            ("/cam0/annotations", "foxglove.ImageAnnotations"),
            ("/cam0/calibration", "foxglove.CameraCalibration"),
            ("/cam0/image", "sensor_msgs/msg/Image"),
            ("/colour_ranges", "marsupial.ColourRanges"),
            ("/command", "marsupial.MotorCommand"),
            ("/ground_truth", "foxglove.PoseInFrame"),
            ("/log", "foxglove.Log"),
            ("/odometry", "foxglove.PoseInFrame"),
            ("/percept", "marsupial.Percept"),
            ("/tf", "foxglove.FrameTransform"),
            ("/trace", "marsupial.TraceLine"),
        ]
    );
    for (topic, (_, enc, _)) in &topics {
        assert_eq!(enc, if topic == "/cam0/image" { "cdr" } else { "json" }, "{topic}");
    }
    // The summary a viewer seeks with: statistics, channels and chunk indexes.
    let bytes = std::fs::read(&file).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().expect("a summary section");
    let stats = summary.stats.as_ref().unwrap();
    let total: usize = topics.values().map(|(_, _, m)| m.len()).sum();
    assert_eq!(stats.message_count as usize, total);
    assert_eq!(summary.channels.len(), topics.len());
    assert!(!summary.chunk_indexes.is_empty());
    // One command per tick: the loop ran 4 s at 10 Hz.
    let ticks = topics["/command"].2.len();
    assert_eq!(ticks, (record.time_s * 10.0).round() as usize, "{record:?}");
    let cameras = 1;
    for t in ["/cam0/image", "/cam0/calibration"] {
        assert_eq!(topics[t].2.len(), ticks * cameras, "{t}");
    }
    for t in [
        "/cam0/annotations",
        "/percept",
        "/colour_ranges",
        "/trace",
        "/odometry",
        "/ground_truth",
    ] {
        assert_eq!(topics[t].2.len(), ticks, "{t}");
    }
    // Per tick dock→base_link; at the mission's start dock→odom and base_link→cam0.
    assert_eq!(topics["/tf"].2.len(), ticks + 2);
    // Log: the run's start, the mission's, the world's timeout, the outcome.
    let log: Vec<String> = topics["/log"]
        .2
        .iter()
        .map(|b| json(b)["message"].as_str().unwrap().to_string())
        .collect();
    assert!(log[0].starts_with("run 0 of short"), "{log:?}");
    assert!(log.last().unwrap().contains(&record.outcome), "{log:?}");
    // And the library's own `tracing` events of the run (the arbiters' and the loop's),
    // under their targets, at debug level and above.
    let traced: Vec<(String, u64, String)> = topics["/log"]
        .2
        .iter()
        .map(|b| json(b))
        .filter(|l| l["name"] != "marsupial::sim")
        .map(|l| {
            (
                l["name"].as_str().unwrap().to_string(),
                l["level"].as_u64().unwrap(),
                l["message"].as_str().unwrap().to_string(),
            )
        })
        .collect();
    assert!(
        traced.iter().any(|(name, level, message)| name == "marsupial::arbiter"
            && *level == 1
            && message.starts_with("sequencer transition arbiter=close_dock from=search to=approach")),
        "{traced:?}"
    );
    assert!(
        traced
            .iter()
            .all(|(name, level, _)| name.starts_with("marsupial::") && (1..=4).contains(level)),
        "{traced:?}"
    );
    // The trace is the --trace line; the command carries its twist.
    let first = json(&topics["/trace"].2[0]);
    assert_eq!(first["mission"], "docking");
    assert!(first["nodes"].as_array().is_some_and(|n| !n.is_empty()), "{first}");
    let cmd = json(&topics["/command"].2[5]);
    assert!(cmd["v"].is_number() && cmd["omega"].is_number(), "{cmd}");
    // The percept is the two-block flap's, with its SCT ranges.
    let percept = json(&topics["/percept"].2[ticks - 1]);
    assert!(percept["percept"]["two_block"]["found"].is_boolean(), "{percept}");
    assert!(
        json(&topics["/colour_ranges"].2[0])["sct"]
            .as_array()
            .is_some_and(|r| r.len() == 2)
    );
    // Frames: CDR rgb8, equal to the PNG the simulator saved for that tick, decoded by
    // the replay's CDR reader (as a ROS 2 tool or Foxglove would read it).
    for k in [0, ticks / 2, ticks - 1] {
        let im = marsupial::msgs::cdr::decode_image(&topics["/cam0/image"].2[k]).unwrap();
        assert_eq!((im.encoding, im.is_bigendian, im.header.frame_id), ("rgb8", 0, "cam0"));
        let (w, h) = (u64::from(im.width), u64::from(im.height));
        assert_eq!(u64::from(im.step), w * 3);
        let png = marsupial::image_io::load_rgb(&frames.join(format!("frame-{:05}-cam0.png", k + 1))).unwrap();
        assert_eq!((png.width() as u64, png.height() as u64), (w, h));
        assert!(
            im.data == png.as_bytes(),
            "tick {k}: the recorded frame differs from the simulator's"
        );
    }
    // Timestamps: the simulation clock, 0.1 s per tick.
    let im = marsupial::msgs::cdr::decode_image(&topics["/cam0/image"].2[3]).unwrap();
    assert_eq!(im.header.stamp.ns(), Some(300_000_000));
    // Calibration: the profile's pin-hole intrinsics.
    let cal = json(&topics["/cam0/calibration"].2[0]);
    assert_eq!(cal["K"].as_array().unwrap().len(), 9);
    assert_eq!(cal["distortion_model"], "plumb_bob");
    // Recording did not change the run.
    let s = common::scenario_file(&d, "short", "bujold.toml", SHORT);
    let p = campaign::prepare(Scenario::load(&s).unwrap()).unwrap();
    let plain = campaign::run_one(&p, &p.runs[0], &agent_for, &mut Recording::default()).unwrap();
    assert_eq!(
        serde_json::to_string(&plain).unwrap(),
        serde_json::to_string(&record).unwrap()
    );
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn the_same_run_records_the_same_file_and_jpeg_frames_decode() {
    let d = dir("same");
    let (a, b) = (d.join("a.mcap"), d.join("b.mcap"));
    short_run(&d, &a, None, RecordOptions::default());
    short_run(&d, &b, None, RecordOptions::default());
    assert!(
        std::fs::read(&a).unwrap() == std::fs::read(&b).unwrap(),
        "two recordings of one run differ"
    );
    let j = d.join("jpeg.mcap");
    short_run(
        &d,
        &j,
        None,
        RecordOptions {
            jpeg: true,
            ..RecordOptions::default()
        },
    );
    let topics = read(&j);
    let (schema, _, images) = &topics["/cam0/image"];
    assert_eq!(schema, "foxglove.CompressedImage");
    assert_eq!(images.len(), topics["/command"].2.len());
    let im = json(&images[0]);
    assert_eq!(im["format"], "jpeg");
    let data = base64::engine::general_purpose::STANDARD
        .decode(im["data"].as_str().unwrap())
        .unwrap();
    assert_eq!(&data[..2], &[0xFF, 0xD8], "not a JPEG");
    assert!(std::fs::metadata(&j).unwrap().len() * 3 < std::fs::metadata(&a).unwrap().len());
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn record_failed_keeps_only_the_failed_runs_recorded_as_they_ran() {
    // A scripted backer: on the axis it docks; 6 cm off it, it catches the entrance.
    let d = dir("failed");
    let s = common::scenario_file(
        &d,
        "two",
        "bujold.toml",
        "seed = 11\ntrials = 1\ntimeout_s = 15.0\n[imprint]\nenabled = false\n[starts]\npoints = [ { x_m = 0.3, y_m = 0.0, heading_deg = 0.0 }, { x_m = 0.3, y_m = 0.06, heading_deg = 0.0 } ]\n[motion]\nslip_scale = 0.0\n",
    );
    let p = campaign::prepare(Scenario::load(&s).unwrap()).unwrap();
    let rec_dir = d.join("rec");
    let run = |failed_only: bool| {
        let _ = std::fs::remove_dir_all(&rec_dir);
        let opts = CampaignOptions {
            jobs: 2,
            record: Some(RecordRuns {
                dir: rec_dir.clone(),
                failed_only,
                options: RecordOptions::default(),
            }),
            ..Default::default()
        };
        let (records, _) = campaign::run_campaign(&p, &common::backer, &opts).unwrap();
        let mut files: Vec<String> = std::fs::read_dir(&rec_dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        files.sort();
        (records, files)
    };
    let (records, all) = run(false);
    assert_eq!(all, ["run-00000.mcap", "run-00001.mcap"]);
    let failed: Vec<String> = records
        .iter()
        .filter(|r| !r.success)
        .map(|r| format!("run-{:05}.mcap", r.index))
        .collect();
    assert_eq!(failed, ["run-00001.mcap"], "{records:?}");
    let recorded = std::fs::read(rec_dir.join(&failed[0])).unwrap();
    let (again, kept) = run(true);
    assert_eq!(kept, failed);
    assert_eq!(again, records, "recording changed the runs");
    // The failed run, recorded by running it again, is the same file as when every run
    // is recorded as it goes.
    assert!(std::fs::read(rec_dir.join(&failed[0])).unwrap() == recorded);
    let _ = std::fs::remove_dir_all(&d);
}
