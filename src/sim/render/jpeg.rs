//! A baseline JPEG round trip (encode and decode, without the entropy coding, which is
//! lossless): what a webcam's compression does to a frame before the robot sees it.
//!
//! The steps are those of a baseline JFIF encoder and decoder (ITU-T T.81, JFIF 1.02):
//!
//! 1. RGB → Y′CbCr with the JFIF (full-range BT.601) matrix, each plane rounded to 8 bits
//!    as an encoder stores it;
//! 2. 4:2:0 chroma subsampling: Cb and Cr averaged over 2 × 2 pixels;
//! 3. every plane padded to whole 8 × 8 blocks by repeating its last row and column (the
//!    luminance to whole 16 × 16 macroblocks), level-shifted by −128, and transformed by
//!    the 8 × 8 DCT-II;
//! 4. each coefficient divided by its entry of the IJG quantisation table (Annex K.1 of
//!    T.81, luminance or chrominance) scaled by the quality as libjpeg's
//!    `jpeg_quality_scaling` does (q < 50: 5000/q %, else 200 − 2q %, entries clamped to
//!    1–255), and rounded: the only lossy step besides the subsampling;
//! 5. the decoder multiplies back, inverse-transforms, rounds and clamps each plane to
//!    8 bits, replicates each chroma sample over its 2 × 2 pixels (libjpeg's plain
//!    upsampling; its default "fancy" triangle filter is smoother), and converts back to
//!    RGB.
//!
//! The DCT is separable: eight 1-D transforms along rows, then eight along columns, by a
//! precomputed 8 × 8 cosine matrix (1,024 multiply-adds a block instead of the 4,096 of
//! the direct 2-D sum, which the tests keep as the reference). [`JpegCodec`] owns every
//! plane and reuses it, so a round trip allocates nothing once the frame size is known.

use crate::perception::RgbImage;

/// IJG luminance quantisation table (T.81 Annex K, Table K.1), row-major, quality 50.
const LUMA_Q: [u16; 64] = [
    16, 11, 10, 16, 24, 40, 51, 61, //
    12, 12, 14, 19, 26, 58, 60, 55, //
    14, 13, 16, 24, 40, 57, 69, 56, //
    14, 17, 22, 29, 51, 87, 80, 62, //
    18, 22, 37, 56, 68, 109, 103, 77, //
    24, 35, 55, 64, 81, 104, 113, 92, //
    49, 64, 78, 87, 103, 121, 120, 101, //
    72, 92, 95, 98, 112, 100, 103, 99,
];

/// IJG chrominance quantisation table (T.81 Annex K, Table K.2), row-major, quality 50.
const CHROMA_Q: [u16; 64] = [
    17, 18, 24, 47, 99, 99, 99, 99, //
    18, 21, 26, 66, 99, 99, 99, 99, //
    24, 26, 56, 99, 99, 99, 99, 99, //
    47, 66, 99, 99, 99, 99, 99, 99, //
    99, 99, 99, 99, 99, 99, 99, 99, //
    99, 99, 99, 99, 99, 99, 99, 99, //
    99, 99, 99, 99, 99, 99, 99, 99, //
    99, 99, 99, 99, 99, 99, 99, 99,
];

/// Rounds to the nearest integer (ties to even) for |x| < 2²²: adding and removing
/// 1.5·2²³ leaves the float rounded by the FPU. `f32::round` is a libm call on the baseline
/// x86-64 target, and the round trip rounds every sample and coefficient.
#[inline(always)]
fn rint(x: f32) -> f32 {
    const MAGIC: f32 = 12_582_912.0;
    (x + MAGIC) - MAGIC
}

/// A base table scaled for `quality` (1–100, clamped) as libjpeg scales it.
pub fn scaled_table(base: &[u16; 64], quality: u8) -> [f32; 64] {
    let q = i32::from(quality.clamp(1, 100));
    let scale = if q < 50 { 5000 / q } else { 200 - 2 * q };
    base.map(|b| ((i32::from(b) * scale + 50) / 100).clamp(1, 255) as f32)
}

/// The orthonormal 8-point DCT-II matrix: `C[k][n] = c(k)·cos((2n + 1)kπ/16)` with
/// c(0) = √(1/8), c(k) = √(2/8); its transpose is the inverse.
fn dct_matrix() -> [[f32; 8]; 8] {
    let mut c = [[0.0f32; 8]; 8];
    for (k, row) in c.iter_mut().enumerate() {
        let ck = if k == 0 {
            (1.0f64 / 8.0).sqrt()
        } else {
            (2.0f64 / 8.0).sqrt()
        };
        for (n, v) in row.iter_mut().enumerate() {
            *v = (ck * ((2 * n + 1) as f64 * k as f64 * std::f64::consts::PI / 16.0).cos()) as f32;
        }
    }
    c
}

