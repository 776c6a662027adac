//! Trial campaigns: every run of a scenario, in parallel, streamed to `runs.jsonl`.
//!
//! Runs are independent and seeded from (scenario seed, run index), so a run's record does
//! not depend on which worker ran it or when. Records are written in run order (a small
//! reorder buffer holds early finishers), so the same scenario and seed give the same
//! `runs.jsonl` byte for byte whatever `--jobs` is. Runs that differ only in segmentation
//! mode share a `pair_seed`: same lighting instant, same placement error and the same
//! imprint, as in the paper's paired protocol.
//!
//! # Killed campaigns and `--resume`
//! Each record is appended as one whole line with a single `write_all`, after the run's
//! own files (trajectory CSV, frames) are written, so a campaign killed at any instant
//! (SIGKILL, a crash, Ctrl-C) leaves in `runs.jsonl` the whole lines of runs `0..k` and at
//! most one torn last line. `--resume` ([`read_resumable`]) checks those lines against the
//! campaign, cuts the file after the last whole record (one truncation, never a rewrite,
//! so being killed during the resume loses nothing either) and appends the remaining
//! runs: the result is byte for byte the file of an uninterrupted campaign, with any
//! `--jobs` on either side (`tests/campaign_resume.rs` kills campaigns at random instants
//! and mid-write). Any other damage (a bad line before the last, a run out of place, a
//! file from another scenario or seed) is an error naming the line, not silently
//! dropped. `summary.json` is written from every record, resumed ones included, at the
//! end, and replaced atomically (the plots, `report::plot`, are the CLI's, drawn after). The guarantee is for
//! the process being killed; after a power loss the operating system may not have
//! written the file's last pages.

use super::SimError;
use super::lighting_random::LightingDraw;
use super::record::RecordOptions;
use super::robot::SimDevices;
pub use super::run::{Recording, run_one};
use super::scenario::{Loaded, RunSpec};
use super::tether::TetherTally;
use super::world::{self, World};
use crate::behaviors::BuildError;
use crate::perception::RgbImage;
use crate::profile::{NamedColor, Profile, TwoBlockSpec};
use crate::schemas::Agent;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Builds a fresh agent for a (per-run) profile.
pub type AgentFactory = dyn Fn(&Profile) -> Result<Box<dyn Agent>, BuildError> + Sync;

/// The record of one run (one line of `runs.jsonl`). `Default` is an empty record (no
/// start, not docked, every optional figure absent), for struct-update syntax: a run's
/// record fills the figures every run has and leaves the fault's and the outing's to the
/// stages that add them.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct RunRecord {
    /// Run index in the campaign.
    pub index: usize,
    /// Start label.
    pub start: String,
    /// Lighting programme.
    pub lighting: String,
    /// Segmentation mode.
    pub segmentation: String,
    /// Terrain.
    pub terrain: String,
    /// The flap's paints `[left, right]`, when the scenario has a `fiducial_colors`
    /// axis (absent otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fiducial_colors: Option<[NamedColor; 2]>,
    /// Trial number.
    pub trial: u32,
    /// Run seed.
    pub seed: u64,
    /// Start distance from the entrance, m.
    pub distance_m: f64,
    /// Start angle off the dock axis, degrees.
    pub angle_deg: f64,
    /// Docked (the simulator's ground truth: contact with the plates).
    pub success: bool,
    /// `docked`, or the failure reason.
    pub outcome: String,
    /// Time from placement to docking or failure, s.
    pub time_s: f64,
    /// Distance driven, m.
    pub path_m: f64,
    /// Effective velocity: start distance / time, cm/s (successful runs).
    pub v_eff_cmps: f64,
    /// Drive-command changes per metre driven.
    pub commands_per_m: f64,
    /// Lateral error at the entrance, m (when the robot reached it).
    pub entrance_lateral_m: Option<f64>,
    /// Heading error at the entrance, degrees.
    pub entrance_heading_deg: Option<f64>,
    /// Ticks in safe stop.
    pub safe_stops: u64,
    /// Departure imprinted successfully (when the agent has a departure).
    pub imprinted: Option<bool>,
    /// Alignment manoeuvres started (RAPOSA's region-II iterations).
    #[serde(default)]
    pub manoeuvres: u32,
    /// The tether's largest slack, tension and reel current over the docking, from the
    /// simulator's truth (robots with a tether; absent otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tether: Option<TetherTally>,
    /// The run's lighting draw, when its lighting is a `[lighting_random.NAME]`
    /// distribution (absent otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lighting_draw: Option<LightingDraw>,
    /// The injected fault's name, when the scenario has `[[faults]]` (absent otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fault: Option<String>,
    /// The run ended as the fault's `expect` says.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fault_as_expected: Option<bool>,
    /// Ticks with motion commanded while the fault left an input the loop must not act on
    /// (must be 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stale_motion_ticks: Option<u64>,
    /// Time in safe stop, s (with a fault).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub safe_stop_s: Option<f64>,
    /// The cycle of an endurance outing this record is (absent outside outings,
    /// [`super::endurance`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cycle: Option<usize>,
    /// The outing's clock when the cycle began (its departure), s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub outing_clock_s: Option<f64>,
    /// How far odometry's position was from the truth when the cycle's docking began, m
    /// (odometry's frame is the docked pose the outing began at; it is never reset).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub odometry_error_m: Option<f64>,
    /// Odometry's heading error then, degrees.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub odometry_error_deg: Option<f64>,
    /// The excursion reached the cycle's start (within 3 cm and 2°) before its time limit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub excursion_reached: Option<bool>,
    /// The cycle failed and the proctor carried the robot back into the dock.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub carried_back: Option<bool>,
    /// True path, [x, y] in mm every 0.5 s.
    pub track: Vec<[i32; 2]>,
}

