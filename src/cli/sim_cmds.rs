//! `marsupial dock` and `marsupial trials`: runs in the simulator.

use super::Plugins;
use crate::report::paper::cell;
use crate::sim::SimError;
use crate::sim::campaign::{self, CampaignOptions, GroupSummary, Recording, RunRecord, Summary};
use crate::sim::record::RecordOptions;
use crate::sim::scenario::Scenario;
use crate::sim::shard;
use std::io::Write;
use std::path::PathBuf;

/// Options of `marsupial dock` (also its command-line arguments).
#[derive(Debug, Clone, Default, clap::Args)]
pub struct DockOptions {
    /// Scenario file.
    #[arg(long, value_name = "S")]
    pub scenario: PathBuf,
    /// Start label (grid position 1–16, or list entry); default the first.
    #[arg(long, value_name = "N", conflicts_with = "at")]
    pub start: Option<String>,
    /// Explicit start: x,y,heading (metres, metres, degrees) in the dock frame.
    #[arg(long, value_name = "X,Y,HEADING", value_parser = parse_at)]
    pub at: Option<(f64, f64, f64)>,
    /// Run exactly run N of the scenario's campaign (the `index` field of `trials`'
    /// runs.jsonl): same start, trial, lighting, segmentation, terrain and seeds, so a
    /// failed campaign run can be replayed with --out and logging. For an endurance
    /// scenario N is a cycle: the outing runs through cycle N (every cycle depends on the
    /// ones before it) and only cycle N is traced, recorded and saved.
    #[arg(long, value_name = "N", conflicts_with_all = ["start", "at", "seed"])]
    pub index: Option<usize>,
    /// Seed (default: the scenario's).
    #[arg(long, value_name = "K")]
    pub seed: Option<u64>,
    /// Print the run record as JSON.
    #[arg(long)]
    pub json: bool,
    /// Output folder (trajectory CSV, frames).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Write the decision trace, one JSON object per tick: the mission, the loop status,
    /// the command, and each arbiter that ran (active children, their proposals, the
    /// winner, transitions with the events that fired them).
    #[arg(long, value_name = "FILE.jsonl")]
    pub trace: Option<PathBuf>,
    /// With --out, save every Nth camera frame (departure included), overriding the
    /// scenario's `[record] frames_every`; 0 saves none.
    #[arg(long, value_name = "N", requires = "out")]
    pub frames_every: Option<u32>,
    /// Record the run to an MCAP file for Foxglove: every frame with its calibration,
    /// the percept (as image annotations and JSON), the command, the decision trace, the
    /// odometry and true poses, the colour ranges and a log (see the README's topics).
    #[arg(long, value_name = "FILE.mcap")]
    pub record: Option<PathBuf>,
    /// With --record, store frames as JPEG (`foxglove.CompressedImage`) instead of raw
    /// RGB: files about ten times smaller, slower to write.
    #[arg(long, requires = "record")]
    pub jpeg: bool,
}

/// Parses `--at x,y,heading`.
///
/// # Errors
/// A message when the text is not three finite comma-separated numbers.
pub fn parse_at(s: &str) -> Result<(f64, f64, f64), String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>().map_err(|e| format!("`{x}`: {e}")))
        .collect::<Result<_, _>>()?;
    match v[..] {
        [x, y, h] if v.iter().all(|x| x.is_finite()) => Ok((x, y, h)),
        _ => Err("expected three finite numbers: x,y,heading".into()),
    }
}

/// Runs one docking run of the crate's robots (see [`dock_with`]).
///
/// # Errors
/// As [`dock_with`].
pub fn dock(opts: &DockOptions, out: &mut dyn Write) -> Result<RunRecord, SimError> {
    dock_with(opts, &Plugins::default(), out)
}

