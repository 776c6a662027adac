//! `marsupial estimate` (seed 003 Table I) on short rendered sequences: it writes its
//! files with sane errors, bad sequence files are refused naming the field, the same
//! seed gives the same summary bit for bit, and the error knobs degrade what they
//! should.

use crate::common;

use marsupial::cli::estimate::{DOF_NAMES, EstimateOptions, estimate, run};
use marsupial::cli::estimate_runtime::{RuntimePath, estimate_runtime, estimate_threads};
use marsupial::sim::krawler_sequence::SequenceSpec;
use std::path::{Path, PathBuf};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("marsupial-estimate-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A turn into a steering sweep, then rocking in place: every kind of motion within
/// `seconds`.
fn short(seconds: f64, extra: &str) -> String {
    let third = seconds / 3.0;
    format!(
        "name = \"short\"\nduration_s = {seconds}\nseed = 9\n\
         [[segments]]\nkind = \"turn\"\nduration_s = {third}\nsteer_deg = 20.0\n\
         [[segments]]\nkind = \"sweep\"\nduration_s = {third}\nsteer_deg = 30.0\n\
         [[segments]]\nkind = \"articulate\"\nduration_s = {third}\nspeed_scale = 0.0\n{extra}"
    )
}

fn profile_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/autokrawler.toml")
}

