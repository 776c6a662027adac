//! The campaign's tables (`tables.txt`, and stdout without `--json`): per stream and
//! distance the pose errors beside seed 000's figures, the reprojection errors and the
//! two ablations, and per number of visible marks what the labelling and pose did. It
//! reads only the records, so every figure in a table can be traced to `runs.jsonl`.

use super::{CameraRun, PoseCampaign, PoseOutcome, PoseRun, is_wrong};
use std::io::Write;

/// The paper's pose error at a distance (seed 000 §V-C), where it gives one.
pub fn paper_figure(distance_m: f64) -> Option<&'static str> {
    match (distance_m * 10.0).round() as i64 {
        10 => Some("2.56 cm / 2.5°"),
        20 => Some("4.12 cm / 4.58°"),
        40 => Some("up to 30 cm"),
        50 => Some("about 20 cm"),
        _ => None,
    }
}

/// Mean, SD and largest of some values (zeros when there are none).
fn stats(v: &[f64]) -> (f64, f64, f64) {
    if v.is_empty() {
        return (0.0, 0.0, 0.0);
    }
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let sd = (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / n).sqrt();
    (m, sd, v.iter().copied().fold(f64::MIN, f64::max))
}

/// "found/total, mean / worst cm, mean / worst °" of some pose outcomes.
fn pose_cells(outcomes: &[&PoseOutcome]) -> (String, String, String) {
    let found: Vec<&&PoseOutcome> = outcomes.iter().filter(|o| o.found).collect();
    let pos: Vec<f64> = found
        .iter()
        .filter_map(|o| o.position_err_m)
        .map(|e| 100.0 * e)
        .collect();
    let head: Vec<f64> = found.iter().filter_map(|o| o.heading_err_deg).collect();
    let (pm, _, pw) = stats(&pos);
    let (hm, _, hw) = stats(&head);
    let none = found.is_empty();
    let cell = |m: f64, w: f64, unit: &str| {
        if none {
            "–".to_string()
        } else {
            format!("{m:.2} / {w:.2}{unit}")
        }
    };
    (
        format!("{}/{}", found.len(), outcomes.len()),
        cell(pm, pw, " cm"),
        cell(hm, hw, "°"),
    )
}

