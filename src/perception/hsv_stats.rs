//! HSV colour statistics for imprinting and adaptation of RAPOSA's bands (the paper's
//! future work, seed 001 §IV: "use the imprint/adapt method of seed 004 instead of an
//! operator retuning the HSV volumes").
//!
//! Each colour is summarised by the mean and SD of hue (a circular quantity: samples are
//! unwrapped around the first one, which is exact while the colour spans under 180°), of
//! saturation and of value. A band is built from them as
//!
//! * hue: mean ± n·SD, wrapping through red;
//! * saturation and value: **one-sided**, [mean − n·SD, 1]. Brightness changes with every
//!   cloud and a brighter or purer pixel is never less like the target, so only the lower
//!   bound carries information (the table bands are one-sided too: `s = [0.45, 1]`). The
//!   value bound also admits at least half the mean value, since a cloud can halve the
//!   brightness faster than auto-exposure restores it.
//!
//! SDs are clamped to [floor, ceiling] per axis (a flat patch must not collapse its band,
//! a noisy one must not swallow grey), and the lower S and V bounds never drop below hard
//! minima that keep greys and black out whatever the statistics say.

use super::colour_model::Blend;
use super::hsv::Hsv;
use super::segment::HsvRange;
use serde::Serialize;

/// Mean and SD of one colour in HSV.
///
/// # Example
///
/// A learned blue becomes a band: hue 220° ± 4·2°, saturation from 0.8 − 4·0.05 up, and
/// value from the lower of 0.6 − 4·0.05 and half the mean value (0.3) up.
///
/// ```
/// use marsupial::perception::{Blend, HsvLimits, HsvRange, HsvStats};
///
/// let limits = HsvLimits { n_sd: 4.0, hue_sd_deg: [1.0, 20.0], sv_sd: [0.01, 0.1], min_s: 0.2, min_v: 0.05 };
/// let blue = HsvStats { mean_h_deg: 220.0, sd_h_deg: 2.0, mean_s: 0.8, sd_s: 0.05, mean_v: 0.6, sd_v: 0.05, n: 100 };
/// let band = blue.band(&limits);
/// assert_eq!(band.h, [212.0, 228.0]);
/// assert!((band.s[0] - 0.6).abs() < 1e-6 && band.s[1] == 1.0);
/// assert!((band.v[0] - 0.3).abs() < 1e-6 && band.v[1] == 1.0);
/// assert!(band.contains([30, 80, 150])); // H = 215°, S = 0.8, V = 0.59
/// assert!(!band.contains([30, 150, 150]), "cyan, H = 180°");
///
/// // The operator's red band through 0° as statistics: centre 0°, SD 20°/4.
/// let red = HsvRange { h: [340.0, 20.0], s: [0.5, 1.0], v: [0.2, 1.0] };
/// let r = HsvStats::from_band(&red, 4.0);
/// assert!(r.mean_h_deg.abs() < 1e-9 && (r.sd_h_deg - 5.0).abs() < 1e-9);
///
/// // Blending moves hue along the shorter arc: halfway from 350° to 10° is 0°, not 180°.
/// let a = HsvStats { mean_h_deg: 350.0, ..r };
/// let b = HsvStats { mean_h_deg: 10.0, ..r };
/// let m = a.blend(&b, 0.5).mean_h_deg;
/// assert!(m.min(360.0 - m) < 1e-9, "{m}");
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct HsvStats {
    /// Circular mean hue, degrees in [0, 360).
    pub mean_h_deg: f64,
    /// Hue SD, degrees.
    pub sd_h_deg: f64,
    /// Mean saturation.
    pub mean_s: f64,
    /// Saturation SD.
    pub sd_s: f64,
    /// Mean value.
    pub mean_v: f64,
    /// Value SD.
    pub sd_v: f64,
    /// Pixels the statistics came from (0 for a band turned into statistics).
    pub n: u64,
}

