//! Colour segmentation by per-colour ranges in SCT or HSV space, into reusable masks.
//!
//! The SCT test needs no trigonometry at all. Because A = atan2(√(r²+g²), b) and
//! B = atan2(g, r) are monotonic in ratios of the channels, each bound becomes a sign test
//! on a product of the channels with precomputed cosines and sines:
//!
//! * B ≥ b₀ ⇔ g·cos b₀ − r·sin b₀ ≥ 0 (and r, g not both 0 when b₀ > 0),
//! * B ≤ b₁ ⇔ g·cos b₁ − r·sin b₁ ≤ 0,
//! * A ≥ a₀ ⇔ (r²+g²)·cos² a₀ − b²·sin² a₀ ≥ 0,
//! * A ≤ a₁ ⇔ (r²+g²)·cos² a₁ − b²·sin² a₁ ≤ 0,
//!
//! plus a brightness gate L² ≥ L_min². This is the exact SCT classification (agreeing with
//! `f64` trigonometry except within ~1e-6 rad of a bound, tested), costs a handful of
//! multiplies per pixel, and vectorises: in 2003 the SCT took over 80 % of the cycle
//! (seed 004 §V); here it is a fraction of the labelling time.

use super::hsv::Hsv;
use super::image::RgbView;
use super::sct::Sct;
use super::{VisionError, check_same_size};
use std::f64::consts::FRAC_PI_2;

/// An axis-aligned box in SCT (A, B) space with a brightness floor. Angles in radians; a
/// range with `lo > hi` on either axis matches nothing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SctRange {
    /// [A_lo, A_hi], radians.
    pub a: [f64; 2],
    /// [B_lo, B_hi], radians.
    pub b: [f64; 2],
    /// Smallest L (0–441.7) a pixel needs to be classified at all (dark pixels carry no
    /// usable chromaticity). Values below 1 are treated as 1, so black never matches.
    pub min_l: f64,
}

/// A box in HSV space. Hue in degrees; `h[0] > h[1]` wraps through 0 (e.g. [340, 20] for
/// red). S and V in [0, 1].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HsvRange {
    /// [H_lo, H_hi], degrees.
    pub h: [f32; 2],
    /// [S_lo, S_hi].
    pub s: [f32; 2],
    /// [V_lo, V_hi].
    pub v: [f32; 2],
}

/// One colour's range in either space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ColorRange {
    /// SCT box.
    Sct(SctRange),
    /// HSV box.
    Hsv(HsvRange),
}

impl SctRange {
    /// Reference classification with `f64` trigonometry (slow; for tests and tools).
    pub fn contains(&self, rgb: [u8; 3]) -> bool {
        let s = Sct::from_rgb(rgb);
        s.l >= self.min_l.max(1.0) && s.a >= self.a[0] && s.a <= self.a[1] && s.b >= self.b[0] && s.b <= self.b[1]
    }
}

impl HsvRange {
    /// True when the pixel falls in the box.
    #[inline]
    pub fn contains(&self, rgb: [u8; 3]) -> bool {
        let p = Hsv::from_rgb(rgb);
        let h_ok = if self.h[0] <= self.h[1] {
            p.h >= self.h[0] && p.h <= self.h[1]
        } else {
            p.h >= self.h[0] || p.h <= self.h[1]
        };
        h_ok && p.s >= self.s[0] && p.s <= self.s[1] && p.v >= self.v[0] && p.v <= self.v[1]
    }
}

impl ColorRange {
    /// Reference classification of one pixel.
    pub fn contains(&self, rgb: [u8; 3]) -> bool {
        match self {
            ColorRange::Sct(r) => r.contains(rgb),
            ColorRange::Hsv(r) => r.contains(rgb),
        }
    }
}

/// A binary mask: one byte per pixel, 0 or 1, row-major.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Mask {
    width: usize,
    height: usize,
    data: Vec<u8>,
}

impl Mask {
    /// An all-zero mask.
    pub fn new(width: usize, height: usize) -> Self {
        Self {
            width,
            height,
            data: vec![0; width * height],
        }
    }

