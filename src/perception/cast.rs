//! Compensation of fast colour casts: a flashing coloured beacon, a cloud, a sodium lamp
//! switching on. Ours, not the paper's (README, "Colour casts").
//!
//! A coloured light that flashes tints the whole scene at once: both of Bujold's blocks
//! move the same way in SCT space, by 5–14° of A within one frame under a strong beacon,
//! while the colour ranges are a few degrees wide (mean ± 4 SD of a steady block). No
//! adaptation that blends frames can follow a flash of a fraction of a second, and the
//! ranges cannot be widened that far without taking in the background. So the frame is
//! brought back to the light the ranges were learnt under before it is segmented.
//!
//! The method measures what a change of light does and a change of scene does not: a
//! light that changes colour multiplies every pixel's channels by the same factors, while
//! a scene that changes (a flap coming into view, the robot turning) replaces some pixels
//! and leaves the rest. So the cast is the median, over the frame, of each channel's
//! log-ratio between this frame and the last one, taken pixel by pixel; the median is
//! untouched by the part of the view that changed as long as most of it did not. The
//! changes accumulate into the cast the frame is under, which fades with the time
//! constant [`CastParams::tau_s`], so a light that stays changed is handed over to the
//! colour model's adaptation and a flash that comes and goes is removed. The frame is
//! then scaled per channel by the inverse (von Kries), with the three gains' product held
//! at 1, so only its colour is corrected (SCT angles do not depend on brightness; a
//! change of exposure is no cast). Gains within [`CastParams::dead_band`] of 1 are
//! treated as 1: a 2 % chromatic gain moves an SCT angle by under 0.6°, inside the
//! narrowest range.
//!
//! The ratios are taken over every second pixel of every second row, leaving out pixels
//! dark or clipped in either frame (their ratios are noise or saturation). The previous
//! frame's samples, the log table and the histograms are allocated once; the correction
//! is a per-channel table of 256 entries applied into a buffer allocated once. Nothing is
//! allocated per frame.

use super::image::{RgbImage, RgbView};

/// Tuning of [`CastCompensator`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CastParams {
    /// Time constant with which a measured cast fades into the light the colour model
    /// adapts to, s; 0 turns the compensation off.
    pub tau_s: f64,
    /// Gains within this fraction of 1 are not applied.
    pub dead_band: f64,
}

impl CastParams {
    /// No compensation: every frame passes through.
    pub const OFF: CastParams = CastParams {
        tau_s: 0.0,
        dead_band: 0.0,
    };
}

/// Channels below this value carry too few levels for a ratio.
const DARK: u8 = 16;
/// Channels at or above this value are clipped.
const CLIPPED: u8 = 250;
/// Log-ratio histogram: 1001 bins of 0.002 centred on 0, over ±1 (a factor of e
/// either way); a change too small to move the median one bin is no cast.
const BINS: usize = 1001;
const BIN_WIDTH: f32 = 0.002;
/// Fewer usable samples than this and the frame is not measured.
const MIN_SAMPLES: u32 = 64;

/// Removes fast colour casts from frames (see the module docs). One per camera.
///
/// # Example
///
/// A scene under steady light passes through; the same scene suddenly under a bluish
/// light is brought back to the steady light's colour; a large new object in view is
/// not mistaken for a cast.
///
/// ```
/// use marsupial::perception::{CastCompensator, CastParams, RgbImage};
///
/// let mut c = CastCompensator::new(CastParams { tau_s: 2.0, dead_band: 0.02 }, 16, 16);
/// let mut im = RgbImage::new(16, 16);
/// for y in 0..16 {
///     for x in 0..16 {
///         im.put(x, y, [60 + 8 * x as u8, 100, 60 + 8 * y as u8]);
///     }
/// }
/// for k in 0..10 {
///     assert_eq!(c.correct(im.view(), k as f64 * 0.1).get(3, 3), Some(im.view().get(3, 3).unwrap()));
/// }
/// let mut flash = im.clone();
/// for px in flash.as_bytes_mut().chunks_exact_mut(3) {
///     px[0] = (px[0] as f64 * 0.8) as u8;
///     px[2] = (px[2] as f64 * 1.2) as u8;
/// }
/// let out = c.correct(flash.view(), 1.0).get(5, 9).unwrap();
/// let want = im.view().get(5, 9).unwrap();
/// assert!((0..3).all(|i| out[i].abs_diff(want[i]) <= 3), "{out:?} {want:?}");
///
/// let mut object = flash.clone();
/// for y in 0..6 {
///     for x in 0..16 {
///         object.put(x, y, [200, 20, 180]);
///     }
/// }
/// c.correct(object.view(), 1.1);
/// assert!(c.gains().iter().all(|g| (g - 1.0).abs() < 0.3)); // still only the flash's
/// ```
#[derive(Debug, Clone)]
pub struct CastCompensator {
    params: CastParams,
    /// The last frame's samples and stamp, when there is one of this size.
    previous: Vec<u8>,
    previous_stamp: Option<f64>,
    previous_size: (usize, usize),
    /// The cast the last frame was under, as a log gain per channel.
    cast: [f64; 3],
    gains: [f64; 3],
    ln: [f32; 256],
    histograms: Vec<u32>,
    lut: [[u8; 256]; 3],
    buffer: RgbImage,
}

