//! Randomized lighting (`[lighting_random.NAME]` on the lighting axis) and random starts
//! (`[starts.random]`), end to end through the CLI: every run draws and records its own
//! programme, the paired adaptive and static runs of a start and trial share it, `dock
//! --index` replays a run's draw and whole record, `trials --bin` groups by a drawn
//! parameter, and bad distributions and bin arguments are named errors.

use crate::common;

use marsupial::cli::sim_cmds::{DockOptions, TrialsOptions, dock, trials};
use marsupial::sim::SimError;
use marsupial::sim::campaign::{self, RunRecord};
use marsupial::sim::scenario::Scenario;
use std::path::PathBuf;

/// A short Bujold campaign on a drawn light: one grid start and two random ones, one
/// trial, adaptive and static (6 runs, 40 s each at most).
const REST: &str = "seed = 31\ntrials = 1\ntimeout_s = 40.0\n\
    [starts]\ngrid = \"paper16\"\nselect = [9]\n\
    random = { count = 2, distance_m = [0.4, 1.2], angle_deg = [-30.0, 30.0] }\n\
    [axes]\nlighting = [\"mixed\"]\nsegmentation = [\"adaptive\", \"static\"]\n\
    [lighting_random.mixed]\nbeacons = [1, 2]\nshadows = [1, 1]\n\
    [sensor]\nwhite_balance = \"switch\"\n";

fn dir(tag: &str) -> PathBuf {
    std::env::temp_dir().join(format!("marsupial-lighting-random-{tag}-{}", std::process::id()))
}

#[test]
fn runs_draw_record_share_and_replay_their_light() {
    let d = dir("campaign");
    let _ = std::fs::remove_dir_all(&d);
    let s = common::scenario_file(&d, "drawn", "bujold.toml", REST);
    let out = d.join("out");
    let mut text = Vec::new();
    trials(
        &TrialsOptions {
            scenario: s.clone(),
            out: Some(out.clone()),
            jobs: 2,
            bin: vec!["beacons".into(), "beacon_power:2".into()],
            ..Default::default()
        },
        &mut text,
    )
    .unwrap();
    let records: Vec<RunRecord> = campaign::read_runs(&out.join("runs.jsonl"));
    assert_eq!(records.len(), 6);
    assert_eq!(
        records.iter().map(|r| r.start.as_str()).collect::<Vec<_>>(),
        ["9", "9", "r1", "r1", "r2", "r2"]
    );
    for pair in records.chunks(2) {
        let (a, b) = (&pair[0], &pair[1]);
        assert_eq!(
            (a.segmentation.as_str(), b.segmentation.as_str()),
            ("adaptive", "static")
        );
        let (da, db) = (a.lighting_draw.as_ref().unwrap(), b.lighting_draw.as_ref().unwrap());
        assert_eq!(da, db, "start {}: the paired runs see the same light", a.start);
        let n = da.spec.flashers.as_ref().unwrap().len();
        assert!((1..=2).contains(&n) && da.params["beacons"] == n as f64);
        assert_eq!(da.spec.shadows.as_ref().unwrap().len(), 1);
    }
    assert_ne!(
        records[0].lighting_draw, records[2].lighting_draw,
        "each start draws anew"
    );
    // The random starts lie in the declared sector.
    for r in &records[2..] {
        assert!(
            (0.4..=1.2).contains(&r.distance_m) && r.angle_deg.abs() <= 30.0,
            "{}",
            r.start
        );
    }
    // The bins are printed per mode.
    let text = String::from_utf8(text).unwrap();
    assert!(
        text.contains("success by beacons") && text.contains("success by beacon_power"),
        "{text}"
    );
    // `dock --index` replays the draw and the whole record, byte for byte.
    let lines: Vec<String> = std::fs::read_to_string(out.join("runs.jsonl"))
        .unwrap()
        .lines()
        .map(String::from)
        .collect();
    for index in [1, 4] {
        let rec = dock(
            &DockOptions {
                scenario: s.clone(),
                start: None,
                at: None,
                index: Some(index),
                seed: None,
                json: false,
                out: None,
                frames_every: None,
                trace: None,
                record: None,
                jpeg: false,
            },
            &mut Vec::new(),
        )
        .unwrap();
        assert_eq!(serde_json::to_string(&rec).unwrap(), lines[index], "--index {index}");
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn bad_distributions_and_bin_arguments_are_named() {
    let d = dir("bad");
    let _ = std::fs::remove_dir_all(&d);
    let bad = REST.replace(
        "beacons = [1, 2]",
        "beacons = [1, 2]\nbeacon_power = [-1.0, 2.0]\nbeacon_colours = []\nintensity = [2.0, 1.0]",
    );
    let s = common::scenario_file(&d, "bad", "bujold.toml", &bad);
    let e = Scenario::load(&s).unwrap_err().to_string();
    for field in ["beacon_power", "beacon_colours", "intensity"] {
        assert!(e.contains(&format!("lighting_random.mixed.{field}")), "{field} in: {e}");
    }
    let clash = REST.replace(
        "[lighting_random.mixed]",
        "[lighting.mixed]\npreset = \"lab\"\n[lighting_random.mixed]",
    );
    let s = common::scenario_file(&d, "clash", "bujold.toml", &clash);
    assert!(
        Scenario::load(&s)
            .unwrap_err()
            .to_string()
            .contains("lighting_random.mixed")
    );
    // An unknown parameter, and binning a campaign that draws nothing, fail before any run.
    let good = common::scenario_file(&d, "good", "bujold.toml", REST);
    let run = |scenario: PathBuf, bin: &str| {
        trials(
            &TrialsOptions {
                scenario,
                bin: vec![bin.into()],
                ..Default::default()
            },
            &mut Vec::new(),
        )
    };
    match run(good, "beacon_colour") {
        Err(SimError::InvalidArgument(m)) => assert!(m.contains("beacon_power"), "{m}"),
        other => panic!("{other:?}"),
    }
    let fixed = common::scenario_file(&d, "fixed", "bujold.toml", &REST.replace("[\"mixed\"]", "[\"lab\"]"));
    match run(fixed, "glare") {
        Err(SimError::InvalidArgument(m)) => assert!(m.contains("lighting_random"), "{m}"),
        other => panic!("{other:?}"),
    }
    let _ = std::fs::remove_dir_all(&d);
}
