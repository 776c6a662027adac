//! `marsupial replay` of an AutoKrawler belly-camera log: a log recorded here as
//! `marsupial dock --record` writes one (Foxglove MCAP, JPEG frames and odometry), of the gear with
//! its wheels turning at the profile's traverse speed for 2 s, then stalled. Replayed
//! alone, the estimator's θ follows the wheels and then holds; replayed with the whole
//! behavior, the tree traverses until the slip monitor sees the stall and halts.

use crate::common::krawler::Rig;

use marsupial::cli::replay::{ReplayOptions, run};
use marsupial::geometry::Pose2;
use marsupial::perception::RgbImage;
use marsupial::sim::record::{McapRecorder, RecordOptions};
use marsupial::sim::render::SensorParams;
use std::path::{Path, PathBuf};

const FPS: f64 = 30.0;
const MOVING_FRAMES: usize = 60;
const FRAMES: usize = 120;

/// The wheels' true θ at frame `k`: 0.05 m/s over the 0.115 m tread for 2 s, then stalled.
fn theta(k: usize) -> f64 {
    0.05 / 0.115 * k.min(MOVING_FRAMES) as f64 / FPS
}

/// Records the log once per test process.
fn log() -> PathBuf {
    static LOG: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    LOG.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("marsupial-krawler-replay-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("belly.mcap");
        // A noisy sensor, as a real camera's: noise-free frames of the stalled gear would be
        // bit-identical, which the loop takes for a frozen camera.
        let mut rig = Rig::new(SensorParams::default(), 3);
        let opts = RecordOptions {
            jpeg: true,
            jpeg_quality: 92,
        };
        let mut rec = McapRecorder::create(&path, &rig.profile.cameras.clone(), opts).unwrap();
        let cam = &rig.profile.cameras[0];
        let mut frame = RgbImage::new(cam.width_px, cam.height_px);
        for k in 0..FRAMES {
            let mut state = rig.rest;
            state.wheel = [theta(k); 4];
            rig.render(&state, &mut frame);
            let t = k as f64 / FPS;
            rec.perception(t, std::slice::from_ref(&frame), None);
            // The encoders' odometry: the rover rolls while its wheels turn.
            rec.odometry(t, &Pose2::new(theta(k) * 0.115, 0.0, 0.0));
        }
        rec.finish().unwrap();
        path
    })
    .clone()
}

fn replay(behavior: bool) -> Vec<serde_json::Value> {
    let o = ReplayOptions {
        log: log(),
        profile: Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/autokrawler.toml"),
        image_topic: None,
        odom_topic: Some("/odometry".into()),
        behavior,
        json: true,
        record: None,
    };
    let mut out = Vec::new();
    run(&o, &mut out).unwrap();
    let lines: Vec<serde_json::Value> = String::from_utf8(out)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    lines.into_iter().filter(|l| l["kind"] == "frame").collect()
}

fn wheels(line: &serde_json::Value) -> Vec<f64> {
    let w = &line["percept"]["krawler"]["wheel_rad"];
    (0..4).map(|i| w[i].as_f64().unwrap()).collect()
}

#[test]
fn the_estimator_alone_follows_the_logged_wheels_and_holds_when_they_stall() {
    let frames = replay(false);
    assert_eq!(frames.len(), FRAMES);
    for l in &frames {
        assert_eq!(l["found"], true, "all eight markers in every frame: {l}");
    }
    let moving = wheels(&frames[MOVING_FRAMES]);
    let truth = theta(MOVING_FRAMES);
    for (i, w) in moving.iter().enumerate() {
        assert!((w - truth).abs() < 0.15 * truth, "wheel {i}: θ {w} against {truth}");
    }
    let last = wheels(frames.last().unwrap());
    for (a, b) in last.iter().zip(&moving) {
        assert!((a - b).abs() < 0.02, "stalled wheels read still: {b} then {a}");
    }
}

#[test]
fn the_behavior_replays_open_loop_and_halts_on_the_logged_stall() {
    let frames = replay(true);
    assert_eq!(frames.len(), FRAMES);
    let status = |l: &serde_json::Value| l["status"]["status"].as_str().unwrap().to_string();
    let finished = frames
        .iter()
        .position(|l| status(l) == "finished")
        .expect("the stall is caught");
    for l in &frames[..MOVING_FRAMES] {
        assert_eq!(status(l), "running", "{l}");
        assert!(l["v"].as_f64().unwrap() > 0.0, "the traverse drives: {l}");
    }
    // The first full window after the stall (1 s) catches it.
    assert!(
        (MOVING_FRAMES..MOVING_FRAMES + 2 * FPS as usize).contains(&finished),
        "caught at frame {finished}"
    );
    let outcome = frames[finished]["status"]["outcome"].to_string();
    assert!(outcome.contains("stuck_contact"), "{outcome}");
    assert_eq!(frames.last().unwrap()["v"].as_f64(), Some(0.0));
    assert!(
        !frames[0]["percept"]["krawler"].is_null(),
        "the agent exposes its estimate"
    );
}
