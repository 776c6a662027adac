//! Imprinting, adaptation and the parameter fallback chain (seed 004 §IV.C, Fig. 5).
//!
//! Colour statistics are the mean and standard deviation of the SCT angles A and B per
//! colour. A colour's segmentation range is mean ± n·SD on each angle (n = 4: Chebyshev
//! guarantees ≥ 93.75 % of any distribution per angle; with two angles the union bound
//! guarantees 87.5 %). Three sets of statistics exist:
//!
//! * **table**: defaults from the fiducial's nominal paint colours;
//! * **imprinted**: measured from a few well-aligned frames as the daughter leaves the dock;
//! * **adapted**: measured every frame the fiducial is found, from the pixels segmented for
//!   each block.
//!
//! While the fiducial is found, the adapted statistics drive the next frame. If it is not
//! found for `timeout1` seconds, the model assumes adaptation drifted and reverts to the
//! imprinted set; after `timeout2` seconds without a detection it assumes the imprint is
//! bad too and reverts to the table. Every switch is logged (`tracing`, target
//! `marsupial::perception`). In **static** mode (the paper's comparison) the imprinted
//! statistics are used unchanged: no adaptation and no fallback.
//!
//! SDs are clamped to [floor, ceiling] so a flat-coloured patch cannot collapse its range
//! to nothing and a noisy one cannot swallow the colour space (ALGORITHMS §2 pitfalls).
//! The two colours' ranges never overlap each other or reach halfway to grey
//! ([`separate_ranges`]): adaptation cannot grow one colour's range over the other's block
//! or over the grey body around it. In the table fallback, "grey" is grey as the imprint
//! saw it ([`seen_grey`]): the table's colours were measured under another light.

use super::image::RgbView;
use super::sct::Sct;
use super::segment::{ChromaGate, SctRange};
use serde::{Deserialize, Serialize};
use std::fmt;

/// Adaptive (imprint + adapt + fallback), static (imprint only) or fixed (table values
/// only) segmentation. A profile's `perception.mode` (re-exported as
/// `profile::SegmentationMode`); it lives here because the trackers act on it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SegmentationMode {
    /// Imprint, then adapt every frame; fall back on timeouts (seed 004 Fig. 5).
    Adaptive,
    /// Imprint, never adapt (the paper's comparison, Table II).
    Static,
    /// The table values alone: no imprint, no adaptation (RAPOSA's operator-tuned HSV
    /// bands, seed 001 §II.D).
    Fixed,
}

impl SegmentationMode {
    /// The name used in TOML and output.
    pub fn as_str(&self) -> &'static str {
        match self {
            SegmentationMode::Adaptive => "adaptive",
            SegmentationMode::Static => "static",
            SegmentationMode::Fixed => "fixed",
        }
    }
}

/// Mean and standard deviation of the SCT angles of one colour, radians.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct AngleStats {
    /// Mean of A.
    pub mean_a: f64,
    /// SD of A.
    pub sd_a: f64,
    /// Mean of B.
    pub mean_b: f64,
    /// SD of B.
    pub sd_b: f64,
    /// Pixels the statistics came from (0 for table defaults).
    pub n: u64,
}

impl AngleStats {
    /// Nominal statistics of a paint colour: its exact SCT angles with SD `sd` (rad).
    pub fn nominal(rgb: [u8; 3], sd: f64) -> Self {
        let s = Sct::from_rgb(rgb);
        Self {
            mean_a: s.a,
            sd_a: sd,
            mean_b: s.b,
            sd_b: sd,
            n: 0,
        }
    }

    /// The segmentation range mean ± `p.n_sd`·SD, with each SD clamped to
    /// [`p.sd_floor`, `p.sd_ceiling`], and the brightness and chroma gates of `p`.
    ///
    /// # Example
    ///
    /// Pure red has A = π/2 and B = 0; with an SD of 0.05 rad and 4 SDs the range is
    /// ±0.2 rad about them, which holds a darker, slightly orange red but not blue.
    ///
    /// ```
    /// use marsupial::perception::{AngleStats, ColorModelParams};
    /// use std::f64::consts::FRAC_PI_2;
    ///
    /// let p = ColorModelParams {
    ///     n_sd: 4.0,
    ///     sd_floor: 0.01,
    ///     sd_ceiling: 0.2,
    ///     min_l: 20.0,
    ///     min_chroma: 0.05,
    ///     timeout1: 2.0,
    ///     timeout2: 5.0,
    ///     adaptive: true,
    ///     adapt_rate: 1.0,
    /// };
    /// let red = AngleStats::nominal([255, 0, 0], 0.05);
    /// assert_eq!((red.mean_a, red.mean_b), (FRAC_PI_2, 0.0));
    /// let r = red.range(&p);
    /// assert!((r.a[0] - (FRAC_PI_2 - 0.2)).abs() < 1e-12 && (r.b[1] - 0.2).abs() < 1e-12);
    /// assert!(r.contains([200, 30, 10]));
    /// assert!(!r.contains([10, 10, 200]));
    /// // An SD of 0 is floored at 0.01 rad: the range never collapses.
    /// let flat = AngleStats { sd_a: 0.0, sd_b: 0.0, ..red }.range(&p);
    /// assert!((flat.b[1] - 0.04).abs() < 1e-12);
    /// ```
    pub fn range(&self, p: &ColorModelParams) -> SctRange {
        let sa = self.sd_a.clamp(p.sd_floor, p.sd_ceiling) * p.n_sd;
        let sb = self.sd_b.clamp(p.sd_floor, p.sd_ceiling) * p.n_sd;
        SctRange {
            a: [self.mean_a - sa, self.mean_a + sa],
            b: [self.mean_b - sb, self.mean_b + sb],
            min_l: p.min_l,
            min_chroma: p.min_chroma,
        }
    }
}