#[cfg(test)]
impl RunRecord {
    /// A lab-light, adaptive record of start `start` with every measured figure at a
    /// neutral value (1 m, 10 s, no faults, no draw): what the tests of the tables built
    /// from records (`bins`, `paper`) start from, overriding what they group by.
    pub(crate) fn for_test(start: &str, success: bool) -> Self {
        Self {
            start: start.into(),
            lighting: "lab".into(),
            segmentation: "adaptive".into(),
            terrain: "lab_floor".into(),
            distance_m: 1.0,
            success,
            outcome: if success { "docked" } else { "timeout" }.into(),
            time_s: 10.0,
            path_m: 1.0,
            ..Self::default()
        }
    }
}

/// Options for [`run_campaign`].
#[derive(Debug, Clone, Default)]
pub struct CampaignOptions {
    /// Output folder (runs.jsonl, summary.json, per-run files; `trials` adds the plots).
    pub out: Option<PathBuf>,
    /// Worker threads (0: all cores).
    pub jobs: usize,
    /// Go on with an interrupted campaign in `out`: keep the runs already in
    /// `out/runs.jsonl` (dropping a torn last line, see [`read_resumable`]) and run the
    /// rest.
    pub resume: bool,
    /// How progress is shown on stderr.
    pub progress: Progress,
    /// Write each run's trajectory CSV (and frames, when the scenario asks).
    pub per_run_files: bool,
    /// Record runs to MCAP files, one per run (`DIR/run-00042.mcap`).
    pub record: Option<RecordRuns>,
}

/// Which runs of a campaign are recorded to MCAP, and where ([`super::record`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RecordRuns {
    /// The folder: run N goes to `DIR/run-NNNNN.mcap`.
    pub dir: PathBuf,
    /// Record only the failed runs. In a campaign each run goes unrecorded, and one that
    /// fails is run again with the recorder (runs are deterministic), so docked runs cost
    /// nothing. An endurance outing's cycles start where the one before left the robot and
    /// cannot be run alone, so they are recorded as they go and a docked cycle's file is
    /// deleted.
    pub failed_only: bool,
    /// How each run is recorded.
    pub options: RecordOptions,
}

impl RecordRuns {
    /// The recording of run `index`.
    pub fn path(&self, index: usize) -> PathBuf {
        self.dir.join(format!("run-{index:05}.mcap"))
    }
}

/// How a campaign shows its progress on stderr.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Progress {
    /// Nothing (the library's default).
    #[default]
    Off,
    /// A live bar with the elapsed time, an ETA and the success count (for a terminal).
    Bar,
    /// A plain line at every tenth of the campaign (for logs and CI, where a bar's
    /// redraws would be noise): runs done, docked, elapsed time and ETA.
    Lines,
}

/// Everything shared by the runs of a campaign.
pub struct Prepared {
    /// Scenario and profile.
    pub loaded: Loaded,
    /// The built world (shared by every run's simulation), with the profile's paints.
    pub world: Arc<World>,
    /// The world repainted with each pair of a `fiducial_colors` axis, in axis order
    /// (empty without the axis).
    pub painted: Vec<([NamedColor; 2], Arc<World>)>,
    /// Every run.
    pub runs: Vec<RunSpec>,
    /// How the simulator simulates the profile's `[[sensors]]` by kind (the built-in
    /// `range`, plus any kind a caller registers for its own schemas).
    pub devices: Arc<SimDevices>,
}

