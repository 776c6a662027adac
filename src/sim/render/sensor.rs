//! The camera sensor: white balance, exposure, shot and read noise, clipping and sRGB
//! gamma, from linear scene radiance to 8-bit RGB.
//!
//! The noise is physical, in electrons. A pixel at output level L (linear, 1 = full scale)
//! collected e = L·FW/g electrons, where FW is the full well at unity gain and g the
//! analogue gain; its noise is the shot noise √e and the read noise r added in quadrature,
//! √(e + r²) electrons, which the gain carries to the output as √(e + r²)·g/FW. Exposure is
//! integration time first: auto-exposure lengthens it up to `max_integration` (relative to
//! the exposure that puts a unit radiance at full scale) and then raises the gain, so a dim
//! scene brightened to the same output is noisier than a bright one, as on a real camera.
//!
//! White balance is the camera's own estimate by default: grey-world over the near-neutral
//! pixels, as a camera's auto white balance gathers its statistics. Each channel's mean
//! over the pixels that are neither dark, clipped, nor strongly coloured (more than a
//! factor of two from grey in red/green or blue/green under the balance in force) is made
//! equal to green's. A coloured illuminant, or a view filled by one colour, still fools it,
//! as it fools a real camera; a small saturated object (a beacon, a fiducial) does not. A
//! scenario can instead balance for a named illuminant (`Fixed`), including each run's
//! true one (the perfect balance of earlier versions).
//!
//! Auto-exposure moves halfway toward what this frame needs each frame, in log terms, so a
//! sudden light change over- or under-exposes the next few frames. The white balance
//! follows its estimate with a time constant in seconds (a camera's AWB settles over a
//! second or two, far slower than its exposure), so a flashing beacon does not swing it
//! frame by frame. Noise comes from a per-row offset into a seeded table of normal
//! deviates, scaled per output level.

use crate::perception::RgbImage;
use crate::sim::rng::{NoiseTable, splitmix64};
use crate::sim::scene::srgb_to_linear;

/// How the camera balances white.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum WhiteBalance {
    /// Per-channel multipliers fixed in advance (`[1, 1, 1]` is none).
    Fixed([f32; 3]),
    /// Estimated by grey-world over the near-neutral pixels, followed with a time
    /// constant (module docs).
    GreyWorld,
}

/// Sensor settings (from the scenario).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorParams {
    /// Full well at unity gain: electrons that bring a pixel to full scale.
    pub full_well_e: f32,
    /// Read noise SD, electrons.
    pub read_noise_e: f32,
    /// Fixed exposure multiplier when auto-exposure is off.
    pub exposure: f32,
    /// Follow the scene brightness.
    pub auto_exposure: bool,
    /// Mean linear level auto-exposure aims for (0–1).
    pub target_level: f32,
    /// Base analogue gain.
    pub gain: f32,
    /// The longest integration, as an exposure multiplier: beyond it auto-exposure (or a
    /// fixed exposure) raises the analogue gain instead, and the noise with it.
    pub max_integration: f32,
    /// White balance.
    pub white_balance: WhiteBalance,
    /// Highlight protection of auto-exposure: the largest fraction of pixels allowed to
    /// clip in any channel (1 = plain mean metering, which burns out a bright target in
    /// front of a dark body).
    pub highlight_clip: f32,
    /// Time constant of the auto white balance, s: it moves 1 − e^(−Δt/τ) of the way (in
    /// log terms) toward each frame's estimate.
    pub white_balance_tau_s: f32,
    /// Time between frames, s (the simulator renders every camera every loop tick, so it
    /// sets this from the profile's loop rate).
    pub frame_interval_s: f32,
    /// Blur each frame by the camera's own motion during its exposure time
    /// ([`SensorParams::exposure_time_s`]), which auto-exposure lengthens in dim light.
    pub motion_blur: bool,
    /// Rolling shutter: time from the first row's exposure to the last's, s (0: a global
    /// shutter, every row at once).
    pub rolling_shutter_readout_s: f32,
    /// Vignetting: the light a corner pixel receives relative to the centre, (0, 1]
    /// (1: none), with the cos⁴ law's shape in between; it darkens the radiance before
    /// auto-exposure meters it and before the noise, as on a real sensor.
    pub vignetting_corner: f32,
    /// A thin lens's defocus (`None`: a pin-hole, sharp at every depth).
    pub defocus: Option<Defocus>,
    /// JPEG quality of the camera's stream, 1–100 (IJG scaling); 0 delivers the raw frame.
    pub jpeg_quality: u8,
}