/// Colour statistics that adaptation can move toward a new measurement. The fallback
/// chain of [`ColorModel`] is the same whatever the colour space; only the statistics and
/// how they become a segmentation range differ (SCT angles here, HSV in
/// [`HsvStats`](super::HsvStats)).
///
/// # Example
///
/// ```
/// use marsupial::perception::{AngleStats, Blend};
///
/// let old = AngleStats { mean_a: 0.8, sd_a: 0.02, mean_b: 0.4, sd_b: 0.02, n: 100 };
/// let new = AngleStats { mean_a: 0.9, sd_a: 0.04, mean_b: 0.4, sd_b: 0.02, n: 50 };
/// let half = old.blend(&new, 0.5);
/// assert!((half.mean_a - 0.85).abs() < 1e-12 && (half.sd_a - 0.03).abs() < 1e-12);
/// assert_eq!(half.n, 50);
/// assert!((old.blend(&new, 1.0).mean_a - 0.9).abs() < 1e-12, "rate 1 replaces");
/// ```
pub trait Blend: Copy {
    /// Moves toward `new` with rate `beta` in (0, 1] (1 replaces).
    fn blend(&self, new: &Self, beta: f64) -> Self;
}

impl Blend for AngleStats {
    fn blend(&self, new: &AngleStats, beta: f64) -> AngleStats {
        let mix = |a: f64, b: f64| a + beta * (b - a);
        AngleStats {
            mean_a: mix(self.mean_a, new.mean_a),
            sd_a: mix(self.sd_a, new.sd_a),
            mean_b: mix(self.mean_b, new.mean_b),
            sd_b: mix(self.sd_b, new.sd_b),
            n: new.n,
        }
    }
}

impl<T: Blend, const N: usize> Blend for [T; N] {
    fn blend(&self, new: &Self, beta: f64) -> Self {
        std::array::from_fn(|i| self[i].blend(&new[i], beta))
    }
}

/// Streaming mean/variance of (A, B) pairs in `f64`, by shifted sums: samples are taken
/// relative to the first one, which keeps E\[x²\] − E\[x\]² well conditioned (the naive form
/// loses precision; ALGORITHMS §2) without a division per sample.
///
/// # Example
///
/// ```
/// use marsupial::perception::StatsAccumulator;
///
/// let mut acc = StatsAccumulator::default();
/// acc.push(0.1, 1.0);
/// assert!(acc.finish().is_none(), "one sample has no spread");
/// acc.push(0.3, 1.0);
/// let s = acc.finish().unwrap();
/// assert_eq!(s.n, 2);
/// assert!((s.mean_a - 0.2).abs() < 1e-12 && (s.sd_a - 0.1).abs() < 1e-12);
/// assert!((s.mean_b - 1.0).abs() < 1e-12 && s.sd_b == 0.0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StatsAccumulator {
    n: u64,
    ref_a: f64,
    ref_b: f64,
    sum_a: f64,
    sum_aa: f64,
    sum_b: f64,
    sum_bb: f64,
}

impl StatsAccumulator {
    /// Adds one sample (radians).
    #[inline]
    pub fn push(&mut self, a: f64, b: f64) {
        if self.n == 0 {
            self.ref_a = a;
            self.ref_b = b;
        }
        self.n += 1;
        let (da, db) = (a - self.ref_a, b - self.ref_b);
        self.sum_a += da;
        self.sum_aa += da * da;
        self.sum_b += db;
        self.sum_bb += db * db;
    }

    /// Samples so far.
    pub fn count(&self) -> u64 {
        self.n
    }

    /// The statistics (population SD), or `None` with fewer than 2 samples.
    pub fn finish(&self) -> Option<AngleStats> {
        if self.n < 2 {
            return None;
        }
        let n = self.n as f64;
        let var = |s: f64, ss: f64| ((ss - s * s / n) / n).max(0.0);
        Some(AngleStats {
            mean_a: self.ref_a + self.sum_a / n,
            sd_a: var(self.sum_a, self.sum_aa).sqrt(),
            mean_b: self.ref_b + self.sum_b / n,
            sd_b: var(self.sum_b, self.sum_bb).sqrt(),
            n: self.n,
        })
    }
}

/// Which statistics drive segmentation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ColorMode {
    /// Adapted from the last frames where the fiducial was found.
    Adapted,
    /// Imprinted on departure.
    Imprinted,
    /// Table defaults.
    Table,
}

impl fmt::Display for ColorMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            ColorMode::Adapted => "adapted",
            ColorMode::Imprinted => "imprinted",
            ColorMode::Table => "table",
        })
    }
}

/// Tuning of a [`ColorModel`] (a profile's `[perception]` gives them through
/// `ColorModelParams::from_spec` in `profile`). `sd_floor`, `sd_ceiling`, `min_l` and `min_chroma` shape the SCT ranges
/// of [`ColorModel::ranges`]; HSV models carry their own limits
/// ([`HsvLimits`](super::HsvLimits)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ColorModelParams {
    /// Range half-width in SDs (paper: 4).
    pub n_sd: f64,
    /// Smallest SD used, rad (SCT).
    pub sd_floor: f64,
    /// Largest SD used, rad (SCT).
    pub sd_ceiling: f64,
    /// Brightness gate, L units (0–441.7) (SCT).
    pub min_l: f64,
    /// Chroma gate, rad: pixels nearer the grey axis are never classified (SCT; see
    /// [`SctRange::min_chroma`]).
    pub min_chroma: f64,
    /// Seconds without detection before adapted → imprinted.
    pub timeout1: f64,
    /// Seconds without detection before imprinted → table.
    pub timeout2: f64,
    /// Adapt (true) or keep the imprint static (false).
    pub adaptive: bool,
    /// Blend rate of adaptation in (0, 1]; 1 is the paper's (replace each frame).
    pub adapt_rate: f64,
}