/// Runs one docking run, its robot built from `plugins`' catalog and its dock drawn by
/// `plugins`' painters.
///
/// # Errors
/// [`SimError`] for bad scenarios, missing behaviors or unwritable output.
pub fn dock_with(opts: &DockOptions, plugins: &Plugins, out: &mut dyn Write) -> Result<RunRecord, SimError> {
    // The factory runs on the campaign's worker threads: it owns its catalog (a few Arcs).
    let catalog = plugins.catalog.clone();
    let agent = move |p: &crate::profile::Profile| catalog.agent(p);
    let mut loaded = Scenario::load_with(&opts.scenario, plugins.catalog.fiducials())?;
    if let Some(s) = opts.seed {
        loaded.scenario.seed = s;
    }
    if let Some((x, y, h)) = opts.at {
        loaded.scenario.starts.grid = None;
        loaded.scenario.starts.points = vec![crate::sim::scenario::StartPoint {
            distance_m: None,
            angle_deg: None,
            x_m: Some(x),
            y_m: Some(y),
            heading_deg: Some(h),
            label: Some("at".into()),
        }];
    }
    let prepared = campaign::prepare_with(loaded, &plugins.sim)?;
    let spec = match (&opts.start, opts.index) {
        (_, Some(i)) => Some(prepared.runs.get(i).ok_or_else(|| {
            SimError::Unsupported(format!(
                "no run {i} in the scenario: its campaign has runs 0–{}",
                prepared.runs.len().saturating_sub(1)
            ))
        })?),
        (None, None) => prepared.runs.first(),
        (Some(label), None) => prepared
            .runs
            .iter()
            .find(|r| &r.start.label == label || r.start.label == format!("p{label}")),
    }
    .cloned()
    .ok_or_else(|| {
        SimError::Unsupported(format!(
            "no start {:?} in the scenario",
            opts.start.clone().unwrap_or_default()
        ))
    })?;
    let frames_dir = opts.out.as_ref().map(|d| d.join("frames"));
    if let Some(d) = &frames_dir {
        std::fs::create_dir_all(d).map_err(|source| SimError::Io {
            path: d.display().to_string(),
            source,
        })?;
    }
    let every = opts
        .frames_every
        .unwrap_or(prepared.loaded.scenario.record.frames_every);
    let mut trace = match &opts.trace {
        Some(path) => Some(std::io::BufWriter::new(std::fs::File::create(path).map_err(
            |source| SimError::Io {
                path: path.display().to_string(),
                source,
            },
        )?)),
        None => None,
    };
    let mut recording = Recording {
        frames: frames_dir.as_deref().map(|d| (d, every)),
        trace: trace.as_mut().map(|w| w as &mut dyn Write),
        mcap: opts.record.as_deref().map(|p| {
            (
                p,
                RecordOptions {
                    jpeg: opts.jpeg,
                    ..RecordOptions::default()
                },
            )
        }),
    };
    let rec = if prepared.loaded.scenario.endurance.is_some() {
        // An outing's cycle depends on every cycle before it: run the outing through it,
        // recording and tracing that cycle only.
        let mcap = recording.mcap.take().map(|(p, o)| (p.to_path_buf(), o));
        let mcap_for = |i: usize| mcap.clone().filter(|_| i == spec.index);
        let mut found = None;
        crate::sim::endurance::run_outing(
            &prepared,
            &agent,
            spec.index,
            crate::sim::endurance::OutingRecording {
                traced: Some(spec.index),
                recording: &mut recording,
                mcap_for: &mcap_for,
            },
            &mut |r| {
                if r.index == spec.index {
                    found = Some(r);
                }
                Ok(())
            },
        )?;
        found.ok_or_else(|| SimError::Unsupported(format!("the outing ended before cycle {}", spec.index)))?
    } else {
        campaign::run_one(&prepared, &spec, &agent, &mut recording)?
    };
    if let (Some(w), Some(path)) = (trace.as_mut(), &opts.trace) {
        w.flush().map_err(|source| SimError::Io {
            path: path.display().to_string(),
            source,
        })?;
    }
    if let Some(d) = &opts.out {
        let p = d.join("trajectory.csv");
        campaign::write_track_csv(&p, &rec).map_err(|source| SimError::Io {
            path: p.display().to_string(),
            source,
        })?;
    }
    let _ = if opts.json {
        writeln!(out, "{}", serde_json::to_string(&rec).unwrap_or_default())
    } else {
        writeln!(
            out,
            "start {} ({:.2} m, {:+.0}°): {} in {:.1} s, {:.2} m driven{}",
            rec.start,
            rec.distance_m,
            rec.angle_deg,
            rec.outcome,
            rec.time_s,
            rec.path_m,
            rec.entrance_lateral_m
                .map(|l| format!(
                    ", entrance error {:+.1} cm / {:+.1}°",
                    l * 100.0,
                    rec.entrance_heading_deg.unwrap_or(0.0)
                ))
                .unwrap_or_default()
        )
    };
    Ok(rec)
}

