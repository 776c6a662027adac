//! Trial campaigns: every run of a scenario, in parallel, streamed to `runs.jsonl`.
//!
//! Runs are independent and seeded from (scenario seed, run index), so a run's record does
//! not depend on which worker ran it or when. Records are written in run order (a small
//! reorder buffer holds early finishers), so the same scenario and seed give the same
//! `runs.jsonl` byte for byte whatever `--jobs` is; `--resume` skips runs already in the
//! file. Runs that differ only in segmentation mode share a `pair_seed`: same lighting
//! instant, same placement error and the same imprint, as in the paper's paired protocol.

use super::SimError;
use super::lighting_random::LightingDraw;
use super::robot::SimDevices;
pub use super::run::{Recording, run_one};
use super::scenario::{Loaded, RunSpec};
use super::world::{self, World};
use crate::behaviors::BuildError;
use crate::perception::RgbImage;
use crate::profile::{NamedColor, Profile};
use crate::schemas::Agent;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Builds a fresh agent for a (per-run) profile.
pub type AgentFactory = dyn Fn(&Profile) -> Result<Box<dyn Agent>, BuildError> + Sync;

/// The record of one run (one line of `runs.jsonl`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
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
    /// The run's lighting draw, when its lighting is a `[lighting_random.NAME]`
    /// distribution (absent otherwise).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lighting_draw: Option<LightingDraw>,
    /// True path, [x, y] in mm every 0.5 s.
    pub track: Vec<[i32; 2]>,
}

/// Options for [`run_campaign`].
#[derive(Debug, Clone, Default)]
pub struct CampaignOptions {
    /// Output folder (runs.jsonl, summary.json, plots, per-run files).
    pub out: Option<PathBuf>,
    /// Worker threads (0: all cores).
    pub jobs: usize,
    /// Skip runs already in `out/runs.jsonl`.
    pub resume: bool,
    /// Show a progress bar on stderr.
    pub progress: bool,
    /// Write each run's trajectory CSV (and frames, when the scenario asks).
    pub per_run_files: bool,
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
    let dir = loaded.file.parent().unwrap_or(Path::new(".")).to_path_buf();
    let backdrops: Vec<Arc<RgbImage>> = loaded
        .scenario
        .backgrounds
        .iter()
        .map(|b| crate::image_io::load_rgb(&dir.join(b)).map(Arc::new))
        .collect::<Result<_, _>>()?;
    let world = world::build(&loaded.profile, &loaded.scenario.clutter, &backdrops)?;
    let painted = loaded
        .scenario
        .axes
        .fiducial_colors
        .iter()
        .flatten()
        .map(|pair| {
            let profile = repainted(&loaded.profile, Some(*pair));
            world::build(&profile, &loaded.scenario.clutter, &backdrops).map(|w| (*pair, Arc::new(w)))
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
        devices: Arc::new(SimDevices::default()),
    })
}

/// `profile` with its two-block flap painted `colors` (`[left, right]`); unchanged for
/// `None` or a profile without a two-block flap.
fn repainted(profile: &Profile, colors: Option<[NamedColor; 2]>) -> Profile {
    let mut p = profile.clone();
    if let (Some(fid), Some([left, right])) = (p.fiducial.two_block.as_mut(), colors) {
        fid.left_color = left;
        fid.right_color = right;
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
    }
}

/// Reads the records of an earlier (possibly interrupted) campaign.
pub fn read_runs(path: &Path) -> Vec<RunRecord> {
    std::fs::read_to_string(path)
        .map(|s| s.lines().filter_map(|l| serde_json::from_str(l).ok()).collect())
        .unwrap_or_default()
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
    // Fail early if the profile has no behavior.
    make_agent(&p.loaded.profile).map_err(|e| SimError::Unsupported(e.to_string()))?;
    let mut done: BTreeMap<usize, RunRecord> = BTreeMap::new();
    let mut jsonl = None;
    if let Some(dir) = &opts.out {
        std::fs::create_dir_all(dir).map_err(io(dir))?;
        let path = dir.join("runs.jsonl");
        if opts.resume {
            for r in read_runs(&path) {
                done.insert(r.index, r);
            }
            // Rewrite the file with only complete, ordered lines.
            let mut f = std::fs::File::create(&path).map_err(io(&path))?;
            for r in done.values() {
                writeln!(f, "{}", serde_json::to_string(r).unwrap_or_default()).map_err(io(&path))?;
            }
        } else {
            std::fs::File::create(&path).map_err(io(&path))?;
        }
        jsonl = Some(
            std::fs::OpenOptions::new()
                .append(true)
                .open(&path)
                .map_err(io(&path))?,
        );
    }
    let pending: Vec<&RunSpec> = p.runs.iter().filter(|r| !done.contains_key(&r.index)).collect();
    let jobs = if opts.jobs == 0 {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    } else {
        opts.jobs
    };
    let bar = opts.progress.then(|| {
        let b = indicatif::ProgressBar::new(p.runs.len() as u64);
        b.set_style(
            indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} runs  {elapsed_precise} (eta {eta})  {msg}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        b.set_position(done.len() as u64);
        b
    });
    let next = AtomicUsize::new(0);
    let (tx, rx) = crossbeam::channel::unbounded::<Result<RunRecord, SimError>>();
    let mut error = None;
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
                    let mut rec_opts = Recording {
                        frames: frames_dir.as_deref().map(|d| (d, every)),
                        trace: None,
                    };
                    let rec = run_one(p, spec, make_agent, &mut rec_opts);
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
                    if let Some(b) = &bar {
                        b.inc(1);
                        b.set_message(format!("last: start {} {}", r.start, r.outcome));
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
                if let Some(f) = jsonl.as_mut() {
                    let _ = writeln!(f, "{}", serde_json::to_string(&r).unwrap_or_default());
                    let _ = f.flush();
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
        let path = dir.join("summary.json");
        std::fs::write(&path, serde_json::to_string_pretty(&summary).unwrap_or_default()).map_err(io(&path))?;
        super::plot::write_plots(dir, &p.world, &p.loaded.profile, &records).map_err(io(dir))?;
    }
    Ok((records, summary))
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
