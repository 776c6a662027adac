//! `marsupial dock`: `--index` replays exactly one run of the campaign (its start, trial,
//! lighting and segmentation, and so its outcome, time, path and every other field of its
//! `runs.jsonl` line) and names the valid range when out of it; `--out` with
//! `--frames-every` writes the departure's and the docking's frames.

use marsupial::cli::sim_cmds::{DockOptions, dock};
use marsupial::sim::campaign::{self, RunRecord};
use marsupial::sim::scenario::Scenario;
use std::path::{Path, PathBuf};

fn scenario() -> PathBuf {
    shipped("bujold-yellow")
}

fn shipped(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("scenarios/{name}.toml"))
}

/// Line `index` of the campaign's committed `runs.jsonl` (`tests/golden/NAME.jsonl`, which
/// `scripts/golden` holds to what `marsupial trials` writes, byte for byte).
fn campaign_line(name: &str, index: usize) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("tests/golden/{name}.jsonl"));
    let text = std::fs::read_to_string(&path).unwrap();
    let line = text.lines().nth(index).unwrap().to_string();
    let rec: RunRecord = serde_json::from_str(&line).unwrap();
    assert_eq!(rec.index, index, "{}", path.display());
    line
}

/// `dock --index` gives the campaign's own record of that run: the same outcome, time,
/// path, entrance error, imprint, manoeuvres, command changes, safe stops and track.
fn assert_replays(name: &str, index: usize, rec: &RunRecord) {
    let line = campaign_line(name, index);
    let want: RunRecord = serde_json::from_str(&line).unwrap();
    let key = |r: &RunRecord| {
        (
            r.success,
            r.outcome.clone(),
            r.time_s,
            r.path_m,
            r.entrance_lateral_m,
            r.entrance_heading_deg,
            r.imprinted,
            r.manoeuvres,
            r.commands_per_m,
            r.safe_stops,
            r.track.len(),
        )
    };
    assert_eq!(key(rec), key(&want), "{name} --index {index}: replay ≠ campaign run");
    // Every field, byte for byte as `trials` writes it.
    assert!(
        serde_json::to_string(rec).unwrap() == line,
        "{name} --index {index}: the replay's runs.jsonl line differs from the campaign's"
    );
}

fn opts(index: Option<usize>, out: Option<PathBuf>, frames_every: Option<u32>) -> DockOptions {
    DockOptions {
        scenario: scenario(),
        start: None,
        at: None,
        index,
        seed: None,
        json: false,
        out,
        frames_every,
        trace: None,
        record: None,
        jpeg: false,
    }
}

#[test]
fn index_replays_that_campaign_run_and_writes_its_frames() {
    let prepared = campaign::prepare(Scenario::load(&scenario()).unwrap()).unwrap();
    let want = prepared.runs[5].clone();
    let dir = std::env::temp_dir().join(format!("marsupial-dock-cli-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let mut text = Vec::new();
    let rec = dock(&opts(Some(5), Some(dir.clone()), Some(50)), &mut text).unwrap();
    assert_eq!(rec.index, 5);
    assert_eq!(
        (rec.start.as_str(), rec.trial, rec.seed),
        (want.start.label.as_str(), want.trial, want.seed)
    );
    assert_eq!(rec.lighting, want.lighting);
    // Recording frames does not change the run: it is the campaign's run 5 (docked after
    // 41 s from 1.33 m on the axis).
    assert_replays("bujold-yellow", 5, &rec);
    let names: Vec<String> = std::fs::read_dir(dir.join("frames"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(names.iter().any(|n| n.starts_with("depart-")), "{names:?}");
    assert!(names.iter().any(|n| n.starts_with("frame-")), "{names:?}");
    assert!(dir.join("trajectory.csv").exists());
}

/// Runs that are not short and not all successes: Bujold's Table II run 23 (static
/// segmentation at dusk, timing out from 0.33 m at −70° after 150 s), and RAPOSA
/// with a repainted ball, run 36 (fixed bands: stuck on the pyramid after 79 s) and run
/// 14 (static bands imprinted on departure: docked after a region-II manoeuvre, 73 s).
#[test]
fn index_gives_the_campaigns_own_record_of_that_run() {
    for (name, index, outcome) in [
        ("bujold-table2", 23, "timeout"),
        ("raposa-repaint", 36, "stuck_contact"),
        ("raposa-repaint", 14, "docked"),
    ] {
        let mut o = opts(Some(index), None, None);
        o.scenario = shipped(name);
        let rec = dock(&o, &mut Vec::new()).unwrap();
        assert_eq!(rec.outcome, outcome, "{name} --index {index}");
        assert!(rec.time_s > 60.0, "{name} --index {index}: {} s", rec.time_s);
        assert_replays(name, index, &rec);
    }
}

#[test]
fn an_index_past_the_campaign_names_the_range() {
    let e = dock(&opts(Some(999), None, None), &mut Vec::new())
        .unwrap_err()
        .to_string();
    assert!(e.contains("no run 999") && e.contains("runs 0–7"), "{e}");
}

#[test]
fn a_start_inside_the_mothers_body_is_refused() {
    // Beside the gate with its rear 10 cm into the body (whatever the proctor's 2 cm and
    // 3° of jitter): a robot placed there could never move, so the run is refused rather
    // than timed out.
    let mut o = opts(None, None, None);
    o.at = Some((0.1, -0.3, 0.0));
    let e = dock(&o, &mut Vec::new()).unwrap_err().to_string();
    assert!(e.contains("overlapping the dock's body"), "{e}");
    o.at = Some((0.9, 0.0, 0.0));
    assert!(dock(&o, &mut Vec::new()).is_ok());
}

#[test]
fn the_trace_has_every_tick_and_the_timeline_reads_it() {
    let path = std::env::temp_dir().join(format!("marsupial-trace-{}.jsonl", std::process::id()));
    let mut o = opts(Some(0), None, None);
    o.trace = Some(path.clone());
    let rec = dock(&o, &mut Vec::new()).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let lines: Vec<serde_json::Value> = text.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    let ticks = |m: &str| {
        lines
            .iter()
            .filter(|l| l["mission"] == m && l["nodes"].is_array())
            .count()
    };
    // One line per loop tick of each mission (10 Hz): the docking's match the run's time.
    assert!(ticks("departure") > 100, "{}", ticks("departure"));
    let docking = ticks("docking") as f64;
    assert!(
        (docking - rec.time_s * 10.0).abs() <= 2.0,
        "{docking} ticks for {} s",
        rec.time_s
    );
    // Every tick names the root sequencer and the leaf that won.
    let first = &lines[0]["nodes"];
    assert_eq!(first[0]["node"], "bujold");
    assert_eq!(first[1]["winner"], "undock");
    assert_eq!(lines.last().unwrap()["world"], rec.outcome.as_str());

    let mut out = Vec::new();
    let n = marsupial::cli::timeline::run(&path, &mut out).unwrap();
    let out = String::from_utf8(out).unwrap();
    assert!(n >= 5, "{out}");
    assert!(out.contains("departure: undock → drive_out (out)"), "{out}");
    assert!(out.contains("close_dock: search → approach (acquired)"), "{out}");
    assert!(out.contains("finished: completed"), "{out}");

    // Not a trace: the file and line are named.
    std::fs::write(&path, "{\"mission\":\"docking\",\"t\":0.0,\"nodes\":[]}\nnot json\n").unwrap();
    let e = marsupial::cli::timeline::run(&path, &mut Vec::new())
        .unwrap_err()
        .to_string();
    assert!(e.contains(":2: not a decision-trace line"), "{e}");
    let _ = std::fs::remove_file(&path);
}
