//! `marsupial trials` writes the same `runs.jsonl`, byte for byte, whatever `--jobs` is,
//! for real campaigns: Bujold's and RAPOSA's composed behaviors with perception, each run
//! departing from the dock and imprinting first, in adaptive segmentation, with placement
//! jitter, under random cloud cover that changes the light over the session, two runs in
//! parallel with `--jobs 2`. (`tests/sim_scripted.rs`
//! checks the same with a scripted driver that has no perception and no imprint.)

use crate::common;

use marsupial::cli::sim_cmds::{TrialsOptions, trials};
use marsupial::sim::campaign::{self, RunRecord};

/// Runs the campaign through the CLI's `trials` with `--jobs 1` and `--jobs 2` and checks
/// the two `runs.jsonl` (and `summary.json`) are identical; returns the records.
fn same_runs_whatever_the_jobs(name: &str, profile: &str, rest: &str) -> Vec<RunRecord> {
    let dir = std::env::temp_dir().join(format!("marsupial-jobs-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let s = common::scenario_file(&dir, name, profile, rest);
    let run = |jobs: usize| {
        let out = dir.join(format!("jobs{jobs}"));
        let opts = TrialsOptions {
            scenario: s.clone(),
            out: Some(out.clone()),
            jobs,
            ..Default::default()
        };
        trials(&opts, &mut Vec::new()).unwrap();
        let read = |f: &str| std::fs::read(out.join(f)).unwrap();
        (read("runs.jsonl"), read("summary.json"))
    };
    let (runs1, summary1) = run(1);
    let (runs2, summary2) = run(2);
    assert!(!runs1.is_empty());
    assert!(
        runs1 == runs2,
        "{name}: runs.jsonl differs between --jobs 1 and --jobs 2:\n{}\n---\n{}",
        String::from_utf8_lossy(&runs1),
        String::from_utf8_lossy(&runs2)
    );
    assert!(summary1 == summary2, "{name}: summary.json differs");
    let records = campaign::read_runs(&dir.join("jobs1/runs.jsonl"));
    let _ = std::fs::remove_dir_all(&dir);
    records
}

/// What both campaigns must be: four real runs (each departed and imprinted, then docked
/// or failed on what it saw, in adaptive segmentation), at least one docked, and four
/// distinct seeds, so the runs are not copies of one another.
fn assert_four_real_runs(records: &[RunRecord]) {
    assert_eq!(records.len(), 4);
    for r in records {
        assert_eq!(r.imprinted, Some(true), "run {}: {}", r.index, r.outcome);
        assert_eq!(r.segmentation, "adaptive");
        assert!(r.path_m > 0.3, "run {}: drove {:.2} m", r.index, r.path_m);
    }
    assert!(records.iter().any(|r| r.success), "no run docked");
    let mut seeds: Vec<u64> = records.iter().map(|r| r.seed).collect();
    seeds.sort_unstable();
    seeds.dedup();
    assert_eq!(seeds.len(), 4);
}

#[test]
fn a_bujold_campaign_with_imprint_and_adaptive_segmentation_is_the_same_on_1_or_2_jobs() {
    let records = same_runs_whatever_the_jobs(
        "bujold",
        "bujold.toml",
        "seed = 19\ntrials = 2\ntimeout_s = 60.0\n\
         [starts]\ngrid = \"paper16\"\nselect = [2, 5]\nposition_jitter_m = 0.02\nheading_jitter_deg = 3.0\n\
         [axes]\nlighting = [\"clouds\"]\nsegmentation = [\"adaptive\"]\n\
         [imprint]\nenabled = true\n",
    );
    assert_four_real_runs(&records);
}

#[test]
fn a_raposa_campaign_with_imprint_and_adaptive_bands_is_the_same_on_1_or_2_jobs() {
    let records = same_runs_whatever_the_jobs(
        "raposa",
        "raposa.toml",
        "seed = 2014\ntrials = 2\ntimeout_s = 60.0\n\
         [starts]\ngrid = \"paper16\"\nselect = [5, 9]\nposition_jitter_m = 0.02\nheading_jitter_deg = 3.0\n\
         [axes]\nlighting = [\"clouds\"]\nsegmentation = [\"adaptive\"]\n\
         [sensor]\nwhite_balance = \"daylight\"\n\
         [imprint]\nenabled = true\n",
    );
    assert_four_real_runs(&records);
}