/// Loads backdrops, builds the world and lists the runs of a loaded scenario.
///
/// # Errors
/// [`SimError`] when a backdrop cannot be read, the world cannot be built, or a start
/// places the robot inside the dock's body (before any run, so no campaign stops midway).
pub fn prepare(loaded: Loaded) -> Result<Prepared, SimError> {
    prepare_with(loaded, &super::kinds::SimKinds::default())
}

/// [`prepare`] with `kinds` drawing the dock and simulating the devices (a crate's own
/// fiducial and sensor kinds).
///
/// # Errors
/// As [`prepare`].
pub fn prepare_with(loaded: Loaded, kinds: &super::kinds::SimKinds) -> Result<Prepared, SimError> {
    let dir = loaded.file.parent().unwrap_or(Path::new(".")).to_path_buf();
    let backdrops: Vec<Arc<RgbImage>> = loaded
        .scenario
        .backgrounds
        .iter()
        .map(|b| crate::image_io::load_rgb(&dir.join(b)).map(Arc::new))
        .collect::<Result<_, _>>()?;
    let world = world::build_with(&loaded.profile, &loaded.scenario.clutter, &backdrops, &kinds.painters)?;
    let painted = loaded
        .scenario
        .axes
        .fiducial_colors
        .iter()
        .flatten()
        .map(|pair| {
            let profile = repainted(&loaded.profile, Some(*pair));
            world::build_with(&profile, &loaded.scenario.clutter, &backdrops, &kinds.painters)
                .map(|w| (*pair, Arc::new(w)))
        })
        .collect::<Result<_, _>>()?;
    let runs = loaded.scenario.runs(&loaded.profile);
    let body = &loaded.profile.body;
    if let Some(r) = runs
        .iter()
        .find(|r| super::dock::overlaps(&world.dock, &r.start.pose, body.length_m, body.width_m))
    {
        let p = r.start.pose;
        return Err(SimError::InvalidStart(format!(
            "start `{}` places the robot at ({:.3} m, {:.3} m, {:.1}°), overlapping the dock's body",
            r.start.label,
            p.x,
            p.y,
            p.theta.to_degrees()
        )));
    }
    Ok(Prepared {
        loaded,
        world: Arc::new(world),
        painted,
        runs,
        devices: Arc::new(kinds.devices.clone()),
    })
}

/// `profile` with its two-block flap painted `colors` (`[left, right]`); unchanged for
/// `None` or a profile without a two-block flap.
fn repainted(profile: &Profile, colors: Option<[NamedColor; 2]>) -> Profile {
    let mut p = profile.clone();
    if let (Some(&fid), Some([left, right])) = (p.fiducial.get::<TwoBlockSpec>(), colors) {
        p.fiducial.set(TwoBlockSpec {
            left_color: left,
            right_color: right,
            ..fid
        });
    }
    p
}

impl Prepared {
    /// The profile run `spec`'s robot is built from: the scenario's, with the run's
    /// segmentation mode and paints.
    pub fn profile_for(&self, spec: &RunSpec) -> Profile {
        let mut p = repainted(&self.loaded.profile, spec.fiducial_colors);
        p.perception.mode = spec.segmentation;
        p
    }

    /// The world run `spec` runs in: the one painted with its colours, if it has any.
    pub fn world_for(&self, spec: &RunSpec) -> &Arc<World> {
        spec.fiducial_colors
            .and_then(|c| self.painted.iter().find(|(pair, _)| *pair == c))
            .map_or(&self.world, |(_, w)| w)
    }
}

/// Summary of a set of runs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GroupSummary {
    /// Start label (`*` for all).
    pub start: String,
    /// Lighting (`*` for all).
    pub lighting: String,
    /// Segmentation (`*` for all).
    pub segmentation: String,
    /// Terrain (`*` for all).
    pub terrain: String,
    /// The flap's paints, `left|right` (absent without a `fiducial_colors` axis, and for
    /// all runs together).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fiducial_colors: Option<String>,
    /// Runs.
    pub runs: usize,
    /// Successful runs.
    pub successes: usize,
    /// successes / runs.
    pub success_rate: f64,
    /// Mean time to dock of the successful runs, s.
    pub mean_time_s: Option<f64>,
    /// SD of that time, s.
    pub sd_time_s: Option<f64>,
    /// Mean effective velocity of the successful runs, cm/s.
    pub v_eff_cmps: Option<f64>,
    /// Mean drive-command changes per metre.
    pub commands_per_m: f64,
    /// Failures by reason.
    pub failures: BTreeMap<String, usize>,
    /// Alignment manoeuvres per successful run: [min, max] (absent without successes).
    #[serde(default)]
    pub manoeuvres: Option<[u32; 2]>,
}