/// The per-colour statistics with the fallback chain. `S` holds every colour's
/// statistics: by default the SCT angles of two colours (index 0 is the block on the
/// image's left, 1 the block on its right); RAPOSA's pyramid uses `[HsvStats; 2]`
/// (orange, blue).
///
/// # Example
///
/// The fallback chain of seed 004 Fig. 5 on a hand-made timeline, with timeouts of 2 s
/// and 5 s.
///
/// ```
/// use marsupial::perception::{AngleStats, ColorMode, ColorModel, ColorModelParams};
///
/// let params = ColorModelParams {
///     n_sd: 4.0,
///     sd_floor: 0.01,
///     sd_ceiling: 0.2,
///     min_l: 20.0,
///     min_chroma: 0.05,
///     timeout1: 2.0,
///     timeout2: 5.0,
///     adaptive: true,
///     adapt_rate: 1.0,
/// };
/// let table = [AngleStats::nominal([0, 255, 255], 0.1), AngleStats::nominal([255, 0, 255], 0.1)];
/// let stats = |a: f64| AngleStats { mean_a: a, sd_a: 0.02, mean_b: 0.5, sd_b: 0.02, n: 100 };
///
/// let mut m = ColorModel::new(table, params);
/// assert_eq!(m.mode(), ColorMode::Table);
/// m.imprint([stats(0.70), stats(0.80)], 0.0);
/// assert_eq!(m.mode(), ColorMode::Imprinted);
/// m.update(1.0, Some([stats(0.72), stats(0.78)])); // found: adapt
/// assert_eq!(m.mode(), ColorMode::Adapted);
/// assert!((m.current()[0].mean_a - 0.72).abs() < 1e-12);
/// // The next frame's ranges come from the adapted statistics: 0.72 ± 4·0.02.
/// assert!((m.ranges()[0].a[0] - 0.64).abs() < 1e-12);
/// m.update(3.5, None); // lost for 2.5 s > timeout 1
/// assert_eq!(m.mode(), ColorMode::Imprinted);
/// m.update(6.5, None); // lost for 5.5 s > timeout 2
/// assert_eq!(m.mode(), ColorMode::Table);
/// assert_eq!(m.switches(), 4);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct ColorModel<S: Blend = [AngleStats; 2]> {
    params: ColorModelParams,
    table: S,
    imprinted: Option<S>,
    adapted: Option<S>,
    mode: ColorMode,
    reference_time: Option<f64>,
    switches: u32,
    looking: bool,
}

impl<S: Blend> ColorModel<S> {
    /// Starts on the table defaults.
    pub fn new(table: S, params: ColorModelParams) -> Self {
        Self {
            params,
            table,
            imprinted: None,
            adapted: None,
            mode: ColorMode::Table,
            reference_time: None,
            switches: 0,
            looking: true,
        }
    }

    /// The parameters.
    pub fn params(&self) -> &ColorModelParams {
        &self.params
    }

    /// Current mode.
    pub fn mode(&self) -> ColorMode {
        self.mode
    }

    /// Number of mode switches so far.
    pub fn switches(&self) -> u32 {
        self.switches
    }

    /// Imprinted statistics, if any.
    pub fn imprinted(&self) -> Option<&S> {
        self.imprinted.as_ref()
    }

    /// Statistics in use.
    pub fn current(&self) -> &S {
        match self.mode {
            ColorMode::Adapted => self.adapted.as_ref().unwrap_or(&self.table),
            ColorMode::Imprinted => self.imprinted.as_ref().unwrap_or(&self.table),
            ColorMode::Table => &self.table,
        }
    }

    /// Installs imprinted statistics at time `now` and switches to them.
    pub fn imprint(&mut self, stats: S, now: f64) {
        self.imprinted = Some(stats);
        self.adapted = None;
        self.reference_time = Some(now);
        self.switch(ColorMode::Imprinted, now, "imprinted");
    }

    /// Restarts the timeout clock at `now`, as if the target had just been seen (e.g. a
    /// detection too small to measure).
    pub fn restart_clock(&mut self, now: f64) {
        self.reference_time = Some(now);
    }

    /// Tells the model whether the robot expects the target in view. While it does not
    /// (a blind manoeuvre such as RAPOSA's region-II travel), frames without the target
    /// do not count toward the timeouts, and the clock restarts when looking resumes at
    /// `now`: turning away on purpose is no evidence that the statistics drifted.
    pub fn set_looking(&mut self, looking: bool, now: f64) {
        if looking && !self.looking {
            self.restart_clock(now);
        }
        self.looking = looking;
    }

    /// Switches to adaptive or static segmentation.
    pub fn set_adaptive(&mut self, adaptive: bool) {
        self.params.adaptive = adaptive;
    }

    fn switch(&mut self, to: ColorMode, now: f64, why: &'static str) {
        if to != self.mode {
            tracing::info!(target: "marsupial::perception", from = %self.mode, to = %to, now, why, "colour statistics switched");
            self.mode = to;
            self.switches += 1;
        }
    }

    /// Feeds one frame's result: `measured` holds the statistics of the accepted blocks'
    /// pixels when the fiducial was found, `None` otherwise.
    pub fn update(&mut self, now: f64, measured: Option<S>) {
        if measured.is_none() && !self.looking {
            return;
        }
        let reference = *self.reference_time.get_or_insert(now);
        if let Some(m) = measured {
            self.reference_time = Some(now);
            if self.params.adaptive {
                let beta = self.params.adapt_rate;
                self.adapted = Some(self.current().blend(&m, beta));
                self.switch(ColorMode::Adapted, now, "fiducial found");
            }
            return;
        }
        if !self.params.adaptive {
            return;
        }
        let waited = now - reference;
        if self.mode == ColorMode::Adapted && waited > self.params.timeout1 {
            let to = if self.imprinted.is_some() {
                ColorMode::Imprinted
            } else {
                ColorMode::Table
            };
            self.switch(to, now, "timeout 1: adaptation assumed at fault");
        }
        if self.mode == ColorMode::Imprinted && waited > self.params.timeout2 {
            self.switch(ColorMode::Table, now, "timeout 2: imprint assumed at fault");
        }
    }
}

