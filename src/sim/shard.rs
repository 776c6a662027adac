//! Campaigns across machines: `trials S --shard K/N` runs a deterministic share of a
//! campaign, and `marsupial merge` joins the shares into the campaign's outputs.
//!
//! Shard K of N (1-based, like an array job's task number) runs the runs at campaign
//! positions K−1, K−1+N, K−1+2N, …: a round-robin split, so every shard gets a mix of
//! starts and axes and about the same work. Which runs a shard holds depends only on the
//! scenario, K and N, never on the machine, its core count or its speed, and each run's
//! seeds come from the scenario and the run's index, so a run gives the same record in
//! any shard on any machine.
//!
//! Each shard's output folder holds its runs' `runs.jsonl` (in campaign order), its own
//! `summary.json`, and `shard.json` ([`ShardInfo`]), which names the scenario, K, N and
//! the campaign's size so that [`merge`] can check the shares belong together and cover
//! the campaign exactly. The merged `runs.jsonl` is the shards' lines, byte for byte,
//! in campaign order, and the merged `summary.json` is computed from them as a single
//! machine computes it: both equal an unsharded run's (`tests/shard_merge.rs`).

use super::SimError;
use super::campaign::{self, RunRecord, Summary};
use super::scenario::RunSpec;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One share of a campaign: shard `k` of `n` (1 ≤ k ≤ n).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// This shard's number, 1-based.
    pub k: usize,
    /// The number of shards.
    pub n: usize,
}

impl std::str::FromStr for Shard {
    type Err = String;

    /// Parses `K/N` with 1 ≤ K ≤ N.
    fn from_str(s: &str) -> Result<Self, String> {
        let (k, n) = s
            .split_once('/')
            .ok_or_else(|| format!("`{s}`: expected K/N, e.g. 2/8 for the second of eight shards"))?;
        let parse = |x: &str, what: &str| {
            x.trim()
                .parse::<usize>()
                .map_err(|e| format!("`{s}`: {what} `{x}`: {e}"))
        };
        let (k, n) = (parse(k, "K")?, parse(n, "N")?);
        if n == 0 || k == 0 || k > n {
            return Err(format!(
                "`{s}`: K must be 1..=N and N at least 1 (shards are numbered from 1)"
            ));
        }
        Ok(Self { k, n })
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.k, self.n)
    }
}

impl Shard {
    /// Whether the run at campaign position `position` belongs to this shard.
    pub fn holds(&self, position: usize) -> bool {
        position % self.n == self.k - 1
    }

    /// This shard's runs, in campaign order.
    pub fn select(&self, runs: &[RunSpec]) -> Vec<RunSpec> {
        runs.iter()
            .enumerate()
            .filter(|(i, _)| self.holds(*i))
            .map(|(_, r)| r.clone())
            .collect()
    }
}

/// `shard.json`: what a shard's output folder is a share of.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ShardInfo {
    /// The scenario's name (as in `summary.json`).
    pub scenario: String,
    /// The share.
    pub shard: Shard,
    /// Runs in the whole campaign.
    pub campaign_runs: usize,
    /// Runs in this shard.
    pub shard_runs: usize,
}

/// Writes `dir/shard.json`.
///
/// # Errors
/// [`SimError::Io`] when it cannot be written.
pub fn write_info(dir: &Path, info: &ShardInfo) -> Result<(), SimError> {
    let path = dir.join("shard.json");
    std::fs::create_dir_all(dir)
        .and_then(|()| std::fs::write(&path, serde_json::to_string_pretty(info).unwrap_or_default()))
        .map_err(|source| SimError::Io {
            path: path.display().to_string(),
            source,
        })
}

/// What [`merge`] produced.
#[derive(Debug, Clone)]
pub struct Merged {
    /// Every record, in campaign order.
    pub records: Vec<RunRecord>,
    /// The campaign's summary.
    pub summary: Summary,
    /// The shards' common description (with `shard` of the first folder).
    pub info: ShardInfo,
    /// The merged `runs.jsonl`: the shards' lines, byte for byte, in campaign order.
    pub runs_jsonl: String,
}

impl Merged {
    /// Writes `out/runs.jsonl` and `out/summary.json`.
    ///
    /// # Errors
    /// [`SimError::Io`] when they cannot be written.
    pub fn write(&self, out: &Path) -> Result<(), SimError> {
        std::fs::create_dir_all(out).map_err(io_err(out))?;
        let runs_path = out.join("runs.jsonl");
        std::fs::write(&runs_path, &self.runs_jsonl).map_err(io_err(&runs_path))?;
        let summary_path = out.join("summary.json");
        std::fs::write(
            &summary_path,
            serde_json::to_string_pretty(&self.summary).unwrap_or_default(),
        )
        .map_err(io_err(&summary_path))
    }
}

fn io_err(path: &Path) -> impl FnOnce(std::io::Error) -> SimError + '_ {
    move |source| SimError::Io {
        path: path.display().to_string(),
        source,
    }
}

fn bad(path: &Path, what: impl std::fmt::Display) -> SimError {
    SimError::InvalidArgument(format!("{}: {what}", path.display()))
}

