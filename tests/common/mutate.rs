//! Deterministic mutations of configuration text, for tests that a loader never panics:
//! truncations, byte flips, values swapped for another type (string ↔ number ↔ bool ↔
//! array ↔ table, and numbers at the edges: NaN, infinities, huge, negative, zero) and
//! deleted lines. A fixed-seed generator chooses the positions, so every run tries the
//! same inputs and a failure names one that can be replayed.
#![allow(dead_code)]

/// The crate's seeded generator ([`marsupial::sim::rng::Rng`]), picking positions.
pub struct Rng(marsupial::sim::rng::Rng);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(marsupial::sim::rng::Rng::new(seed))
    }

    pub fn next(&mut self) -> u64 {
        self.0.next_u64()
    }

    /// Uniform in 0..n (n > 0).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

/// One mutated text and how it was made (for the failure message).
pub struct Mutant {
    pub what: String,
    pub bytes: Vec<u8>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kind {
    Str,
    Num,
    Bool,
    Array,
    Table,
    Other,
}

/// A value's span in the text (after a `key =`) and its kind.
struct Value {
    start: usize,
    end: usize,
    kind: Kind,
}

/// The end of the string starting at `i` (a `"` or `'`), past its closing quote.
fn string_end(b: &[u8], i: usize) -> usize {
    let q = b[i];
    let mut j = i + 1;
    while j < b.len() && b[j] != q && b[j] != b'\n' {
        if q == b'"' && b[j] == b'\\' {
            j += 1;
        }
        j += 1;
    }
    (j + 1).min(b.len())
}

/// The end of the bracketed value starting at `i` (`[` or `{`), past its closing bracket.
fn bracket_end(b: &[u8], i: usize) -> usize {
    let mut depth = 0usize;
    let mut j = i;
    while j < b.len() {
        match b[j] {
            b'"' | b'\'' => {
                j = string_end(b, j);
                continue;
            }
            b'#' => {
                while j < b.len() && b[j] != b'\n' {
                    j += 1;
                }
                continue;
            }
            b'[' | b'{' => depth += 1,
            b']' | b'}' => {
                depth -= 1;
                if depth == 0 {
                    return j + 1;
                }
            }
            _ => {}
        }
        j += 1;
    }
    b.len()
}

/// Every value assigned with `=` (top level or in inline tables), in text order.
fn values(src: &str) -> Vec<Value> {
    let b = src.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'#' => {
                while i < b.len() && b[i] != b'\n' {
                    i += 1;
                }
            }
            b'"' | b'\'' => i = string_end(b, i),
            b'=' => {
                let mut s = i + 1;
                while s < b.len() && (b[s] == b' ' || b[s] == b'\t') {
                    s += 1;
                }
                if s >= b.len() {
                    break;
                }
                let (end, kind) = match b[s] {
                    b'"' | b'\'' => (string_end(b, s), Kind::Str),
                    b'[' => (bracket_end(b, s), Kind::Array),
                    b'{' => (bracket_end(b, s), Kind::Table),
                    _ => {
                        let mut e = s;
                        while e < b.len() && !b" \t\r\n,]}#".contains(&b[e]) {
                            e += 1;
                        }
                        let word = &src[s..e];
                        let kind = if word == "true" || word == "false" {
                            Kind::Bool
                        } else if word.starts_with(|c: char| c.is_ascii_digit() || c == '-' || c == '+') {
                            Kind::Num
                        } else {
                            Kind::Other
                        };
                        (e, kind)
                    }
                };
                out.push(Value { start: s, end, kind });
                // Go on inside arrays and inline tables, to their own `key =`s.
                i = s;
                continue;
            }
            _ => {}
        }
        i += 1;
    }
    out
}