/// Options of `marsupial trials` (also its command-line arguments).
#[derive(Debug, Clone, Default, clap::Args)]
pub struct TrialsOptions {
    /// Scenario file.
    #[arg(value_name = "S")]
    pub scenario: PathBuf,
    /// Output folder.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Print the summary JSON instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Worker threads (default: all cores).
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub jobs: usize,
    /// Go on with an interrupted campaign: keep the runs in DIR/runs.jsonl (dropping a
    /// torn last line) and run the rest.
    #[arg(long, requires = "out")]
    pub resume: bool,
    /// Print success binned by a drawn lighting parameter, `PARAM` or `PARAM:N` (N bins,
    /// default 5; repeatable), for a scenario whose lighting axis names a
    /// `[lighting_random.NAME]`. Parameters: intensity, outdoor, ambient, sun,
    /// sun_elevation_deg, sun_azimuth_deg, glare, beacons, beacon_power,
    /// beacon_distance_m, shadows, shadow_speed_mps, shadow_strength, clouds.
    #[arg(long, value_name = "PARAM[:N]")]
    pub bin: Vec<String>,
    /// Run only shard K of N (1-based): the runs at campaign positions K−1, K−1+N, …
    /// The same runs on any machine; join the shards' output folders with
    /// `marsupial merge`. With --out, also writes DIR/shard.json.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<crate::sim::shard::Shard>,
    /// Record each run to an MCAP file for Foxglove, `DIR/run-NNNNN.mcap` (N the run's
    /// index; see `dock --record`).
    #[arg(long, value_name = "DIR")]
    pub record_dir: Option<PathBuf>,
    /// With --record-dir, record only the failed runs: a run that fails is run again with
    /// the recorder (runs are deterministic, so the file is that run's), and the runs that
    /// dock cost nothing to record.
    #[arg(long, requires = "record_dir")]
    pub record_failed: bool,
    /// With --record-dir, store frames as JPEG instead of raw RGB.
    #[arg(long, requires = "record_dir")]
    pub jpeg: bool,
    /// Progress on stderr (the binary sets a bar when stderr is a terminal, plain lines
    /// otherwise).
    #[arg(skip)]
    pub progress: campaign::Progress,
}

/// Prints a summary as a table like the paper's: one row per group (start × the axes
/// that vary), then all runs; with a `fiducial_colors` axis, then one row per paint pair
/// (× the other varying axes) over all starts.
pub fn print_table(s: &Summary, out: &mut dyn Write) -> std::io::Result<()> {
    writeln!(out, "{}", s.scenario)?;
    print_groups(&s.groups, Some(&s.overall), out)?;
    if !s.by_colors.is_empty() {
        writeln!(out, "\nby fiducial colours, over all starts")?;
        print_groups(&s.by_colors, None, out)?;
    }
    if let Some(e) = &s.endurance {
        print_endurance(e, out)?;
    }
    if !s.by_fault.is_empty() {
        let w = s
            .by_fault
            .iter()
            .map(|f| f.fault.chars().count())
            .max()
            .unwrap_or(5)
            .max(5);
        writeln!(out, "\nby fault, over all starts")?;
        writeln!(
            out,
            "{:<w$}  runs  as expected  docked  typed failures  other  safe stop (s)  stale-motion ticks",
            "fault"
        )?;
        for f in &s.by_fault {
            writeln!(
                out,
                "{:<w$}  {:>4}  {:>11}  {:>6}  {:>14}  {:>5}  {:>13.1}  {:>18}",
                f.fault,
                f.runs,
                f.as_expected,
                f.docked,
                f.typed_failures,
                f.other,
                f.mean_safe_stop_s,
                f.stale_motion_ticks
            )?;
        }
    }
    Ok(())
}