/// A lens focused at one distance: what makes a near target blurred.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Defocus {
    /// Distance the lens is focused at, m.
    pub focus_m: f32,
    /// f-number N (focal length over aperture diameter).
    pub f_number: f32,
    /// Physical focal length, mm (with N it gives the aperture diameter; the image scale
    /// in pixels comes from the camera model).
    pub focal_length_mm: f32,
}

impl Default for SensorParams {
    /// A small, cheap colour sensor: 2,100 e⁻ full well and 12 e⁻ read noise, which at
    /// unity gain give 1.5 linear 8-bit units of read noise and 0.35·√signal of shot noise
    /// (the model's earlier defaults, now added in quadrature), grey-world white balance
    /// settling with a 1 s time constant, 10 frames a second. The lens and shutter
    /// imperfections (motion blur, rolling shutter, vignetting, defocus, JPEG) are off, so
    /// a scenario that does not ask for them renders as before.
    fn default() -> Self {
        Self {
            full_well_e: 2100.0,
            read_noise_e: 12.0,
            exposure: 1.0,
            auto_exposure: true,
            target_level: 0.18,
            gain: 1.0,
            max_integration: 4.0,
            white_balance: WhiteBalance::GreyWorld,
            highlight_clip: 0.01,
            white_balance_tau_s: 1.0,
            frame_interval_s: 0.1,
            motion_blur: false,
            rolling_shutter_readout_s: 0.0,
            vignetting_corner: 1.0,
            defocus: None,
            jpeg_quality: 0,
        }
    }
}

impl SensorParams {
    /// The analogue gain an exposure multiplier `k` needs: 1 × the base gain while the
    /// integration time can supply it, more beyond.
    pub fn analogue_gain(&self, k: f32) -> f32 {
        self.gain.max(1e-6) * (k / self.max_integration.max(1e-6)).max(1.0)
    }

    /// Exposure (integration) time, s, of a frame taken at exposure multiplier `k`: the
    /// integration at `max_integration` fills the frame interval, shorter exposures take
    /// their share of it, and beyond `max_integration` the gain rises instead, so
    /// T = min(k, max_integration) / max_integration × `frame_interval_s`.
    pub fn exposure_time_s(&self, k: f32) -> f32 {
        let m = self.max_integration.max(1e-6);
        k.clamp(0.0, m) / m * self.frame_interval_s.max(0.0)
    }

    /// Noise SD in linear 8-bit units (0–255) of a pixel at output linear level `lin`
    /// (0–1) under analogue gain `g`: √(e + r²)·g/FW with e = lin·FW/g (module docs).
    /// An infinite full well means no shot noise (and, with no read noise, a noiseless
    /// sensor, [`SensorParams::noiseless`]).
    pub fn noise_sd_lin255(&self, lin: f32, g: f32) -> f32 {
        let fw = self.full_well_e.max(1e-6);
        // In output units: shot variance e·(g/FW)² = lin·g/FW, read variance (r·g/FW)².
        let read = self.read_noise_e * g / fw;
        (lin.max(0.0) * g / fw + read * read).sqrt() * 255.0
    }

    /// A sensor without noise, auto-exposure or white balance (exposure 1): renders whose
    /// pixel values a test reads.
    pub fn noiseless() -> Self {
        Self {
            full_well_e: f32::INFINITY,
            read_noise_e: 0.0,
            auto_exposure: false,
            exposure: 1.0,
            white_balance: WhiteBalance::Fixed([1.0; 3]),
            ..Self::default()
        }
    }
}