/// What a value of `kind` may be swapped for: every other type, and for numbers the
/// edges a validator must refuse or survive.
fn replacements(kind: Kind) -> Vec<&'static str> {
    let mut r = Vec::new();
    if kind != Kind::Str {
        r.extend(["\"0.5\"", "\"\"", "\"paper16\""]);
    }
    if kind != Kind::Num {
        r.extend(["1", "-2.5", "0"]);
    }
    if kind != Kind::Bool {
        r.extend(["true", "false"]);
    }
    if kind != Kind::Array {
        r.extend(["[]", "[1.0, 2.0]", "[\"a\", 3]", "[[]]"]);
    }
    if kind != Kind::Table {
        r.extend(["{}", "{ x = 1 }"]);
    }
    r.extend([
        "nan",
        "inf",
        "-inf",
        "-1",
        "0",
        "1e308",
        "-1e308",
        "9223372036854775807",
        "-9223372036854775808",
        "4294967296",
        "1e-320",
    ]);
    r
}

/// The mutants of `src`, deterministic for a given `seed`:
/// * truncations at every line end and in the middle of every line, and at `cuts` other
///   byte offsets (which may cut a character in two);
/// * one byte in every `flip_every` replaced (at a random offset in each stretch) by a
///   byte TOML cares about or, one time in four, an arbitrary one;
/// * every `key = value` value swapped for `swaps` replacements of other types;
/// * every line deleted, one at a time.
pub fn mutants(src: &str, seed: u64, cuts: usize, flip_every: usize, swaps: usize) -> Vec<Mutant> {
    let mut rng = Rng::new(seed);
    let b = src.as_bytes();
    let mut out = Vec::new();
    let mut at: Vec<usize> = Vec::new();
    let mut line_start = 0;
    for (i, &c) in b.iter().enumerate() {
        if c == b'\n' {
            at.push(i);
            at.push(line_start + (i - line_start) / 2);
            line_start = i + 1;
        }
    }
    for _ in 0..cuts {
        at.push(rng.below(b.len() + 1));
    }
    at.sort_unstable();
    at.dedup();
    for cut in at {
        out.push(Mutant {
            what: format!("truncated at byte {cut}"),
            bytes: b[..cut].to_vec(),
        });
    }
    const TOML_BYTES: &[u8] = b"=[]{}\"'.,-+#\n 0179eExtf_\\";
    for stretch in (0..b.len()).step_by(flip_every.max(1)) {
        let i = (stretch + rng.below(flip_every.max(1))).min(b.len() - 1);
        let byte = if rng.below(4) == 0 {
            rng.next() as u8
        } else {
            TOML_BYTES[rng.below(TOML_BYTES.len())]
        };
        let mut m = b.to_vec();
        m[i] = byte;
        out.push(Mutant {
            what: format!("byte {i} ({:?}) replaced by {:?}", b[i] as char, byte as char),
            bytes: m,
        });
    }
    for v in values(src) {
        let mut alts = replacements(v.kind);
        for _ in 0..swaps.min(alts.len()) {
            let alt = alts.swap_remove(rng.below(alts.len()));
            let mut m = Vec::with_capacity(b.len() + alt.len());
            m.extend_from_slice(&b[..v.start]);
            m.extend_from_slice(alt.as_bytes());
            m.extend_from_slice(&b[v.end..]);
            out.push(Mutant {
                what: format!(
                    "line {}: `{}` replaced by `{alt}`",
                    src[..v.start].matches('\n').count() + 1,
                    &src[v.start..v.end]
                ),
                bytes: m,
            });
        }
    }
    let lines: Vec<&str> = src.split_inclusive('\n').collect();
    for k in 0..lines.len() {
        let mut m = String::with_capacity(src.len());
        for (j, l) in lines.iter().enumerate() {
            if j != k {
                m.push_str(l);
            }
        }
        out.push(Mutant {
            what: format!("line {} deleted: `{}`", k + 1, lines[k].trim_end()),
            bytes: m.into_bytes(),
        });
    }
    out
}

/// Runs `f` on every mutant and returns those that panicked (how each was made).
pub fn panicking(mutants: &[Mutant], mut f: impl FnMut(&Mutant)) -> Vec<String> {
    let mut bad = Vec::new();
    for m in mutants {
        if std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| f(m))).is_err() {
            bad.push(m.what.clone());
        }
    }
    bad
}
