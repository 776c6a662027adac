//! Semantic validation with field paths and line numbers.

use super::error::Problem;
use toml::de::{DeTable, DeValue};

/// Implemented by configuration types: report every semantic problem to `v`.
pub trait Validate {
    /// Checks ranges and consistency, reporting problems with their field paths.
    fn validate(&self, v: &mut Validator<'_>);
}

/// Collects problems and finds the line of each field path in the source.
pub struct Validator<'a> {
    src: &'a str,
    doc: Option<&'a DeTable<'a>>,
    problems: Vec<Problem>,
}

/// 1-based line of byte offset `pos` in `src`.
pub fn line_of_offset(src: &str, pos: usize) -> usize {
    src.as_bytes()[..pos.min(src.len())]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

enum Seg<'p> {
    Key(&'p str),
    Index(usize),
}

fn segments(path: &str) -> Vec<Seg<'_>> {
    let mut out = Vec::new();
    for part in path.split('.') {
        let (key, rest) = match part.find('[') {
            Some(i) => (&part[..i], &part[i..]),
            None => (part, ""),
        };
        if !key.is_empty() {
            out.push(Seg::Key(key));
        }
        for idx in rest.split('[').filter(|s| !s.is_empty()) {
            if let Ok(i) = idx.trim_end_matches(']').parse() {
                out.push(Seg::Index(i));
            }
        }
    }
    out
}

impl<'a> Validator<'a> {
    /// A validator over `src`, parsed as `doc` (if it parsed).
    pub fn new(src: &'a str, doc: Option<&'a DeTable<'a>>) -> Self {
        Self {
            src,
            doc,
            problems: Vec::new(),
        }
    }

    /// The problems found so far.
    pub fn into_problems(self) -> Vec<Problem> {
        self.problems
    }

    /// Line of the value at `path` (or of its deepest existing ancestor).
    pub fn line_of(&self, path: &str) -> Option<usize> {
        let doc = self.doc?;
        let mut span: Option<std::ops::Range<usize>> = None;
        let mut table: Option<&DeTable<'_>> = Some(doc);
        let mut value: Option<&DeValue<'_>> = None;
        for seg in segments(path) {
            match seg {
                Seg::Key(k) => {
                    let t = match (table, value) {
                        (Some(t), None) => t,
                        (_, Some(DeValue::Table(t))) => t,
                        _ => break,
                    };
                    let Some((key, v)) = t.iter().find(|(key, _)| key.get_ref().as_ref() == k) else {
                        break;
                    };
                    span = Some(key.span());
                    value = Some(v.get_ref());
                    table = None;
                }
                Seg::Index(i) => {
                    let Some(DeValue::Array(a)) = value else { break };
                    let Some(item) = a.get(i) else { break };
                    span = Some(item.span());
                    value = Some(item.get_ref());
                }
            }
        }
        span.map(|s| line_of_offset(self.src, s.start))
    }

    /// Reports a problem at `path`.
    pub fn problem(&mut self, path: &str, message: impl Into<String>) {
        let line = self.line_of(path);
        self.problems.push(Problem {
            path: path.to_string(),
            line,
            message: message.into(),
        });
    }

    /// Reports a problem unless `ok`.
    pub fn require(&mut self, ok: bool, path: &str, message: impl FnOnce() -> String) {
        if !ok {
            self.problem(path, message());
        }
    }

    /// `value` must be finite and > 0.
    pub fn positive(&mut self, path: &str, value: f64) {
        self.require(value.is_finite() && value > 0.0, path, || {
            format!("expected a positive number, got {value}")
        });
    }

    /// `value` must be finite and ≥ 0.
    pub fn non_negative(&mut self, path: &str, value: f64) {
        self.require(value.is_finite() && value >= 0.0, path, || {
            format!("expected a number ≥ 0, got {value}")
        });
    }

    /// `value` must be finite.
    pub fn finite(&mut self, path: &str, value: f64) {
        self.require(value.is_finite(), path, || {
            format!("expected a finite number, got {value}")
        });
    }

    /// `value` must lie in [lo, hi].
    pub fn range(&mut self, path: &str, value: f64, lo: f64, hi: f64) {
        self.require(value.is_finite() && value >= lo && value <= hi, path, || {
            format!("expected a number in [{lo}, {hi}], got {value}")
        });
    }

    /// `bounds` must be an interval [low, high] of finite numbers with low ≤ high, within
    /// [lo, hi] (a range a scenario draws from).
    pub fn interval(&mut self, path: &str, bounds: [f64; 2], lo: f64, hi: f64) {
        let [a, b] = bounds;
        self.require(
            a.is_finite() && b.is_finite() && a <= b && a >= lo && b <= hi,
            path,
            || format!("expected [low, high] with {lo} ≤ low ≤ high ≤ {hi}, got {bounds:?}"),
        );
    }

    /// `value` must lie in (0, 1] (a rate, factor or fraction where 0 would switch
    /// the thing off).
    pub fn fraction(&mut self, path: &str, value: f64) {
        self.require(value > 0.0 && value <= 1.0, path, || {
            format!("expected a number in (0, 1], got {value}")
        });
    }

    /// A count must be ≥ 1.
    pub fn nonzero(&mut self, path: &str, value: usize) {
        self.require(value >= 1, path, || format!("expected an integer ≥ 1, got {value}"));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fraction_accepts_the_half_open_unit_interval() {
        let mut v = Validator::new("", None);
        for ok in [1e-9, 0.5, 1.0] {
            v.fraction("f", ok);
        }
        assert!(v.into_problems().is_empty());
        let mut v = Validator::new("", None);
        for bad in [0.0, -0.1, 1.01, f64::NAN, f64::INFINITY] {
            v.fraction("f", bad);
        }
        let problems = v.into_problems();
        assert_eq!(problems.len(), 5);
        assert!(problems[0].message.contains("expected a number in (0, 1], got 0"));
    }
}