/// Bins of the highlight histogram: sixteen per octave, from 2⁻¹² to 2⁴ of full scale.
const HIGHLIGHT_BINS: usize = 256;

/// Highlight-histogram bin of a linear level `v` > 0: the float's exponent and top four
/// mantissa bits (sixteen equal steps per octave, none wider than 6.25 %), offset so 2⁻¹²
/// is bin 0. No `log2` call: it runs on every sampled pixel.
#[inline]
fn octave_bin(v: f32) -> usize {
    let code = (v.max(1e-30).to_bits() >> 19) as i64 - ((127 - 12) << 4);
    code.clamp(0, HIGHLIGHT_BINS as i64 - 1) as usize
}

/// The upper edge (linear level) of highlight bin `b`.
fn octave_bin_top(b: usize) -> f32 {
    f32::from_bits((((b as u32) + 1 + ((127 - 12) << 4)) << 19).min(0x7f7f_ffff))
}

/// Entries of the linear → sRGB table (a power of two, so an index is masked, not checked).
const LUT_LEN: usize = 1 << 12;
const LUT_MAX: f32 = (LUT_LEN - 1) as f32;

/// ⌊x⌋ for x in [0, 2²²), by the float-rounding trick: adding 1.5·2²³ leaves the integer
/// part in the low mantissa bits. Unlike `as i32`, which must saturate and map NaN, it
/// compiles to plain vector adds, so the pass that scales a row into table indices
/// vectorises. (An exact integer x may round down to x − 1: one table step, 1/4095 of full
/// scale.)
#[inline(always)]
fn floor_index(x: f32) -> i32 {
    const MAGIC: f32 = 12_582_912.0; // 1.5 · 2²³
    (x - 0.5 + MAGIC).to_bits().wrapping_sub(MAGIC.to_bits()) as i32
}

/// Fixed-point scale of the noise SD table: sixteenths of an output level, so an SD of
/// 1.4 levels is not rounded to 1.
const SD_ONE: i32 = 16;

/// The sensor's state across frames: exposure, and the tables it reuses.
#[derive(Debug, Clone)]
pub(super) struct Sensor {
    noise: NoiseTable,
    /// Linear level (× `LUT_MAX`) → sRGB byte.
    to_srgb: Box<[u8; LUT_LEN]>,
    /// Linear level (0–1) of each output byte.
    level_lin: [f32; 256],
    /// Output levels per 8-bit linear unit at each output byte: the sRGB curve's slope.
    level_slope: [f32; 256],
    /// This frame's linear level (× `LUT_MAX`) → output byte | its noise SD << 8: one
    /// lookup per channel instead of two dependent ones.
    level_and_sd: Box<[i32; LUT_LEN]>,
    /// White-balance × exposure gain per value of a row (r, g, b, r, g, b, …).
    row_gain: Vec<f32>,
    /// Per value of a row: its table index, then its table entry.
    row_code: Vec<i32>,
    exposure: f32,
    /// Grey-world white balance in force (multipliers, green = 1); `None` before the first
    /// frame.
    balance: Option<[f32; 3]>,
    /// Histogram of sampled pixels' brightest channel, by [`octave_bin`].
    highlights: [u32; HIGHLIGHT_BINS],
}

impl Sensor {
    /// A sensor whose noise table is seeded by `noise_seed`.
    pub fn new(noise_seed: u64) -> Self {
        let mut to_srgb = Box::new([0u8; LUT_LEN]);
        for (i, o) in to_srgb.iter_mut().enumerate() {
            let l = i as f32 / LUT_MAX;
            let s = if l <= 0.003_130_8 {
                12.92 * l
            } else {
                1.055 * l.powf(1.0 / 2.4) - 0.055
            };
            *o = (s * 255.0 + 0.5).clamp(0.0, 255.0) as u8;
        }
        let mut level_lin = [0.0; 256];
        let mut level_slope = [0.0; 256];
        for level in 0..256 {
            let s = level as f32 / 255.0;
            let lin = srgb_to_linear(s);
            let lin2 = srgb_to_linear((s + 1.0 / 255.0).min(1.0));
            level_lin[level] = lin;
            // One output level spans (lin2 − lin)·255 linear 8-bit units.
            level_slope[level] = if lin2 > lin { 1.0 / ((lin2 - lin) * 255.0) } else { 1.0 };
        }
        Self {
            noise: NoiseTable::new(noise_seed),
            to_srgb,
            level_lin,
            level_slope,
            level_and_sd: Box::new([0; LUT_LEN]),
            row_gain: Vec::new(),
            row_code: Vec::new(),
            exposure: 1.0,
            balance: None,
            highlights: [0; HIGHLIGHT_BINS],
        }
    }

