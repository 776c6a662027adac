//! `marsupial merge`: joins the output folders of a campaign's shards
//! (`trials S --shard K/N --out DIR`) into the campaign's outputs
//! ([`crate::sim::shard::merge`]).

use crate::sim::SimError;
use crate::sim::campaign;
use crate::sim::scenario::Scenario;
use crate::sim::shard;
use std::io::Write;
use std::path::PathBuf;

/// Options of `marsupial merge` (also its command-line arguments).
#[derive(Debug, Clone, Default, clap::Args)]
pub struct MergeOptions {
    /// The shards' output folders (each with shard.json and runs.jsonl), in any order.
    #[arg(required = true, value_name = "DIR")]
    pub shards: Vec<PathBuf>,
    /// Where the merged runs.jsonl and summary.json go.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// The campaign's scenario: also checks that the shards' runs are this scenario's
    /// (index, start, trial and seed), and writes the plots and paper comparison an
    /// unsharded `trials --out` writes.
    #[arg(long, value_name = "S")]
    pub scenario: Option<PathBuf>,
    /// Print the summary JSON instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// Merges shard folders and prints the campaign's table (or JSON).
///
/// # Errors
/// [`SimError`] when the folders are not the complete set of one campaign's shards, do
/// not match `--scenario`, or output cannot be written.
pub fn run(opts: &MergeOptions, out: &mut dyn Write) -> Result<campaign::Summary, SimError> {
    let merged = shard::merge(&opts.shards)?;
    let mut comparison = None;
    if let Some(path) = &opts.scenario {
        let prepared = campaign::prepare(Scenario::load(path)?)?;
        if prepared.loaded.scenario.name != merged.info.scenario || prepared.runs.len() != merged.records.len() {
            return Err(SimError::InvalidArgument(format!(
                "--scenario {}: {} with {} runs, but the shards are of {} with {} runs",
                path.display(),
                prepared.loaded.scenario.name,
                prepared.runs.len(),
                merged.info.scenario,
                merged.records.len()
            )));
        }
        for (spec, r) in prepared.runs.iter().zip(&merged.records) {
            if (spec.index, spec.seed, spec.trial, spec.start.label.as_str())
                != (r.index, r.seed, r.trial, r.start.as_str())
            {
                return Err(SimError::InvalidArgument(format!(
                    "--scenario {}: run {} is start {}, trial {}, seed {} in the scenario but start {}, trial {}, seed {} in the shards",
                    path.display(),
                    spec.index,
                    spec.start.label,
                    spec.trial,
                    spec.seed,
                    r.start,
                    r.trial,
                    r.seed
                )));
            }
        }
        merged.write(&opts.out)?;
        let io = |p: &std::path::Path, source| SimError::Io {
            path: p.display().to_string(),
            source,
        };
        crate::report::plot::write_plots(&opts.out, &prepared.world, &prepared.loaded.profile, &merged.records)
            .map_err(|e| io(&opts.out, e))?;
        if let Some(t) = prepared.loaded.scenario.compare {
            let c = crate::report::paper::comparison(t, &merged.records);
            let p = opts.out.join("paper_comparison.txt");
            std::fs::write(&p, &c).map_err(|e| io(&p, e))?;
            comparison = Some(c);
        }
    } else {
        merged.write(&opts.out)?;
    }
    if opts.json {
        let _ = writeln!(
            out,
            "{}",
            serde_json::to_string_pretty(&merged.summary).unwrap_or_default()
        );
    } else {
        let _ = super::sim_cmds::print_table(&merged.summary, out);
        if let Some(c) = &comparison {
            let _ = writeln!(out, "\n{c}");
        }
        let _ = writeln!(
            out,
            "merged {} shards: {} runs",
            merged.info.shard.n,
            merged.records.len()
        );
    }
    Ok(merged.summary)
}
