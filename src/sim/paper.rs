//! The papers' published figures, for side-by-side tables printed by `marsupial trials`.
//! A scenario opts in with `compare = "bujold-table1"` (or `"bujold-table2"`).

use super::campaign::RunRecord;
use serde::{Deserialize, Serialize};
use std::fmt::Write as _;

/// Which published table a scenario reproduces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PaperTable {
    /// Seed 004 Table Ia (mean time to dock by symmetric start group) and §VI.A totals.
    BujoldTable1,
    /// Seed 004 Table II (time and success by lighting and segmentation).
    BujoldTable2,
}

/// Seed 004 Table Ia: start groups and the autonomous mean time to dock, s.
pub const BUJOLD_TABLE_1A: [(&[&str], f64); 10] = [
    (&["1", "3"], 89.2),
    (&["2"], 25.6),
    (&["4", "6"], 61.3),
    (&["5"], 39.6),
    (&["7", "11"], 64.0),
    (&["8", "10"], 59.8),
    (&["9"], 54.3),
    (&["12", "16"], 81.6),
    (&["13", "15"], 67.5),
    (&["14"], 66.6),
];

/// One row of Table II: lighting, segmentation, and (mean time s, success rate) or `None`
/// where the paper did not test.
pub type Table2Row = (&'static str, &'static str, Option<(f64, f64)>);

/// Seed 004 Table II.
pub const BUJOLD_TABLE_2: [Table2Row; 8] = [
    ("lab", "adaptive", Some((68.0, 0.93))),
    ("lab", "static", None),
    ("flashers", "adaptive", Some((93.0, 0.87))),
    ("flashers", "static", Some((84.0, 0.93))),
    ("noon", "adaptive", Some((89.0, 0.87))),
    ("noon", "static", Some((106.0, 0.53))),
    ("dusk", "adaptive", Some((93.0, 1.00))),
    ("dusk", "static", Some((109.0, 0.70))),
];

fn stats(rs: &[&RunRecord]) -> (usize, usize, Option<f64>) {
    let ok: Vec<f64> = rs.iter().filter(|r| r.success).map(|r| r.time_s).collect();
    let mean = (!ok.is_empty()).then(|| ok.iter().sum::<f64>() / ok.len() as f64);
    (rs.len(), ok.len(), mean)
}

fn cell(v: Option<f64>, prec: usize) -> String {
    v.map(|x| format!("{x:.prec$}")).unwrap_or_else(|| "-".into())
}

/// The side-by-side table for `records`.
pub fn comparison(table: PaperTable, records: &[RunRecord]) -> String {
    let mut s = String::new();
    match table {
        PaperTable::BujoldTable1 => {
            let _ = writeln!(
                s,
                "versus seed 004 Table Ia (autonomous mean time to dock, successful runs)"
            );
            let _ = writeln!(s, "group    runs  docked  ours (s)  paper (s)");
            for (group, paper) in BUJOLD_TABLE_1A {
                let rs: Vec<&RunRecord> = records.iter().filter(|r| group.contains(&r.start.as_str())).collect();
                if rs.is_empty() {
                    continue;
                }
                let (n, ok, mean) = stats(&rs);
                let _ = writeln!(
                    s,
                    "{:<8} {:>4}  {:>6}  {:>8}  {:>9.1}",
                    group.join(","),
                    n,
                    ok,
                    cell(mean, 1),
                    paper
                );
            }
            let all: Vec<&RunRecord> = records.iter().collect();
            let (n, ok, _) = stats(&all);
            let veff: Vec<f64> = records.iter().filter(|r| r.success).map(|r| r.v_eff_cmps).collect();
            let v = (!veff.is_empty()).then(|| veff.iter().sum::<f64>() / veff.len() as f64);
            let _ = writeln!(
                s,
                "success {ok}/{n} = {:.0} % (paper 96 % of 48); effective velocity {} cm/s (paper 2.4)",
                100.0 * ok as f64 / n.max(1) as f64,
                cell(v, 2)
            );
        }
        PaperTable::BujoldTable2 => {
            let _ = writeln!(
                s,
                "versus seed 004 Table II (mean time of successful runs, success rate)"
            );
            let _ = writeln!(
                s,
                "lighting  segmentation  runs  ours time (s)  ours rate  paper time (s)  paper rate"
            );
            for (light, seg, paper) in BUJOLD_TABLE_2 {
                let rs: Vec<&RunRecord> = records
                    .iter()
                    .filter(|r| r.lighting == light && r.segmentation == seg)
                    .collect();
                if rs.is_empty() {
                    continue;
                }
                let (n, ok, mean) = stats(&rs);
                let (pt, pr) = match paper {
                    Some((t, r)) => (format!("{t:.0}"), format!("{r:.2}")),
                    None => ("not tested".into(), "-".into()),
                };
                let _ = writeln!(
                    s,
                    "{light:<9} {seg:<12}  {n:>4}  {:>13}  {:>9.2}  {pt:>14}  {pr:>10}",
                    cell(mean, 0),
                    ok as f64 / n.max(1) as f64
                );
            }
        }
    }
    s
}