    /// Current exposure multiplier.
    pub fn exposure(&self) -> f32 {
        self.exposure
    }

    /// Exposes `radiance` (linear, row-major, `width` wide) into `out`; `frame_seed` picks
    /// this frame's noise. Leaves `radiance` zeroed for the next frame: each row is cleared
    /// as soon as it is read, while it is in cache.
    #[allow(
        clippy::manual_clamp,
        reason = "max/min send NaN to 0 and vectorise; clamp keeps NaN"
    )]
    pub fn expose(
        &mut self,
        radiance: &mut [[f32; 3]],
        width: usize,
        params: &SensorParams,
        frame_seed: u64,
        out: &mut RgbImage,
    ) {
        let height = radiance.len() / width.max(1);
        out.resize(width, height);
        let balance = match params.white_balance {
            WhiteBalance::Fixed(m) => m,
            WhiteBalance::GreyWorld => self.grey_world(radiance, params),
        };
        if params.auto_exposure {
            self.meter(radiance, params, balance);
        } else {
            self.exposure = params.exposure;
        }
        let k = self.exposure * params.gain;
        let g = params.analogue_gain(self.exposure);
        let wb = [0, 1, 2].map(|c| balance[c] * k * LUT_MAX);
        // This frame's noise SD per output byte, in output levels × [`SD_ONE`]: the
        // electrons' noise at that level under this frame's gain, through the slope of the
        // sRGB curve there.
        let mut sd_out = [0i32; 256];
        for ((sd, lin), slope) in sd_out.iter_mut().zip(&self.level_lin).zip(&self.level_slope) {
            let sd_lin = params.noise_sd_lin255(*lin, g);
            // An SD past the whole output range means nothing more; the cap also bounds
            // the fixed-point products below whatever noise a scenario asks for.
            *sd = (sd_lin * slope.min(8.0) * SD_ONE as f32)
                .round()
                .clamp(0.0, 255.0 * SD_ONE as f32) as i32;
        }
        for (e, &g) in self.level_and_sd.iter_mut().zip(self.to_srgb.iter()) {
            *e = g as i32 | (sd_out[g as usize] << 8);
        }
        let lut = &*self.level_and_sd;
        let row_len = width * 3;
        // The white balance repeated along a row, so the scaling pass is one flat loop.
        self.row_gain.clear();
        self.row_gain.extend((0..row_len).map(|i| wb[i % 3]));
        self.row_code.resize(row_len, 0);
        let (gain, code) = (&self.row_gain[..row_len], &mut self.row_code[..row_len]);
        for (y, (rad_row, out_row)) in radiance
            .chunks_exact_mut(width)
            .zip(out.as_bytes_mut().chunks_exact_mut(row_len))
            .enumerate()
        {
            // Three passes per row; the first and last vectorise, the middle one is the
            // table lookup. Scale into table indices (max/min also send NaN to 0):
            for ((c, &r), &g) in code.iter_mut().zip(rad_row.as_flattened()).zip(gain) {
                *c = floor_index((r * g).max(0.0).min(LUT_MAX));
            }
            rad_row.as_flattened_mut().fill(0.0);
            // look up the output byte and its noise SD,
            for c in code.iter_mut() {
                *c = lut[*c as usize & (LUT_LEN - 1)];
            }
            // and add noise. Each row reads the noise table sequentially from a random
            // start: cache friendly, and no visible repetition between rows or frames.
            let start = splitmix64(frame_seed ^ ((y as u64) << 32)) as usize;
            let noise = self.noise.window(start, row_len);
            for ((o, &e), &n) in out_row.iter_mut().zip(code.iter()).zip(noise) {
                // Noise values are N(0, 1) × 256 and SDs × 16: the product is in levels
                // × 4096, rounded to the nearest level (a bare shift would floor, darkening
                // every noisy pixel by half a level on average).
                let v = (e & 0xFF) + ((n as i32 * (e >> 8) + 2048) >> 12);
                *o = v.clamp(0, 255) as u8;
            }
        }
    }

    /// Auto-exposure: the mean green level, subsampled, and a histogram of each sample's
    /// brightest white-balanced channel. The exposure aims the mean at the target unless
    /// that would clip more than `highlight_clip` of the pixels, then it protects the
    /// highlights. It adapts partly toward the aim each frame (camera lag).
    fn meter(&mut self, radiance: &[[f32; 3]], params: &SensorParams, wbn: [f32; 3]) {
        let mut sum = 0.0f32;
        let mut n = 0u32;
        self.highlights.fill(0);
        for px in radiance.iter().step_by(7) {
            sum += px[1];
            n += 1;
            let m = (px[0] * wbn[0]).max(px[1] * wbn[1]).max(px[2] * wbn[2]);
            self.highlights[octave_bin(m)] += 1;
        }
        let mean = (sum / n.max(1) as f32).max(1e-4);
        let mut want = params.target_level / mean;
        let allowed = (params.highlight_clip.clamp(0.0, 1.0) * n as f32) as u32;
        if allowed < n {
            let mut above = 0u32;
            for b in (0..HIGHLIGHT_BINS).rev() {
                above += self.highlights[b];
                if above > allowed {
                    want = want.min(1.0 / (octave_bin_top(b) * params.gain.max(1e-6)));
                    break;
                }
            }
        }
        self.exposure *= (want / self.exposure).powf(0.5);
        self.exposure = self.exposure.clamp(1e-3, 1e3);
    }
}

