//! Adaptive (local-mean) threshold into black and white masks.
//!
//! Seed 000 §III.A.2 thresholds adaptively "to handle lighting variations" with levels
//! "chosen empirically"; it gives neither the window nor the offset. Ours compares each
//! pixel's grey level g with the mean m of a square window around it (from an integral
//! image, so the cost does not depend on the window): black when g < m − offset, white
//! when g > m + offset, neither in between. The dead band keeps flat regions (where m ≈ g
//! and only noise differs) out of both masks, so they cannot join a mark's blobs.
//!
//! Two scales: a pixel the window leaves in its dead band is decided by a second, wider
//! window when one is given ([`AdaptiveThreshold::wide_window_px`]), so that both thin rims
//! of far marks (which need a window no wider than the mark) and wide black areas of near
//! ones (which need a window wider than the area) are thresholded.
//!
//! Grey is the luma approximation (R + 2G + B)/4.

use crate::perception::Mask;
use crate::perception::image::RgbView;

/// Grey level of an RGB pixel: (R + 2G + B)/4, rounded.
#[inline]
pub fn grey_from_rgb(p: [u8; 3]) -> u8 {
    ((p[0] as u16 + 2 * p[1] as u16 + p[2] as u16 + 2) / 4) as u8
}

/// Writes the grey image of `src` into `grey` (resized to width × height).
pub fn grey_from_view(src: &RgbView<'_>, grey: &mut Vec<u8>) {
    grey.clear();
    grey.extend(
        src.as_bytes()
            .chunks_exact(3)
            .map(|p| grey_from_rgb([p[0], p[1], p[2]])),
    );
}

/// The local-mean threshold's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdaptiveThreshold {
    /// Side of the square averaging window, px (made odd, at least 3).
    pub window_px: usize,
    /// Dead band either side of the local mean, grey levels.
    pub offset: u8,
    /// A wider window (made odd; 0, or not wider than `window_px`: none) that decides the
    /// pixels the first leaves in its dead band. A narrow window sees a small mark's thin
    /// rim against its own bright ring and margin, but in the middle of a black area wider
    /// than itself (a near mark's rim or core) its mean is the pixel's own grey, and the
    /// area goes hollow; there the wider window still sees the surround.
    pub wide_window_px: usize,
}

/// The threshold's reusable integral image (the masks are the caller's).
#[derive(Debug, Clone, Default)]
pub struct Thresholder {
    integral: Vec<u32>,
}

impl Thresholder {
    /// A thresholder with its integral image sized for `width × height`.
    pub fn new(width: usize, height: usize) -> Self {
        Self {
            integral: Vec::with_capacity((width + 1) * (height + 1)),
        }
    }

    /// Thresholds the `width × height` grey image into `black` and `white` (each reset to
    /// that size; a pixel is set in at most one of them).
    pub fn apply(
        &mut self,
        grey: &[u8],
        width: usize,
        height: usize,
        params: &AdaptiveThreshold,
        black: &mut Mask,
        white: &mut Mask,
    ) {
        if width == 0 || height == 0 || grey.len() != width * height {
            black.reset(width, height);
            white.reset(width, height);
            return;
        }
        // Every pixel of both masks, and every entry of the integral image off its zero
        // first row and column, is written below, so none is cleared first.
        black.resize_for_overwrite(width, height);
        white.resize_for_overwrite(width, height);
        let iw = width + 1;
        self.integral.resize(iw * (height + 1), 0);
        self.integral[..iw].fill(0);
        for y in 0..height {
            let mut row = 0u32;
            let (above, here) = self.integral.split_at_mut((y + 1) * iw);
            let above = &above[y * iw..];
            here[0] = 0;
            for x in 0..width {
                row += grey[y * width + x] as u32;
                here[x + 1] = above[x + 1] + row;
            }
        }
        let off = params.offset as u32;
        let (bd, wd) = (black.data_mut(), white.data_mut());
        let r = (params.window_px.max(3) | 1) / 2;
        decide(&self.integral, grey, width, height, r, off, bd, wd, false);
        if params.wide_window_px > 0 {
            let wide = (params.wide_window_px.max(3) | 1) / 2;
            if wide > r {
                decide(&self.integral, grey, width, height, wide, off, bd, wd, true);
            }
        }
    }
}