/// `summary.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// Scenario name.
    pub scenario: String,
    /// All runs together.
    pub overall: GroupSummary,
    /// One entry per combination of the axes (start, fiducial colours, lighting,
    /// segmentation, terrain).
    pub groups: Vec<GroupSummary>,
    /// With a `fiducial_colors` axis: one entry per paint pair and combination of the
    /// other axes, over all starts (`start` is `*`), in campaign order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub by_colors: Vec<GroupSummary>,
    /// With `[[faults]]`: one entry per fault, over all runs that had it, in campaign
    /// order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub by_fault: Vec<FaultSummary>,
    /// With `[endurance]`: success and drift over the outing.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub endurance: Option<super::endurance::EnduranceSummary>,
}

/// How the runs with one injected fault ended (`summary.json`'s `by_fault`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FaultSummary {
    /// The fault's name.
    pub fault: String,
    /// Runs.
    pub runs: usize,
    /// Runs that ended as the fault's `expect` says.
    pub as_expected: usize,
    /// Docked runs.
    pub docked: usize,
    /// Runs that ended in a typed failure of the behavior.
    pub typed_failures: usize,
    /// Runs that ended otherwise (timeout, collision, stuck, false dock): bugs.
    pub other: usize,
    /// Mean time in safe stop per run, s.
    pub mean_safe_stop_s: f64,
    /// Ticks with motion commanded while an input was invalid, over all its runs (must
    /// be 0).
    pub stale_motion_ticks: u64,
}

/// The per-fault rows of a campaign with `[[faults]]` (none without).
pub fn fault_summaries(records: &[RunRecord]) -> Vec<FaultSummary> {
    let mut names: Vec<&str> = Vec::new();
    for r in records {
        if let Some(f) = r.fault.as_deref()
            && !names.contains(&f)
        {
            names.push(f);
        }
    }
    names
        .iter()
        .map(|name| {
            let rs: Vec<&RunRecord> = records.iter().filter(|r| r.fault.as_deref() == Some(name)).collect();
            let docked = rs.iter().filter(|r| r.outcome == "docked").count();
            let other = rs
                .iter()
                .filter(|r| !super::faults::Expected::DockOrTypedFailure.accepts(&r.outcome))
                .count();
            FaultSummary {
                fault: name.to_string(),
                runs: rs.len(),
                as_expected: rs.iter().filter(|r| r.fault_as_expected == Some(true)).count(),
                docked,
                typed_failures: rs.len() - docked - other,
                other,
                mean_safe_stop_s: rs.iter().filter_map(|r| r.safe_stop_s).sum::<f64>() / rs.len().max(1) as f64,
                stale_motion_ticks: rs.iter().filter_map(|r| r.stale_motion_ticks).sum(),
            }
        })
        .collect()
}

/// Summarises records with the given labels.
pub fn summarise(records: &[&RunRecord], labels: [&str; 4]) -> GroupSummary {
    let ok: Vec<&&RunRecord> = records.iter().filter(|r| r.success).collect();
    let mean = |f: &dyn Fn(&RunRecord) -> f64| {
        (!ok.is_empty()).then(|| ok.iter().map(|r| f(r)).sum::<f64>() / ok.len() as f64)
    };
    let mean_time = mean(&|r| r.time_s);
    let sd_time = mean_time.map(|m| (ok.iter().map(|r| (r.time_s - m).powi(2)).sum::<f64>() / ok.len() as f64).sqrt());
    let mut failures = BTreeMap::new();
    for r in records.iter().filter(|r| !r.success) {
        *failures.entry(r.outcome.clone()).or_insert(0) += 1;
    }
    GroupSummary {
        start: labels[0].into(),
        lighting: labels[1].into(),
        segmentation: labels[2].into(),
        terrain: labels[3].into(),
        fiducial_colors: None,
        runs: records.len(),
        successes: ok.len(),
        success_rate: if records.is_empty() {
            0.0
        } else {
            ok.len() as f64 / records.len() as f64
        },
        mean_time_s: mean_time,
        sd_time_s: sd_time,
        v_eff_cmps: mean(&|r| r.v_eff_cmps),
        commands_per_m: if records.is_empty() {
            0.0
        } else {
            records.iter().map(|r| r.commands_per_m).sum::<f64>() / records.len() as f64
        },
        failures,
        manoeuvres: (!ok.is_empty()).then(|| {
            let it = ok.iter().map(|r| r.manoeuvres);
            [it.clone().min().unwrap_or(0), it.max().unwrap_or(0)]
        }),
    }
}