/// Grey-world gate: a sample counts toward the balance when, under the balance in force,
/// its red/green and blue/green both lie within this factor of grey. Wide enough for any
/// illuminant the scenarios use seen through a neutral balance (tungsten's blue/green is
/// 0.56), narrow enough to leave out saturated paint and beacons.
const NEUTRAL_GATE: f32 = 2.0;

/// Fewer gated samples than this fraction of the subsample, and grey-world uses them all
/// (a view with almost nothing near grey, where the gate has nothing to go on).
const MIN_NEUTRAL_FRACTION: f32 = 0.02;

impl Sensor {
    /// Grey-world white balance over the near-neutral, unclipped, not-dark pixels of a
    /// subsample ([`NEUTRAL_GATE`]), followed with the time constant
    /// `params.white_balance_tau_s`. The first frame takes its estimate at once; a frame
    /// too dark to say anything keeps the last balance.
    fn grey_world(&mut self, radiance: &[[f32; 3]], params: &SensorParams) -> [f32; 3] {
        let last = self.balance.unwrap_or([1.0; 3]);
        // Linear radiance at which a balanced channel clips at the current exposure, and
        // below which a pixel is in the noise (a thousandth of that).
        let k = (self.exposure * params.gain).max(1e-6);
        let (clip, dark) = (1.0 / k, 1e-3 / k);
        let (lo, hi) = (1.0 / NEUTRAL_GATE, NEUTRAL_GATE);
        let mut all = [0.0f32; 3];
        let mut neutral = [0.0f32; 3];
        let (mut n_all, mut n_neutral) = (0u32, 0u32);
        for px in radiance.iter().step_by(7) {
            let p = px.map(|v| v.max(0.0));
            for c in 0..3 {
                all[c] += p[c];
            }
            n_all += 1;
            let q = [0, 1, 2].map(|c| p[c] * last[c]);
            let (r, g, b) = (q[0], q[1], q[2]);
            if g > dark && r.max(g).max(b) < clip && (lo * g..=hi * g).contains(&r) && (lo * g..=hi * g).contains(&b) {
                for c in 0..3 {
                    neutral[c] += p[c];
                }
                n_neutral += 1;
            }
        }
        let sum = if n_neutral as f32 >= MIN_NEUTRAL_FRACTION * n_all as f32 {
            neutral
        } else {
            all
        };
        if !sum.iter().all(|&s| s > 1e-6) {
            return *self.balance.get_or_insert(last);
        }
        let want = [sum[1] / sum[0], 1.0, sum[1] / sum[2]].map(|m| m.clamp(0.25, 4.0));
        let now = match self.balance {
            None => want,
            Some(b) => {
                let tau = params.white_balance_tau_s.max(0.0);
                let step = if tau > 0.0 {
                    1.0 - (-params.frame_interval_s.max(0.0) / tau).exp()
                } else {
                    1.0
                };
                [0, 1, 2].map(|c| b[c] * (want[c] / b[c]).powf(step))
            }
        };
        self.balance = Some(now);
        now
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat field at linear level `lin` through a fixed exposure: (mean, SD) of the
    /// output in levels.
    fn flat_field_stats(lin: f32, params: &SensorParams) -> (f64, f64) {
        let (w, h) = (64, 64);
        let mut sensor = Sensor::new(5);
        let mut out = RgbImage::default();
        let mut values = Vec::new();
        for frame in 0..4 {
            let mut radiance = vec![[lin; 3]; w * h];
            sensor.expose(&mut radiance, w, params, frame, &mut out);
            assert!(radiance.iter().all(|p| *p == [0.0; 3]), "exposing clears the radiance");
            values.extend(out.as_bytes().iter().map(|&v| v as f64));
        }
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
        (mean, var.sqrt())
    }

    /// Output levels (0–255) per linear 8-bit unit at linear level `lin`: the slope of
    /// the sRGB encoding (IEC 61966-2-1), to carry an output SD back to linear units.
    fn srgb_slope(lin: f64) -> f64 {
        let to_srgb = |l: f64| {
            if l <= 0.003_130_8 {
                12.92 * l
            } else {
                1.055 * l.powf(1.0 / 2.4) - 0.055
            }
        };
        let dl = 1e-5;
        (to_srgb(lin + dl) - to_srgb(lin - dl)) / (2.0 * dl)
    }

    #[test]
    fn the_photon_transfer_curve_gives_back_the_full_well_and_read_noise() {
        // A photon-transfer measurement, as one characterises a real sensor: flat fields
        // at several levels, the variance against the mean in linear units. Shot noise is
        // Poisson in electrons, so var = (255·g/FW)·mean + (255·g·r/FW)²: the slope gives
        // the full well, the intercept the read noise. Read and shot noise adding as SDs
        // (not variances) would bend the line and miss both.
        let params = SensorParams {
            auto_exposure: false,
            white_balance: WhiteBalance::Fixed([1.0; 3]),
            ..SensorParams::default()
        };
        let points: Vec<(f64, f64)> = [0.05f32, 0.1, 0.18, 0.3, 0.45, 0.6]
            .iter()
            .map(|&lin| {
                let (mean, sd) = flat_field_stats(lin, &params);
                let level = srgb_level(lin);
                assert!((mean - level).abs() < 0.6, "lin {lin}: mean {mean:.2} vs {level:.2}");
                // Output levels → linear 8-bit units; the 1/12 level² of rounding removed.
                let var_out = (sd * sd - 1.0 / 12.0).max(0.0);
                let slope = srgb_slope(lin as f64) * 255.0 / 255.0;
                (lin as f64 * 255.0, var_out / (slope * slope))
            })
            .collect();
        let n = points.len() as f64;
        let (mx, my) = points.iter().fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
        let sxy: f64 = points.iter().map(|(x, y)| (x - mx) * (y - my)).sum();
        let sxx: f64 = points.iter().map(|(x, _)| (x - mx).powi(2)).sum();
        let (a, b) = (sxy / sxx, my - sxy / sxx * mx);
        let full_well = 255.0 / a;
        let read = b.max(0.0).sqrt() * full_well / 255.0;
        assert!(
            (full_well / 2100.0 - 1.0).abs() < 0.1,
            "full well {full_well:.0} e⁻ (2100)"
        );
        assert!((read / 12.0 - 1.0).abs() < 0.25, "read noise {read:.1} e⁻ (12)");
        // No noise asked, none given; absurd noise saturates the output, never overflows.
        assert_eq!(flat_field_stats(0.18, &SensorParams::noiseless()).1, 0.0);
        let loud = SensorParams {
            read_noise_e: 1e12,
            ..params
        };
        let (mean, sd) = flat_field_stats(0.18, &loud);
        assert!(sd > 100.0 && (0.0..=255.0).contains(&mean), "{mean} {sd}");
    }

    #[test]
    fn a_dim_scene_brightened_by_auto_exposure_is_noisier() {
        // The same output level from a bright field and from one 16× dimmer: the dim one
        // integrates to the limit (4×) and then needs 4× gain, so it collected a quarter
        // of the electrons: twice the shot noise, four times the read noise (output units).
        let params = SensorParams {
            white_balance: WhiteBalance::Fixed([1.0; 3]),
            ..SensorParams::default()
        };
        let settled = |radiance: f32| {
            let mut sensor = Sensor::new(9);
            let mut out = RgbImage::default();
            let (w, h) = (64, 64);
            for frame in 0..30 {
                let mut r = vec![[radiance; 3]; w * h];
                sensor.expose(&mut r, w, &params, frame, &mut out);
            }
            let v: Vec<f64> = out.as_bytes().iter().map(|&b| b as f64).collect();
            let mean = v.iter().sum::<f64>() / v.len() as f64;
            let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / v.len() as f64).sqrt();
            (mean, sd)
        };
        let (m_bright, sd_bright) = settled(0.18);
        let (m_dim, sd_dim) = settled(0.18 / 16.0);
        assert!(
            (m_bright - m_dim).abs() < 2.0,
            "same output: {m_bright:.1} vs {m_dim:.1}"
        );
        assert!(sd_dim > 1.8 * sd_bright, "dim {sd_dim:.2} vs bright {sd_bright:.2}");
    }