/// The endurance lines of [`print_table`]: cycles docked, the proctor's carries, and
/// the drift in time to dock and odometry's error over the outing.
fn print_endurance(e: &crate::sim::endurance::EnduranceSummary, out: &mut dyn Write) -> std::io::Result<()> {
    writeln!(
        out,
        "\nendurance: {}/{} cycles docked in one outing ({} carried back by the proctor, {} excursions short of their start); last cycle began at {:.2} h",
        e.docked, e.cycles, e.carried_back, e.excursions_short, e.last_cycle_at_h
    )?;
    writeln!(
        out,
        "time to dock: first {q} cycles {} s, last {q} cycles {} s; trend {} s per cycle over docked cycles, {} within starts",
        cell(e.first_quarter_mean_s, 1),
        cell(e.last_quarter_mean_s, 1),
        e.slope_s_per_cycle.map_or("–".into(), |v| format!("{v:+.3}")),
        e.slope_within_starts_s_per_cycle
            .map_or("–".into(), |v| format!("{v:+.3}")),
        q = e.quarter
    )?;
    writeln!(
        out,
        "odometry error at the start of docking: first cycle {:.2} m, last {:.2} m, largest {:.2} m",
        e.odometry_error_m[0], e.odometry_error_m[1], e.odometry_error_m[2]
    )
}

/// The rows of [`print_table`]: a column for the start and for each axis that varies
/// among `groups`, then the figures; `overall` last.
fn print_groups(groups: &[GroupSummary], overall: Option<&GroupSummary>, out: &mut dyn Write) -> std::io::Result<()> {
    let vary = |f: &dyn Fn(&GroupSummary) -> Option<&str>| {
        let first = groups.first().map(f);
        groups.iter().any(|g| Some(f(g)) != first)
    };
    let (vc, vl, vs, vt) = (
        vary(&|g| g.fiducial_colors.as_deref()),
        vary(&|g| Some(&g.lighting)),
        vary(&|g| Some(&g.segmentation)),
        vary(&|g| Some(&g.terrain)),
    );
    // The start and colour columns fit their longest label (explicit starts may be named).
    let width = |f: &dyn Fn(&GroupSummary) -> usize, least: usize| groups.iter().map(f).max().unwrap_or(0).max(least);
    let sw = width(&|g| g.start.chars().count(), 5);
    let cw = width(&|g| g.fiducial_colors.as_deref().map_or(0, |c| c.chars().count()), 7);
    let mut head = format!("{:<sw$} ", "start");
    if vc {
        head.push_str(&format!(" {:<cw$}", "colours"));
    }
    if vl {
        head.push_str(" lighting  ");
    }
    if vs {
        head.push_str(" segmentation");
    }
    if vt {
        head.push_str(" terrain   ");
    }
    writeln!(
        out,
        "{head}  runs  success  mean time (s)  sd (s)  v_eff (cm/s)  cmds/m  failures"
    )?;
    let row = |g: &GroupSummary, out: &mut dyn Write| -> std::io::Result<()> {
        let mut line = format!("{:<sw$} ", g.start);
        if vc {
            line.push_str(&format!(" {:<cw$}", g.fiducial_colors.as_deref().unwrap_or("*")));
        }
        if vl {
            line.push_str(&format!(" {:<10}", g.lighting));
        }
        if vs {
            line.push_str(&format!(" {:<12}", g.segmentation));
        }
        if vt {
            line.push_str(&format!(" {:<10}", g.terrain));
        }
        let fails: Vec<String> = g.failures.iter().map(|(k, v)| format!("{k}×{v}")).collect();
        writeln!(
            out,
            "{line}  {:>4}  {:>6.2}  {:>13}  {:>6}  {:>12}  {:>6.2}  {}",
            g.runs,
            g.success_rate,
            cell(g.mean_time_s, 1),
            cell(g.sd_time_s, 1),
            cell(g.v_eff_cmps, 2),
            g.commands_per_m,
            fails.join(" ")
        )
    };
    for g in groups {
        row(g, out)?;
    }
    if let Some(g) = overall {
        row(g, out)?;
    }
    Ok(())
}