impl ColorModel<[AngleStats; 2]> {
    /// SCT segmentation ranges for the next frame, never overlapping: see
    /// [`separate_ranges`]. On the table, each range is cut halfway to the grey the
    /// imprint saw ([`seen_grey`], when a change of light explains the imprint): the
    /// table's colours were measured under a light of their own, and the imprint's say
    /// where grey lies under this one. The imprinted and adapted ranges were measured
    /// under this light and centred on it, and keep the cut at r = g = b.
    pub fn ranges(&self) -> [SctRange; 2] {
        let p = &self.params;
        let stats = self.current();
        let mut r = stats.map(|s| s.range(p));
        let grey = match (self.mode, &self.imprinted) {
            (ColorMode::Table, Some(imp)) => {
                let seen = seen_grey(&self.table, imp);
                tracing::trace!(
                    target: "marsupial::perception",
                    seen_grey_deg = ?seen.map(|g| (g.0.to_degrees(), g.1.to_degrees())),
                    "table ranges cut toward grey (None: at r = g = b)"
                );
                seen.unwrap_or(GREY_AB)
            }
            _ => GREY_AB,
        };
        separate_ranges_about(&mut r, stats, grey);
        r
    }
}

/// Makes the two colours' boxes disjoint from each other and from grey: where they
/// overlap, each is cut at the midpoint between the two means along the angle (A or B)
/// on which the means lie farther apart. A pixel is then never both colours, and one that
/// could be either goes to the nearer. Grey is treated as a third colour
/// (see `off_grey`): no range reaches past the midpoint between its mean and grey.
///
/// Why: adaptation measures each colour from the pixels its own range segmented. At a
/// grazing view the blocks are a few pixels wide, and their shared edge holds every
/// mixture of the two paints; a range that takes in some of those mixtures measures a
/// larger SD, widens, takes in more, and runs away until it holds the other block too.
/// We replayed it (bujold-table1 run 45, 2 m at +60°): cyan's B range grew from 72–81°
/// to 5–86° over 40 s while the robot swung to 70° off the axis, the cyan block was
/// counted over the whole flap, and the ratio cue put the robot on the wrong side of the
/// axis. Two opposite colours never need overlapping ranges, so the cut costs nothing
/// where adaptation is healthy (the imprint's and the table's ranges are disjoint
/// already) and stops the runaway where it is not.
///
/// ```
/// use marsupial::perception::colour_model::separate_ranges;
/// use marsupial::perception::AngleStats;
/// use marsupial::perception::segment::SctRange;
///
/// let st = |b: f64| AngleStats { mean_a: 0.8, sd_a: 0.02, mean_b: b, sd_b: 0.1, n: 100 };
/// let stats = [st(0.2), st(1.2)]; // B 11° and 69°; grey is at B 45° (0.785 rad)
/// let range = |s: &AngleStats, half_b: f64| SctRange {
///     a: [s.mean_a - 0.1, s.mean_a + 0.1],
///     b: [s.mean_b - half_b, s.mean_b + half_b],
///     min_l: 20.0,
///     min_chroma: 0.05,
/// };
/// // Healthy ranges (B 0–0.4 and 1.0–1.4) are left alone…
/// let before = [range(&stats[0], 0.2), range(&stats[1], 0.2)];
/// let mut r = before;
/// separate_ranges(&mut r, &stats);
/// assert_eq!(r, before);
/// // …but one drifted over grey and the other colour (B 0.1–2.3) starts halfway between
/// // its mean and grey.
/// let mut r = [range(&stats[0], 0.2), range(&stats[1], 1.1)];
/// separate_ranges(&mut r, &stats);
/// assert_eq!(r[0], before[0]);
/// let grey_b = std::f64::consts::FRAC_PI_4;
/// assert!((r[1].b[0] - (1.2 + grey_b) / 2.0).abs() < 1e-12 && (r[1].b[1] - 2.3).abs() < 1e-12);
/// ```
pub fn separate_ranges(r: &mut [SctRange; 2], stats: &[AngleStats; 2]) {
    separate_ranges_about(r, stats, GREY_AB);
}

/// As [`separate_ranges`], with grey seen at SCT angles `grey` (A, B) instead of at
/// r = g = b: under a coloured light a grey surface takes the light's colour, and the
/// cut between a colour and grey belongs halfway to the grey the camera sees (see
/// [`seen_grey`]).
pub fn separate_ranges_about(r: &mut [SctRange; 2], stats: &[AngleStats; 2], grey: (f64, f64)) {
    for (range, s) in r.iter_mut().zip(stats) {
        off_grey(range, s, grey);
    }
    let overlap = |x: [f64; 2], y: [f64; 2]| x[0] < y[1] && y[0] < x[1];
    if !(overlap(r[0].a, r[1].a) && overlap(r[0].b, r[1].b)) {
        return;
    }
    let (da, db) = (stats[1].mean_a - stats[0].mean_a, stats[1].mean_b - stats[0].mean_b);
    let [r0, r1] = r;
    if da.abs() >= db.abs() {
        cut(&mut r0.a, &mut r1.a, stats[0].mean_a, stats[1].mean_a);
    } else {
        cut(&mut r0.b, &mut r1.b, stats[0].mean_b, stats[1].mean_b);
    }
}

/// SCT angles (A, B) of grey, r = g = b: A = atan(√2), B = 45°.
const GREY_AB: (f64, f64) = (0.955_316_618_124_509_3, std::f64::consts::FRAC_PI_4);

