//! Campaigns that survive being killed (issue 21, item 5): the `marsupial` binary is
//! killed with SIGKILL at random instants, several times, and resumed with `--resume`
//! each time; the final `runs.jsonl` (and `summary.json`) must equal an uninterrupted
//! campaign's byte for byte, and after every kill the file must hold whole lines of the
//! uninterrupted file's first runs and at most a torn start of the next line: no line
//! lost, duplicated or cut in the middle.
//!
//! The kills are drawn from a seeded generator (the seed is printed; set
//! `MARSUPIAL_RESUME_SEED` to replay its delays, `--jobs` and write pauses, though where a
//! delay lands in the campaign still depends on the machine's speed) and land anywhere: during start-up, during a
//! run, while a record is being written (the campaign's `MARSUPIAL_TEST_SLOW_WRITE` hook
//! writes each line in two halves with a pause between, to widen that window), during
//! the resume's own truncation, while `summary.json` is written, or after the end. Each
//! invocation draws `--jobs 1` or `--jobs 2`. `cargo test` runs 5 kills per test; the
//! 20-kill campaigns of the figure are `#[ignore]`d and run by
//! `scripts/resume-kills` (or `cargo test --test cli campaign_resume:: -- --ignored`).
//!
//! The reader `--resume` uses is also tested on hand-made files: torn tails of every kind
//! are dropped, and anything else is an error naming its line.

use crate::common;

use marsupial::sim::campaign::{self, TEST_SLOW_WRITE_ENV, read_resumable};
use marsupial::sim::rng::Rng;
use marsupial::sim::scenario::{RunSpec, Scenario};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A small, fast campaign of Bujold's: 12 short runs (4 starts × 3 trials, 4 s of
/// simulated time each, no departure), clouds so each run's light differs.
const SCENARIO: &str = "seed = 77\ntrials = 3\ntimeout_s = 4.0\n\
    [starts]\ngrid = \"paper16\"\nselect = [2, 5, 6, 11]\nposition_jitter_m = 0.02\nheading_jitter_deg = 3.0\n\
    [axes]\nlighting = [\"clouds\"]\nsegmentation = [\"adaptive\"]\n\
    [imprint]\nenabled = false\n";

/// Starts `marsupial trials SCENARIO --out OUT --jobs JOBS [--resume]`, with the slow-write
/// hook's pause when given.
fn spawn(scenario: &Path, out: &Path, jobs: usize, resume: bool, slow_write_ms: Option<u64>) -> Child {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_marsupial"));
    cmd.arg("trials")
        .arg(scenario)
        .arg("--out")
        .arg(out)
        .args(["--jobs", &jobs.to_string()])
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .env_remove(TEST_SLOW_WRITE_ENV);
    if resume {
        cmd.arg("--resume");
    }
    if let Some(ms) = slow_write_ms {
        cmd.env(TEST_SLOW_WRITE_ENV, ms.to_string());
    }
    cmd.spawn().unwrap()
}

/// Waits for a campaign to finish and checks it succeeded.
fn finish(child: Child, what: &str) {
    let out = child.wait_with_output().unwrap();
    assert!(
        out.status.success(),
        "{what}: {}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Every file under `dir`, by path relative to it, with its contents.
fn tree(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut files = BTreeMap::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                todo.push(p);
            } else {
                let rel = p.strip_prefix(dir).unwrap().to_path_buf();
                files.insert(rel, std::fs::read(&p).unwrap());
            }
        }
    }
    files
}

/// Checks that a resumed campaign's output folder is the uninterrupted one's: the same
/// files (`runs.jsonl`, `summary.json`, the plots, every run's trajectory CSV), byte for
/// byte, and no temporary file left.
fn assert_same_output(out: &Path, reference: &Reference, ctx: &str) {
    let got = tree(out);
    let runs = got.get(Path::new("runs.jsonl")).cloned().unwrap_or_default();
    assert!(
        runs == reference.runs,
        "{ctx}: the resumed runs.jsonl differs from the uninterrupted one:\n{}\n---\n{}",
        String::from_utf8_lossy(&runs),
        String::from_utf8_lossy(&reference.runs)
    );
    let names = |t: &BTreeMap<PathBuf, Vec<u8>>| t.keys().cloned().collect::<Vec<_>>();
    assert_eq!(names(&got), names(&reference.files), "{ctx}: not the same files");
    for (name, bytes) in &got {
        assert!(reference.files[name] == *bytes, "{ctx}: {} differs", name.display());
    }
}

