//! The papers' published figures, for side-by-side tables printed by `marsupial trials`.
//! A scenario opts in with `compare = "bujold-table1"` (or `"bujold-table2"`,
//! `"raposa-table1"`, `"raposa-range"`, `"raposa-wide"`, `"axel-field"`,
//! `"axel-reel-only"`, `"axel-lighting"`).

use crate::sim::campaign::{RunRecord, summarise};
use crate::sim::scenario::PaperTable;
use std::fmt::Write as _;

/// Seed 000 §V-B: (docked, runs) overall and away from the workspace boundary.
pub const AXEL_FIELD: [(&str, usize, usize); 2] = [("all starts", 29, 40), ("away from the boundary", 20, 24)];

/// Seed 000 §V-E, fixed thresholds: (lighting, docked, runs) in uniform light and under
/// the shadow.
pub const AXEL_LIGHTING: [(&str, usize, usize); 2] = [("uniform", 21, 25), ("shadow", 8, 15)];

/// Seed 000 §V-C's limits of pure reeling, degrees: it docks for |α| below the first and
/// tolerates |h| below the second.
pub const AXEL_REEL_ONLY_LIMITS_DEG: (f64, f64) = (5.0, 90.0);

/// (α, h) in degrees from an `axel-reel-only` start label `r<m>/a<α>/h<h>`.
fn reel_only_cell(label: &str) -> Option<(i64, i64)> {
    let mut parts = label.split('/');
    let (_r, a, h) = (parts.next()?, parts.next()?, parts.next()?);
    Some((a.strip_prefix('a')?.parse().ok()?, h.strip_prefix('h')?.parse().ok()?))
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

/// One row of seed 001 Table I: start group, mean time s, σ s, v_mean cm/s, success.
pub type RaposaRow = (&'static [&'static str], f64, f64, f64, f64);

/// Seed 001 Table I (points 1 and 3 never docked and are not in the table).
pub const RAPOSA_TABLE_1: [RaposaRow; 9] = [
    (&["2"], 19.41, 2.04, 1.7, 1.0),
    (&["5"], 24.29, 2.41, 2.1, 1.0),
    (&["9"], 37.88, 2.04, 3.5, 1.0),
    (&["14"], 46.06, 2.48, 4.3, 1.0),
    (&["8", "10"], 45.08, 3.98, 3.0, 1.0),
    (&["13", "15"], 51.10, 5.24, 3.9, 1.0),
    (&["4", "6"], 92.77, 25.18, 0.5, 0.875),
    (&["7", "11"], 73.00, 30.72, 1.82, 1.0),
    (&["12", "16"], 68.34, 12.18, 2.9, 1.0),
];

/// Seed 001 §III: success at 0° against start distance (2.7 m: "performed well").
pub const RAPOSA_RANGE: [(f64, &str); 4] = [(2.5, "100 %"), (2.7, "performed well"), (2.8, "75 %"), (3.0, "0 %")];

/// (runs, successes, mean time of successful runs): the campaign's own group summary.
fn stats(rs: &[&RunRecord]) -> (usize, usize, Option<f64>) {
    let g = summarise(rs, [""; 4]);
    (g.runs, g.successes, g.mean_time_s)
}

/// A published success figure: `docked/runs = rate %`.
fn published(docked: usize, runs: usize) -> String {
    format!("{docked}/{runs} = {:.0} %", 100.0 * docked as f64 / runs as f64)
}