/// Cuts `r` at the midpoint between its colour's mean and grey, as if grey were a third
/// colour: a pixel nearer grey than the colour is background. The chroma gate
/// ([`SctRange::min_chroma`]) keeps out pixels within a few degrees of grey, but a grey
/// surface's sensor noise scatters well past it; a colour range widened by adaptation
/// toward grey (a far, thin block whose edge pixels are half body grey) then segments the
/// mother's grey body pixel by pixel next to the block, the block's component grows into
/// it, and the range widens further. We replayed it (bujold-table1 run 45 at 1.9 m,
/// 60° off the axis): cyan's range came to hold half the body's rear face, and the pose
/// read 0.5 m where the robot stood 1.9 m away.
fn off_grey(r: &mut SctRange, s: &AngleStats, grey_ab: (f64, f64)) {
    let (da, db) = (s.mean_a - grey_ab.0, s.mean_b - grey_ab.1);
    let (x, mean, grey) = if da.abs() >= db.abs() {
        (&mut r.a, s.mean_a, grey_ab.0)
    } else {
        (&mut r.b, s.mean_b, grey_ab.1)
    };
    let mid = (mean + grey) / 2.0;
    if mean >= grey {
        x[0] = x[0].max(mid);
    } else {
        x[1] = x[1].min(mid);
    }
}

/// The unit RGB direction of SCT angles (A, B): the inverse of [`Sct::from_rgb`] up to
/// brightness.
fn rgb_of(a: f64, b: f64) -> [f64; 3] {
    let (sa, ca) = a.sin_cos();
    let (sb, cb) = b.sin_cos();
    [sa * cb, sa * sb, ca]
}

/// SCT angles (A, B) of an RGB direction.
fn angles_of(rgb: [f64; 3]) -> (f64, f64) {
    (rgb[0].hypot(rgb[1]).atan2(rgb[2]), rgb[1].atan2(rgb[0]))
}

/// Largest RMS angle error, rad, with which a change of light may explain the imprint:
/// beyond it the imprint is not the table's colours under another light (it took in
/// something else, or the table is a nominal sRGB that no camera sees), and grey stays
/// at r = g = b.
const SEEN_GREY_MAX_RMS: f64 = 0.05;

/// Grey as the camera saw it when it imprinted: the SCT angles of r = g = b under the
/// light that takes the table's colours to the imprinted ones, or `None` when no change
/// of light explains the imprint.
///
/// The table holds the paints as the camera sees them under the light they were
/// measured in; the imprint holds them under the light of the departure. A change of
/// light multiplies each channel by its own gain (von Kries), so the two gain ratios
/// r/g and b/g are fitted by Gauss–Newton to the two colours' four angles, and grey is
/// moved by the same gains. A warm low sun, for one, makes a grey surface warm: the
/// midpoint between a colour and grey, where [`separate_ranges_about`] cuts, then lies toward that
/// warm grey, and a blue block whose sheen takes some of the warm light is still blue.
///
/// # Example
///
/// ```
/// use marsupial::perception::colour_model::seen_grey;
/// use marsupial::perception::{AngleStats, Sct};
///
/// let st = |rgb: [u8; 3]| {
///     let s = Sct::from_rgb(rgb);
///     AngleStats { mean_a: s.a, sd_a: 0.02, mean_b: s.b, sd_b: 0.02, n: 100 }
/// };
/// // Cyan and magenta paints, then the same paints under a light with gains (1.2, 1, 0.8).
/// let table = [st([40, 160, 170]), st([170, 40, 150])];
/// let warm = [st([48, 160, 136]), st([204, 40, 120])];
/// let (a, b) = seen_grey(&table, &warm).unwrap();
/// let truth = Sct::from_rgb([120, 100, 80]);
/// assert!((a - truth.a).abs() < 1e-3 && (b - truth.b).abs() < 1e-3);
/// // The same light: grey is grey.
/// let (a, b) = seen_grey(&table, &table).unwrap();
/// assert!((a - Sct::from_rgb([9, 9, 9]).a).abs() < 1e-9 && (b - std::f64::consts::FRAC_PI_4).abs() < 1e-9);
/// // An imprint of something else entirely is no change of light.
/// assert!(seen_grey(&table, &[st([40, 160, 170]), st([40, 160, 170])]).is_none());
/// ```
pub fn seen_grey(table: &[AngleStats; 2], imprint: &[AngleStats; 2]) -> Option<(f64, f64)> {
    let lit = |p: [f64; 2], s: &AngleStats| {
        let [r, g, b] = rgb_of(s.mean_a, s.mean_b);
        angles_of([r * p[0].exp(), g, b * p[1].exp()])
    };
    let residuals = |p: [f64; 2]| {
        let mut e = [0.0; 4];
        for (k, (t, i)) in table.iter().zip(imprint).enumerate() {
            let (a, b) = lit(p, t);
            e[2 * k] = a - i.mean_a;
            e[2 * k + 1] = b - i.mean_b;
        }
        e
    };
    let mut p = [0.0f64; 2];
    for _ in 0..20 {
        let e = residuals(p);
        // Numerical Jacobian, 4 × 2; normal equations JᵀJ δ = −Jᵀe.
        let h = 1e-6;
        let cols = [0, 1].map(|j| {
            let mut q = p;
            q[j] += h;
            let f = residuals(q);
            [0, 1, 2, 3].map(|k| (f[k] - e[k]) / h)
        });
        let dot = |x: &[f64; 4], y: &[f64; 4]| x.iter().zip(y).map(|(a, b)| a * b).sum::<f64>();
        let (m00, m01, m11) = (
            dot(&cols[0], &cols[0]),
            dot(&cols[0], &cols[1]),
            dot(&cols[1], &cols[1]),
        );
        let (g0, g1) = (dot(&cols[0], &e), dot(&cols[1], &e));
        let det = m00 * m11 - m01 * m01;
        if !det.is_finite() || det.abs() < 1e-12 {
            return None;
        }
        let step = [-(m11 * g0 - m01 * g1) / det, -(m00 * g1 - m01 * g0) / det];
        p = [p[0] + step[0].clamp(-1.0, 1.0), p[1] + step[1].clamp(-1.0, 1.0)];
        if step[0].abs().max(step[1].abs()) < 1e-10 {
            break;
        }
    }
    let e = residuals(p);
    let rms = (e.iter().map(|x| x * x).sum::<f64>() / 4.0).sqrt();
    (rms.is_finite() && rms <= SEEN_GREY_MAX_RMS).then(|| angles_of([p[0].exp(), 1.0, p[1].exp()]))
}