/// Limits on bands built from [`HsvStats`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HsvLimits {
    /// Band half-width in SDs.
    pub n_sd: f64,
    /// [floor, ceiling] of the hue SD, degrees.
    pub hue_sd_deg: [f64; 2],
    /// [floor, ceiling] of the saturation and value SDs.
    pub sv_sd: [f64; 2],
    /// The lower saturation bound never goes below this (keeps greys out).
    pub min_s: f64,
    /// The lower value bound never goes below this (keeps black out).
    pub min_v: f64,
}

/// A learned band admits value down to this fraction of its mean, whatever the SD.
const V_DROP: f64 = 0.5;

/// `h` wrapped into [0, 360).
pub(crate) fn wrap_deg(h: f64) -> f64 {
    let w = h.rem_euclid(360.0);
    if w >= 360.0 { 0.0 } else { w }
}

/// The hue band centred on `mean` (degrees) with half-width `half`, wrapping through red;
/// the whole circle once the half-width reaches 180°.
pub(crate) fn hue_band(mean: f64, half: f64) -> [f32; 2] {
    let h = if half >= 180.0 {
        [0.0, 360.0]
    } else {
        [wrap_deg(mean - half), wrap_deg(mean + half)]
    };
    h.map(|x| x as f32)
}

/// Signed shortest hue difference `to − from`, degrees in [−180, 180).
fn hue_diff(from: f64, to: f64) -> f64 {
    (to - from + 180.0).rem_euclid(360.0) - 180.0
}

impl HsvStats {
    /// Statistics whose band (under `n_sd`, one-sided S and V) is `band`: the hue centre
    /// and half-width / n_sd, and S and V lower bounds at mean − n_sd·SD. Used to start
    /// the fallback chain from the operator's table bands.
    pub fn from_band(band: &HsvRange, n_sd: f64) -> HsvStats {
        let [h0, h1] = band.h.map(f64::from);
        let width = if h0 <= h1 { h1 - h0 } else { h1 + 360.0 - h0 };
        let side = |r: [f32; 2]| {
            let (lo, hi) = (f64::from(r[0]), f64::from(r[1]));
            ((lo + hi) / 2.0, (hi - lo) / 2.0 / n_sd)
        };
        let (mean_s, sd_s) = side(band.s);
        let (mean_v, sd_v) = side(band.v);
        HsvStats {
            mean_h_deg: wrap_deg(h0 + width / 2.0),
            sd_h_deg: width / 2.0 / n_sd,
            mean_s,
            sd_s,
            mean_v,
            sd_v,
            n: 0,
        }
    }

    /// The segmentation band under `limits`.
    pub fn band(&self, limits: &HsvLimits) -> HsvRange {
        let n = limits.n_sd;
        let half_h = self.sd_h_deg.clamp(limits.hue_sd_deg[0], limits.hue_sd_deg[1]) * n;
        let lower = |mean: f64, sd: f64| mean - sd.clamp(limits.sv_sd[0], limits.sv_sd[1]) * n;
        // Brightness follows the light, not the paint: a passing cloud can halve it
        // faster than auto-exposure recovers, so V admits at least half its mean.
        let v_lo = lower(self.mean_v, self.sd_v).min(self.mean_v * V_DROP);
        HsvRange {
            h: hue_band(self.mean_h_deg, half_h),
            s: [lower(self.mean_s, self.sd_s).clamp(limits.min_s, 1.0) as f32, 1.0],
            v: [v_lo.clamp(limits.min_v, 1.0) as f32, 1.0],
        }
    }
}

impl Blend for HsvStats {
    /// Hue moves along the shorter arc; the rest linearly.
    fn blend(&self, new: &HsvStats, beta: f64) -> HsvStats {
        let mix = |a: f64, b: f64| a + beta * (b - a);
        HsvStats {
            mean_h_deg: wrap_deg(self.mean_h_deg + beta * hue_diff(self.mean_h_deg, new.mean_h_deg)),
            sd_h_deg: mix(self.sd_h_deg, new.sd_h_deg),
            mean_s: mix(self.mean_s, new.mean_s),
            sd_s: mix(self.sd_s, new.sd_s),
            mean_v: mix(self.mean_v, new.mean_v),
            sd_v: mix(self.sd_v, new.sd_v),
            n: new.n,
        }
    }
}