impl CastCompensator {
    /// A compensator for `width × height` frames (its buffers are allocated here, and
    /// again only if the frame size changes) with no history.
    pub fn new(params: CastParams, width: usize, height: usize) -> Self {
        let on = params.tau_s > 0.0;
        let (w, h) = if on { (width, height) } else { (0, 0) };
        Self {
            params,
            previous: Vec::with_capacity(samples(w, h) * 3),
            previous_stamp: None,
            previous_size: (0, 0),
            cast: [0.0; 3],
            gains: [1.0; 3],
            ln: std::array::from_fn(|v| (v.max(1) as f32).ln()),
            histograms: if on { vec![0; 3 * BINS] } else { Vec::new() },
            lut: [[0; 256]; 3],
            buffer: RgbImage::new(w, h),
        }
    }

    /// The tuning.
    pub fn params(&self) -> &CastParams {
        &self.params
    }

    /// The gains applied to the last corrected frame (R, G, B); all 1 when it passed
    /// through.
    pub fn gains(&self) -> [f64; 3] {
        self.gains
    }

    /// Forgets the history: the next frame starts with no cast.
    pub fn reset(&mut self) {
        self.previous_stamp = None;
        self.cast = [0.0; 3];
        self.gains = [1.0; 3];
    }

    /// Corrects the frame taken at `stamp` and returns the view to segment: `view`
    /// itself when no cast is found, otherwise the corrected copy in the compensator's
    /// buffer. A stamp that goes backwards, a jump of more than one time constant or a
    /// change of frame size starts the history again.
    pub fn correct<'s>(&'s mut self, view: RgbView<'s>, stamp: f64) -> RgbView<'s> {
        self.gains = [1.0; 3];
        if self.params.tau_s <= 0.0 || view.is_empty() {
            return view;
        }
        let size = (view.width(), view.height());
        let continues = self.previous_size == size
            && self
                .previous_stamp
                .is_some_and(|t| stamp >= t && stamp - t <= self.params.tau_s);
        if continues {
            let dt = stamp - self.previous_stamp.unwrap_or(stamp);
            let step = self.step(&view);
            let fade = (-dt / self.params.tau_s).exp();
            self.cast = std::array::from_fn(|c| self.cast[c] * fade + step[c]);
        } else {
            self.cast = [0.0; 3];
        }
        self.remember(&view, stamp);
        // Colour only: the log gains are centred so their product is 1.
        let mean = self.cast.iter().sum::<f64>() / 3.0;
        let gains: [f64; 3] = std::array::from_fn(|c| (mean - self.cast[c]).exp());
        if gains.iter().all(|g| (g - 1.0).abs() <= self.params.dead_band) {
            return view;
        }
        self.gains = gains;
        self.apply(view)
    }

    /// Applies the last frame's gains to another view (e.g. a frame sampled for
    /// imprinting right after it was processed); passes it through when the last frame
    /// had no cast.
    pub fn reapply<'s>(&'s mut self, view: RgbView<'s>) -> RgbView<'s> {
        if self.gains == [1.0; 3] || view.is_empty() {
            return view;
        }
        self.apply(view)
    }