/// The uninterrupted campaign: its `runs.jsonl`, every file it wrote, and its wall time.
struct Reference {
    runs: Vec<u8>,
    files: BTreeMap<PathBuf, Vec<u8>>,
    wall: Duration,
}

fn reference(scenario: &Path, out: &Path) -> Reference {
    let t = Instant::now();
    finish(spawn(scenario, out, 2, false, None), "uninterrupted campaign");
    let wall = t.elapsed();
    let files = tree(out);
    let runs = files[Path::new("runs.jsonl")].clone();
    assert_eq!(runs.iter().filter(|&&b| b == b'\n').count(), 12);
    assert_eq!(
        files.len(),
        12 + 4,
        "runs.jsonl, summary.json, 2 plots, 12 CSVs: {:?}",
        files.keys()
    );
    Reference { runs, files, wall }
}

/// What a kill left: the number of whole lines and the torn tail's length, after checking
/// the whole lines are the reference's first ones and the tail a start of the next.
fn check_prefix(file: &[u8], reference: &[u8], ctx: &str) -> (usize, usize) {
    let whole = file.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
    assert!(
        reference.starts_with(&file[..whole]),
        "{ctx}: the whole lines left are not the uninterrupted campaign's first lines:\n{}",
        String::from_utf8_lossy(file)
    );
    let tail = &file[whole..];
    let next_line = reference[whole..]
        .split_inclusive(|&b| b == b'\n')
        .next()
        .unwrap_or_default();
    assert!(
        tail.is_empty() || (next_line.starts_with(tail) && tail.len() < next_line.len()),
        "{ctx}: the torn tail is not a start of the next line: {}",
        String::from_utf8_lossy(tail)
    );
    (file[..whole].iter().filter(|&&b| b == b'\n').count(), tail.len())
}

/// One randomized kill test: `kills` SIGKILLs at delays drawn from `seed`, a resume after
/// each, then a resume to the end; returns how many kills left a torn line.
fn kill_and_resume(scenario: &Path, dir: &Path, reference: &Reference, seed: u64, kills: usize) -> usize {
    let out = dir.join(format!("killed-{seed}"));
    let _ = std::fs::remove_dir_all(&out);
    let mut rng = Rng::new(seed);
    // Kill within about the time the remaining runs take (plus start-up and the end's
    // summary and plots), so kills land at start-up, in runs, mid-write and at or after
    // the end; writes pause 10–40 ms halfway.
    let total = reference.runs.iter().filter(|&&b| b == b'\n').count() as f64;
    let mut remaining = total;
    let mut torn = 0;
    for k in 0..kills {
        let jobs = 1 + (rng.next_u64() % 2) as usize;
        let slow = Some(10 + rng.next_u64() % 31);
        let span_s = reference.wall.as_secs_f64() * (0.2 + remaining / total);
        let delay = Duration::from_secs_f64(rng.range(0.0, span_s));
        let mut child = spawn(scenario, &out, jobs, k > 0, slow);
        std::thread::sleep(delay);
        // SIGKILL (a no-op if it has already finished).
        let _ = child.kill();
        let status = child.wait().unwrap();
        let ctx = format!(
            "seed {seed}, kill {} of {kills} at {:.0} ms (--jobs {jobs})",
            k + 1,
            delay.as_secs_f64() * 1e3
        );
        let file = std::fs::read(out.join("runs.jsonl")).unwrap_or_default();
        let (lines, tail) = check_prefix(&file, &reference.runs, &ctx);
        remaining = total - lines as f64;
        if tail > 0 {
            torn += 1;
        }
        eprintln!(
            "  {ctx}: {} with {lines} whole lines{}",
            if status.success() { "had finished" } else { "killed" },
            if tail > 0 {
                format!(" and a torn line of {tail} bytes")
            } else {
                String::new()
            }
        );
    }
    let jobs = 1 + (rng.next_u64() % 2) as usize;
    finish(spawn(scenario, &out, jobs, true, None), "final resume");
    assert_same_output(&out, reference, &format!("seed {seed}"));
    let _ = std::fs::remove_dir_all(&out);
    torn
}

