//! `marsupial pose-trials CAMPAIGN.toml`: Axel's perception campaigns (issue 16:
//! `axel-pose`, `axel-occlusion` and their ablations), run against the simulator's truth.
//!
//! A campaign file names a profile with circle fiducials and a grid of rover poses about
//! the central module (distance, α off its axis, the heading turned off facing it, noise
//! seeds), and optionally marks to hide behind occluding panels and false marks to place
//! near the module. Each run renders both cameras through the file's `[sensor]` (the
//! webcam's noise, vignetting, defocus, JPEG), detects, labels and poses the module
//! (stereo, and mono per camera), and compares with the truth. The ablations run on the
//! same detections: the mono pose through a pin-hole that ignores the fish-eye's
//! distortion, and the labelling that accepts 4-mark fits (seed 000 §V-D's bug,
//! [`CorrespondenceParams::ablation_four_point_fits`]). Every run is seeded from the
//! campaign's seed and its index alone, so the records are the same bytes whatever
//! `--jobs` is.
//!
//! One concept a file: `campaign.rs` the campaign file's types, validation and loading;
//! `grid.rs` the runs its pose grid makes; `run.rs` one run's rendering, detection,
//! labelling and poses; `score.rs` those measured against the simulator's truth;
//! `record.rs` the records `runs.jsonl` holds; `runner.rs` the campaign's runs on worker
//! threads; `tables.rs` the tables written from the records. This file holds the command:
//! its options and [`run()`], which ties them together, and re-exports the rest.
//!
//! [`CorrespondenceParams::ablation_four_point_fits`]: crate::perception::circles::CorrespondenceParams::ablation_four_point_fits

mod campaign;
mod grid;
mod record;
mod run;
mod runner;
mod score;
mod tables;

pub use campaign::{DecoySpec, LoadedCampaign, OcclusionSpec, PoseCampaign, PoseGrid};
pub use grid::{RunSpec, rover_pose, runs};
pub use record::{CameraRun, Labelling, PoseOutcome, PoseRun, is_wrong};
pub use runner::run_campaign;
pub use tables::{paper_figure, write_tables};

use crate::sim::SimError;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Options of `marsupial pose-trials` (also its command-line arguments).
#[derive(Debug, Clone, Default, clap::Args)]
pub struct PoseTrialsOptions {
    /// Campaign file: a scenario-like file with a `[pose]` table.
    #[arg(value_name = "CAMPAIGN.toml")]
    pub campaign: PathBuf,
    /// Print each run's record as one JSON line instead of the tables.
    #[arg(long)]
    pub json: bool,
    /// Output folder: DIR/runs.jsonl (one line per run, in run order) and DIR/tables.txt.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Runs rendered at once (0: one per core).
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub jobs: usize,
    /// With --out, also save each run's measured frames as DIR/frames/RUN-CAMERA.png, to
    /// look at what the detector was given.
    #[arg(long, requires = "out")]
    pub frames: bool,
}

/// Runs `marsupial pose-trials`: the campaign's records (as JSON lines with `--json`,
/// else the tables) to `out`, and with `--out DIR` DIR/runs.jsonl and DIR/tables.txt.
///
/// # Errors
/// [`SimError`] for a bad campaign file, a failed run or unwritable output.
pub fn run(opts: &PoseTrialsOptions, out: &mut dyn Write) -> Result<Vec<PoseRun>, SimError> {
    let loaded = PoseCampaign::load(&opts.campaign)?;
    let total = runs(&loaded.campaign).len();
    let done = AtomicUsize::new(0);
    let progress = |_: &PoseRun| {
        let k = done.fetch_add(1, Ordering::Relaxed) + 1;
        if k.is_multiple_of(10) || k == total {
            eprintln!("{k}/{total} runs");
        }
    };
    let io = |path: &Path| {
        let path = path.display().to_string();
        move |source| SimError::Io { path, source }
    };
    let frames = match (&opts.out, opts.frames) {
        (Some(dir), true) => {
            let f = dir.join("frames");
            std::fs::create_dir_all(&f).map_err(io(&f))?;
            Some(f)
        }
        _ => None,
    };
    let recs = run_campaign(&loaded, opts.jobs, frames.as_deref(), &progress)?;
    let mut tables = Vec::new();
    write_tables(&loaded.campaign, &recs, &mut tables).map_err(io(Path::new("<tables>")))?;
    if opts.json {
        for r in &recs {
            super::json_line(out, r).map_err(io(Path::new("<stdout>")))?;
        }
    } else {
        out.write_all(&tables).map_err(io(Path::new("<stdout>")))?;
    }
    if let Some(dir) = &opts.out {
        std::fs::create_dir_all(dir).map_err(io(dir))?;
        let mut lines = Vec::new();
        for r in &recs {
            super::json_line(&mut lines, r).map_err(io(dir))?;
        }
        let runs_path = dir.join("runs.jsonl");
        std::fs::write(&runs_path, lines).map_err(io(&runs_path))?;
        let tables_path = dir.join("tables.txt");
        std::fs::write(&tables_path, tables).map_err(io(&tables_path))?;
    }
    Ok(recs)
}