/// Formats an optional number, "-" when absent (also used by the trials table).
pub(crate) fn cell(v: Option<f64>, prec: usize) -> String {
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
            let g = summarise(&all, [""; 4]);
            let (n, ok, v) = (g.runs, g.successes, g.v_eff_cmps);
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
        PaperTable::RaposaTable1 => {
            let _ = writeln!(
                s,
                "versus seed 001 Table I (successful runs; v = start distance / time)"
            );
            let _ = writeln!(
                s,
                "group    runs  docked  time (s)  σ (s)  v (cm/s)  | paper: time (s)  σ (s)  v (cm/s)  success"
            );
            let mut rows: Vec<(&[&str], Option<RaposaRow>)> = vec![(&["1", "3"], None)];
            rows.extend(RAPOSA_TABLE_1.iter().map(|r| (r.0, Some(*r))));
            for (group, paper) in rows {
                let rs: Vec<&RunRecord> = records.iter().filter(|r| group.contains(&r.start.as_str())).collect();
                if rs.is_empty() {
                    continue;
                }
                let g = summarise(&rs, [""; 4]);
                let (n, ok, mean, sd, v) = (g.runs, g.successes, g.mean_time_s, g.sd_time_s, g.v_eff_cmps);
                let paper = match paper {
                    Some((_, t, sd, v, rate)) => format!("{t:>15.2}  {sd:>5.2}  {v:>8.2}  {:>6.1} %", rate * 100.0),
                    None => format!("{:>15}  {:>5}  {:>8}  {:>6} %", "never docked", "-", "-", 0),
                };
                let _ = writeln!(
                    s,
                    "{:<8} {:>4}  {:>6}  {:>8}  {:>5}  {:>8}  | {paper}",
                    group.join(","),
                    n,
                    ok,
                    cell(mean, 2),
                    cell(sd, 2),
                    cell(v, 2),
                );
            }
        }
        PaperTable::RaposaRange => {
            let _ = writeln!(s, "versus seed 001 §III (success against distance at 0°)");
            let _ = writeln!(s, "distance (m)  runs  docked  ours   paper");
            let mut ds: Vec<f64> = records.iter().map(|r| r.distance_m).collect();
            ds.sort_by(f64::total_cmp);
            ds.dedup_by(|a, b| (*a - *b).abs() < 1e-6);
            for d in ds {
                let rs: Vec<&RunRecord> = records.iter().filter(|r| (r.distance_m - d).abs() < 1e-6).collect();
                let (n, ok, _) = stats(&rs);
                let paper = RAPOSA_RANGE
                    .iter()
                    .find(|(pd, _)| (pd - d).abs() < 1e-6)
                    .map_or("-", |p| p.1);
                let _ = writeln!(
                    s,
                    "{d:>12.2}  {n:>4}  {ok:>6}  {:>3.0} %  {paper}",
                    100.0 * ok as f64 / n.max(1) as f64
                );
            }
        }
        PaperTable::RaposaWide => {
            let _ = writeln!(
                s,
                "versus seed 001 §III (80°, 90°, 110° at about 1.5 m: all docked in 1–4 min with 2–4 region-II iterations)"
            );
            let _ = writeln!(s, "angle (°)  runs  docked  time (s) min–max  iterations min–max");
            let mut angles: Vec<f64> = records.iter().map(|r| r.angle_deg.abs().round()).collect();
            angles.sort_by(f64::total_cmp);
            angles.dedup();
            for a in angles {
                let rs: Vec<&RunRecord> = records
                    .iter()
                    .filter(|r| (r.angle_deg.abs().round() - a).abs() < 0.5)
                    .collect();
                let (n, ok, _) = stats(&rs);
                let okr: Vec<&&RunRecord> = rs.iter().filter(|r| r.success).collect();
                let span = |f: &dyn Fn(&RunRecord) -> f64| {
                    let lo = okr.iter().map(|r| f(r)).fold(f64::INFINITY, f64::min);
                    let hi = okr.iter().map(|r| f(r)).fold(f64::NEG_INFINITY, f64::max);
                    if okr.is_empty() {
                        "-".to_string()
                    } else {
                        format!("{lo:.0}–{hi:.0}")
                    }
                };
                let _ = writeln!(
                    s,
                    "{a:>9.0}  {n:>4}  {ok:>6}  {:>17}  {:>19}",
                    span(&|r| r.time_s),
                    span(&|r| r.manoeuvres as f64)
                );
            }
        }
        PaperTable::AxelField => {
            let _ = writeln!(s, "versus seed 000 §V-B (field runs in the JPL Mars Yard)");
            let _ = writeln!(s, "starts                    runs  docked  ours     | paper");
            let boundary = |r: &&RunRecord| r.start.starts_with('b');
            let groups: [(&str, Vec<&RunRecord>); 4] = [
                ("all starts", records.iter().collect()),
                (
                    "away from the boundary",
                    records.iter().filter(|r| !boundary(r)).collect(),
                ),
                ("boundary (7 m, > 40°)", records.iter().filter(boundary).collect()),
                (
                    "fig10 (4 m, α 15°, h 0°)",
                    records.iter().filter(|r| r.start == "fig10").collect(),
                ),
            ];
            for (name, rs) in groups {
                if rs.is_empty() {
                    continue;
                }
                let (n, ok, _) = stats(&rs);
                let paper = match AXEL_FIELD.iter().find(|p| p.0 == name) {
                    Some(&(_, d, t)) => published(d, t),
                    None if name.starts_with("boundary") => "9/16 = 56 % (29 − 20 of 40 − 24)".into(),
                    None => "docked (Fig. 10)".into(),
                };
                let _ = writeln!(
                    s,
                    "{name:<25} {n:>4}  {ok:>6}  {:>5.0} %  | {paper}",
                    100.0 * ok as f64 / n.max(1) as f64
                );
            }
        }
        PaperTable::AxelReelOnly => reel_only_table(&mut s, records),
        PaperTable::AxelLighting => {
            let _ = writeln!(s, "versus seed 000 §V-E (the paper's fixed thresholds)");
            let _ = writeln!(s, "lighting     runs  docked  ours     | paper");
            let mut lights: Vec<&str> = records.iter().map(|r| r.lighting.as_str()).collect();
            lights.sort_unstable();
            lights.dedup();
            for light in lights {
                let rs: Vec<&RunRecord> = records.iter().filter(|r| r.lighting == light).collect();
                let (n, ok, _) = stats(&rs);
                let paper = match AXEL_LIGHTING.iter().find(|p| p.0 == light) {
                    Some(&(_, d, t)) => published(d, t),
                    None => "-".into(),
                };
                let _ = writeln!(
                    s,
                    "{light:<12} {n:>4}  {ok:>6}  {:>5.0} %  | {paper}",
                    100.0 * ok as f64 / n.max(1) as f64
                );
            }
        }
    }
    s
}