    /// Exposes `frames` frames of `scene(frame, pixel)` (70 × 10) through grey-world
    /// with `params`, returning the last output.
    fn grey_world_frames(params: &SensorParams, frames: u64, scene: &dyn Fn(u64, usize) -> [f32; 3]) -> RgbImage {
        let params = SensorParams {
            white_balance: WhiteBalance::GreyWorld,
            ..*params
        };
        let mut sensor = Sensor::new(1);
        let mut out = RgbImage::default();
        for frame in 0..frames {
            let mut r: Vec<[f32; 3]> = (0..70 * 10).map(|i| scene(frame, i)).collect();
            sensor.expose(&mut r, 70, &params, frame, &mut out);
        }
        out
    }

    #[test]
    fn grey_world_balances_a_grey_scene_and_is_fooled_by_a_coloured_one() {
        let params = SensorParams::noiseless();
        let dusk = [1.0f32, 0.72, 0.48];
        let tungsten = [1.0f32, 0.68, 0.38];
        // A grey card filling the view under dusk or tungsten light comes out grey.
        for light in [dusk, tungsten] {
            let grey = grey_world_frames(&params, 60, &|_, _| light.map(|c| c * 0.3));
            let px = grey.view().get(5, 5).unwrap();
            assert!(px.iter().all(|&c| (c as i32 - px[1] as i32).abs() <= 1), "{px:?}");
        }
        // Under daylight, a view nine-tenths a greenish-blue surface (near enough to grey
        // to pass the gate, as a lawn or a painted wall does) pulls the balance toward
        // red: the grey card beside it turns reddish.
        let wall = grey_world_frames(&params, 60, &|_, i| {
            if i % 70 < 63 { [0.2, 0.3, 0.35] } else { [0.3; 3] }
        });
        let card = wall.view().get(66, 5).unwrap();
        assert!(card[0] as i32 > card[2] as i32 + 20, "{card:?}");
    }