/// `tests` randomized kill tests of `kills` kills each; every one must end identical
/// (each asserts), so it returns only if all `tests` did.
fn randomized(tag: &str, tests: usize, kills: usize) {
    let dir = common::TempDir::new(tag);
    let scenario = common::scenario_file(&dir.0, "resume", "bujold.toml", SCENARIO);
    let reference = reference(&scenario, &dir.0.join("reference"));
    let seed0 = std::env::var("MARSUPIAL_RESUME_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| {
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(1, |d| d.as_secs())
        });
    eprintln!(
        "{tag}: uninterrupted campaign {:.2} s; seeds {seed0}..{} (MARSUPIAL_RESUME_SEED={seed0} replays)",
        reference.wall.as_secs_f64(),
        seed0 + tests as u64
    );
    let mut torn = 0;
    for t in 0..tests {
        torn += kill_and_resume(&scenario, &dir.0, &reference, seed0 + t as u64, kills);
    }
    eprintln!(
        "{tag}: identical output in {tests} of {tests} randomized kill tests ({kills} kills each, {torn} kills mid-write)"
    );
}

#[test]
fn a_campaign_killed_5_times_at_random_resumes_to_the_uninterrupted_runs_jsonl() {
    randomized("5-kills", 1, 5);
}

/// The figure: 20 randomized kill tests of 5 kills each (`scripts/resume-kills`).
#[test]
#[ignore = "about a minute or more; run by scripts/resume-kills"]
fn twenty_randomized_kill_tests_all_resume_to_the_uninterrupted_runs_jsonl() {
    randomized("20-tests", 20, 5);
}