/// The summary of a campaign's records (in campaign order).
pub fn summary(name: &str, records: &[RunRecord]) -> Summary {
    let all: Vec<&RunRecord> = records.iter().collect();
    let colours = |r: &RunRecord| r.fiducial_colors.as_ref().map(super::scenario::colors_label);
    // Groups in order of first appearance, by (start, colours, lighting, segmentation,
    // terrain); `starts` false pools the starts.
    let grouped = |starts: bool| -> Vec<GroupSummary> {
        let key = |r: &RunRecord| {
            (
                if starts { r.start.clone() } else { "*".into() },
                colours(r),
                [r.lighting.clone(), r.segmentation.clone(), r.terrain.clone()],
            )
        };
        let mut keys = Vec::new();
        for r in records {
            let k = key(r);
            if !keys.contains(&k) {
                keys.push(k);
            }
        }
        keys.iter()
            .map(|k| {
                let rs: Vec<&RunRecord> = records.iter().filter(|r| key(r) == *k).collect();
                let mut g = summarise(&rs, [&k.0, &k.2[0], &k.2[1], &k.2[2]]);
                g.fiducial_colors = k.1.clone();
                g
            })
            .collect()
    };
    let by_colors = if records.iter().any(|r| r.fiducial_colors.is_some()) {
        grouped(false)
    } else {
        Vec::new()
    };
    Summary {
        scenario: name.into(),
        overall: summarise(&all, ["*", "*", "*", "*"]),
        groups: grouped(true),
        by_colors,
        by_fault: fault_summaries(records),
        endurance: super::endurance::summarise(records),
    }
}

/// Reads the records of a `runs.jsonl` for analysis, leniently: lines that are not run
/// records are skipped, and a missing file gives none. `--resume` does not use this: it
/// reads with [`read_resumable`], which refuses anything but a torn last line.
pub fn read_runs(path: &Path) -> Vec<RunRecord> {
    std::fs::read_to_string(path)
        .map(|s| s.lines().filter_map(|l| serde_json::from_str(l).ok()).collect())
        .unwrap_or_default()
}

/// What `--resume` keeps of an interrupted campaign's `runs.jsonl` ([`read_resumable`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Resumable {
    /// The finished runs, in campaign order: runs `0..records.len()`.
    pub records: Vec<RunRecord>,
    /// Bytes of the file that hold them (whole lines, each ending in `\n`); the file is
    /// cut to this length before the campaign goes on.
    pub keep_bytes: u64,
    /// Bytes after them: a torn last line (a write the kill cut short), dropped.
    pub torn_bytes: u64,
}

/// Reads an interrupted campaign's `runs.jsonl` for `--resume`, checking it against the
/// campaign's `runs`.
///
/// The campaign appends one whole line per run, in run order, so a kill at any instant
/// leaves whole lines for runs `0..k`, then possibly a torn last line: bytes after the
/// last `\n` (a line cut short mid-write), or a last line that does not parse. That torn
/// line, and only it, is dropped (its run runs again). A missing file is an empty one.
///
/// # Errors
/// [`SimError::Io`] when the file cannot be read, or names the first line (1-based) that
/// a kill cannot explain: a line before the last that is not a run record, or a record
/// that is not the campaign's run for its line (its index, start, trial and seed), as
/// when the file was edited or written by another scenario or seed. Nothing is dropped
/// silently; fix or remove the file, or run without `--resume`.
pub fn read_resumable(path: &Path, runs: &[RunSpec]) -> Result<Resumable, SimError> {
    let bytes = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Vec::new(),
        Err(e) => return Err(io(path)(e)),
    };
    parse_resumable(&bytes, path, runs)
}