/// The `axel-reel-only` grid: docked/runs per (α, h) cell, a `*` where the paper's limits
/// say pure reeling docks, and how many cells agree with them.
fn reel_only_table(s: &mut String, records: &[RunRecord]) {
    let (a_max, h_max) = AXEL_REEL_ONLY_LIMITS_DEG;
    let cells: Vec<((i64, i64), &RunRecord)> = records
        .iter()
        .filter_map(|r| reel_only_cell(&r.start).map(|c| (c, r)))
        .collect();
    let mut alphas: Vec<i64> = cells.iter().map(|(c, _)| c.0).collect();
    let mut headings: Vec<i64> = cells.iter().map(|(c, _)| c.1).collect();
    for v in [&mut alphas, &mut headings] {
        v.sort_unstable();
        v.dedup();
    }
    let _ = writeln!(
        s,
        "versus seed 000 §V-C (pure reeling: docks for |α| < {a_max}°, tolerates |h| < {h_max}°)"
    );
    let _ = writeln!(
        s,
        "docked/runs per start cell over every distance and terrain; * where the paper's limits say it docks"
    );
    let _ = write!(s, "{:>8}", "α \\ h");
    for h in &headings {
        let _ = write!(s, " {:>8}", format!("{h}°"));
    }
    let _ = writeln!(s);
    let (mut agree, mut total) = (0, 0);
    for a in &alphas {
        let _ = write!(s, "{:>8}", format!("{a}°"));
        for h in &headings {
            let rs: Vec<&RunRecord> = cells.iter().filter(|(c, _)| c == &(*a, *h)).map(|(_, r)| *r).collect();
            if rs.is_empty() {
                let _ = write!(s, " {:>8}", "");
                continue;
            }
            let ok = rs.iter().filter(|r| r.success).count();
            let inside = (*a as f64).abs() < a_max && (*h as f64).abs() < h_max;
            // A cell agrees when all its runs dock inside the limits and none outside.
            total += 1;
            agree += usize::from(if inside { ok == rs.len() } else { ok == 0 });
            let mark = if inside { "*" } else { " " };
            let _ = write!(s, " {:>8}", format!("{ok}/{}{mark}", rs.len()));
        }
        let _ = writeln!(s);
    }
    let _ = writeln!(
        s,
        "cells agreeing with the paper's limits (all docked inside, none outside): {agree}/{total}"
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reel_only_labels_give_alpha_and_h() {
        assert_eq!(reel_only_cell("r4/a-7/h120"), Some((-7, 120)));
        assert_eq!(reel_only_cell("r2/a0/h0"), Some((0, 0)));
        for bad in ["fig10", "r4/a-7", "r4/x3/h0", "r4/a3/hx", ""] {
            assert_eq!(reel_only_cell(bad), None, "{bad}");
        }
    }

    #[test]
    fn the_lighting_table_sets_each_light_beside_the_paper() {
        let lit = |light: &str, ok: bool| RunRecord {
            lighting: light.into(),
            ..RunRecord::for_test("i1", ok)
        };
        let records = [
            lit("uniform", true),
            lit("shadow", true),
            lit("uniform", true),
            lit("shadow", false),
            lit("dusk", true),
        ];
        let t = comparison(PaperTable::AxelLighting, &records);
        assert!(t.contains("uniform         2       2    100 %  | 21/25 = 84 %"), "{t}");
        assert!(t.contains("shadow          2       1     50 %  | 8/15 = 53 %"), "{t}");
        assert!(t.contains("dusk            1       1    100 %  | -"), "{t}");
    }

    #[test]
    fn the_reel_only_table_counts_cells_against_the_paper_limits() {
        let records = [
            RunRecord::for_test("r2/a0/h0", true),     // inside, docked: agrees
            RunRecord::for_test("r4/a0/h0", true),     // same cell
            RunRecord::for_test("r2/a3/h120", false),  // outside (h), failed: agrees
            RunRecord::for_test("r2/a7/h0", true),     // outside (α), docked: disagrees
            RunRecord::for_test("r2/a-3/h-80", false), // inside, failed: disagrees
            RunRecord::for_test("fig10", true),        // not a grid start: left out
        ];
        let t = comparison(PaperTable::AxelReelOnly, &records);
        assert!(t.contains("2/2*"), "{t}");
        assert!(t.contains("0/1*"), "{t}");
        assert!(
            t.contains("cells agreeing with the paper's limits (all docked inside, none outside): 2/4"),
            "{t}"
        );
    }
}