/// Cuts intervals `x` (about mean `mx`) and `y` (about `my`) at the midpoint of the means.
fn cut(x: &mut [f64; 2], y: &mut [f64; 2], mx: f64, my: f64) {
    let mid = (mx + my) / 2.0;
    if mx <= my {
        x[1] = x[1].min(mid);
        y[0] = y[0].max(mid);
    } else {
        x[0] = x[0].max(mid);
        y[1] = y[1].min(mid);
    }
}

/// Collects imprint statistics from well-aligned frames: a block in the middle of each
/// rectangle where the profile says the two coloured blocks appear.
///
/// # Example
///
/// An 8×4 frame, cyan on its left half and magenta on its right; each rectangle is one
/// half, and the middle half of it by side (2 × 2 = 4 px per frame) is sampled. Three
/// frames give the 10 pixels per block that [`Imprinter::finish`] needs.
///
/// ```
/// use marsupial::perception::{Imprinter, RgbImage, Sct};
///
/// let (cyan, magenta) = ([0, 200, 220], [210, 10, 200]);
/// let mut im = RgbImage::new(8, 4);
/// for y in 0..4 {
///     for x in 0..8 {
///         im.put(x, y, if x < 4 { cyan } else { magenta });
///     }
/// }
/// let mut imp = Imprinter::new([[0.0, 0.0, 0.5, 1.0], [0.5, 0.0, 1.0, 1.0]], 0.5, 20.0, 0.05);
/// assert_eq!(imp.sample_rect(0, 8, 4), [1, 1, 3, 3]);
/// for _ in 0..2 {
///     imp.add_frame(&im.view());
/// }
/// assert!(imp.finish().is_none(), "8 px per block so far");
/// imp.add_frame(&im.view());
/// assert_eq!(imp.frames(), 3);
/// let [left, right] = imp.finish().unwrap();
/// assert_eq!((left.n, right.n), (12, 12));
/// assert!((left.mean_b - Sct::from_rgb(cyan).b).abs() < 1e-12 && left.sd_b < 1e-9);
/// assert!((right.mean_a - Sct::from_rgb(magenta).a).abs() < 1e-12);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Imprinter {
    rects: [[f64; 4]; 2],
    sample_frac: f64,
    min_l: f64,
    chroma: ChromaGate,
    acc: [StatsAccumulator; 2],
    frames: u32,
}

impl Imprinter {
    /// `rects` are (x0, y0, x1, y1) as fractions of the image size for the left and right
    /// block; the middle `sample_frac` of each (by side length) is sampled. Pixels darker
    /// than `min_l` or within `min_chroma` (rad) of grey are skipped, as the segmenter
    /// skips them, so a misaligned departure cannot imprint on the mother's grey body.
    pub fn new(rects: [[f64; 4]; 2], sample_frac: f64, min_l: f64, min_chroma: f64) -> Self {
        Self {
            rects,
            sample_frac,
            min_l,
            chroma: ChromaGate::new(min_chroma),
            acc: [StatsAccumulator::default(); 2],
            frames: 0,
        }
    }

    /// Pixel rectangle (x0, y0, x1, y1), end exclusive, sampled for block `i` in a
    /// `w × h` image.
    pub fn sample_rect(&self, i: usize, w: usize, h: usize) -> [usize; 4] {
        let [x0, y0, x1, y1] = self.rects[i.min(1)];
        let (cx, cy) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
        let (hw, hh) = (
            (x1 - x0).abs() * self.sample_frac / 2.0,
            (y1 - y0).abs() * self.sample_frac / 2.0,
        );
        let px = |f: f64, n: usize| ((f * n as f64).round().max(0.0) as usize).min(n);
        let (a, c) = (px(cx - hw, w), px(cx + hw, w));
        let (b, d) = (px(cy - hh, h), px(cy + hh, h));
        [a, b, c.max(a + 1).min(w), d.max(b + 1).min(h)]
    }

    /// Samples one frame.
    pub fn add_frame(&mut self, view: &RgbView<'_>) {
        let (w, h) = (view.width(), view.height());
        if w == 0 || h == 0 {
            return;
        }
        for i in 0..2 {
            let [x0, y0, x1, y1] = self.sample_rect(i, w, h);
            for y in y0..y1 {
                for x in x0..x1 {
                    if let Some(px) = view.get(x, y) {
                        let s = Sct::from_rgb(px);
                        if s.l >= self.min_l && self.chroma.passes_rgb(px) {
                            self.acc[i].push(s.a, s.b);
                        }
                    }
                }
            }
        }
        self.frames += 1;
    }

    /// The fractional rectangle of block `i` (0 left, 1 right).
    pub fn rect(&self, i: usize) -> [f64; 4] {
        self.rects[i.min(1)]
    }

    /// The sampled fraction of each rectangle.
    pub fn sample_frac(&self) -> f64 {
        self.sample_frac
    }

    /// Forgets everything sampled.
    pub fn clear(&mut self) {
        self.acc = [StatsAccumulator::default(); 2];
        self.frames = 0;
    }

    /// Frames sampled so far.
    pub fn frames(&self) -> u32 {
        self.frames
    }

