//! `marsupial timeline`: the phase timeline of a run, read from its decision trace
//! (`marsupial dock --trace FILE.jsonl`).
//!
//! One line per transition of any sequencer in the tree (when, which sequencer, from
//! which state to which, and the event that fired it), and one per mission's end: the
//! behavior's outcome, or the simulator's verdict when the world ended it first.

use serde_json::Value;
use std::io::{BufRead, Write};
use std::path::Path;
use thiserror::Error;

/// Why a trace could not be read.
#[derive(Debug, Error)]
pub enum TimelineError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// Why.
        source: std::io::Error,
    },
    /// A line is not a trace line.
    #[error("{path}:{line}: not a decision-trace line ({why})")]
    Format {
        /// The file.
        path: String,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        why: String,
    },
}

/// Prints the timeline of the trace at `path` to `out`; returns the number of
/// transitions.
///
/// # Errors
/// [`TimelineError`] naming the file (and line) that cannot be read.
pub fn run(path: &Path, out: &mut dyn Write) -> Result<usize, TimelineError> {
    let shown = path.display().to_string();
    let file = std::fs::File::open(path).map_err(|source| TimelineError::Io {
        path: shown.clone(),
        source,
    })?;
    let mut count = 0;
    for (i, line) in std::io::BufReader::new(file).lines().enumerate() {
        let line = line.map_err(|source| TimelineError::Io {
            path: shown.clone(),
            source,
        })?;
        if line.trim().is_empty() {
            continue;
        }
        let bad = |why: &str| TimelineError::Format {
            path: shown.clone(),
            line: i + 1,
            why: why.into(),
        };
        let v: Value = serde_json::from_str(&line).map_err(|e| bad(&e.to_string()))?;
        let mission = v["mission"].as_str().ok_or_else(|| bad("no `mission`"))?;
        let t = v["t"].as_f64().ok_or_else(|| bad("no `t`"))?;
        // The simulator ended the mission (the plates closed, the robot caught the
        // entrance, time ran out).
        if let Some(world) = v["world"].as_str() {
            let _ = writeln!(out, "{mission:<9} {t:7.1} s  simulator: {world}");
            continue;
        }
        let nodes = v["nodes"].as_array().ok_or_else(|| bad("no `nodes`"))?;
        for n in nodes {
            for tr in n["transitions"].as_array().into_iter().flatten() {
                let (from, to, event) = (
                    tr["from"].as_str().unwrap_or("?"),
                    tr["to"].as_str().unwrap_or("?"),
                    tr["event"].as_str().unwrap_or("?"),
                );
                let node = n["node"].as_str().unwrap_or("?");
                let _ = if from == to {
                    writeln!(out, "{mission:<9} {t:7.1} s  {node}: {to} ({event})")
                } else {
                    writeln!(out, "{mission:<9} {t:7.1} s  {node}: {from} → {to} ({event})")
                };
                count += 1;
            }
        }
        if v["status"]["status"] == "finished" {
            let outcome = &v["status"]["outcome"];
            let outcome = outcome
                .as_str()
                .map(str::to_string)
                .or_else(|| outcome["failed"].as_str().map(|r| format!("failed: {r}")))
                .unwrap_or_else(|| outcome.to_string());
            let _ = writeln!(out, "{mission:<9} {t:7.1} s  finished: {outcome}");
        }
    }
    Ok(count)
}
