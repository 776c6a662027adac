//! Y′CbCr camera frames to packed RGB8: the packed 4:2:2 layouts UVC webcams and V4L2
//! drivers deliver (`yuyv`, `uyvy`) and the 4:2:0 semi-planar ones of phone and embedded
//! camera pipelines (`nv12`, `nv21`).
//!
//! **Matrix and range: BT.601, limited ("studio") range**, Y′ in 16..=235 and Cb, Cr in
//! 16..=240 centred on 128. That is what UVC webcams send (the UVC colour matching
//! descriptor's default is BT.601 / SMPTE 170M) and what V4L2 assumes for their YUYV
//! frames. A camera that sends full range or BT.709 still decodes, a little too
//! contrasty or with slightly shifted hues; values outside the nominal range are clamped
//! after conversion, never refused:
//!
//! ```text
//! R = 1.164 (Y′ − 16)                 + 1.596 (Cr − 128)
//! G = 1.164 (Y′ − 16) − 0.392 (Cb − 128) − 0.813 (Cr − 128)
//! B = 1.164 (Y′ − 16) + 2.017 (Cb − 128)
//! ```
//!
//! computed in 16-bit fixed point ([`rgb_from_ycbcr`]; within 1 of the real-valued
//! formula, rounded, for every one of the 2²⁴ inputs: a unit test checks them all).
//!
//! **Chroma siting.** 4:2:2 shares one Cb, Cr pair between two horizontally adjacent
//! pixels, 4:2:0 between a 2×2 block; each pixel takes its block's pair as it is
//! (nearest, no interpolation). Colour segmentation works on blobs many pixels wide, so
//! interpolating chroma would cost time for no gain in what it finds.
//!
//! The layouts (V4L2's and ROS's `sensor_msgs/image_encodings`): a `yuyv` row is
//! `Y0 Cb Y1 Cr` per pixel pair, `uyvy` `Cb Y0 Cr Y1`, `step` bytes apart; `nv12` is
//! `height` rows of Y′ then `height / 2` rows of interleaved `Cb Cr` (`nv21`: `Cr Cb`),
//! all `step` bytes apart. The sizes are checked by the caller
//! ([`super::pixels::rgb_into_raw`]): these kernels take a validated buffer.

use crate::perception::RgbImage;

/// Byte order of a packed 4:2:2 pixel pair.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Packing {
    /// `Y0 Cb Y1 Cr` (V4L2 `YUYV`, ROS `yuyv` and the older `yuv422_yuy2`).
    Yuyv,
    /// `Cb Y0 Cr Y1` (V4L2 `UYVY`, ROS `uyvy` and the older `yuv422`).
    Uyvy,
}

impl Packing {
    /// Offsets of Y0, Cb, Y1 and Cr in a 4-byte pair.
    fn offsets(self) -> [usize; 4] {
        match self {
            Packing::Yuyv => [0, 1, 2, 3],
            Packing::Uyvy => [1, 0, 3, 2],
        }
    }
}

/// Order of the two chroma samples in a 4:2:0 semi-planar frame's chroma plane.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ChromaOrder {
    /// `Cb Cr` (`nv12`).
    CbCr,
    /// `Cr Cb` (`nv21`).
    CrCb,
}

/// BT.601 limited-range coefficients × 2¹⁶ (255/219, and 255/224 times the matrix's).
const YK: i32 = 76309;
const RV: i32 = 104597;
const GU: i32 = 25675;
const GV: i32 = 53279;
const BU: i32 = 132201;
const HALF: i32 = 1 << 15;

fn clamp8(v: i32) -> u8 {
    v.clamp(0, 255) as u8
}

/// One BT.601 limited-range Y′CbCr sample to RGB, in fixed point (round half up, then
/// clamped to 0..=255).
///
/// # Example
///
/// ```
/// use marsupial::msgs::yuv::rgb_from_ycbcr;
///
/// assert_eq!(rgb_from_ycbcr(16, 128, 128), [0, 0, 0]); // studio black
/// assert_eq!(rgb_from_ycbcr(235, 128, 128), [255, 255, 255]); // studio white
/// let [r, g, b] = rgb_from_ycbcr(81, 90, 240); // BT.601 red
/// assert!(r >= 254 && g == 0 && b == 0);
/// ```
#[inline]
pub fn rgb_from_ycbcr(y: u8, cb: u8, cr: u8) -> [u8; 3] {
    let y = (i32::from(y) - 16) * YK + HALF;
    let u = i32::from(cb) - 128;
    let v = i32::from(cr) - 128;
    [
        clamp8((y + RV * v) >> 16),
        clamp8((y - GU * u - GV * v) >> 16),
        clamp8((y + BU * u) >> 16),
    ]
}

/// A validated packed 4:2:2 buffer (`width` even, `step ≥ 2·width`, `height` rows) into
/// `out`, which is `width × height`.
pub(crate) fn fill_from_yuv422(packing: Packing, step: usize, data: &[u8], out: &mut RgbImage) {
    let [y0, u, y1, v] = packing.offsets();
    let w = out.width();
    for (row, dst) in out.as_bytes_mut().chunks_exact_mut(w * 3).enumerate() {
        let Some(src) = data.get(row * step..row * step + 2 * w) else {
            return;
        };
        for (d, s) in dst.chunks_exact_mut(6).zip(src.chunks_exact(4)) {
            d[..3].copy_from_slice(&rgb_from_ycbcr(s[y0], s[u], s[v]));
            d[3..].copy_from_slice(&rgb_from_ycbcr(s[y1], s[u], s[v]));
        }
    }
}