/// The checks of [`read_resumable`] on the bytes of a `runs.jsonl` already read (`path`
/// is used in messages only): whole lines that are the campaign's runs in order, then at
/// most a torn last line.
///
/// # Errors
/// As [`read_resumable`], for a line a kill cannot explain.
pub fn parse_resumable(bytes: &[u8], path: &Path, runs: &[RunSpec]) -> Result<Resumable, SimError> {
    let bad = |line: usize, what: String| SimError::Io {
        path: path.display().to_string(),
        source: std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!(
                "line {line}: {what}; --resume only drops a torn last line (fix or remove the file, or run without --resume)"
            ),
        ),
    };
    // Whole lines end in `\n`; anything after the last one is a torn write.
    let whole = bytes.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
    let lines: Vec<&[u8]> = bytes[..whole].split_inclusive(|&b| b == b'\n').collect();
    let mut records = Vec::with_capacity(lines.len());
    let mut keep = 0usize;
    for (i, line) in lines.iter().enumerate() {
        let record: RunRecord = match serde_json::from_slice(&line[..line.len() - 1]) {
            Ok(r) => r,
            // The last line may be whole but unparseable only if nothing follows it.
            Err(_) if i + 1 == lines.len() && whole == bytes.len() => break,
            Err(e) => return Err(bad(i + 1, format!("not a run record ({e})"))),
        };
        match runs.get(i) {
            Some(spec)
                if record.index == spec.index
                    && record.seed == spec.seed
                    && record.trial == spec.trial
                    && record.start == spec.start.label => {}
            Some(spec) => {
                return Err(bad(
                    i + 1,
                    format!(
                        "run {} (start {}, trial {}, seed {}) where this campaign's run {} (start {}, trial {}, seed {}) belongs",
                        record.index,
                        record.start,
                        record.trial,
                        record.seed,
                        spec.index,
                        spec.start.label,
                        spec.trial,
                        spec.seed
                    ),
                ));
            }
            None => return Err(bad(i + 1, format!("the campaign has only {} runs", runs.len()))),
        }
        records.push(record);
        keep += line.len();
    }
    Ok(Resumable {
        records,
        keep_bytes: keep as u64,
        torn_bytes: (bytes.len() - keep) as u64,
    })
}

/// The environment variable of a test hook: when it holds a number of milliseconds, each
/// `runs.jsonl` line is written in two halves with that sleep between them, so a test
/// that kills the campaign can land the kill mid-write (`tests/campaign_resume.rs`).
/// Read once per campaign; unset (always, outside tests), a line is one `write_all`.
pub const TEST_SLOW_WRITE_ENV: &str = "MARSUPIAL_TEST_SLOW_WRITE";

/// Appends one whole `runs.jsonl` line (`line` ends in `\n`) with a single `write_all`,
/// or, under the [`TEST_SLOW_WRITE_ENV`] hook, in two halves `pause` apart.
fn append_line(f: &mut std::fs::File, line: &[u8], pause: Option<std::time::Duration>) -> std::io::Result<()> {
    match pause {
        None => f.write_all(line),
        Some(d) => {
            let (a, b) = line.split_at(line.len() / 2);
            f.write_all(a)?;
            std::thread::sleep(d);
            f.write_all(b)
        }
    }
}

/// Replaces `path` with `bytes` atomically: a temporary file in the same folder, synced,
/// then renamed over it, so a kill leaves the old file or the new one, never a torn one.
fn write_atomically(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let mut name = path.file_name().unwrap_or_default().to_os_string();
    name.push(".tmp");
    let tmp = path.with_file_name(name);
    let mut f = std::fs::File::create(&tmp)?;
    f.write_all(bytes)?;
    f.sync_all()?;
    drop(f);
    std::fs::rename(&tmp, path)
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> SimError + '_ {
    move |source| SimError::Io {
        path: path.display().to_string(),
        source,
    }
}

