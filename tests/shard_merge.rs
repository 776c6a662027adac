//! Campaigns across machines (`trials --shard K/N`, `marsupial merge`): shards of a
//! campaign, merged, give the unsharded campaign's `runs.jsonl` and `summary.json` byte
//! for byte, whatever N and `--jobs`; and merge refuses folders that do not make one
//! whole campaign, naming what is wrong.

use crate::common;

use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A small, fast Bujold campaign: 10 short runs (5 starts × 2 trials, 3 s of simulated
/// time, no departure), clouds so each run's light differs.
const SCENARIO: &str = "seed = 91\ntrials = 2\ntimeout_s = 3.0\n\
    [starts]\ngrid = \"paper16\"\nselect = [1, 4, 7, 10, 13]\nposition_jitter_m = 0.02\nheading_jitter_deg = 3.0\n\
    [axes]\nlighting = [\"clouds\"]\nsegmentation = [\"adaptive\"]\n\
    [imprint]\nenabled = false\n";

fn marsupial(args: &[OsString]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_marsupial"))
        .args(args)
        .output()
        .unwrap()
}

fn os(s: impl AsRef<std::ffi::OsStr>) -> OsString {
    s.as_ref().to_owned()
}

fn trials(scenario: &Path, out: &Path, jobs: usize, shard: Option<&str>) {
    let mut args = vec![
        os("trials"),
        os(scenario),
        os("--out"),
        os(out),
        os("--jobs"),
        os(jobs.to_string()),
    ];
    if let Some(s) = shard {
        args.extend([os("--shard"), os(s)]);
    }
    let o = marsupial(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // Not a terminal: plain progress lines, the last one at the end of the campaign.
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.lines().any(|l| l.contains(" runs, ") && l.contains(" docked, ")),
        "{err}"
    );
}

fn merge(dirs: &[PathBuf], out: &Path, scenario: Option<&Path>) -> Output {
    let mut args = vec![os("merge")];
    args.extend(dirs.iter().map(os));
    args.extend([os("--out"), os(out)]);
    if let Some(s) = scenario {
        args.extend([os("--scenario"), os(s)]);
    }
    marsupial(&args)
}

fn read(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

#[test]
fn merged_shards_equal_the_unsharded_campaign() {
    let dir = common::TempDir::new("shard-identity");
    let scenario = common::scenario_file(&dir.0, "shard", "bujold.toml", SCENARIO);
    let whole = dir.0.join("whole");
    trials(&scenario, &whole, 2, None);
    let want_runs = read(&whole.join("runs.jsonl"));
    let want_summary = read(&whole.join("summary.json"));
    assert_eq!(want_runs.iter().filter(|&&b| b == b'\n').count(), 10);
    for (n, jobs) in [(3usize, 1usize), (4, 2), (1, 1)] {
        let shards: Vec<PathBuf> = (1..=n).map(|k| dir.0.join(format!("s{n}-{k}"))).collect();
        // Given in reverse: merge orders them itself.
        for (k, d) in shards.iter().enumerate().rev() {
            trials(&scenario, d, jobs, Some(&format!("{}/{n}", k + 1)));
        }
        let out = dir.0.join(format!("merged{n}"));
        let o = merge(&shards, &out, Some(&scenario));
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert_eq!(read(&out.join("runs.jsonl")), want_runs, "N = {n}: runs.jsonl differs");
        assert_eq!(
            read(&out.join("summary.json")),
            want_summary,
            "N = {n}: summary.json differs"
        );
        assert!(out.join("success_map.svg").exists() || out.join("trajectories.svg").exists());
    }
}

#[test]
fn merge_refuses_what_is_not_one_whole_campaign() {
    let dir = common::TempDir::new("shard-refuse");
    let scenario = common::scenario_file(&dir.0, "shard", "bujold.toml", SCENARIO);
    let other = common::scenario_file(
        &dir.0.join("other"),
        "shard",
        "bujold.toml",
        &SCENARIO.replace("seed = 91", "seed = 92"),
    );
    let s: Vec<PathBuf> = (1..=3).map(|k| dir.0.join(format!("s{k}"))).collect();
    for (k, d) in s.iter().enumerate() {
        trials(&scenario, d, 1, Some(&format!("{}/3", k + 1)));
    }
    let out = dir.0.join("out");
    let fails = |dirs: &[PathBuf], scenario: Option<&Path>, want: &str| {
        let o = merge(dirs, &out, scenario);
        let err = String::from_utf8_lossy(&o.stderr).into_owned();
        assert!(!o.status.success() && err.contains(want), "want {want:?}, got {err:?}");
        assert!(!out.join("runs.jsonl").exists(), "a refused merge wrote output");
    };
    fails(&s[..2], None, "shards 3/3 of");
    fails(&[s[0].clone(), s[1].clone(), s[1].clone()], None, "shard 2/3 again");
    fails(&[s[0].clone(), s[1].clone(), dir.0.join("nowhere")], None, "shard.json");
    // A shard of another split.
    let odd = dir.0.join("odd");
    trials(&scenario, &odd, 1, Some("2/2"));
    fails(&[s[0].clone(), s[1].clone(), odd], None, "N = 2");
    // A shard cut short, mid-line and at a line's end.
    let runs = s[2].join("runs.jsonl");
    let full = read(&runs);
    std::fs::write(&runs, &full[..full.len() - 7]).unwrap();
    fails(&s, None, "torn");
    let last_line = full[..full.len() - 1].iter().rposition(|&b| b == b'\n').unwrap() + 1;
    std::fs::write(&runs, &full[..last_line]).unwrap();
    fails(&s, None, "finish it with `trials --resume`");
    std::fs::write(&runs, &full).unwrap();
    // The shards of another scenario's campaign.
    fails(&s, Some(&other), "seed");
    // And whole again: it merges.
    let o = merge(&s, &out, Some(&scenario));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn bad_shard_arguments_are_refused() {
    let dir = common::TempDir::new("shard-args");
    let scenario = common::scenario_file(&dir.0, "shard", "bujold.toml", SCENARIO);
    for bad in ["0/3", "4/3", "2", "1/0"] {
        let o = marsupial(&[os("trials"), os(&scenario), os("--shard"), os(bad)]);
        assert!(!o.status.success(), "{bad} accepted");
        assert!(String::from_utf8_lossy(&o.stderr).contains(bad), "{bad}");
    }
}