    #[test]
    fn saturated_colour_does_not_move_the_balance() {
        // A fifth of the view a saturated orange (a beacon, a painted block) beside grey:
        // the gate leaves it out, and the grey stays grey. Plain grey-world over every
        // pixel would have turned the grey card blue.
        let params = SensorParams::noiseless();
        let out = grey_world_frames(&params, 60, &|_, i| {
            if i % 70 < 14 { [0.9, 0.25, 0.02] } else { [0.3; 3] }
        });
        let px = out.view().get(40, 5).unwrap();
        assert!(px.iter().all(|&c| (c as i32 - px[1] as i32).abs() <= 1), "{px:?}");
    }

    #[test]
    fn the_balance_settles_with_its_time_constant() {
        // The light turns from daylight to dusk after the first frame. With τ = 1 s at
        // 10 frames a second the balance has moved 1 − e^(−1) ≈ 63 % (in log terms) of
        // the way after 1 s, and all of it after 6 s; with τ = 0 at once.
        let params = SensorParams::noiseless();
        let dusk = [1.0f32, 0.72, 0.48];
        let scene = |frame: u64, _| if frame == 0 { [0.3; 3] } else { dusk.map(|c| c * 0.3) };
        let blue_over_green = |frames: u64, tau: f32| {
            let p = SensorParams {
                white_balance_tau_s: tau,
                frame_interval_s: 0.1,
                ..params
            };
            let out = grey_world_frames(&p, frames, &scene);
            let px = out.view().get(5, 5).unwrap();
            srgb_to_linear(px[2] as f32 / 255.0) / srgb_to_linear(px[1] as f32 / 255.0)
        };
        // Uncorrected, blue/green is 0.48/0.72 = 0.667; corrected, 1.
        let moved = |ratio: f32| ratio.ln() / (0.48f32 / 0.72).ln();
        let after_1s = 1.0 - moved(blue_over_green(11, 1.0));
        assert!((after_1s - 0.632).abs() < 0.05, "moved {after_1s:.3} of the way in 1 s");
        assert!((blue_over_green(61, 1.0) - 1.0).abs() < 0.02);
        assert!((blue_over_green(2, 0.0) - 1.0).abs() < 0.02);
    }