/// Joins shard output folders: the campaign's `runs.jsonl` (the shards' lines, byte for
/// byte, in campaign order) and summary, to be written with [`Merged::write`].
///
/// Every folder must hold a `shard.json` of the same scenario, N and campaign size, the
/// folders must be shards 1..=N each exactly once, and each shard's `runs.jsonl` must be
/// complete (every line whole and parseable, `shard_runs` of them, each run index the
/// shard holds). Anything else is an error naming the folder and what is wrong.
///
/// # Errors
/// [`SimError::InvalidArgument`] for folders that do not make one whole campaign,
/// [`SimError::Io`] for unreadable files.
pub fn merge(dirs: &[PathBuf]) -> Result<Merged, SimError> {
    let mut first: Option<ShardInfo> = None;
    let mut seen: BTreeMap<usize, &Path> = BTreeMap::new();
    let mut lines: BTreeMap<usize, (String, RunRecord)> = BTreeMap::new();
    for dir in dirs {
        let info_path = dir.join("shard.json");
        let text = std::fs::read_to_string(&info_path).map_err(io_err(&info_path))?;
        let info: ShardInfo =
            serde_json::from_str(&text).map_err(|e| bad(&info_path, format!("not a shard description: {e}")))?;
        if let Some(f) = &first
            && (f.scenario.as_str(), f.shard.n, f.campaign_runs)
                != (info.scenario.as_str(), info.shard.n, info.campaign_runs)
        {
            return Err(bad(
                &info_path,
                format!(
                    "shard of {} (N = {}, {} runs), but the first folder is a shard of {} (N = {}, {} runs)",
                    info.scenario, info.shard.n, info.campaign_runs, f.scenario, f.shard.n, f.campaign_runs
                ),
            ));
        }
        if let Some(other) = seen.insert(info.shard.k, dir) {
            return Err(bad(
                dir,
                format!("shard {} again (also {})", info.shard, other.display()),
            ));
        }
        let runs_path = dir.join("runs.jsonl");
        let body = std::fs::read_to_string(&runs_path).map_err(io_err(&runs_path))?;
        if !body.is_empty() && !body.ends_with('\n') {
            return Err(bad(
                &runs_path,
                "the last line is torn (finish the shard with `trials --resume` first)",
            ));
        }
        let mut count = 0;
        for (n, line) in body.lines().enumerate() {
            let r: RunRecord = serde_json::from_str(line)
                .map_err(|e| bad(&runs_path, format!("line {}: not a run record: {e}", n + 1)))?;
            if r.index >= info.campaign_runs || !info.shard.holds(r.index) {
                return Err(bad(
                    &runs_path,
                    format!("line {}: run {} is not one of shard {}'s", n + 1, r.index, info.shard),
                ));
            }
            let index = r.index;
            if lines.insert(index, (line.to_owned(), r)).is_some() {
                return Err(bad(&runs_path, format!("line {}: run {index} twice", n + 1)));
            }
            count += 1;
        }
        if count != info.shard_runs {
            return Err(bad(
                &runs_path,
                format!(
                    "{count} runs, but shard {} has {} (finish it with `trials --resume`)",
                    info.shard, info.shard_runs
                ),
            ));
        }
        first.get_or_insert(info);
    }
    let Some(info) = first else {
        return Err(SimError::InvalidArgument("merge: no shard folders given".into()));
    };
    let missing: Vec<String> = (1..=info.shard.n)
        .filter(|k| !seen.contains_key(k))
        .map(|k| format!("{k}/{}", info.shard.n))
        .collect();
    if !missing.is_empty() {
        return Err(SimError::InvalidArgument(format!(
            "merge: shards {} of {} are missing",
            missing.join(", "),
            info.scenario
        )));
    }
    if lines.len() != info.campaign_runs {
        return Err(SimError::InvalidArgument(format!(
            "merge: the shards hold {} runs, but {} has {}",
            lines.len(),
            info.scenario,
            info.campaign_runs
        )));
    }
    let mut runs_jsonl = String::new();
    let mut records = Vec::with_capacity(lines.len());
    for (line, r) in lines.into_values() {
        runs_jsonl.push_str(&line);
        runs_jsonl.push('\n');
        records.push(r);
    }
    let summary = campaign::summary(&info.scenario, &records);
    Ok(Merged {
        records,
        summary,
        info,
        runs_jsonl,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_rejects() {
        assert_eq!("2/8".parse::<Shard>(), Ok(Shard { k: 2, n: 8 }));
        assert_eq!(" 1 / 1 ".parse::<Shard>(), Ok(Shard { k: 1, n: 1 }));
        for bad in ["0/3", "4/3", "1/0", "3", "a/2", "1/b", "-1/2", ""] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
    }

    #[test]
    fn shards_partition_every_campaign() {
        for n in 1..7 {
            for len in 0..20 {
                let mut count = vec![0; len];
                for k in 1..=n {
                    let s = Shard { k, n };
                    for (i, c) in count.iter_mut().enumerate() {
                        if s.holds(i) {
                            *c += 1;
                        }
                    }
                }
                assert!(count.iter().all(|&c| c == 1), "n={n} len={len}");
            }
        }
    }
}