/// Streaming HSV statistics by shifted sums (samples relative to the first one; hue
/// unwrapped to within ±180° of it).
///
/// # Example
///
/// Two reds on either side of 0°: the circular mean is 0° and the SD 10°.
///
/// ```
/// use marsupial::perception::{Hsv, HsvAccumulator};
///
/// let mut acc = HsvAccumulator::default();
/// acc.push(&Hsv { h: 350.0, s: 0.5, v: 0.8 });
/// acc.push(&Hsv { h: 10.0, s: 0.7, v: 0.8 });
/// let s = acc.finish().unwrap();
/// assert_eq!(s.n, 2);
/// assert!(s.mean_h_deg.min(360.0 - s.mean_h_deg) < 1e-9);
/// assert!((s.sd_h_deg - 10.0).abs() < 1e-9);
/// assert!((s.mean_s - 0.6).abs() < 1e-6 && (s.sd_s - 0.1).abs() < 1e-6 && s.sd_v == 0.0);
/// acc.clear();
/// assert_eq!(acc.count(), 0);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct HsvAccumulator {
    n: u64,
    reference: [f64; 3],
    sum: [f64; 3],
    sum_sq: [f64; 3],
}

impl HsvAccumulator {
    /// Adds one pixel.
    #[inline]
    pub fn push(&mut self, p: &Hsv) {
        let x = [f64::from(p.h), f64::from(p.s), f64::from(p.v)];
        if self.n == 0 {
            self.reference = x;
        }
        self.n += 1;
        let d = [
            hue_diff(self.reference[0], x[0]),
            x[1] - self.reference[1],
            x[2] - self.reference[2],
        ];
        for ((sum, sq), d) in self.sum.iter_mut().zip(&mut self.sum_sq).zip(d) {
            *sum += d;
            *sq += d * d;
        }
    }

    /// Pixels so far.
    pub fn count(&self) -> u64 {
        self.n
    }

    /// Forgets every sample.
    pub fn clear(&mut self) {
        *self = Self::default();
    }