/// Writes the campaign's tables: per distance, the stereo and mono pose errors beside the
/// paper's, the reprojection errors, the two ablations, and per number of visible marks
/// what the labelling and pose did.
///
/// # Errors
/// Writing to `out`.
pub fn write_tables(c: &PoseCampaign, recs: &[PoseRun], out: &mut dyn Write) -> std::io::Result<()> {
    // Rows: each stream (JPEG quality) and distance, in run order.
    let mut keys: Vec<(u32, f64)> = Vec::new();
    for r in recs {
        if !keys.contains(&(r.jpeg_quality, r.distance_m)) {
            keys.push((r.jpeg_quality, r.distance_m));
        }
    }
    let at = |(q, d): (u32, f64)| recs.iter().filter(move |r| r.jpeg_quality == q && r.distance_m == d);
    let stream = |q: u32| if q == 0 { "raw".to_string() } else { format!("JPEG {q}") };
    writeln!(out, "{}: {} runs ({})", c.name, recs.len(), c.description)?;
    writeln!(out)?;
    writeln!(
        out,
        "| stream | distance | stereo found | stereo position mean / worst | stereo heading mean / worst | mono found (per camera) | mono position mean / worst | mono heading mean / worst | wrong poses (stereo, mono) | paper (stereo) |"
    )?;
    writeln!(out, "|---|---|---|---|---|---|---|---|---|---|")?;
    for &(q, d) in &keys {
        let st: Vec<&PoseOutcome> = at((q, d)).map(|r| &r.stereo).collect();
        let mo: Vec<&PoseOutcome> = at((q, d)).flat_map(|r| r.cameras.iter().map(|k| &k.mono)).collect();
        let (sf, sp, sh) = pose_cells(&st);
        let (mf, mp, mh) = pose_cells(&mo);
        let ws = st.iter().filter(|o| is_wrong(o, d)).count();
        let wm = mo.iter().filter(|o| is_wrong(o, d)).count();
        writeln!(
            out,
            "| {} | {d:.1} m | {sf} | {sp} | {sh} | {mf} | {mp} | {mh} | {ws}, {wm} | {} |",
            stream(q),
            paper_figure(d).unwrap_or("")
        )?;
    }
    writeln!(out)?;
    writeln!(
        out,
        "| stream | distance | labelled frames | homography reprojection mean ± SD (worst) | stereo pose reprojection mean ± SD (worst) | paper |"
    )?;
    writeln!(out, "|---|---|---|---|---|---|")?;
    for &(q, d) in &keys {
        let frames: Vec<&CameraRun> = at((q, d)).flat_map(|r| r.cameras.iter()).collect();
        let h: Vec<f64> = frames.iter().filter_map(|k| k.labelling.reprojection_px).collect();
        let s: Vec<f64> = at((q, d)).filter_map(|r| r.stereo.reprojection_px).collect();
        let (hm, hs, hw) = stats(&h);
        let (sm, ss, sw) = stats(&s);
        writeln!(
            out,
            "| {} | {d:.1} m | {}/{} | {hm:.2} ± {hs:.2} px ({hw:.2}) | {sm:.2} ± {ss:.2} px ({sw:.2}) | 8.21 ± 2.4 px |",
            stream(q),
            h.len(),
            frames.len()
        )?;
    }
    writeln!(out)?;
    writeln!(
        out,
        "| stream | distance | mono, lens model: position / heading (mean / worst) | mono, pin-hole (distortion ignored) | 4-point labelling: frames labelled, mislabelled | ≥ 5 (ours): labelled, mislabelled | 4-point stereo: found, wrong | ours stereo: found, wrong |"
    )?;
    writeln!(out, "|---|---|---|---|---|---|---|---|")?;
    for &(q, d) in &keys {
        let frames: Vec<&CameraRun> = at((q, d)).flat_map(|r| r.cameras.iter()).collect();
        let lens: Vec<&PoseOutcome> = frames.iter().map(|k| &k.mono).collect();
        let pin: Vec<&PoseOutcome> = frames.iter().map(|k| &k.mono_pinhole).collect();
        let (_, lp, lh) = pose_cells(&lens);
        let (pf, pp, ph) = pose_cells(&pin);
        let count = |f: &dyn Fn(&CameraRun) -> bool| frames.iter().filter(|k| f(k)).count();
        let l4 = count(&|k| k.labelling_four_point.found);
        let m4 = count(&|k| k.labelling_four_point.mislabelled > 0);
        let l5 = count(&|k| k.labelling.found);
        let m5 = count(&|k| k.labelling.mislabelled > 0);
        let s4f = at((q, d)).filter(|r| r.stereo_four_point.found).count();
        let s4w = at((q, d)).filter(|r| is_wrong(&r.stereo_four_point, d)).count();
        let s5f = at((q, d)).filter(|r| r.stereo.found).count();
        let s5w = at((q, d)).filter(|r| is_wrong(&r.stereo, d)).count();
        writeln!(
            out,
            "| {} | {d:.1} m | {lp}, {lh} | {pp}, {ph} ({pf}) | {l4}, {m4} | {l5}, {m5} | {s4f}, {s4w} | {s5f}, {s5w} |",
            stream(q)
        )?;
    }
    writeln!(out)?;
    writeln!(
        out,
        "| stream | visible marks | decoy | frames | labelled (≥ 5) | mono pose | wrong | clean failures | 4-point: labelled | mislabelled | wrong mono poses |"
    )?;
    writeln!(out, "|---|---|---|---|---|---|---|---|---|---|---|")?;
    let mut qualities: Vec<u32> = keys.iter().map(|k| k.0).collect();
    qualities.dedup();
    for q in qualities {
        for decoy in [false, true] {
            for v in (0..=8).rev() {
                let frames: Vec<(&PoseRun, &CameraRun)> = recs
                    .iter()
                    .filter(|r| r.decoy == decoy && r.jpeg_quality == q)
                    .flat_map(|r| r.cameras.iter().map(move |k| (r, k)))
                    .filter(|(_, k)| k.visible == v)
                    .collect();
                if frames.is_empty() {
                    continue;
                }
                let n = |f: &dyn Fn(&PoseRun, &CameraRun) -> bool| frames.iter().filter(|(r, k)| f(r, k)).count();
                let mut failures: Vec<(String, usize)> = Vec::new();
                for (_, k) in &frames {
                    if let Some(e) = &k.mono.error {
                        match failures.iter_mut().find(|(name, _)| name == e) {
                            Some(f) => f.1 += 1,
                            None => failures.push((e.clone(), 1)),
                        }
                    }
                }
                failures.sort();
                let failures = if failures.is_empty() {
                    "–".to_string()
                } else {
                    failures
                        .iter()
                        .map(|(e, n)| format!("{e} {n}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                };
                writeln!(
                    out,
                    "| {} | {v} | {} | {} | {} | {} | {} | {failures} | {} | {} | {} |",
                    stream(q),
                    if decoy { "yes" } else { "no" },
                    frames.len(),
                    n(&|_, k| k.labelling.found),
                    n(&|_, k| k.mono.found),
                    n(&|r, k| is_wrong(&k.mono, r.distance_m)),
                    n(&|_, k| k.labelling_four_point.found),
                    n(&|_, k| k.labelling_four_point.mislabelled > 0),
                    n(&|r, k| is_wrong(&k.mono_four_point, r.distance_m)),
                )?;
            }
        }
    }
    Ok(())
}