/// Forward 8 × 8 DCT-II of `block` (row-major) in place, separably with `c`.
pub fn fdct8x8(c: &[[f32; 8]; 8], block: &mut [f32; 64]) {
    let mut tmp = [0.0f32; 64];
    // Rows: tmp[y][k] = Σₙ C[k][n]·block[y][n].
    for y in 0..8 {
        for k in 0..8 {
            let mut s = 0.0;
            for n in 0..8 {
                s += c[k][n] * block[y * 8 + n];
            }
            tmp[y * 8 + k] = s;
        }
    }
    // Columns: block[k][·] = Σₙ C[k][n]·tmp[n][·], a row of eight at a time.
    for k in 0..8 {
        let mut row = [0.0f32; 8];
        for n in 0..8 {
            for x in 0..8 {
                row[x] += c[k][n] * tmp[n * 8 + x];
            }
        }
        block[k * 8..k * 8 + 8].copy_from_slice(&row);
    }
}

/// Inverse of [`fdct8x8`] (the DCT-III), in place.
pub fn idct8x8(c: &[[f32; 8]; 8], block: &mut [f32; 64]) {
    let mut tmp = [0.0f32; 64];
    for y in 0..8 {
        for n in 0..8 {
            let mut s = 0.0;
            for k in 0..8 {
                s += c[k][n] * block[y * 8 + k];
            }
            tmp[y * 8 + n] = s;
        }
    }
    for n in 0..8 {
        let mut row = [0.0f32; 8];
        for k in 0..8 {
            for x in 0..8 {
                row[x] += c[k][n] * tmp[k * 8 + x];
            }
        }
        block[n * 8..n * 8 + 8].copy_from_slice(&row);
    }
}

/// The JPEG round trip with its planes and tables, reused frame after frame.
#[derive(Debug, Clone)]
pub struct JpegCodec {
    dct: [[f32; 8]; 8],
    /// The quality the tables below are scaled for (0: none yet).
    quality: u8,
    luma_q: [f32; 64],
    chroma_q: [f32; 64],
    /// Reciprocals of the tables' entries (the quantiser multiplies).
    luma_inv: [f32; 64],
    chroma_inv: [f32; 64],
    /// Planes padded to whole blocks: luminance at full size, chroma at half.
    y: Vec<f32>,
    cb: Vec<f32>,
    cr: Vec<f32>,
}

impl Default for JpegCodec {
    fn default() -> Self {
        Self::new()
    }
}

impl JpegCodec {
    /// A codec with no planes yet (they are sized by the first frame).
    pub fn new() -> Self {
        Self {
            dct: dct_matrix(),
            quality: 0,
            luma_q: [1.0; 64],
            chroma_q: [1.0; 64],
            luma_inv: [1.0; 64],
            chroma_inv: [1.0; 64],
            y: Vec::new(),
            cb: Vec::new(),
            cr: Vec::new(),
        }
    }