/// Runs every run of `p` and returns the records in campaign order plus the summary.
///
/// # Errors
/// [`SimError`] when output cannot be written or no agent can be built.
pub fn run_campaign(
    p: &Prepared,
    make_agent: &AgentFactory,
    opts: &CampaignOptions,
) -> Result<(Vec<RunRecord>, Summary), SimError> {
    if p.loaded.scenario.endurance.is_some() {
        return super::endurance::run_campaign(p, make_agent, opts);
    }
    // Fail early if the profile has no behavior.
    make_agent(&p.loaded.profile).map_err(|e| SimError::Unsupported(e.to_string()))?;
    let mut done: BTreeMap<usize, RunRecord> = BTreeMap::new();
    if let Some(r) = &opts.record {
        std::fs::create_dir_all(&r.dir).map_err(io(&r.dir))?;
    }
    let mut jsonl = None;
    if let Some(dir) = &opts.out {
        std::fs::create_dir_all(dir).map_err(io(dir))?;
        let path = dir.join("runs.jsonl");
        let f = if opts.resume {
            // Keep the finished runs' whole lines where they are and cut off a torn last
            // line: one truncation, so a kill here too leaves a file a resume accepts.
            let kept = read_resumable(&path, &p.runs)?;
            if kept.torn_bytes > 0 {
                tracing::info!(
                    "{}: dropped a torn last line ({} bytes) after {} finished runs",
                    path.display(),
                    kept.torn_bytes,
                    kept.records.len()
                );
            }
            let f = std::fs::OpenOptions::new()
                .append(true)
                .create(true)
                .open(&path)
                .map_err(io(&path))?;
            f.set_len(kept.keep_bytes).map_err(io(&path))?;
            done.extend(kept.records.into_iter().map(|r| (r.index, r)));
            f
        } else {
            std::fs::File::create(&path).map_err(io(&path))?;
            std::fs::OpenOptions::new()
                .append(true)
                .open(&path)
                .map_err(io(&path))?
        };
        jsonl = Some((f, path));
    }
    let slow_write = std::env::var(TEST_SLOW_WRITE_ENV)
        .ok()
        .and_then(|v| v.parse().ok())
        .map(std::time::Duration::from_millis);
    let pending: Vec<&RunSpec> = p.runs.iter().filter(|r| !done.contains_key(&r.index)).collect();
    let jobs = if opts.jobs == 0 {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    } else {
        opts.jobs
    };
    let bar = (opts.progress == Progress::Bar).then(|| {
        let b = indicatif::ProgressBar::new(p.runs.len() as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} runs  {elapsed_precise} (eta {eta})  {msg}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        b.set_position(done.len() as u64);
        b
    });
    let mut lines = (opts.progress == Progress::Lines).then(|| ProgressLines::new(p, done.values()));
    let next = AtomicUsize::new(0);
    let (tx, rx) = crossbeam::channel::unbounded::<Result<RunRecord, SimError>>();
    let mut error = None;
    let (mut docked, mut finished) = (done.values().filter(|r| r.success).count(), done.len());
    std::thread::scope(|s| {
        for _ in 0..jobs.min(pending.len().max(1)) {
            let tx = tx.clone();
            let (next, pending) = (&next, &pending);
            s.spawn(move || {
                loop {
                    let k = next.fetch_add(1, Ordering::SeqCst);
                    let Some(spec) = pending.get(k) else { break };
                    let frames_dir = opts
                        .out
                        .as_ref()
                        .filter(|_| opts.per_run_files)
                        .map(|d| d.join(format!("run-{:04}", spec.index)));
                    if let Some(d) = &frames_dir {
                        let _ = std::fs::create_dir_all(d);
                    }
                    let every = p.loaded.scenario.record.frames_every;
                    let mcap = opts.record.as_ref().map(|r| (r.path(spec.index), r.options));
                    let to_mcap = mcap.as_ref().map(|(path, options)| (path.as_path(), *options));
                    let failed_only = opts.record.as_ref().is_some_and(|r| r.failed_only);
                    let mut rec_opts = Recording {
                        frames: frames_dir.as_deref().map(|d| (d, every)),
                        trace: None,
                        mcap: to_mcap.filter(|_| !failed_only),
                    };
                    let mut rec = run_one(p, spec, make_agent, &mut rec_opts);
                    // `--record-failed`: a run is recorded only once it has failed, by
                    // running it again with the recorder. The same seed gives the same run
                    // and recording changes nothing in it, so the file is the failed run's,
                    // and the runs that dock cost nothing to record.
                    if failed_only
                        && let (Ok(first), Some(to)) = (&rec, to_mcap)
                        && !first.success
                    {
                        let mut again = Recording {
                            frames: None,
                            trace: None,
                            mcap: Some(to),
                        };
                        match run_one(p, spec, make_agent, &mut again) {
                            // Compared as `runs.jsonl` holds them (a NaN is not == itself).
                            Ok(r) if serde_json::to_vec(&r).ok() == serde_json::to_vec(first).ok() => {}
                            Ok(_) => tracing::warn!(target: "marsupial::sim", index = spec.index, "the recorded re-run of a failed run differs from it"),
                            Err(e) => rec = Err(e),
                        }
                    }
                    if let (Ok(r), Some(d)) = (&rec, &frames_dir) {
                        let _ = write_track_csv(&d.join("trajectory.csv"), r);
                    }
                    if tx.send(rec).is_err() {
                        break;
                    }
                }
            });
        }
        drop(tx);
        // Write in campaign order.
        let mut buffer: BTreeMap<usize, RunRecord> = BTreeMap::new();
        let mut cursor = 0usize;
        for rec in rx.iter() {
            match rec {
                Ok(r) => {
                    docked += usize::from(r.success);
                    finished += 1;
                    if let Some(b) = &bar {
                        b.inc(1);
                        b.set_message(format!(
                            "docked {docked}/{finished}  last: start {} {}",
                            r.start, r.outcome
                        ));
                    }
                    if let Some(l) = lines.as_mut() {
                        l.record(r.success);
                    }
                    buffer.insert(r.index, r);
                }
                Err(e) => {
                    error.get_or_insert(e);
                    next.store(usize::MAX / 2, Ordering::SeqCst);
                }
            }
            while cursor < p.runs.len() {
                let idx = p.runs[cursor].index;
                if done.contains_key(&idx) {
                    cursor += 1;
                    continue;
                }
                let Some(r) = buffer.remove(&idx) else { break };
                if let Some((f, path)) = jsonl.as_mut() {
                    // One whole line per write: a kill can only tear the last line.
                    let mut line = serde_json::to_vec(&r).unwrap_or_default();
                    line.push(b'\n');
                    if let Err(e) = append_line(f, &line, slow_write) {
                        // Stop: later lines after a short write would tear the middle.
                        error.get_or_insert(io(path)(e));
                        next.store(usize::MAX / 2, Ordering::SeqCst);
                        jsonl = None;
                    }
                }
                done.insert(idx, r);
                cursor += 1;
            }
        }
    });
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    if let Some(e) = error {
        return Err(e);
    }
    let records: Vec<RunRecord> = done.into_values().collect();
    let summary = summary(&p.loaded.scenario.name, &records);
    if let Some(dir) = &opts.out {
        // From every record, the resumed ones included; replaced atomically.
        let path = dir.join("summary.json");
        write_atomically(
            &path,
            serde_json::to_string_pretty(&summary).unwrap_or_default().as_bytes(),
        )
        .map_err(io(&path))?;
    }
    Ok((records, summary))
}

