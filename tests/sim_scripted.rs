//! The simulator end to end with a trivial scripted driver (no behavior logic in the
//! simulator): dock and trials, determinism across job counts, resume, contact failures.

use crate::common;

use marsupial::sim::campaign::{self, CampaignOptions, Prepared};
use marsupial::sim::scenario::Scenario;
use std::path::{Path, PathBuf};

fn scenario(body: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("marsupial-sim-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let profile = Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/bujold.toml");
    let name = format!("s{}.toml", body.len());
    let path = dir.join(name);
    std::fs::write(
        &path,
        format!(
            "name = \"scripted\"\nprofile = \"{}\"\nseed = 5\n{body}",
            profile.display()
        ),
    )
    .unwrap();
    path
}

fn prepared(body: &str) -> Prepared {
    campaign::prepare(Scenario::load(&scenario(body)).unwrap()).unwrap()
}

#[test]
fn aligned_backing_docks_and_misaligned_gets_stuck() {
    let p = prepared(
        "trials = 1\ntimeout_s = 40\n[imprint]\nenabled = false\n[starts]\npoints = [ { x_m = 0.8, y_m = 0.0, heading_deg = 0.0 }, { x_m = 0.8, y_m = 0.06, heading_deg = 0.0 }, { x_m = 0.8, y_m = 0.0, heading_deg = 12.0 } ]\n[motion]\nslip_scale = 0.0\n",
    );
    let (records, summary) = campaign::run_campaign(
        &p,
        &common::backer,
        &CampaignOptions {
            jobs: 1,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(records.len(), 3);
    assert!(records[0].success, "{:?}", records[0]);
    assert_eq!(records[0].outcome, "docked");
    assert!(records[0].entrance_lateral_m.unwrap().abs() < 0.005);
    // 6 cm off the axis: catches the entrance edge (the paper's failure mode).
    assert!(!records[1].success);
    assert_eq!(records[1].outcome, "stuck_contact");
    // 12° off: backs diagonally into the gate.
    assert!(!records[2].success, "{:?}", records[2]);
    assert_eq!(summary.overall.successes, 1);
    assert_eq!(summary.groups.len(), 3);
    assert_eq!(summary.overall.failures.get("stuck_contact"), Some(&2));
    // Time: 0.8 − 0.2 (half the body) + 0.45 pouch = 1.05 m at ~5 cm/s.
    assert!((records[0].time_s - 21.0).abs() < 2.0, "{}", records[0].time_s);
}

#[test]
fn same_seed_same_runs_jsonl_whatever_the_job_count_and_resume_works() {
    let body = "trials = 2\ntimeout_s = 30\n[imprint]\nenabled = false\n[starts]\npoints = [ { x_m = 0.7, y_m = 0.0, heading_deg = 0.0 }, { x_m = 0.7, y_m = 0.01, heading_deg = 1.0 } ]\n[axes]\nlighting = [\"lab\", \"flashers\"]\n";
    let p = prepared(body);
    let out1 = std::env::temp_dir().join(format!("marsupial-sim-out1-{}", std::process::id()));
    let out2 = std::env::temp_dir().join(format!("marsupial-sim-out2-{}", std::process::id()));
    let run = |out: &PathBuf, jobs: usize, resume: bool| {
        let opts = CampaignOptions {
            out: Some(out.clone()),
            jobs,
            resume,
            ..Default::default()
        };
        campaign::run_campaign(&p, &common::backer, &opts).unwrap();
    };
    run(&out1, 1, false);
    run(&out2, 2, false);
    let a = std::fs::read_to_string(out1.join("runs.jsonl")).unwrap();
    let b = std::fs::read_to_string(out2.join("runs.jsonl")).unwrap();
    assert_eq!(a.lines().count(), 8);
    assert!(a == b, "runs.jsonl differs between --jobs 1 and 2");
    // Interrupt: keep the first 3 lines (and a torn fourth), resume, and get the same file.
    let lines: Vec<&str> = a.lines().collect();
    std::fs::write(
        out2.join("runs.jsonl"),
        format!("{}\n{}\n{}\n{{\"index\":3,", lines[0], lines[1], lines[2]),
    )
    .unwrap();
    run(&out2, 2, true);
    assert_eq!(std::fs::read_to_string(out2.join("runs.jsonl")).unwrap(), a);
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out2.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["overall"]["runs"], 8);
    assert_eq!(summary["groups"].as_array().unwrap().len(), 4);
    for key in [
        "start",
        "lighting",
        "segmentation",
        "terrain",
        "runs",
        "successes",
        "success_rate",
        "mean_time_s",
        "sd_time_s",
        "failures",
    ] {
        assert!(summary["groups"][0].get(key).is_some(), "{key}");
    }
    // The plots are the report layer's, drawn from the records (`trials --out` does so).
    let records = campaign::read_runs(&out2.join("runs.jsonl"));
    marsupial::report::plot::write_plots(&out2, &p.world, &p.loaded.profile, &records).unwrap();
    assert!(out2.join("trajectories.svg").exists() && out2.join("success_map.svg").exists());
}