#[test]
fn the_command_writes_its_files_with_sane_errors() {
    let dir = tmp("files");
    let seq = dir.join("short.toml");
    std::fs::write(&seq, short(3.0, "")).unwrap();
    let out_dir = dir.join("out");
    let opts = EstimateOptions {
        sequence: seq.to_string_lossy().into_owned(),
        out: Some(out_dir.clone()),
        seed: None,
        profile: profile_path(),
        json: false,
        no_mount_compensation: false,
        runtime: None,
    };
    let mut printed = Vec::new();
    let s = run(&opts, &mut printed).unwrap();
    let printed = String::from_utf8(printed).unwrap();
    println!("{printed}");
    assert!(
        printed.contains("Table I") && printed.contains("ours short"),
        "{printed}"
    );
    assert_eq!((s.frames, s.delivered), (90, 90));
    for name in DOF_NAMES {
        assert!(out_dir.join(format!("{name}.svg")).is_file(), "{name}.svg");
    }
    let csv = std::fs::read_to_string(out_dir.join("frames.csv")).unwrap();
    assert_eq!(csv.lines().count(), 91, "a header and one line per frame");
    assert!(csv.starts_with("frame,t_s,roll_f_true,roll_f_est,roll_f_valid"));
    assert_eq!(
        std::fs::read_to_string(out_dir.join("odometry.csv"))
            .unwrap()
            .lines()
            .count(),
        91
    );
    assert!(out_dir.join("odometry.svg").is_file());
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out_dir.join("summary.json")).unwrap()).unwrap();
    assert_eq!(json["frames"], 90);
    assert_eq!(json, s.to_json());
    // Sane: well inside the paper's figures on exact, noisy renders.
    for (k, limit) in [(0, 0.3), (1, 0.3), (2, 2.0), (3, 2.0), (4, 1.0), (5, 1.0)] {
        let e = &s.dof[k];
        assert!(e.mae < limit, "{}: MAE {}", DOF_NAMES[k], e.mae);
        assert_eq!(e.valid, 1.0, "{}", DOF_NAMES[k]);
    }
    assert!(s.drift_max < 0.3, "drift {}", s.drift_max);
    for (name, e) in DOF_NAMES.iter().zip(&s.dof).skip(6) {
        assert!(e.max < 0.3, "{name}: {}", e.max);
    }
    // The truth's steering differs from the command (lag and trim), and the estimated
    // steering's odometry follows the true path at least as closely.
    assert!(s.path_m > 0.05);
    assert!(s.odo_estimated.final_m <= s.odo_commanded.final_m + 1e-3, "{s:?}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn bad_sequence_files_name_the_field() {
    let dir = tmp("bad");
    let cases = [
        (
            short(3.0, "").replace("duration_s = 3\n", "duration_s = -1\n"),
            "duration_s",
        ),
        (short(3.0, "[motion]\nspeed = 0.1\n"), "speed"),
        (
            short(3.0, "").replace("kind = \"sweep\"", "kind = \"jump\""),
            "segments[1].kind",
        ),
        (
            short(3.0, "").replace("steer_deg = 30.0", "steer_deg = 45.0"),
            "segments[1].steer_deg",
        ),
        (
            short(3.0, "[errors.mud]\nmarker = 9\nstart_s = 1.0\n"),
            "errors.mud.marker",
        ),
        (short(3.0, "[errors]\nframe_drop = 1.5\n"), "errors.frame_drop"),
        (
            short(3.0, "[errors.light]\nat_s = 1.0\nlevel = 0.0\n"),
            "errors.light.level",
        ),
        (
            short(3.0, "").replacen("seed = 9\n", "seed = 9\npaper_dataset = 4\n", 1),
            "paper_dataset",
        ),
        (short(3.0, "").replace("name = \"short\"\n", ""), "name"),
    ];
    for (i, (text, field)) in cases.iter().enumerate() {
        let path = dir.join(format!("bad{i}.toml"));
        std::fs::write(&path, text).unwrap();
        let e = SequenceSpec::load(path.to_str().unwrap()).expect_err(field).to_string();
        assert!(e.contains(field), "case {i}: `{field}` not named in: {e}");
        assert!(e.contains(&format!("bad{i}.toml")), "case {i}: the file is named: {e}");
    }
    // Through the command: the error, not a panic.
    let opts = EstimateOptions {
        sequence: dir.join("missing.toml").to_string_lossy().into_owned(),
        out: None,
        seed: None,
        profile: profile_path(),
        json: true,
        no_mount_compensation: false,
        runtime: None,
    };
    let e = run(&opts, &mut Vec::new()).unwrap_err();
    assert!(e.contains("missing.toml"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn the_same_seed_gives_the_same_summary() {
    let profile = common::shipped_profile("autokrawler");
    // With frame drops and mud on, so the knobs' draws are covered too.
    let spec = SequenceSpec::parse(
        &short(
            1.5,
            "[errors]\nframe_drop = 0.2\nmud = { marker = 6, start_s = 0.5, duration_s = 0.5 }\n",
        ),
        Path::new("short.toml"),
    )
    .unwrap();
    let a = estimate(&spec, &profile, 5).unwrap().summary;
    let b = estimate(&spec, &profile, 5).unwrap().summary;
    assert_eq!(a, b);
    assert_eq!(a.to_json().to_string(), b.to_json().to_string());
    let c = estimate(&spec, &profile, 6).unwrap().summary;
    assert_ne!(a, c, "another seed, another run");
    assert!(a.delivered < a.frames, "frames were dropped: {a:?}");
}

/// Mud over the rear-left plate marker: the rear axle's roll, drop and steering are
/// invalid while it lasts (held, not guessed), the front axle is not touched.
#[test]
fn mud_invalidates_its_axle_only_while_it_lasts() {
    let profile = common::shipped_profile("autokrawler");
    let spec = SequenceSpec::parse(
        &short(2.0, "[errors.mud]\nmarker = 4\nstart_s = 0.5\nduration_s = 1.0\n"),
        Path::new("mud.toml"),
    )
    .unwrap();
    let s = estimate(&spec, &profile, 3).unwrap().summary;
    println!("{:?}", s.dof);
    assert_eq!(s.dof[0].valid, 1.0, "front roll");
    assert_eq!(s.dof[4].valid, 1.0, "front steering");
    for k in [1, 3, 5] {
        // 30 of 60 frames under mud.
        assert!(
            (s.dof[k].valid - 0.5).abs() < 0.05,
            "{}: {}",
            DOF_NAMES[k],
            s.dof[k].valid
        );
    }
    assert!(s.errors.iter().any(|e| e.contains("mud on marker 4")), "{:?}", s.errors);
}

#[test]
fn scenario_is_another_name_for_sequence() {
    // The same 1-s sequence through either spelling of the option gives the same summary
    // (`--json`: the printed table also carries the wall time).
    let dir = tmp("alias");
    let seq = dir.join("one.toml");
    std::fs::write(&seq, short(1.0, "")).unwrap();
    let summary = |option: &str| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_marsupial"))
            .args(["estimate", "--json", option])
            .arg(&seq)
            .arg("--profile")
            .arg(profile_path())
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{option}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        serde_json::from_slice::<serde_json::Value>(&out.stdout).unwrap()
    };
    let by_sequence = summary("--sequence");
    assert_eq!(by_sequence["frames"], 30, "{by_sequence}");
    assert_eq!(summary("--scenario"), by_sequence);
    std::fs::remove_dir_all(&dir).ok();
}

/// Table I through the robot's loop (`estimate --runtime`): the `krawler` robot's
/// perceptual schema, ticked in lockstep on its camera's frames, gives the offline run's
/// figures bit for bit, lost frames and mud included, and its slip monitor, on the
/// encoders, raises no alarm on a gear that never slips.
#[test]
fn the_loop_gives_the_offline_table_bit_for_bit() {
    let profile = common::shipped_profile("autokrawler");
    let spec = SequenceSpec::parse(
        &short(
            3.0,
            "[errors]\nframe_drop = 0.1\nmud = { marker = 2, start_s = 1.0, duration_s = 0.5 }\n",
        ),
        Path::new("short.toml"),
    )
    .unwrap();
    let params = marsupial::perception::KrawlerParams::default();
    let offline = estimate(&spec, &profile, 5).unwrap().summary;
    let (rt, slip) = estimate_runtime(&spec, &profile, 5, params).unwrap();
    let rt = rt.summary;
    assert!(offline.delivered < offline.frames, "frames were dropped");
    assert_eq!((offline.via, rt.via), ("offline", "lockstep"));
    assert_eq!(rt.delivered, offline.delivered);
    let mut a = offline.to_json();
    let mut b = rt.to_json();
    a["via"] = serde_json::Value::Null;
    b["via"] = serde_json::Value::Null;
    assert_eq!(a.to_string(), b.to_string());
    assert!(slip.windows >= 2, "{slip:?}");
    assert_eq!(slip.alarms, 0, "{slip:?}");
    // Through the command: both rows printed.
    let dir = tmp("runtime");
    let seq = dir.join("short.toml");
    std::fs::write(&seq, short(1.0, "")).unwrap();
    let opts = EstimateOptions {
        sequence: seq.to_string_lossy().into_owned(),
        out: None,
        seed: None,
        profile: profile_path(),
        json: false,
        no_mount_compensation: false,
        runtime: Some(RuntimePath::Lockstep),
    };
    let mut printed = Vec::new();
    run(&opts, &mut printed).unwrap();
    let printed = String::from_utf8(printed).unwrap();
    assert!(
        printed.contains("ours short (offline)") && printed.contains("ours short (lockstep)"),
        "{printed}"
    );
    assert!(printed.contains("same figures as offline: yes"), "{printed}");
}

/// Table I on the threaded runtime (`estimate --runtime threads`): every frame reaches
/// the robot's perceptual schema in order, in real time, and the figures are the offline
/// run's bit for bit.
#[test]
fn the_threaded_runtime_gives_the_offline_table_bit_for_bit() {
    let profile = common::shipped_profile("autokrawler");
    let spec = SequenceSpec::parse(&short(1.5, "[errors]\nframe_drop = 0.1\n"), Path::new("short.toml")).unwrap();
    let params = marsupial::perception::KrawlerParams::default();
    let offline = estimate(&spec, &profile, 7).unwrap().summary;
    let threads = estimate_threads(&spec, &profile, 7, params).unwrap().summary;
    assert_eq!(threads.via, "threads");
    let mut a = offline.to_json();
    let mut b = threads.to_json();
    a["via"] = serde_json::Value::Null;
    b["via"] = serde_json::Value::Null;
    assert_eq!(a.to_string(), b.to_string());
}