    /// The median log-ratio per channel between `view` and the remembered frame; 0 for a
    /// channel with too few usable samples.
    fn step(&mut self, view: &RgbView<'_>) -> [f64; 3] {
        self.histograms.clear();
        self.histograms.resize(3 * BINS, 0);
        let mut n = 0u32;
        for (cur, prev) in sample_pixels(view).zip(self.previous.chunks_exact(3)) {
            let usable = |px: &[u8]| px.iter().all(|&v| (DARK..CLIPPED).contains(&v));
            if !(usable(cur) && usable(prev)) {
                continue;
            }
            n += 1;
            for c in 0..3 {
                let d = self.ln[cur[c] as usize] - self.ln[prev[c] as usize];
                let bin = ((d / BIN_WIDTH).round() + (BINS / 2) as f32).clamp(0.0, (BINS - 1) as f32) as usize;
                self.histograms[c * BINS + bin] += 1;
            }
        }
        if n < MIN_SAMPLES {
            return [0.0; 3];
        }
        std::array::from_fn(|c| median_bin(&self.histograms[c * BINS..(c + 1) * BINS], n))
    }

    fn remember(&mut self, view: &RgbView<'_>, stamp: f64) {
        self.previous.clear();
        for px in sample_pixels(view) {
            self.previous.extend_from_slice(px);
        }
        self.previous_stamp = Some(stamp);
        self.previous_size = (view.width(), view.height());
    }

    fn apply<'s>(&'s mut self, view: RgbView<'s>) -> RgbView<'s> {
        for (c, lut) in self.lut.iter_mut().enumerate() {
            for (v, out) in lut.iter_mut().enumerate() {
                *out = (v as f64 * self.gains[c]).round().clamp(0.0, 255.0) as u8;
            }
        }
        // Allocates only when the frame size changes.
        if (self.buffer.width(), self.buffer.height()) != (view.width(), view.height()) {
            self.buffer = RgbImage::new(view.width(), view.height());
        }
        let lut = &self.lut;
        for (dst, src) in self
            .buffer
            .as_bytes_mut()
            .chunks_exact_mut(3)
            .zip(view.as_bytes().chunks_exact(3))
        {
            dst[0] = lut[0][src[0] as usize];
            dst[1] = lut[1][src[1] as usize];
            dst[2] = lut[2][src[2] as usize];
        }
        self.buffer.view()
    }
}

/// Samples per frame: every second pixel of every second row.
fn samples(width: usize, height: usize) -> usize {
    width.div_ceil(2) * height.div_ceil(2)
}

/// The sampled pixels of a frame, in raster order.
fn sample_pixels<'v>(view: &RgbView<'v>) -> impl Iterator<Item = &'v [u8]> {
    let w = view.width();
    let bytes = view.as_bytes();
    (0..view.height())
        .step_by(2)
        .flat_map(move |y| bytes[y * w * 3..(y + 1) * w * 3].chunks_exact(3).step_by(2))
}