    /// The imprinted statistics, when both blocks gave at least 10 bright pixels.
    pub fn finish(&self) -> Option<[AngleStats; 2]> {
        if self.acc.iter().any(|a| a.count() < 10) {
            return None;
        }
        Some([self.acc[0].finish()?, self.acc[1].finish()?])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params(adaptive: bool) -> ColorModelParams {
        ColorModelParams {
            n_sd: 4.0,
            sd_floor: 0.01,
            sd_ceiling: 0.2,
            min_l: 20.0,
            min_chroma: 0.05,
            timeout1: 2.0,
            timeout2: 5.0,
            adaptive,
            adapt_rate: 1.0,
        }
    }

    fn table() -> [AngleStats; 2] {
        [
            AngleStats::nominal([0, 255, 255], 0.1),
            AngleStats::nominal([255, 0, 255], 0.1),
        ]
    }

    fn stats(a: f64) -> AngleStats {
        AngleStats {
            mean_a: a,
            sd_a: 0.02,
            mean_b: 0.5,
            sd_b: 0.02,
            n: 100,
        }
    }

    #[test]
    fn shifted_sums_match_two_pass() {
        let xs = [0.1, 0.4, 0.35, 0.2, 0.9, 0.05];
        let mut acc = StatsAccumulator::default();
        for (i, x) in xs.iter().enumerate() {
            acc.push(*x, i as f64);
        }
        let s = acc.finish().unwrap();
        let m = xs.iter().sum::<f64>() / 6.0;
        let sd = (xs.iter().map(|x| (x - m).powi(2)).sum::<f64>() / 6.0).sqrt();
        assert!((s.mean_a - m).abs() < 1e-12 && (s.sd_a - sd).abs() < 1e-12);
        assert!((s.mean_b - 2.5).abs() < 1e-12);
        assert!(StatsAccumulator::default().finish().is_none());
    }

    #[test]
    fn range_clamps_sd() {
        let r = AngleStats {
            mean_a: 1.0,
            sd_a: 0.0,
            mean_b: 0.5,
            sd_b: 5.0,
            n: 3,
        }
        .range(&ColorModelParams {
            sd_ceiling: 0.1,
            min_l: 30.0,
            ..params(true)
        });
        assert!((r.a[0] - 0.96).abs() < 1e-12 && (r.a[1] - 1.04).abs() < 1e-12);
        assert!((r.b[0] - 0.1).abs() < 1e-12 && (r.b[1] - 0.9).abs() < 1e-12);
        assert_eq!(r.min_l, 30.0);
        assert_eq!(r.min_chroma, 0.05);
    }

    #[test]
    fn fallback_chain_timing() {
        let mut m = ColorModel::new(table(), params(true));
        assert_eq!(m.mode(), ColorMode::Table);
        m.imprint([stats(0.7), stats(0.8)], 0.0);
        assert_eq!(m.mode(), ColorMode::Imprinted);
        m.update(1.0, Some([stats(0.71), stats(0.79)]));
        assert_eq!(m.mode(), ColorMode::Adapted);
        assert!((m.current()[0].mean_a - 0.71).abs() < 1e-12);
        // Lost at t = 1: still adapted up to t = 3 (timeout 1 = 2 s) …
        m.update(2.9, None);
        assert_eq!(m.mode(), ColorMode::Adapted);
        m.update(3.1, None);
        assert_eq!(m.mode(), ColorMode::Imprinted);
        assert!((m.current()[0].mean_a - 0.7).abs() < 1e-12);
        // … imprinted up to t = 6 (timeout 2 = 5 s after the last detection) …
        m.update(5.9, None);
        assert_eq!(m.mode(), ColorMode::Imprinted);
        m.update(6.1, None);
        assert_eq!(m.mode(), ColorMode::Table);
        // … and a new detection adapts again from the table's segmentation.
        m.update(7.0, Some([stats(0.75), stats(0.85)]));
        assert_eq!(m.mode(), ColorMode::Adapted);
        assert_eq!(m.switches(), 5);
    }

    #[test]
    fn looking_away_pauses_the_timeouts() {
        let mut m = ColorModel::new(table(), params(true));
        m.imprint([stats(0.7), stats(0.8)], 0.0);
        m.update(1.0, Some([stats(0.71), stats(0.79)]));
        m.set_looking(false, 1.5);
        m.update(30.0, None);
        assert_eq!(m.mode(), ColorMode::Adapted, "blind for 29 s: no fallback");
        m.set_looking(true, 30.0);
        m.update(31.9, None);
        assert_eq!(m.mode(), ColorMode::Adapted, "the clock restarted at 30 s");
        m.update(32.1, None);
        assert_eq!(m.mode(), ColorMode::Imprinted);
    }

    #[test]
    fn without_imprint_adapted_falls_back_to_table() {
        let mut m = ColorModel::new(table(), params(true));
        m.update(0.0, Some([stats(0.7), stats(0.8)]));
        assert_eq!(m.mode(), ColorMode::Adapted);
        m.update(2.5, None);
        assert_eq!(m.mode(), ColorMode::Table);
    }

    #[test]
    fn static_mode_never_adapts_or_falls_back() {
        let mut m = ColorModel::new(table(), params(false));
        m.imprint([stats(0.7), stats(0.8)], 0.0);
        m.update(1.0, Some([stats(0.2), stats(0.3)]));
        assert_eq!(m.mode(), ColorMode::Imprinted);
        assert!((m.current()[0].mean_a - 0.7).abs() < 1e-12);
        m.update(100.0, None);
        assert_eq!(m.mode(), ColorMode::Imprinted);
    }

    #[test]
    fn imprinter_samples_the_middle_of_each_block() {
        let mut im = crate::perception::RgbImage::new(40, 20);
        im.fill([20, 20, 20]);
        for y in 5..15 {
            for x in 8..20 {
                im.put(x, y, [0, 200, 220]);
            }
            for x in 20..32 {
                im.put(x, y, [210, 10, 200]);
            }
        }
        // Rectangles a bit larger than the blocks: sampling their middle half stays inside.
        let mut imp = Imprinter::new([[0.15, 0.2, 0.5, 0.8], [0.5, 0.2, 0.85, 0.8]], 0.5, 20.0, 0.05);
        assert!(imp.finish().is_none());
        imp.add_frame(&im.view());
        imp.add_frame(&im.view());
        let s = imp.finish().unwrap();
        let cyan = Sct::from_rgb([0, 200, 220]);
        let magenta = Sct::from_rgb([210, 10, 200]);
        assert!((s[0].mean_a - cyan.a).abs() < 1e-9 && (s[0].mean_b - cyan.b).abs() < 1e-9 && s[0].sd_a < 1e-9);
        assert!((s[1].mean_a - magenta.a).abs() < 1e-9 && (s[1].mean_b - magenta.b).abs() < 1e-9);
        assert_eq!(imp.frames(), 2);
    }

    #[test]
    fn imprinter_skips_grey_pixels() {
        // A misaligned departure looking at the mother's bluish-grey body imprints nothing.
        let mut im = crate::perception::RgbImage::new(40, 20);
        im.fill([87, 90, 93]);
        let rects = [[0.15, 0.2, 0.5, 0.8], [0.5, 0.2, 0.85, 0.8]];
        let mut imp = Imprinter::new(rects, 0.5, 20.0, 5f64.to_radians());
        imp.add_frame(&im.view());
        assert!(imp.finish().is_none());
        let mut open = Imprinter::new(rects, 0.5, 20.0, 0.0);
        open.add_frame(&im.view());
        assert!(open.finish().is_some(), "without the gate the grey is imprinted");
    }

    fn box_at(a: f64, b: f64, half: f64) -> SctRange {
        SctRange {
            a: [a - half, a + half],
            b: [b - half, b + half],
            min_l: 20.0,
            min_chroma: 0.05,
        }
    }

    fn stats_at(a: f64, b: f64) -> AngleStats {
        AngleStats {
            mean_a: a,
            sd_a: 0.02,
            mean_b: b,
            sd_b: 0.02,
            n: 10,
        }
    }

    #[test]
    fn overlapping_colours_are_cut_at_the_midpoint_of_their_means() {
        // Orange and red, both on the warm side of grey (A 78–79°, B 13–28°), drifted to
        // ±15°: cut apart on B (15° apart against 1° on A) at B 20.8°.
        let d = f64::to_radians;
        let stats = [stats_at(d(78.0), d(13.3)), stats_at(d(79.1), d(28.3))];
        let mut r = [box_at(d(78.0), d(13.3), d(15.0)), box_at(d(79.1), d(28.3), d(15.0))];
        separate_ranges(&mut r, &stats);
        let mid = d(20.8);
        assert!((r[0].b[1] - mid).abs() < 1e-12 && (r[1].b[0] - mid).abs() < 1e-12);
        assert_eq!(r[0].b[0], d(13.3) - d(15.0));
        // No pixel is both colours.
        for b in 0..900 {
            let b = d(f64::from(b) / 10.0);
            assert!(!(r[0].b[0] <= b && b <= r[0].b[1] && r[1].b[0] < b && b <= r[1].b[1]));
        }
    }

    #[test]
    fn no_range_reaches_halfway_to_grey() {
        let d = f64::to_radians;
        // Blue (A 22.5°, B 55°) is farther from grey (A 54.7°) on A: cut at A 38.6°.
        let stats = [stats_at(d(22.5), d(55.1)), stats_at(d(80.5), d(45.0))];
        let mut r = [box_at(d(22.5), d(55.1), d(30.0)), box_at(d(80.5), d(45.0), d(30.0))];
        separate_ranges(&mut r, &stats);
        let grey_a = 2f64.sqrt().atan();
        assert!((r[0].a[1] - (d(22.5) + grey_a) / 2.0).abs() < 1e-12);
        // Yellow (A 80.5°) from the other side.
        assert!((r[1].a[0] - (d(80.5) + grey_a) / 2.0).abs() < 1e-12);
        assert!(!r[0].contains([128, 128, 128]) && !r[1].contains([128, 128, 128]));
    }

    #[test]
    fn the_table_fallback_cuts_halfway_to_the_grey_the_imprint_saw() {
        // Blue and red paints under a light with gains (1.25, 1, 0.73), a warm low sun:
        // the imprint sees them moved toward warm, and so is grey.
        let st = |rgb: [f64; 3]| {
            let (a, b) = angles_of(rgb);
            AngleStats {
                mean_a: a,
                sd_a: 0.1,
                mean_b: b,
                sd_b: 0.1,
                n: 100,
            }
        };
        let gains = [1.25, 1.0, 0.73];
        let warm = |c: [f64; 3]| [c[0] * gains[0], c[1] * gains[1], c[2] * gains[2]];
        let (blue, red) = ([0.25, 0.35, 0.9], [0.9, 0.2, 0.15]);
        let table = [st(blue), st(red)];
        let mut m = ColorModel::new(table, params(true));
        m.imprint([st(warm(blue)), st(warm(red))], 0.0);
        let grey = seen_grey(&table, m.imprinted().unwrap()).unwrap();
        let truth = angles_of(gains);
        assert!((grey.0 - truth.0).abs() < 1e-6 && (grey.1 - truth.1).abs() < 1e-6);
        // Imprinted and adapted ranges keep the cut at r = g = b ...
        let imprinted = m.ranges()[0];
        m.update(6.0, None);
        assert_eq!(m.mode(), ColorMode::Table);
        // ... the table's blue, farther from grey on A, is cut halfway to the warm grey.
        let r = m.ranges();
        assert!((r[0].a[1] - (table[0].mean_a + truth.0) / 2.0).abs() < 1e-9);
        assert!(
            r[0].a[1] > (table[0].mean_a + GREY_AB.0) / 2.0,
            "warm grey lies past r = g = b"
        );
        assert!(imprinted.a[1] <= (m.imprinted().unwrap()[0].mean_a + GREY_AB.0) / 2.0 + 1e-12);
        // A warm grey surface is still outside both ranges.
        let warm_grey = [(128.0 * gains[0]) as u8, 128, (128.0 * gains[2]) as u8];
        assert!(!r[0].contains(warm_grey) && !r[1].contains(warm_grey));
    }
}