    /// A mask from 0/1 bytes (any non-zero byte counts as set and is stored as 1).
    ///
    /// # Errors
    /// [`VisionError::SizeMismatch`] when `data.len() != width*height`.
    pub fn from_vec(width: usize, height: usize, mut data: Vec<u8>) -> Result<Self, VisionError> {
        if data.len() != width * height {
            return Err(VisionError::SizeMismatch {
                expected: (width, height),
                got: (data.len(), 1),
            });
        }
        data.iter_mut().for_each(|b| *b = (*b != 0) as u8);
        Ok(Self { width, height, data })
    }

    /// Resizes (reusing the allocation when possible) and clears.
    pub fn reset(&mut self, width: usize, height: usize) {
        self.width = width;
        self.height = height;
        self.data.clear();
        self.data.resize(width * height, 0);
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// (width, height).
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// The bytes (0 or 1).
    pub fn data(&self) -> &[u8] {
        &self.data
    }

    /// True when (x, y) is set; false outside.
    pub fn get(&self, x: usize, y: usize) -> bool {
        x < self.width && y < self.height && self.data[y * self.width + x] != 0
    }

    /// Sets (x, y); ignored outside.
    pub fn set(&mut self, x: usize, y: usize, on: bool) {
        if x < self.width && y < self.height {
            self.data[y * self.width + x] = on as u8;
        }
    }

    /// Number of set pixels.
    pub fn count(&self) -> usize {
        self.data.iter().map(|&b| b as usize).sum()
    }
}

/// Precomputed coefficients of the trig-free SCT test (see the module docs).
#[derive(Debug, Clone, Copy)]
struct SctTest {
    l2_min: f32,
    rg2_min: f32,
    cb0: f32,
    sb0: f32,
    cb1: f32,
    sb1: f32,
    ca0: f32,
    sa0: f32,
    ca1: f32,
    sa1: f32,
    empty: bool,
}

impl SctTest {
    fn new(r: &SctRange) -> Self {
        let (a0, a1, b0, b1) = (r.a[0], r.a[1], r.b[0], r.b[1]);
        let empty = !(a0 <= a1 && b0 <= b1) || a0 > FRAC_PI_2 || b0 > FRAC_PI_2 || a1 < 0.0 || b1 < 0.0;
        // A disabled bound gets coefficients that make its test always true.
        let (cb0, sb0) = if b0 > 0.0 { (b0.cos(), b0.sin()) } else { (1.0, 0.0) };
        let (cb1, sb1) = if b1 < FRAC_PI_2 {
            (b1.cos(), b1.sin())
        } else {
            (0.0, 1.0)
        };
        let (ca0, sa0) = if a0 > 0.0 {
            (a0.cos().powi(2), a0.sin().powi(2))
        } else {
            (1.0, 0.0)
        };
        let (ca1, sa1) = if a1 < FRAC_PI_2 {
            (a1.cos().powi(2), a1.sin().powi(2))
        } else {
            (0.0, 1.0)
        };
        let l = r.min_l.max(1.0);
        Self {
            l2_min: (l * l) as f32,
            rg2_min: if b0 > 0.0 { 1.0 } else { 0.0 },
            cb0: cb0 as f32,
            sb0: sb0 as f32,
            cb1: cb1 as f32,
            sb1: sb1 as f32,
            ca0: ca0 as f32,
            sa0: sa0 as f32,
            ca1: ca1 as f32,
            sa1: sa1 as f32,
            empty,
        }
    }

    /// Classifies one row given its channels as `f32`.
    #[inline]
    fn run_row(&self, r: &[f32], g: &[f32], b: &[f32], out: &mut [u8]) {
        if self.empty {
            out.fill(0);
            return;
        }
        let t = *self;
        for (((&r, &g), &b), o) in r.iter().zip(g).zip(b).zip(out.iter_mut()) {
            let rg2 = r * r + g * g;
            let b2 = b * b;
            let ok = (rg2 + b2 >= t.l2_min)
                & (rg2 >= t.rg2_min)
                & (g * t.cb0 - r * t.sb0 >= 0.0)
                & (g * t.cb1 - r * t.sb1 <= 0.0)
                & (rg2 * t.ca0 - b2 * t.sa0 >= 0.0)
                & (rg2 * t.ca1 - b2 * t.sa1 <= 0.0);
            *o = ok as u8;
        }
    }
}

/// Segments frames into one mask per colour range. Holds per-row scratch so that
/// segmenting allocates nothing once sized.
#[derive(Debug, Clone, Default)]
pub struct Segmenter {
    r: Vec<f32>,
    g: Vec<f32>,
    b: Vec<f32>,
    tests: Vec<Option<SctTest>>,
}

impl Segmenter {
    /// A segmenter for frames up to `max_width` pixels wide (it grows if needed).
    pub fn new(max_width: usize) -> Self {
        Self {
            r: vec![0.0; max_width],
            g: vec![0.0; max_width],
            b: vec![0.0; max_width],
            tests: Vec::with_capacity(4),
        }
    }