    /// Compresses `img` at `quality` (1–100; values outside are clamped) and decodes it
    /// back into `img`, as a webcam's JPEG stream delivers a frame.
    pub fn round_trip(&mut self, img: &mut RgbImage, quality: u8) {
        let (w, h) = (img.width(), img.height());
        if w == 0 || h == 0 {
            return;
        }
        if quality != self.quality {
            self.quality = quality;
            self.luma_q = scaled_table(&LUMA_Q, quality);
            self.chroma_q = scaled_table(&CHROMA_Q, quality);
            self.luma_inv = self.luma_q.map(|q| 1.0 / q);
            self.chroma_inv = self.chroma_q.map(|q| 1.0 / q);
        }
        // Luminance padded to whole macroblocks, so the chroma planes are whole blocks.
        let (pw, ph) = (w.div_ceil(16) * 16, h.div_ceil(16) * 16);
        let (cw, ch) = (pw / 2, ph / 2);
        self.y.resize(pw * ph, 0.0);
        self.cb.resize(cw * ch, 0.0);
        self.cr.resize(cw * ch, 0.0);
        self.cb.fill(0.0);
        self.cr.fill(0.0);
        let bytes = img.as_bytes();
        // Colour conversion, edge replication and 2 × 2 chroma sums in one pass over the
        // padded luminance.
        for py in 0..ph {
            let sy = py.min(h - 1);
            for px in 0..pw {
                let sx = px.min(w - 1);
                let i = (sy * w + sx) * 3;
                let (r, g, b) = (bytes[i] as f32, bytes[i + 1] as f32, bytes[i + 2] as f32);
                let yy = rint(0.299 * r + 0.587 * g + 0.114 * b);
                let cb = rint(-0.168_736 * r - 0.331_264 * g + 0.5 * b + 128.0).clamp(0.0, 255.0);
                let cr = rint(0.5 * r - 0.418_688 * g - 0.081_312 * b + 128.0).clamp(0.0, 255.0);
                self.y[py * pw + px] = yy;
                let ci = (py / 2) * cw + px / 2;
                self.cb[ci] += cb;
                self.cr[ci] += cr;
            }
        }
        for v in self.cb.iter_mut().chain(self.cr.iter_mut()) {
            *v = rint(*v * 0.25);
        }
        let dct = self.dct;
        code_plane(&dct, &mut self.y, pw, ph, &self.luma_q, &self.luma_inv);
        code_plane(&dct, &mut self.cb, cw, ch, &self.chroma_q, &self.chroma_inv);
        code_plane(&dct, &mut self.cr, cw, ch, &self.chroma_q, &self.chroma_inv);
        let out = img.as_bytes_mut();
        for y in 0..h {
            for x in 0..w {
                let yy = self.y[y * pw + x];
                let ci = (y / 2) * cw + x / 2;
                let (cb, cr) = (self.cb[ci] - 128.0, self.cr[ci] - 128.0);
                let r = yy + 1.402 * cr;
                let g = yy - 0.344_136 * cb - 0.714_136 * cr;
                let b = yy + 1.772 * cb;
                let o = (y * w + x) * 3;
                out[o] = rint(r).clamp(0.0, 255.0) as u8;
                out[o + 1] = rint(g).clamp(0.0, 255.0) as u8;
                out[o + 2] = rint(b).clamp(0.0, 255.0) as u8;
            }
        }
    }
}