/// The centre of the histogram bin holding the median of `n` samples, as a log-ratio.
fn median_bin(hist: &[u32], n: u32) -> f64 {
    let half = n.div_ceil(2);
    let mut seen = 0;
    for (i, &k) in hist.iter().enumerate() {
        seen += k;
        if seen >= half {
            return (i as f64 - (BINS / 2) as f64) * BIN_WIDTH as f64;
        }
    }
    0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    const ON: CastParams = CastParams {
        tau_s: 2.0,
        dead_band: 0.02,
    };

    /// A 32×32 scene with some texture in every channel.
    fn scene() -> RgbImage {
        let mut im = RgbImage::new(32, 32);
        for y in 0..32 {
            for x in 0..32 {
                im.put(x, y, [40 + 5 * x as u8, 90 + (x + y) as u8, 40 + 5 * y as u8]);
            }
        }
        im
    }

    fn tinted(im: &RgbImage, light: [f64; 3]) -> RgbImage {
        let mut out = im.clone();
        for px in out.as_bytes_mut().chunks_exact_mut(3) {
            for c in 0..3 {
                px[c] = (px[c] as f64 * light[c]).round().min(255.0) as u8;
            }
        }
        out
    }

    fn max_diff(a: RgbView<'_>, b: RgbView<'_>) -> u8 {
        a.as_bytes()
            .iter()
            .zip(b.as_bytes())
            .map(|(x, y)| x.abs_diff(*y))
            .max()
            .unwrap()
    }

    #[test]
    fn off_passes_every_frame_through() {
        let mut c = CastCompensator::new(CastParams::OFF, 32, 32);
        let a = scene();
        let b = tinted(&a, [0.7, 1.0, 1.3]);
        c.correct(a.view(), 0.0);
        assert_eq!(c.correct(b.view(), 0.1), b.view());
        assert_eq!(c.gains(), [1.0; 3]);
    }

    #[test]
    fn a_flash_is_removed_and_only_its_colour() {
        let mut c = CastCompensator::new(ON, 32, 32);
        let a = scene();
        for k in 0..5 {
            assert_eq!(c.correct(a.view(), k as f64 * 0.1), a.view());
        }
        // A yellow flash at 1.5× the light: the colour goes, the brightness stays.
        let b = tinted(&a, [1.3, 1.25, 0.8]);
        let out = c.correct(b.view(), 0.5).as_bytes().to_vec();
        let out = RgbView::new(32, 32, &out).unwrap();
        let g = c.gains();
        assert!((g.iter().product::<f64>() - 1.0).abs() < 1e-9, "{g:?}");
        let brighter = tinted(&a, [1.3 * g[0], 1.25 * g[1], 0.8 * g[2]]);
        assert!(max_diff(out, brighter.view()) <= 1);
        let ratio = |px: [u8; 3]| px[0] as f64 / px[2] as f64;
        let (o, want) = (out.get(10, 10).unwrap(), a.view().get(10, 10).unwrap());
        assert!((ratio(o) / ratio(want) - 1.0).abs() < 0.03, "{o:?} against {want:?}");
    }

    #[test]
    fn a_change_of_exposure_is_no_cast() {
        let mut c = CastCompensator::new(ON, 32, 32);
        let a = scene();
        c.correct(a.view(), 0.0);
        let b = tinted(&a, [1.4, 1.4, 1.4]);
        assert_eq!(c.correct(b.view(), 0.1), b.view());
    }

    #[test]
    fn a_new_object_in_view_is_no_cast() {
        // A saturated block covering 40 % of the view appears between two frames.
        let mut c = CastCompensator::new(ON, 32, 32);
        let a = scene();
        c.correct(a.view(), 0.0);
        let mut b = a.clone();
        for y in 0..13 {
            for x in 0..32 {
                b.put(x, y, [210, 30, 190]);
            }
        }
        assert_eq!(c.correct(b.view(), 0.1), b.view());
    }

    #[test]
    fn a_lasting_change_fades_into_the_reference() {
        // The light turns bluish and stays: corrected at first, passed through once the
        // cast has faded below the dead band (a few time constants).
        let mut c = CastCompensator::new(ON, 32, 32);
        let a = scene();
        let b = tinted(&a, [0.9, 1.0, 1.15]);
        c.correct(a.view(), 0.0);
        c.correct(b.view(), 0.1);
        assert_ne!(c.gains(), [1.0; 3]);
        let mut t = 0.1;
        while c.gains() != [1.0; 3] {
            t += 0.1;
            c.correct(b.view(), t);
            assert!(t < 10.0, "never faded");
        }
        assert!(t > 2.0, "faded after {t} s, faster than the time constant");
    }

    #[test]
    fn dark_and_clipped_pixels_are_left_out() {
        // Only pixels that are clipped or dark change: no cast.
        let mut c = CastCompensator::new(ON, 32, 32);
        let mut a = scene();
        for y in 0..32 {
            for x in 0..8 {
                a.put(x, y, [255, 255, 255]);
                a.put(x + 8, y, [5, 5, 5]);
            }
        }
        c.correct(a.view(), 0.0);
        let mut b = a.clone();
        for y in 0..32 {
            for x in 0..8 {
                b.put(x, y, [255, 200, 255]);
                b.put(x + 8, y, [2, 9, 5]);
            }
        }
        assert_eq!(c.correct(b.view(), 0.1), b.view());
    }

    #[test]
    fn a_time_jump_or_a_stamp_going_back_restarts_the_history() {
        let mut c = CastCompensator::new(ON, 32, 32);
        let a = scene();
        let b = tinted(&a, [0.8, 1.0, 1.2]);
        c.correct(a.view(), 1.0);
        assert_ne!(c.correct(b.view(), 1.1), b.view());
        c.correct(a.view(), 1.2);
        assert_eq!(c.correct(b.view(), 0.5), b.view(), "back in time");
        c.correct(a.view(), 0.6);
        assert_eq!(c.correct(b.view(), 60.0), b.view(), "a jump");
    }

    #[test]
    fn reapply_uses_the_last_frames_gains() {
        let mut c = CastCompensator::new(ON, 32, 32);
        let a = scene();
        let b = tinted(&a, [0.8, 1.0, 1.2]);
        c.correct(a.view(), 0.0);
        let corrected = c.correct(b.view(), 0.1).get(4, 4);
        assert_eq!(c.reapply(b.view()).get(4, 4), corrected);
        c.reset();
        assert_eq!(c.reapply(b.view()), b.view());
    }
}