/// A validated 4:2:0 semi-planar buffer (`width` and `height` even, `step ≥ width`,
/// `height · 3 / 2` rows) into `out`, which is `width × height`.
pub(crate) fn fill_from_nv(order: ChromaOrder, step: usize, data: &[u8], out: &mut RgbImage) {
    let (u, v) = match order {
        ChromaOrder::CbCr => (0, 1),
        ChromaOrder::CrCb => (1, 0),
    };
    let (w, h) = (out.width(), out.height());
    let chroma = step * h;
    for (row, dst) in out.as_bytes_mut().chunks_exact_mut(w * 3).enumerate() {
        let c0 = chroma + (row / 2) * step;
        let (Some(luma), Some(c)) = (data.get(row * step..row * step + w), data.get(c0..c0 + w)) else {
            return;
        };
        for ((d, l), c) in dst.chunks_exact_mut(6).zip(luma.chunks_exact(2)).zip(c.chunks_exact(2)) {
            d[..3].copy_from_slice(&rgb_from_ycbcr(l[0], c[u], c[v]));
            d[3..].copy_from_slice(&rgb_from_ycbcr(l[1], c[u], c[v]));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The real-valued BT.601 limited-range formula, rounded and clamped.
    fn reference(y: u8, cb: u8, cr: u8) -> [u8; 3] {
        let (kr, kb) = (0.299, 0.114);
        let kg = 1.0 - kr - kb;
        let y = (f64::from(y) - 16.0) * 255.0 / 219.0;
        let u = (f64::from(cb) - 128.0) * 255.0 / 224.0;
        let v = (f64::from(cr) - 128.0) * 255.0 / 224.0;
        let r = y + 2.0 * (1.0 - kr) * v;
        let g = y - 2.0 * kb * (1.0 - kb) / kg * u - 2.0 * kr * (1.0 - kr) / kg * v;
        let b = y + 2.0 * (1.0 - kb) * u;
        [r, g, b].map(|c| c.round().clamp(0.0, 255.0) as u8)
    }

    #[test]
    fn fixed_point_is_within_one_of_the_formula_for_every_input() {
        let mut worst = 0;
        for y in 0..=255u8 {
            for cb in 0..=255u8 {
                for cr in 0..=255u8 {
                    let (got, want) = (rgb_from_ycbcr(y, cb, cr), reference(y, cb, cr));
                    for c in 0..3 {
                        worst = worst.max(got[c].abs_diff(want[c]));
                    }
                }
            }
        }
        assert!(worst <= 1, "worst {worst}");
    }

    /// Pixel (x, y) of a packed 4:2:2 buffer, straight from the layout's definition.
    fn yuv422_pixel(packing: Packing, step: usize, data: &[u8], x: usize, y: usize) -> [u8; 3] {
        let pair = &data[y * step + (x / 2) * 4..][..4];
        let (luma, cb, cr) = match packing {
            Packing::Yuyv => ([pair[0], pair[2]][x % 2], pair[1], pair[3]),
            Packing::Uyvy => ([pair[1], pair[3]][x % 2], pair[0], pair[2]),
        };
        reference(luma, cb, cr)
    }

    /// Pixel (x, y) of a 4:2:0 semi-planar buffer, from the layout's definition.
    fn nv_pixel(order: ChromaOrder, h: usize, step: usize, data: &[u8], x: usize, y: usize) -> [u8; 3] {
        let luma = data[y * step + x];
        let c = &data[h * step + (y / 2) * step + (x / 2) * 2..][..2];
        let (cb, cr) = match order {
            ChromaOrder::CbCr => (c[0], c[1]),
            ChromaOrder::CrCb => (c[1], c[0]),
        };
        reference(luma, cb, cr)
    }

    fn noise(n: usize, seed: u64) -> Vec<u8> {
        let mut x = seed | 1;
        (0..n)
            .map(|_| {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                x as u8
            })
            .collect()
    }

    fn within_one(got: &RgbImage, want: impl Fn(usize, usize) -> [u8; 3]) -> bool {
        (0..got.height()).all(|y| {
            (0..got.width()).all(|x| {
                let g = &got.as_bytes()[(y * got.width() + x) * 3..][..3];
                g.iter().zip(want(x, y)).all(|(a, b)| a.abs_diff(b) <= 1)
            })
        })
    }

    proptest::proptest! {
        /// Both 4:2:2 byte orders, any even width, row pad and content, match the
        /// per-pixel reading of the layout.
        #[test]
        fn yuv422_matches_the_layout(pairs in 1usize..6, h in 1usize..6, pad in 0usize..5, uyvy: bool, seed: u64) {
            let packing = if uyvy { Packing::Uyvy } else { Packing::Yuyv };
            let (w, step) = (pairs * 2, pairs * 4 + pad);
            let data = noise(step * h, seed);
            let mut out = RgbImage::new(w, h);
            fill_from_yuv422(packing, step, &data, &mut out);
            proptest::prop_assert!(within_one(&out, |x, y| yuv422_pixel(packing, step, &data, x, y)));
        }

        /// NV12 and NV21, any even size, row pad and content, match the per-pixel reading
        /// of the layout.
        #[test]
        fn nv_matches_the_layout(hw in 1usize..6, hh in 1usize..5, pad in 0usize..5, nv21: bool, seed: u64) {
            let order = if nv21 { ChromaOrder::CrCb } else { ChromaOrder::CbCr };
            let (w, h) = (hw * 2, hh * 2);
            let step = w + pad;
            let data = noise(step * (h + h / 2), seed);
            let mut out = RgbImage::new(w, h);
            fill_from_nv(order, step, &data, &mut out);
            proptest::prop_assert!(within_one(&out, |x, y| nv_pixel(order, h, step, &data, x, y)));
        }
    }
}