    /// Writes `masks[i]` = pixels of `src` inside `ranges[i]`.
    ///
    /// # Errors
    /// [`VisionError::SizeMismatch`] when a mask's size differs from the frame's, and
    /// [`VisionError::CountMismatch`] when `ranges` and `masks` differ in length.
    pub fn segment(&mut self, src: &RgbView<'_>, ranges: &[ColorRange], masks: &mut [Mask]) -> Result<(), VisionError> {
        if ranges.len() != masks.len() {
            return Err(VisionError::CountMismatch {
                what: "masks",
                expected: ranges.len(),
                got: masks.len(),
            });
        }
        let (w, h) = (src.width(), src.height());
        for m in masks.iter() {
            check_same_size((w, h), m.size())?;
        }
        if self.r.len() < w {
            self.r.resize(w, 0.0);
            self.g.resize(w, 0.0);
            self.b.resize(w, 0.0);
        }
        self.tests.clear();
        self.tests.extend(ranges.iter().map(|r| match r {
            ColorRange::Sct(r) => Some(SctTest::new(r)),
            ColorRange::Hsv(_) => None,
        }));
        let bytes = src.as_bytes();
        for y in 0..h {
            let row = &bytes[y * w * 3..(y + 1) * w * 3];
            let (r, g, b) = (&mut self.r[..w], &mut self.g[..w], &mut self.b[..w]);
            for (i, px) in row.chunks_exact(3).enumerate() {
                r[i] = px[0] as f32;
                g[i] = px[1] as f32;
                b[i] = px[2] as f32;
            }
            for ((range, test), mask) in ranges.iter().zip(&self.tests).zip(masks.iter_mut()) {
                let out = &mut mask.data[y * w..(y + 1) * w];
                match (range, test) {
                    (_, Some(t)) => t.run_row(r, g, b, out),
                    (ColorRange::Sct(sr), None) => SctTest::new(sr).run_row(r, g, b, out),
                    (ColorRange::Hsv(hr), None) => {
                        for (o, px) in out.iter_mut().zip(row.chunks_exact(3)) {
                            *o = hr.contains([px[0], px[1], px[2]]) as u8;
                        }
                    }
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::perception::RgbImage;

    fn deg(d: f64) -> f64 {
        d.to_radians()
    }

    #[test]
    fn cyan_and_magenta_separate() {
        let cyan = ColorRange::Sct(SctRange {
            a: [deg(35.0), deg(55.0)],
            b: [deg(75.0), deg(90.0)],
            min_l: 30.0,
        });
        let magenta = ColorRange::Sct(SctRange {
            a: [deg(35.0), deg(55.0)],
            b: [deg(0.0), deg(15.0)],
            min_l: 30.0,
        });
        let im = RgbImage::from_raw(4, 1, vec![0, 200, 210, 190, 10, 200, 5, 5, 5, 128, 128, 128]).unwrap();
        let mut masks = [Mask::new(4, 1), Mask::new(4, 1)];
        Segmenter::new(4)
            .segment(&im.view(), &[cyan, magenta], &mut masks)
            .unwrap();
        assert_eq!(masks[0].data(), &[1, 0, 0, 0]);
        assert_eq!(masks[1].data(), &[0, 1, 0, 0]);
    }

    #[test]
    fn fast_test_agrees_with_trigonometry_on_the_whole_cube() {
        // Every 3rd value per channel against the f64 reference, for ranges with each bound
        // active or disabled. Disagreements are allowed only within 1e-5 rad of a bound.
        let ranges = [
            SctRange {
                a: [0.3, 1.1],
                b: [0.2, 0.9],
                min_l: 20.0,
            },
            SctRange {
                a: [0.0, 0.7],
                b: [0.0, 0.4],
                min_l: 0.0,
            },
            SctRange {
                a: [0.9, FRAC_PI_2],
                b: [1.0, FRAC_PI_2],
                min_l: 5.0,
            },
            SctRange {
                a: [-1.0, 3.0],
                b: [-1.0, 3.0],
                min_l: 1.0,
            },
            SctRange {
                a: [0.8, 0.7],
                b: [0.0, 1.0],
                min_l: 1.0,
            },
        ];
        let vals: Vec<u8> = (0..=255).step_by(3).collect();
        let n = vals.len();
        let mut im = RgbImage::new(n, n * n);
        for (i, &r) in vals.iter().enumerate() {
            for (j, &g) in vals.iter().enumerate() {
                for (k, &b) in vals.iter().enumerate() {
                    im.put(k, i * n + j, [r, g, b]);
                }
            }
        }
        let cr: Vec<ColorRange> = ranges.iter().map(|r| ColorRange::Sct(*r)).collect();
        let mut masks: Vec<Mask> = (0..cr.len()).map(|_| Mask::new(n, n * n)).collect();
        Segmenter::new(n).segment(&im.view(), &cr, &mut masks).unwrap();
        for (range, mask) in ranges.iter().zip(&masks) {
            for y in 0..n * n {
                for x in 0..n {
                    let px = im.view().get(x, y).unwrap();
                    let exact = range.contains(px);
                    if mask.get(x, y) != exact {
                        let s = Sct::from_rgb(px);
                        let near = [range.a[0] - s.a, range.a[1] - s.a, range.b[0] - s.b, range.b[1] - s.b]
                            .iter()
                            .any(|d| d.abs() < 1e-5);
                        assert!(near, "{px:?} {s:?} {range:?}: fast {} exact {exact}", mask.get(x, y));
                    }
                }
            }
        }
        assert_eq!(masks[4].count(), 0, "an inverted range matches nothing");
        assert!(!masks[3].get(0, 0), "black never matches");
    }

    #[test]
    fn pure_blue_has_b_zero() {
        let r = SctRange {
            a: [0.0, 0.5],
            b: [0.3, 1.0],
            min_l: 1.0,
        };
        let im = RgbImage::from_raw(1, 1, vec![0, 0, 200]).unwrap();
        let mut m = [Mask::new(1, 1)];
        Segmenter::new(1)
            .segment(&im.view(), &[ColorRange::Sct(r)], &mut m)
            .unwrap();
        assert!(!m[0].get(0, 0));
        assert!(!r.contains([0, 0, 200]));
    }

    #[test]
    fn hsv_ranges_wrap() {
        let red = HsvRange {
            h: [340.0, 20.0],
            s: [0.5, 1.0],
            v: [0.2, 1.0],
        };
        assert!(red.contains([250, 10, 30]));
        assert!(red.contains([250, 30, 10]));
        assert!(!red.contains([10, 250, 30]));
        assert!(!red.contains([120, 110, 110]), "low saturation");
        let im = RgbImage::from_raw(2, 1, vec![250, 10, 30, 20, 20, 20]).unwrap();
        let mut m = [Mask::new(2, 1)];
        Segmenter::new(2)
            .segment(&im.view(), &[ColorRange::Hsv(red)], &mut m)
            .unwrap();
        assert_eq!(m[0].data(), &[1, 0]);
    }

    #[test]
    fn sizes_are_checked() {
        let im = RgbImage::new(3, 2);
        let r = ColorRange::Hsv(HsvRange {
            h: [0.0, 1.0],
            s: [0.0, 1.0],
            v: [0.0, 1.0],
        });
        let mut seg = Segmenter::new(3);
        assert!(matches!(
            seg.segment(&im.view(), &[r], &mut [Mask::new(2, 2)]),
            Err(VisionError::SizeMismatch { .. })
        ));
        assert!(matches!(
            seg.segment(&im.view(), &[r, r], &mut [Mask::new(3, 2)]),
            Err(VisionError::CountMismatch { .. })
        ));
    }
}