/// Sets `bd`/`wd` (black and white mask rows) by the mean of the (2r + 1)² window from the
/// integral image `integral`: every pixel when `dead_only` is false, else only the pixels
/// left in neither mask (the narrower window's dead band).
#[allow(clippy::too_many_arguments)]
fn decide(
    integral: &[u32],
    grey: &[u8],
    width: usize,
    height: usize,
    r: usize,
    off: u32,
    bd: &mut [u8],
    wd: &mut [u8],
    dead_only: bool,
) {
    let iw = width + 1;
    // Where a pixel may be set: always (keep = 0, set = 1), or only when it is in neither
    // mask yet. `(b | w) ^ 1` is 1 exactly for those; with `dead_only` off it is forced 1.
    let all = (!dead_only) as u8;
    for y in 0..height {
        let (y0, y1) = (y.saturating_sub(r), (y + r + 1).min(height));
        let (top, bot) = (&integral[y0 * iw..(y0 + 1) * iw], &integral[y1 * iw..(y1 + 1) * iw]);
        let rows = (y1 - y0) as u32;
        let g_row = &grey[y * width..(y + 1) * width];
        let (b_row, w_row) = (&mut bd[y * width..(y + 1) * width], &mut wd[y * width..(y + 1) * width]);
        // g < m − off  ⇔  (g + off)·n < Σ;  g > m + off  ⇔  g·n > Σ + off·n.
        let mut one = |x: usize| {
            let (x0, x1) = (x.saturating_sub(r), (x + r + 1).min(width));
            let sum = bot[x1] + top[x0] - top[x1] - bot[x0];
            let n = rows * (x1 - x0) as u32;
            let g = g_row[x] as u32;
            let free = all | ((b_row[x] | w_row[x]) ^ 1);
            let (b, w) = (((g + off) * n < sum) as u8, (g * n > sum + off * n) as u8);
            b_row[x] = (b_row[x] & (free ^ 1)) | (b & free);
            w_row[x] = (w_row[x] & (free ^ 1)) | (w & free);
        };
        if width <= 2 * r + 1 {
            (0..width).for_each(&mut one);
            continue;
        }
        (0..r).for_each(&mut one);
        (width - r - 1..width).for_each(&mut one);
        // Interior: the whole window in the row, a constant n; branch-free so it
        // vectorises.
        let n = rows * (2 * r + 1) as u32;
        let m = width - 2 * r - 1;
        let (tl, tr, bl, br) = (&top[..m], &top[2 * r + 1..][..m], &bot[..m], &bot[2 * r + 1..][..m]);
        let g_mid = &g_row[r..][..m];
        let (b_mid, w_mid) = (&mut b_row[r..][..m], &mut w_row[r..][..m]);
        for i in 0..m {
            let sum = br[i] + tl[i] - tr[i] - bl[i];
            let g = g_mid[i] as u32;
            let free = all | ((b_mid[i] | w_mid[i]) ^ 1);
            let (b, w) = (((g + off) * n < sum) as u8, (g * n > sum + off * n) as u8);
            b_mid[i] = (b_mid[i] & (free ^ 1)) | (b & free);
            w_mid[i] = (w_mid[i] & (free ^ 1)) | (w & free);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_dark_square_on_grey_is_black_its_surround_white_and_flat_areas_neither() {
        let (w, h) = (40, 30);
        let mut grey = vec![120u8; w * h];
        for y in 10..20 {
            for x in 15..25 {
                grey[y * w + x] = 20;
            }
        }
        let (mut b, mut wh) = (Mask::new(1, 1), Mask::new(1, 1));
        let p = AdaptiveThreshold {
            window_px: 15,
            offset: 8,
            wide_window_px: 0,
        };
        Thresholder::new(w, h).apply(&grey, w, h, &p, &mut b, &mut wh);
        assert!(b.get(20, 15) && !wh.get(20, 15), "inside the square");
        assert!(wh.get(14, 15) && !b.get(14, 15), "just outside: brighter than its mean");
        assert!(!b.get(2, 2) && !wh.get(2, 2), "far away: flat");
        // Never both.
        assert!(b.data().iter().zip(wh.data()).all(|(p, q)| p & q == 0));
    }

    #[test]
    fn a_wide_window_decides_only_the_narrow_ones_dead_band() {
        // A dark square 21 px wide on grey: a 7-px window leaves its middle in the dead
        // band (the mean there is the pixel's own grey), a 41-px one fills it in.
        let (w, h) = (60, 50);
        let mut grey = vec![120u8; w * h];
        for y in 15..36 {
            for x in 20..41 {
                grey[y * w + x] = 20;
            }
        }
        let narrow = AdaptiveThreshold {
            window_px: 7,
            offset: 8,
            wide_window_px: 0,
        };
        let both = AdaptiveThreshold {
            wide_window_px: 41,
            ..narrow
        };
        let mut t = Thresholder::new(w, h);
        let (mut b1, mut w1) = (Mask::new(1, 1), Mask::new(1, 1));
        t.apply(&grey, w, h, &narrow, &mut b1, &mut w1);
        assert!(
            b1.get(20, 25) && !b1.get(30, 25),
            "narrow alone: the edge is black, the middle hollow"
        );
        let (mut b2, mut w2) = (Mask::new(1, 1), Mask::new(1, 1));
        t.apply(&grey, w, h, &both, &mut b2, &mut w2);
        assert!(b2.get(30, 25) && !w2.get(30, 25), "the wide window fills the middle");
        // Every pixel the narrow window decided keeps its decision; none is in both masks.
        for i in 0..w * h {
            let (x, y) = (i % w, i / w);
            if b1.get(x, y) || w1.get(x, y) {
                assert_eq!((b2.get(x, y), w2.get(x, y)), (b1.get(x, y), w1.get(x, y)), "({x}, {y})");
            }
            assert!(!(b2.get(x, y) && w2.get(x, y)), "({x}, {y})");
        }
        // A wide window no wider than the narrow one changes nothing.
        let same = AdaptiveThreshold {
            wide_window_px: 7,
            ..narrow
        };
        let (mut b3, mut w3) = (Mask::new(1, 1), Mask::new(1, 1));
        t.apply(&grey, w, h, &same, &mut b3, &mut w3);
        assert_eq!((b3.data(), w3.data()), (b1.data(), w1.data()));
    }

    #[test]
    fn the_integral_agrees_with_a_direct_window_mean() {
        let (w, h) = (17, 13);
        let grey: Vec<u8> = (0..w * h).map(|i| ((i * 37 + i / 7 * 11) % 256) as u8).collect();
        let (mut b, mut wh) = (Mask::new(1, 1), Mask::new(1, 1));
        let p = AdaptiveThreshold {
            window_px: 5,
            offset: 3,
            wide_window_px: 0,
        };
        // The buffers are reused, not cleared: first a larger frame and then a bright one
        // of the same size leave every mask pixel and integral entry set before the frame
        // checked.
        let mut t = Thresholder::new(w, h);
        let big: Vec<u8> = (0..40 * 30).map(|i| (i * 91 % 256) as u8).collect();
        t.apply(&big, 40, 30, &p, &mut b, &mut wh);
        t.apply(&vec![255; w * h], w, h, &p, &mut b, &mut wh);
        t.apply(&grey, w, h, &p, &mut b, &mut wh);
        for y in 0..h {
            for x in 0..w {
                let (mut s, mut n) = (0i64, 0i64);
                for yy in y.saturating_sub(2)..(y + 3).min(h) {
                    for xx in x.saturating_sub(2)..(x + 3).min(w) {
                        s += grey[yy * w + xx] as i64;
                        n += 1;
                    }
                }
                let g = grey[y * w + x] as i64;
                assert_eq!(b.get(x, y), (g + 3) * n < s, "({x}, {y})");
                assert_eq!(wh.get(x, y), g * n > s + 3 * n, "({x}, {y})");
            }
        }
    }

    proptest::proptest! {
        /// The integral image, the branch-free interior and the clipped borders against
        /// a plain 64-bit window sum, over small and large images, windows from 3 to
        /// 238 px, and every offset.
        #[test]
        fn the_masks_agree_with_a_plain_window_sum(
            (w, h, window) in proptest::prop_oneof![
                (1usize..48, 1usize..40, 3usize..15),
                (240usize..300, 240usize..260, 183usize..239),
            ],
            offset in proptest::prelude::any::<u8>(),
            seed in 0u64..1000,
        ) {
            let grey: Vec<u8> = (0..w * h).map(|i| (mix(seed, i as u64) % 256) as u8).collect();
            let p = AdaptiveThreshold { window_px: window, offset };
            let (mut b, mut wh) = (Mask::new(1, 1), Mask::new(1, 1));
            Thresholder::new(w, h).apply(&grey, w, h, &p, &mut b, &mut wh);
            // Reference: 64-bit cumulative sums, clipped windows.
            let mut cum = vec![0u64; (w + 1) * (h + 1)];
            for y in 0..h {
                for x in 0..w {
                    cum[(y + 1) * (w + 1) + x + 1] = grey[y * w + x] as u64 + cum[y * (w + 1) + x + 1]
                        + cum[(y + 1) * (w + 1) + x]
                        - cum[y * (w + 1) + x];
                }
            }
            let r = (window.max(3) | 1) / 2;
            for y in 0..h {
                for x in 0..w {
                    let (y0, y1, x0, x1) = (y.saturating_sub(r), (y + r + 1).min(h), x.saturating_sub(r), (x + r + 1).min(w));
                    let s = cum[y1 * (w + 1) + x1] + cum[y0 * (w + 1) + x0] - cum[y0 * (w + 1) + x1] - cum[y1 * (w + 1) + x0];
                    let n = ((y1 - y0) * (x1 - x0)) as u64;
                    let (g, off) = (grey[y * w + x] as u64, offset as u64);
                    proptest::prop_assert_eq!(b.get(x, y), (g + off) * n < s, "black ({}, {})", x, y);
                    proptest::prop_assert_eq!(wh.get(x, y), g * n > s + off * n, "white ({}, {})", x, y);
                }
            }
        }
    }

    /// A cheap hash for test images: varied levels without an RNG dependency.
    fn mix(seed: u64, i: u64) -> u64 {
        let mut z = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ i.wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z ^= z >> 31;
        z.wrapping_mul(0x94D0_49BB_1331_11EB) >> 17
    }

    #[test]
    fn degenerate_sizes_give_empty_masks() {
        let (mut b, mut wh) = (Mask::new(1, 1), Mask::new(1, 1));
        let p = AdaptiveThreshold {
            window_px: 9,
            offset: 8,
            wide_window_px: 0,
        };
        let mut t = Thresholder::default();
        t.apply(&[], 0, 0, &p, &mut b, &mut wh);
        assert_eq!(b.size(), (0, 0));
        t.apply(&[7], 1, 1, &p, &mut b, &mut wh);
        assert_eq!((b.count(), wh.count()), (0, 0));
    }
}
