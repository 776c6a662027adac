//! `marsupial dock`: `--index` replays exactly one run of the campaign (its start, trial,
//! lighting and segmentation) and names the valid range when out of it; `--out` with
//! `--frames-every` writes the departure's and the docking's frames.

use marsupial::cli::sim_cmds::{DockOptions, dock};
use marsupial::sim::campaign;
use marsupial::sim::scenario::Scenario;
use std::path::{Path, PathBuf};

fn scenario() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/bujold-yellow.toml")
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
    let names: Vec<String> = std::fs::read_dir(dir.join("frames"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(names.iter().any(|n| n.starts_with("depart-")), "{names:?}");
    assert!(names.iter().any(|n| n.starts_with("frame-")), "{names:?}");
    assert!(dir.join("trajectory.csv").exists());
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