/// [`Progress::Lines`]: a line on stderr each time another tenth of the campaign is done.
pub(super) struct ProgressLines {
    name: String,
    total: usize,
    done: usize,
    docked: usize,
    /// Runs finished in this invocation (a resume's kept runs cost no time).
    fresh: usize,
    started: std::time::Instant,
    next_tenth: usize,
}

impl ProgressLines {
    pub(super) fn new<'a>(p: &Prepared, kept: impl Iterator<Item = &'a RunRecord>) -> Self {
        let (mut done, mut docked) = (0, 0);
        for r in kept {
            done += 1;
            docked += usize::from(r.success);
        }
        let total = p.runs.len();
        Self {
            name: p.loaded.scenario.name.clone(),
            total,
            done,
            docked,
            fresh: 0,
            started: std::time::Instant::now(),
            next_tenth: (done * 10 / total.max(1)) + 1,
        }
    }

    pub(super) fn record(&mut self, success: bool) {
        self.done += 1;
        self.fresh += 1;
        self.docked += usize::from(success);
        if self.done * 10 >= self.next_tenth * self.total {
            self.next_tenth = self.done * 10 / self.total.max(1) + 1;
            let elapsed = self.started.elapsed().as_secs_f64();
            let eta = elapsed / self.fresh as f64 * (self.total - self.done) as f64;
            eprintln!(
                "{}: {}/{} runs, {} docked, {:.0} s elapsed, eta {:.0} s",
                self.name, self.done, self.total, self.docked, elapsed, eta
            );
        }
    }
}

/// Writes a run's track as CSV (t, x, y).
pub fn write_track_csv(path: &Path, r: &RunRecord) -> std::io::Result<()> {
    let mut s = String::from("t_s,x_m,y_m\n");
    for (i, p) in r.track.iter().enumerate() {
        s.push_str(&format!(
            "{:.1},{:.3},{:.3}\n",
            i as f64 * 0.5,
            p[0] as f64 / 1000.0,
            p[1] as f64 / 1000.0
        ));
    }
    std::fs::write(path, s)
}