    /// The statistics (population SD), or `None` with fewer than 2 samples.
    pub fn finish(&self) -> Option<HsvStats> {
        if self.n < 2 {
            return None;
        }
        let n = self.n as f64;
        let mean = |k: usize| self.sum[k] / n;
        let sd = |k: usize| ((self.sum_sq[k] - self.sum[k] * self.sum[k] / n) / n).max(0.0).sqrt();
        Some(HsvStats {
            mean_h_deg: wrap_deg(self.reference[0] + mean(0)),
            sd_h_deg: sd(0),
            mean_s: self.reference[1] + mean(1),
            sd_s: sd(1),
            mean_v: self.reference[2] + mean(2),
            sd_v: sd(2),
            n: self.n,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limits() -> HsvLimits {
        HsvLimits {
            n_sd: 4.0,
            hue_sd_deg: [1.0, 20.0],
            sv_sd: [0.01, 0.1],
            min_s: 0.2,
            min_v: 0.05,
        }
    }

    fn hsv(h: f32, s: f32, v: f32) -> Hsv {
        Hsv { h, s, v }
    }

    #[test]
    fn accumulator_matches_two_pass_across_red() {
        // Hues straddling 0°: the circular mean is 0°, not 180°.
        let hs = [350.0f32, 355.0, 0.0, 5.0, 10.0];
        let mut acc = HsvAccumulator::default();
        for (i, &h) in hs.iter().enumerate() {
            acc.push(&hsv(h, 0.5 + 0.1 * i as f32, 0.8));
        }
        let s = acc.finish().unwrap();
        assert!(s.mean_h_deg.min(360.0 - s.mean_h_deg) < 1e-9, "{}", s.mean_h_deg);
        let unwrapped = [-10.0, -5.0, 0.0, 5.0, 10.0f64];
        let sd = (unwrapped.iter().map(|x| x * x).sum::<f64>() / 5.0).sqrt();
        assert!((s.sd_h_deg - sd).abs() < 1e-9);
        assert!((s.mean_s - 0.7).abs() < 1e-6 && (s.mean_v - 0.8).abs() < 1e-6 && s.sd_v < 1e-6);
        assert!(HsvAccumulator::default().finish().is_none());
    }

    #[test]
    fn band_round_trips_through_statistics() {
        let band = HsvRange {
            h: [8.0, 45.0],
            s: [0.45, 1.0],
            v: [0.25, 1.0],
        };
        let wide = HsvLimits {
            hue_sd_deg: [0.0, 90.0],
            sv_sd: [0.0, 1.0],
            min_s: 0.0,
            min_v: 0.0,
            ..limits()
        };
        let b = HsvStats::from_band(&band, 4.0).band(&wide);
        for k in 0..2 {
            assert!((b.h[k] - band.h[k]).abs() < 1e-4 && (b.s[k] - band.s[k]).abs() < 1e-6);
            assert!((b.v[k] - band.v[k]).abs() < 1e-6);
        }
        // A band through red survives too.
        let red = HsvRange {
            h: [340.0, 20.0],
            ..band
        };
        let r = HsvStats::from_band(&red, 4.0);
        assert!(r.mean_h_deg.abs() < 1e-9 && (r.sd_h_deg - 5.0).abs() < 1e-9);
        let rb = r.band(&wide);
        assert!((rb.h[0] - 340.0).abs() < 1e-4 && (rb.h[1] - 20.0).abs() < 1e-4);
    }

    #[test]
    fn band_clamps_and_keeps_greys_out() {
        let flat = HsvStats {
            mean_h_deg: 220.0,
            sd_h_deg: 0.0,
            mean_s: 0.3,
            sd_s: 0.5,
            mean_v: 0.5,
            sd_v: 0.0,
            n: 50,
        };
        let b = flat.band(&limits());
        assert_eq!(b.h, [216.0, 224.0], "hue SD floored at 1°");
        assert_eq!(b.s, [0.2, 1.0], "S bound never below min_s");
        assert!((b.v[0] - 0.25).abs() < 1e-6, "V admits half its mean: {}", b.v[0]);
        let bright = HsvStats {
            mean_v: 0.9,
            sd_v: 0.2,
            ..flat
        };
        assert!((bright.band(&limits()).v[0] - 0.45).abs() < 1e-6, "V SD capped at 0.1");
        let noisy = HsvStats {
            sd_h_deg: 200.0,
            ..flat
        };
        assert_eq!(noisy.band(&limits()).h, [140.0, 300.0], "hue SD capped at 20°");
        let all = HsvLimits {
            hue_sd_deg: [1.0, 60.0],
            ..limits()
        };
        assert_eq!(noisy.band(&all).h, [0.0, 360.0]);
    }

    #[test]
    fn blend_moves_hue_along_the_short_arc() {
        let a = HsvStats {
            mean_h_deg: 350.0,
            sd_h_deg: 4.0,
            mean_s: 0.6,
            sd_s: 0.05,
            mean_v: 0.5,
            sd_v: 0.05,
            n: 10,
        };
        let b = HsvStats {
            mean_h_deg: 10.0,
            sd_h_deg: 8.0,
            mean_s: 0.8,
            ..a
        };
        let m = a.blend(&b, 0.5);
        assert!(m.mean_h_deg.abs() < 1e-9 || (m.mean_h_deg - 360.0).abs() < 1e-9);
        assert!((m.sd_h_deg - 6.0).abs() < 1e-12 && (m.mean_s - 0.7).abs() < 1e-12);
        assert_eq!(a.blend(&b, 1.0), b);
    }
}