/// Encodes and decodes one plane (`w × h`, both multiples of 8, samples 0–255) in place:
/// level shift, DCT, quantise with `q` (`inv` its reciprocals), dequantise, inverse DCT,
/// round and clamp.
fn code_plane(dct: &[[f32; 8]; 8], plane: &mut [f32], w: usize, h: usize, q: &[f32; 64], inv: &[f32; 64]) {
    let mut block = [0.0f32; 64];
    for by in (0..h).step_by(8) {
        for bx in (0..w).step_by(8) {
            for r in 0..8 {
                let row = &plane[(by + r) * w + bx..][..8];
                for (b, &v) in block[r * 8..r * 8 + 8].iter_mut().zip(row) {
                    *b = v - 128.0;
                }
            }
            fdct8x8(dct, &mut block);
            for ((b, &qq), &iq) in block.iter_mut().zip(q).zip(inv) {
                *b = rint(*b * iq) * qq;
            }
            idct8x8(dct, &mut block);
            for r in 0..8 {
                let row = &mut plane[(by + r) * w + bx..][..8];
                for (v, &b) in row.iter_mut().zip(&block[r * 8..r * 8 + 8]) {
                    *v = rint(b + 128.0).clamp(0.0, 255.0);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The 2-D DCT-II straight from its definition, O(n⁴) over the block, in f64.
    fn naive_dct(block: &[f32; 64]) -> [f64; 64] {
        let c = |k: usize| if k == 0 { (0.125f64).sqrt() } else { (0.25f64).sqrt() };
        let mut out = [0.0f64; 64];
        for v in 0..8 {
            for u in 0..8 {
                let mut s = 0.0;
                for y in 0..8 {
                    for x in 0..8 {
                        s += block[y * 8 + x] as f64
                            * ((2 * x + 1) as f64 * u as f64 * std::f64::consts::PI / 16.0).cos()
                            * ((2 * y + 1) as f64 * v as f64 * std::f64::consts::PI / 16.0).cos();
                    }
                }
                out[v * 8 + u] = c(u) * c(v) * s;
            }
        }
        out
    }

    proptest! {
        #[test]
        fn the_separable_dct_matches_the_definition(values in proptest::collection::vec(-128.0f32..128.0, 64)) {
            let mut block = [0.0f32; 64];
            block.copy_from_slice(&values);
            let want = naive_dct(&block);
            let c = dct_matrix();
            let mut got = block;
            fdct8x8(&c, &mut got);
            for i in 0..64 {
                prop_assert!((got[i] as f64 - want[i]).abs() < 2e-3, "coefficient {i}: {} vs {}", got[i], want[i]);
            }
            idct8x8(&c, &mut got);
            for i in 0..64 {
                prop_assert!((got[i] - block[i]).abs() < 1e-3, "sample {i}: {} vs {}", got[i], block[i]);
            }
        }
    }

    /// A test card: smooth colour gradients, a sharp vertical edge and a fine checker.
    fn card(w: usize, h: usize) -> RgbImage {
        let mut img = RgbImage::new(w, h);
        for y in 0..h {
            for x in 0..w {
                let px = if x < w / 3 {
                    [(x * 6) as u8, (y * 2) as u8, 200]
                } else if x < 2 * w / 3 {
                    if (x / 2 + y / 2) % 2 == 0 {
                        [230, 230, 230]
                    } else {
                        [20, 20, 20]
                    }
                } else if y < h / 2 {
                    [220, 40, 30]
                } else {
                    [40, 200, 60]
                };
                img.put(x, y, px);
            }
        }
        img
    }

    fn rms(a: &RgbImage, b: &RgbImage) -> f64 {
        let n = a.as_bytes().len() as f64;
        let s: f64 = a
            .as_bytes()
            .iter()
            .zip(b.as_bytes())
            .map(|(&x, &y)| (x as f64 - y as f64).powi(2))
            .sum();
        (s / n).sqrt()
    }

    /// Mean absolute luminance step across the 8-pixel block boundaries, over that
    /// within blocks: above 1 when blocks show.
    fn blockiness(img: &RgbImage) -> f64 {
        let (w, h) = (img.width(), img.height());
        let luma = |x: usize, y: usize| {
            let p = img.view().get(x, y).unwrap();
            0.299 * p[0] as f64 + 0.587 * p[1] as f64 + 0.114 * p[2] as f64
        };
        let (mut at, mut na, mut inside, mut ni) = (0.0, 0, 0.0, 0);
        for y in 0..h {
            for x in 1..w {
                let d = (luma(x, y) - luma(x - 1, y)).abs();
                if x % 8 == 0 {
                    at += d;
                    na += 1;
                } else {
                    inside += d;
                    ni += 1;
                }
            }
        }
        (at / na as f64) / (inside / ni as f64).max(1e-9)
    }

    #[test]
    fn quality_100_is_near_lossless_and_low_quality_degrades_with_visible_blocks() {
        let original = card(70, 45); // not a multiple of 16: the padding is exercised
        let mut codec = JpegCodec::new();
        let coded = |codec: &mut JpegCodec, q: u8| {
            let mut img = original.clone();
            codec.round_trip(&mut img, q);
            img
        };
        // Quality 100 quantises by 1: only rounding and the chroma subsampling remain,
        // which on the fine grey checker costs nothing and on the colour edges a little.
        let e100 = rms(&coded(&mut codec, 100), &original);
        let e75 = rms(&coded(&mut codec, 75), &original);
        let e10 = rms(&coded(&mut codec, 10), &original);
        assert!(e100 < 6.0, "q100 rms {e100:.2}");
        assert!(
            e75 > e100 && e10 > e75,
            "error grows as quality falls: {e100:.2} {e75:.2} {e10:.2}"
        );
        assert!(e10 < 60.0, "q10 rms {e10:.2} bounded");
        // A smooth gradient (no content at the block period) shows 8 × 8 blocks at low
        // quality, and not at high.
        let mut ramp = RgbImage::new(64, 16);
        for y in 0..16 {
            for x in 0..64 {
                let v = (x * 3 + y) as u8;
                ramp.put(x, y, [v, v / 2 + 40, 180 - v / 2]);
            }
        }
        let mut low = ramp.clone();
        codec.round_trip(&mut low, 5);
        let mut high = ramp.clone();
        codec.round_trip(&mut high, 95);
        let (b_low, b_high) = (blockiness(&low), blockiness(&high));
        assert!(b_low > 2.0, "q5 blockiness {b_low:.2}");
        assert!(b_high < 1.5, "q95 blockiness {b_high:.2}");
        // Grey stays grey (the colour matrices invert each other).
        let mut grey = RgbImage::new(16, 16);
        grey.fill([118, 118, 118]);
        codec.round_trip(&mut grey, 75);
        assert!(grey.as_bytes().iter().all(|&v| v.abs_diff(118) <= 1));
    }

    #[test]
    fn tables_scale_as_libjpeg_does() {
        assert_eq!(scaled_table(&LUMA_Q, 50)[0], 16.0);
        assert_eq!(scaled_table(&LUMA_Q, 100), [1.0; 64]);
        // q = 75: 50 % of the base table, rounded.
        assert_eq!(scaled_table(&LUMA_Q, 75)[0], 8.0);
        assert_eq!(scaled_table(&CHROMA_Q, 75)[63], 50.0);
        // q = 1: 5000 %, clamped to 255.
        assert_eq!(scaled_table(&LUMA_Q, 1)[0], 255.0);
    }
}