    fn srgb_level(lin: f32) -> f64 {
        let l = lin as f64;
        (1.055 * l.powf(1.0 / 2.4) - 0.055) * 255.0
    }

    #[test]
    fn floor_index_matches_the_cast_off_integers() {
        let mut x = 0.0f32;
        while x < LUT_MAX {
            let want = x as i32;
            let got = floor_index(x);
            if x.fract() == 0.0 {
                assert!(got == want || got == want - 1, "{x}: {got}");
            } else {
                assert_eq!(got, want, "{x}");
            }
            x += 0.173;
        }
        assert_eq!(floor_index(0.0), 0);
        assert_eq!(floor_index(LUT_MAX - 0.001), LUT_MAX as i32 - 1);
        assert!(floor_index(LUT_MAX) >= LUT_MAX as i32 - 1);
    }

    #[test]
    fn octave_bins_bracket_their_values() {
        for k in 0..2000 {
            let v = 2f32.powf(-11.5 + k as f32 * 0.0075);
            let b = octave_bin(v);
            assert!(octave_bin_top(b) >= v, "{v}: bin {b} tops at {}", octave_bin_top(b));
            assert!(b == 0 || octave_bin_top(b - 1) <= v, "{v}: bin {b}");
            // Sixteen steps per octave, none wider than 6.25 %.
            assert!(octave_bin_top(b) <= v * 1.0625 * 1.0001);
        }
        assert_eq!(octave_bin(0.0), 0);
        assert_eq!(octave_bin(1e9), HIGHLIGHT_BINS - 1);
    }
}
