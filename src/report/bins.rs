//! Success binned by a drawn lighting parameter (`trials --bin PARAM[:N]`), so that the
//! weak regions of a randomized campaign show: success against beacon power, shadow speed,
//! sun elevation, and so on, per segmentation mode.

use crate::sim::campaign::RunRecord;
use crate::sim::lighting_random::LightingDraw;
use std::collections::BTreeMap;
use std::fmt;

/// One bin: the parameter's interval and, per segmentation mode, (docked, runs).
#[derive(Debug, Clone, PartialEq)]
pub struct Bin {
    /// Lower bound (inclusive).
    pub lo: f64,
    /// Upper bound (inclusive for the last bin, exclusive otherwise).
    pub hi: f64,
    /// Segmentation mode → (docked, runs).
    pub by_mode: BTreeMap<String, (u32, u32)>,
}

/// Success against one drawn parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct BinTable {
    /// The parameter (one of [`LightingDraw::PARAMS`]).
    pub param: String,
    /// The bins, in order.
    pub bins: Vec<Bin>,
}

/// Parses `PARAM` or `PARAM:N` (N bins, default 5).
///
/// # Errors
/// A message naming the known parameters, or the bad count.
pub fn parse_bin_arg(arg: &str) -> Result<(String, usize), String> {
    let (param, n) = match arg.split_once(':') {
        Some((p, n)) => {
            let n: usize = n
                .parse()
                .ok()
                .filter(|n| (1..=100).contains(n))
                .ok_or_else(|| format!("--bin {arg}: expected PARAM:N with N in 1..=100"))?;
            (p, n)
        }
        None => (arg, 5),
    };
    if !LightingDraw::PARAMS.contains(&param) {
        return Err(format!(
            "--bin {arg}: unknown parameter `{param}`; the drawn parameters are {}",
            LightingDraw::PARAMS.join(", ")
        ));
    }
    Ok((param.to_string(), n))
}

/// Bins the runs that drew their lighting by `param` into `n` equal-width bins over the
/// drawn range; a parameter that takes at most `n` distinct values (a count, an on/off
/// flag) gets one bin per value.
///
/// # Errors
/// When no run drew its lighting (the scenario has no `[lighting_random]` on its axis).
pub fn bin_by(records: &[RunRecord], param: &str, n: usize) -> Result<BinTable, String> {
    let values: Vec<(f64, &RunRecord)> = records
        .iter()
        .filter_map(|r| {
            r.lighting_draw
                .as_ref()
                .and_then(|d| d.params.get(param))
                .map(|v| (*v, r))
        })
        .collect();
    if values.is_empty() {
        return Err(format!(
            "--bin {param}: no run drew its lighting (name a [lighting_random.NAME] on the lighting axis)"
        ));
    }
    let mut distinct: Vec<f64> = values.iter().map(|v| v.0).collect();
    distinct.sort_by(f64::total_cmp);
    distinct.dedup();
    let edges: Vec<(f64, f64)> = if distinct.len() <= n {
        distinct.iter().map(|&v| (v, v)).collect()
    } else {
        let (lo, hi) = (distinct[0], distinct[distinct.len() - 1]);
        let w = (hi - lo) / n as f64;
        (0..n)
            .map(|i| (lo + w * i as f64, if i + 1 == n { hi } else { lo + w * (i + 1) as f64 }))
            .collect()
    };
    let mut bins: Vec<Bin> = edges
        .iter()
        .map(|&(lo, hi)| Bin {
            lo,
            hi,
            by_mode: BTreeMap::new(),
        })
        .collect();
    let last = bins.len() - 1;
    for (v, r) in values {
        let i = bins
            .iter()
            .position(|b| if b.lo == b.hi { v == b.lo } else { v < b.hi })
            .unwrap_or(last);
        let e = bins[i].by_mode.entry(r.segmentation.clone()).or_insert((0, 0));
        e.0 += u32::from(r.success);
        e.1 += 1;
    }
    Ok(BinTable {
        param: param.to_string(),
        bins,
    })
}

impl fmt::Display for BinTable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let modes: Vec<&String> = {
            let mut m: Vec<&String> = self.bins.iter().flat_map(|b| b.by_mode.keys()).collect();
            m.sort();
            m.dedup();
            m
        };
        write!(f, "{:<22}", format!("success by {}", self.param))?;
        for m in &modes {
            write!(f, "  {m:>16}")?;
        }
        writeln!(f)?;
        for b in &self.bins {
            let label = if b.lo == b.hi {
                format!("{:.3}", b.lo)
            } else {
                format!("{:.3}–{:.3}", b.lo, b.hi)
            };
            write!(f, "{label:<22}")?;
            for m in &modes {
                let cell = match b.by_mode.get(*m) {
                    Some(&(k, n)) => format!("{k}/{n} = {:.2}", f64::from(k) / f64::from(n.max(1))),
                    None => "-".into(),
                };
                write!(f, "  {cell:>16}")?;
            }
            writeln!(f)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rec(seg: &str, success: bool, power: f64, beacons: f64) -> RunRecord {
        let mut params = BTreeMap::new();
        params.insert("beacon_power".to_string(), power);
        params.insert("beacons".to_string(), beacons);
        RunRecord {
            lighting: "mixed".into(),
            segmentation: seg.into(),
            lighting_draw: Some(LightingDraw {
                spec: Default::default(),
                params,
            }),
            ..RunRecord::for_test("1", success)
        }
    }

    #[test]
    fn bins_split_the_drawn_range_and_count_per_mode() {
        let records = vec![
            rec("adaptive", true, 0.0, 0.0),
            rec("adaptive", true, 1.0, 1.0),
            rec("adaptive", false, 3.9, 2.0),
            rec("static", false, 4.0, 2.0),
            rec("static", true, 2.0, 1.0),
        ];
        let t = bin_by(&records, "beacon_power", 2).unwrap();
        assert_eq!(t.bins.len(), 2);
        assert_eq!((t.bins[0].lo, t.bins[0].hi, t.bins[1].hi), (0.0, 2.0, 4.0));
        assert_eq!(t.bins[0].by_mode["adaptive"], (2, 2));
        // 2.0 is the second bin's lower edge; 4.0, the top, belongs to the last bin.
        assert_eq!(t.bins[1].by_mode["static"], (1, 2));
        assert_eq!(t.bins[1].by_mode["adaptive"], (0, 1));
        // A count with no more values than bins: one bin per value.
        let c = bin_by(&records, "beacons", 5).unwrap();
        assert_eq!(c.bins.iter().map(|b| b.lo).collect::<Vec<_>>(), vec![0.0, 1.0, 2.0]);
        assert_eq!(c.bins[2].by_mode["adaptive"], (0, 1));
        let text = t.to_string();
        assert!(text.contains("2/2 = 1.00") && text.contains("static"), "{text}");
    }

    #[test]
    fn bad_bin_arguments_and_campaigns_without_draws_are_errors() {
        assert_eq!(parse_bin_arg("beacon_power").unwrap(), ("beacon_power".into(), 5));
        assert_eq!(parse_bin_arg("glare:3").unwrap(), ("glare".into(), 3));
        assert!(parse_bin_arg("beacon_colour").unwrap_err().contains("beacon_power"));
        assert!(parse_bin_arg("glare:0").is_err());
        assert!(parse_bin_arg("glare:x").is_err());
        let mut r = rec("adaptive", true, 1.0, 1.0);
        r.lighting_draw = None;
        assert!(bin_by(&[r], "glare", 3).unwrap_err().contains("lighting_random"));
    }
}