/// Runs a campaign of the crate's robots (see [`trials_with`]).
///
/// # Errors
/// As [`trials_with`].
pub fn trials(opts: &TrialsOptions, out: &mut dyn Write) -> Result<Summary, SimError> {
    trials_with(opts, &Plugins::default(), out)
}

/// Runs a campaign and prints its table (or JSON), its robot built from `plugins`'
/// catalog and its dock drawn by `plugins`' painters.
///
/// # Errors
/// [`SimError`].
pub fn trials_with(opts: &TrialsOptions, plugins: &Plugins, out: &mut dyn Write) -> Result<Summary, SimError> {
    // The factory runs on the campaign's worker threads: it owns its catalog (a few Arcs).
    let catalog = plugins.catalog.clone();
    let agent = move |p: &crate::profile::Profile| catalog.agent(p);
    let bins = opts
        .bin
        .iter()
        .map(|b| crate::report::bins::parse_bin_arg(b))
        .collect::<Result<Vec<_>, _>>()
        .map_err(SimError::InvalidArgument)?;
    let loaded = Scenario::load_with(&opts.scenario, plugins.catalog.fiducials())?;
    let sc = &loaded.scenario;
    if !bins.is_empty() && !sc.axes.lighting.iter().any(|l| sc.lighting_random.contains_key(l)) {
        return Err(SimError::InvalidArgument(format!(
            "--bin: no lighting on {}'s lighting axis is drawn; name a [lighting_random.NAME] there",
            opts.scenario.display()
        )));
    }
    if sc.endurance.is_some() && opts.shard.is_some() {
        return Err(SimError::InvalidArgument(format!(
            "--shard: {} is an endurance outing, one continuous run of one robot, which cannot be split across machines; run it whole",
            opts.scenario.display()
        )));
    }
    let mut prepared = campaign::prepare_with(loaded, &plugins.sim)?;
    if let Some(shard) = opts.shard {
        let campaign_runs = prepared.runs.len();
        prepared.runs = shard.select(&prepared.runs);
        if let Some(dir) = &opts.out {
            shard::write_info(
                dir,
                &shard::ShardInfo {
                    scenario: prepared.loaded.scenario.name.clone(),
                    shard,
                    campaign_runs,
                    shard_runs: prepared.runs.len(),
                },
            )?;
        }
    }
    let started = std::time::Instant::now();
    let (records, summary) = campaign::run_campaign(
        &prepared,
        &agent,
        &CampaignOptions {
            out: opts.out.clone(),
            jobs: opts.jobs,
            resume: opts.resume,
            progress: opts.progress,
            per_run_files: opts.out.is_some(),
            record: opts.record_dir.as_ref().map(|dir| campaign::RecordRuns {
                dir: dir.clone(),
                failed_only: opts.record_failed,
                options: RecordOptions {
                    jpeg: opts.jpeg,
                    ..RecordOptions::default()
                },
            }),
        },
    )?;
    if let Some(dir) = &opts.out {
        // From every record, resumed ones included (the campaign wrote summary.json).
        crate::report::plot::write_plots(dir, &prepared.world, &prepared.loaded.profile, &records).map_err(
            |source| SimError::Io {
                path: dir.display().to_string(),
                source,
            },
        )?;
    }
    let comparison = prepared
        .loaded
        .scenario
        .compare
        .map(|t| crate::report::paper::comparison(t, &records));
    if let (Some(c), Some(dir)) = (&comparison, &opts.out) {
        let p = dir.join("paper_comparison.txt");
        std::fs::write(&p, c).map_err(|source| SimError::Io {
            path: p.display().to_string(),
            source,
        })?;
    }
    if opts.json {
        let _ = writeln!(out, "{}", serde_json::to_string_pretty(&summary).unwrap_or_default());
    } else {
        let _ = print_table(&summary, out);
        if let Some(c) = &comparison {
            let _ = writeln!(out, "\n{c}");
        }
        for (param, n) in &bins {
            let table = crate::report::bins::bin_by(&records, param, *n).map_err(SimError::InvalidArgument)?;
            let _ = writeln!(out, "\n{table}");
        }
        let _ = writeln!(
            out,
            "{} runs in {:.1} s wall time",
            prepared.runs.len(),
            started.elapsed().as_secs_f64()
        );
    }
    Ok(summary)
}