/// A kill that certainly lands mid-write: the hook pauses 3 s halfway through each line,
/// the test kills as soon as the file ends in half a line, and the resume (without the
/// hook) drops that half line and rewrites it whole.
#[test]
fn a_kill_mid_write_leaves_a_torn_line_that_resume_replaces() {
    let dir = common::TempDir::new("resume-mid-write");
    let scenario = common::scenario_file(&dir.0, "resume", "bujold.toml", SCENARIO);
    let reference = reference(&scenario, &dir.0.join("reference"));
    let out = dir.0.join("killed");
    let mut child = spawn(&scenario, &out, 2, false, Some(3000));
    let path = out.join("runs.jsonl");
    let t = Instant::now();
    loop {
        let file = std::fs::read(&path).unwrap_or_default();
        if file.last().is_some_and(|&b| b != b'\n') {
            break;
        }
        assert!(t.elapsed() < Duration::from_secs(60), "no half-written line appeared");
        std::thread::sleep(Duration::from_millis(2));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let file = std::fs::read(&path).unwrap();
    let (lines, tail) = check_prefix(&file, &reference.runs, "kill mid-write");
    assert_eq!((lines, tail > 0), (0, true), "expected only half of the first line");
    finish(spawn(&scenario, &out, 1, true, None), "resume");
    assert_same_output(&out, &reference, "kill mid-write");
}

/// The runs of the test scenario, and its uninterrupted `runs.jsonl` lines (each ending
/// in `\n`), run in-process.
fn runs_and_lines(dir: &Path) -> (Vec<RunSpec>, Vec<Vec<u8>>) {
    let scenario = common::scenario_file(dir, "reader", "bujold.toml", SCENARIO);
    let prepared = campaign::prepare(Scenario::load(&scenario).unwrap()).unwrap();
    let out = dir.join("out");
    let opts = campaign::CampaignOptions {
        out: Some(out.clone()),
        jobs: 2,
        ..Default::default()
    };
    campaign::run_campaign(&prepared, &marsupial::behaviors::agent_for, &opts).unwrap();
    let file = std::fs::read(out.join("runs.jsonl")).unwrap();
    let lines = file.split_inclusive(|&b| b == b'\n').map(<[u8]>::to_vec).collect();
    (prepared.runs, lines)
}

#[test]
fn the_resume_reader_drops_exactly_a_torn_last_line_and_names_any_other_bad_line() {
    let dir = common::TempDir::new("resume-reader");
    let (runs, lines) = runs_and_lines(&dir.0);
    assert_eq!(lines.len(), 12);
    let path = dir.0.join("runs.jsonl");
    let read = |bytes: &[u8]| {
        std::fs::write(&path, bytes).unwrap();
        read_resumable(&path, &runs)
    };
    let first = |n: usize| lines[..n].concat();
    let kept = |bytes: &[u8]| {
        let r = read(bytes).unwrap_or_else(|e| panic!("{e}"));
        (r.records.len(), r.keep_bytes as usize, r.torn_bytes as usize)
    };

    // Missing or empty: nothing to keep.
    let _ = std::fs::remove_file(&path);
    let r = read_resumable(&path, &runs).unwrap();
    assert_eq!((r.records.len(), r.keep_bytes, r.torn_bytes), (0, 0, 0));
    assert_eq!(kept(b""), (0, 0, 0));
    // Whole lines: all kept, in order.
    let all = first(12);
    assert_eq!(kept(&all), (12, all.len(), 0));
    let r = read(&first(5)).unwrap();
    assert_eq!(r.records.iter().map(|r| r.index).collect::<Vec<_>>(), [0, 1, 2, 3, 4]);
    // A torn tail of every length: the whole lines before it are kept, the tail dropped.
    let line5 = &lines[5];
    for cut in [1, 2, line5.len() / 3, line5.len() / 2, line5.len() - 2, line5.len() - 1] {
        let mut f = first(5);
        f.extend_from_slice(&line5[..cut]);
        assert_eq!(kept(&f), (5, first(5).len(), cut), "cut after {cut} bytes");
    }
    // A whole record without its newline is torn too (the newline is part of the write).
    let mut f = first(5);
    f.extend_from_slice(&line5[..line5.len() - 1]);
    assert_eq!(kept(&f), (5, first(5).len(), line5.len() - 1));
    // A last line that ends in a newline but does not parse: dropped.
    let mut f = first(5);
    f.extend_from_slice(b"{\"index\":5,\n");
    assert_eq!(kept(&f), (5, first(5).len(), 12));

    // Anything else is an error naming the line, never silently dropped.
    let err = |bytes: &[u8]| read(bytes).expect_err("must be refused").to_string();
    // A bad line in the middle (here line 3), whether or not a torn tail follows.
    for tail in [&b""[..], &line5[..7]] {
        let mut f = first(2);
        f.extend_from_slice(b"{\"index\":2,\n");
        f.extend_from_slice(&lines[3]);
        f.extend_from_slice(tail);
        let e = err(&f);
        assert!(e.contains("line 3: not a run record"), "{e}");
    }
    // A bad last line followed by a torn tail is in the middle too.
    let mut f = first(2);
    f.extend_from_slice(b"garbage\n{\"ind");
    assert!(err(&f).contains("line 3: not a run record"));
    // An empty line.
    let mut f = first(2);
    f.extend_from_slice(b"\n");
    f.extend_from_slice(&lines[2]);
    assert!(err(&f).contains("line 3"));
    // A duplicated line, a missing one, and two swapped.
    let e = err(&[first(3), lines[2].clone()].concat());
    assert!(
        e.contains("line 4: run 2 ") && e.contains("this campaign's run 3 "),
        "{e}"
    );
    let e = err(&[first(2), lines[3].clone()].concat());
    assert!(e.contains("line 3: run 3 "), "{e}");
    let e = err(&[lines[1].clone(), lines[0].clone()].concat());
    assert!(e.contains("line 1: run 1 "), "{e}");
    // A file from another seed of the same scenario: same indices, other seeds.
    let other =
        String::from_utf8(lines[0].clone())
            .unwrap()
            .replacen(&format!("\"seed\":{}", runs[0].seed), "\"seed\":1", 1);
    assert!(err(other.as_bytes()).contains("line 1: run 0 (start 2, trial 0, seed 1)"));
    // More runs than the campaign has.
    let short = &runs[..4];
    std::fs::write(&path, first(5)).unwrap();
    let e = read_resumable(&path, short).unwrap_err().to_string();
    assert!(e.contains("line 5: the campaign has only 4 runs"), "{e}");

    // `run_campaign` with resume refuses such a file and leaves it as it was.
    let out = dir.0.join("out");
    let bad = [first(2), b"garbage\n".to_vec(), lines[3].clone()].concat();
    std::fs::write(out.join("runs.jsonl"), &bad).unwrap();
    let prepared =
        campaign::prepare(Scenario::load(&common::scenario_file(&dir.0, "reader", "bujold.toml", SCENARIO)).unwrap())
            .unwrap();
    let opts = campaign::CampaignOptions {
        out: Some(out.clone()),
        jobs: 1,
        resume: true,
        ..Default::default()
    };
    let e = campaign::run_campaign(&prepared, &marsupial::behaviors::agent_for, &opts).unwrap_err();
    assert!(e.to_string().contains("line 3"), "{e}");
    assert_eq!(std::fs::read(out.join("runs.jsonl")).unwrap(), bad);
}
