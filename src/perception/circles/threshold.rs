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
//! ones (which need a window wider than the area) are thresholded. Both means come from
//! the one integral image in the same pass over the pixels, branch-free (the wide verdict
//! is computed for every pixel and kept only in the dead band), so the second window adds
//! a few vector operations per pixel, not a second pass over the frame. The grey image
//! ([`Thresholder::apply_rgb`]) is made row by row as the integral image is summed.
//!
//! Grey is the luma approximation (R + 2G + B)/4.
//!
//! [`Threshold::Fixed`] is the alternative the paper measured against its own (seed 000
//! §V-E: fixed thresholds docked 8 of 15 runs under an uneven shadow): two global grey
//! levels, the same everywhere in the frame. It exists to be compared with the adaptive
//! one (a shadow across the module's face darkens the white of its marks below any
//! level that also keeps the lit ones' black), not as a default.

use crate::perception::Mask;
use crate::perception::image::RgbView;

/// Grey level of an RGB pixel: (R + 2G + B)/4, rounded.
#[inline]
pub fn grey_from_rgb(p: [u8; 3]) -> u8 {
    ((p[0] as u16 + 2 * p[1] as u16 + p[2] as u16 + 2) / 4) as u8
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

/// Two global grey levels: black below the first, white above the second.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FixedThreshold {
    /// Pixels darker than this are black.
    pub black_below: u8,
    /// Pixels brighter than this are white.
    pub white_above: u8,
}

/// How grey levels become the black and white masks.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Threshold {
    /// Against the local mean (ours, the default).
    Adaptive(AdaptiveThreshold),
    /// Against two global levels (the comparison of seed 000 §V-E).
    Fixed(FixedThreshold),
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
        self.start(width, height);
        for (y, g_row) in grey.chunks_exact(width).enumerate() {
            self.integral_row(y, g_row);
        }
        self.decide(grey, width, height, params, black, white);
    }

    /// [`Thresholder::apply`] on the grey image of `src` ([`grey_from_rgb`]), which it
    /// writes into `grey` (resized to the frame) row by row as it builds the integral
    /// image: each grey row is summed while it is still in cache.
    pub fn apply_rgb(
        &mut self,
        src: &RgbView<'_>,
        grey: &mut Vec<u8>,
        params: &AdaptiveThreshold,
        black: &mut Mask,
        white: &mut Mask,
    ) {
        let (width, height) = (src.width(), src.height());
        grey.resize(width * height, 0);
        if width == 0 || height == 0 {
            black.reset(width, height);
            white.reset(width, height);
            return;
        }
        self.start(width, height);
        for (y, (g_row, rgb)) in grey
            .chunks_exact_mut(width)
            .zip(src.as_bytes().chunks_exact(3 * width))
            .enumerate()
        {
            for (g, p) in g_row.iter_mut().zip(rgb.chunks_exact(3)) {
                *g = grey_from_rgb([p[0], p[1], p[2]]);
            }
            self.integral_row(y, g_row);
        }
        self.decide(grey, width, height, params, black, white);
    }

    /// Thresholds the grey image of `src` by `threshold`: [`Thresholder::apply_rgb`] for
    /// the adaptive one; for fixed levels, the grey image (written into `grey` likewise)
    /// against the two levels, pixel by pixel, with no integral image.
    pub fn apply_rgb_with(
        &mut self,
        src: &RgbView<'_>,
        grey: &mut Vec<u8>,
        threshold: &Threshold,
        black: &mut Mask,
        white: &mut Mask,
    ) {
        let levels = match threshold {
            Threshold::Adaptive(p) => return self.apply_rgb(src, grey, p, black, white),
            Threshold::Fixed(levels) => *levels,
        };
        let (width, height) = (src.width(), src.height());
        grey.resize(width * height, 0);
        black.resize_for_overwrite(width, height);
        white.resize_for_overwrite(width, height);
        let pixels = grey.iter_mut().zip(src.as_bytes().chunks_exact(3));
        for (((g, p), b), w) in pixels.zip(black.data_mut()).zip(white.data_mut()) {
            *g = grey_from_rgb([p[0], p[1], p[2]]);
            *b = (*g < levels.black_below) as u8;
            *w = (*g > levels.white_above) as u8;
        }
    }

    /// Sizes the integral image for `width × height` and zeroes its first row. Every
    /// other entry, and every pixel of the masks, is written before it is read, so none
    /// is cleared.
    fn start(&mut self, width: usize, height: usize) {
        let iw = width + 1;
        self.integral.resize(iw * (height + 1), 0);
        self.integral[..iw].fill(0);
    }

    /// Writes row `y` + 1 of the integral image from grey row `y` and the row above.
    fn integral_row(&mut self, y: usize, g_row: &[u8]) {
        let iw = g_row.len() + 1;
        let (above, here) = self.integral.split_at_mut((y + 1) * iw);
        let above = &above[y * iw + 1..][..iw - 1];
        let here = &mut here[..iw];
        here[0] = 0;
        let mut row = 0u32;
        for ((h, &a), &g) in here[1..].iter_mut().zip(above).zip(g_row) {
            // Wrapping: see `box_sum`.
            row = row.wrapping_add(g as u32);
            *h = a.wrapping_add(row);
        }
    }

    /// Both masks from the integral image [`Thresholder::start`] and
    /// [`Thresholder::integral_row`] built.
    fn decide(
        &self,
        grey: &[u8],
        width: usize,
        height: usize,
        params: &AdaptiveThreshold,
        black: &mut Mask,
        white: &mut Mask,
    ) {
        black.resize_for_overwrite(width, height);
        white.resize_for_overwrite(width, height);
        let off = params.offset as i32;
        let (bd, wd) = (black.data_mut(), white.data_mut());
        let r = (params.window_px.max(3) | 1) / 2;
        let wide = (params.wide_window_px.max(3) | 1) / 2;
        if params.wide_window_px > 0 && wide > r {
            decide::<true>(&self.integral, grey, width, height, r, wide, off, bd, wd);
        } else {
            decide::<false>(&self.integral, grey, width, height, r, r, off, bd, wd);
        }
    }
}

/// One window's integral rows for image row `y`: the rows bounding the (2r + 1)² window,
/// clipped to the image, and how many image rows that spans.
#[derive(Clone, Copy)]
struct Window<'a> {
    top: &'a [u32],
    bot: &'a [u32],
    rows: u32,
    r: usize,
}

impl<'a> Window<'a> {
    fn at(integral: &'a [u32], iw: usize, height: usize, y: usize, r: usize) -> Self {
        let (y0, y1) = (y.saturating_sub(r), (y + r + 1).min(height));
        Self {
            top: &integral[y0 * iw..(y0 + 1) * iw],
            bot: &integral[y1 * iw..(y1 + 1) * iw],
            rows: (y1 - y0) as u32,
            r,
        }
    }

    /// Sum and pixel count of the window around column `x`, clipped to `width`.
    #[inline(always)]
    fn clipped(&self, x: usize, width: usize) -> (i32, i32) {
        let (x0, x1) = (x.saturating_sub(self.r), (x + self.r + 1).min(width));
        (
            box_sum(self.bot[x1], self.top[x0], self.top[x1], self.bot[x0]),
            (self.rows * (x1 - x0) as u32) as i32,
        )
    }
}

/// A window's sum from its integral corners (bottom-right, top-left, top-right,
/// bottom-left). The integral image wraps modulo 2³², so this is exact for any window
/// of fewer than 2³¹ / 255 (8.4 M) pixels, however large the image.
#[inline(always)]
fn box_sum(br: u32, tl: u32, tr: u32, bl: u32) -> i32 {
    br.wrapping_add(tl).wrapping_sub(tr).wrapping_sub(bl) as i32
}

/// Black and white verdicts (0 or 1) of grey level `g` against a window of `n` pixels
/// summing to `sum`, mean m = Σ/n: with d = Σ − g·n = n·(m − g), g < m − off ⇔ d > off·n
/// and g > m + off ⇔ d < −off·n (`off_n` = off·n). Signed, so that both are one compare.
#[inline(always)]
fn verdict(g: i32, off_n: i32, sum: i32, n: i32) -> (u8, u8) {
    let d = sum - g * n;
    ((d > off_n) as u8, (d < -off_n) as u8)
}

/// The narrow window's verdict, and where it is in neither mask (its dead band) the wide
/// one's: `(b, w)` of the narrow window, `(bw, ww)` of the wide.
#[inline(always)]
fn combine((b, w): (u8, u8), (bw, ww): (u8, u8)) -> (u8, u8) {
    let dead = (b | w) ^ 1;
    (b | (dead & bw), w | (dead & ww))
}

/// Sets every pixel of `bd`/`wd` (black and white mask rows) in one pass: by the mean of
/// the (2r + 1)² window from the integral image `integral`, and when `TWO`, the pixels
/// that leaves in its dead band by the mean of the (2·wide + 1)² window (`wide` > r).
#[allow(clippy::too_many_arguments)]
fn decide<const TWO: bool>(
    integral: &[u32],
    grey: &[u8],
    width: usize,
    height: usize,
    r: usize,
    wide: usize,
    off: i32,
    bd: &mut [u8],
    wd: &mut [u8],
) {
    let iw = width + 1;
    // The widest window in use: columns closer than this to a side clip it.
    let reach = if TWO { wide } else { r };
    for y in 0..height {
        let nw = Window::at(integral, iw, height, y, r);
        let ww = Window::at(integral, iw, height, y, wide);
        let g_row = &grey[y * width..(y + 1) * width];
        let (b_row, w_row) = (&mut bd[y * width..(y + 1) * width], &mut wd[y * width..(y + 1) * width]);
        let mut one = |x: usize| {
            let g = g_row[x] as i32;
            let (s, n) = nw.clipped(x, width);
            let mut v = verdict(g, off * n, s, n);
            if TWO {
                let (s, n) = ww.clipped(x, width);
                v = combine(v, verdict(g, off * n, s, n));
            }
            (b_row[x], w_row[x]) = v;
        };
        if width <= 2 * reach + 1 {
            (0..width).for_each(&mut one);
            continue;
        }
        (0..reach).for_each(&mut one);
        (width - reach - 1..width).for_each(&mut one);
        // Interior: both windows whole within the row, constant counts; branch-free so
        // it vectorises.
        let m = width - 2 * reach - 1;
        let nn = (nw.rows * (2 * r + 1) as u32) as i32;
        let (tl, tr) = (&nw.top[reach - r..][..m], &nw.top[reach + r + 1..][..m]);
        let (bl, br) = (&nw.bot[reach - r..][..m], &nw.bot[reach + r + 1..][..m]);
        let nwide = (ww.rows * (2 * wide + 1) as u32) as i32;
        let (off_nn, off_nw) = (off * nn, off * nwide);
        let (wtl, wtr) = (&ww.top[reach - wide..][..m], &ww.top[reach + wide + 1..][..m]);
        let (wbl, wbr) = (&ww.bot[reach - wide..][..m], &ww.bot[reach + wide + 1..][..m]);
        let g_mid = &g_row[reach..][..m];
        let (b_mid, w_mid) = (&mut b_row[reach..][..m], &mut w_row[reach..][..m]);
        for i in 0..m {
            let g = g_mid[i] as i32;
            let mut v = verdict(g, off_nn, box_sum(br[i], tl[i], tr[i], bl[i]), nn);
            if TWO {
                v = combine(v, verdict(g, off_nw, box_sum(wbr[i], wtl[i], wtr[i], wbl[i]), nwide));
            }
            (b_mid[i], w_mid[i]) = v;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::ops::Range;

    /// A `w`×`h` grey (120) image with a dark (20) square over columns `xs`, rows `ys`.
    fn dark_square_on_grey(w: usize, h: usize, xs: Range<usize>, ys: Range<usize>) -> Vec<u8> {
        let mut grey = vec![120u8; w * h];
        for y in ys {
            grey[y * w + xs.start..y * w + xs.end].fill(20);
        }
        grey
    }

    #[test]
    fn a_dark_square_on_grey_is_black_its_surround_white_and_flat_areas_neither() {
        let (w, h) = (40, 30);
        let grey = dark_square_on_grey(w, h, 15..25, 10..20);
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
        let grey = dark_square_on_grey(w, h, 20..41, 15..36);
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

    /// The reference: each pixel's verdict from a plain 64-bit window sum, clipped to
    /// the image, by the narrow window, and where that leaves it in the dead band by the
    /// wide one (when it is wider).
    fn reference(grey: &[u8], w: usize, h: usize, p: &AdaptiveThreshold) -> (Vec<bool>, Vec<bool>) {
        let mut cum = vec![0u64; (w + 1) * (h + 1)];
        for y in 0..h {
            for x in 0..w {
                cum[(y + 1) * (w + 1) + x + 1] =
                    grey[y * w + x] as u64 + cum[y * (w + 1) + x + 1] + cum[(y + 1) * (w + 1) + x]
                        - cum[y * (w + 1) + x];
            }
        }
        let off = p.offset as u64;
        let at = |x: usize, y: usize, r: usize| {
            let (y0, y1, x0, x1) = (
                y.saturating_sub(r),
                (y + r + 1).min(h),
                x.saturating_sub(r),
                (x + r + 1).min(w),
            );
            let s = cum[y1 * (w + 1) + x1] + cum[y0 * (w + 1) + x0] - cum[y0 * (w + 1) + x1] - cum[y1 * (w + 1) + x0];
            let n = ((y1 - y0) * (x1 - x0)) as u64;
            let g = grey[y * w + x] as u64;
            ((g + off) * n < s, g * n > s + off * n)
        };
        let r = (p.window_px.max(3) | 1) / 2;
        let wide = (p.wide_window_px.max(3) | 1) / 2;
        let (mut b, mut wh) = (vec![false; w * h], vec![false; w * h]);
        for y in 0..h {
            for x in 0..w {
                let mut v = at(x, y, r);
                if v == (false, false) && p.wide_window_px > 0 && wide > r {
                    v = at(x, y, wide);
                }
                (b[y * w + x], wh[y * w + x]) = v;
            }
        }
        (b, wh)
    }

    proptest::proptest! {
        /// The integral image, the branch-free interior and the clipped borders of one
        /// window or two against the plain reference, over small and large images,
        /// windows from 3 to 238 px, wide windows narrower (ignored) and wider, and every
        /// offset; the images are noise or blocks of noise (wide flat areas, where the
        /// narrow window's dead band leaves the pixels to the wide one).
        #[test]
        fn the_masks_agree_with_a_plain_window_sum(
            (w, h, window, wide) in proptest::prop_oneof![
                (1usize..48, 1usize..40, 3usize..15, 0usize..40),
                (240usize..300, 240usize..260, 183usize..239, 0usize..300),
                (60usize..200, 40usize..120, 3usize..11, 11usize..41),
            ],
            offset in proptest::prelude::any::<u8>(),
            block in 1usize..12,
            seed in 0u64..1000,
        ) {
            let grey: Vec<u8> =
                (0..w * h).map(|i| (mix(seed, ((i % w) / block + (i / w / block) * w) as u64) % 256) as u8).collect();
            let p = AdaptiveThreshold { window_px: window, offset, wide_window_px: wide };
            let (mut b, mut wh) = (Mask::new(1, 1), Mask::new(1, 1));
            Thresholder::new(w, h).apply(&grey, w, h, &p, &mut b, &mut wh);
            let (rb, rw) = reference(&grey, w, h, &p);
            for y in 0..h {
                for x in 0..w {
                    proptest::prop_assert_eq!(b.get(x, y), rb[y * w + x], "black ({}, {})", x, y);
                    proptest::prop_assert_eq!(wh.get(x, y), rw[y * w + x], "white ({}, {})", x, y);
                }
            }
        }

        /// The fused grey-and-integral pass from RGB writes each pixel's
        /// [`grey_from_rgb`] and the masks [`Thresholder::apply`] gives on that grey
        /// image, with the buffers reused across frames of different sizes.
        #[test]
        fn the_rgb_pass_is_the_grey_pass_on_its_grey_image(
            (w, h) in (1usize..90, 1usize..70),
            offset in 0u8..40,
            seed in 0u64..1000,
        ) {
            use crate::perception::RgbImage;
            let mut im = RgbImage::new(w, h);
            for (i, v) in im.as_bytes_mut().iter_mut().enumerate() {
                *v = (mix(seed, (i / 3 / 4) as u64 * 3 + (i % 3) as u64) % 256) as u8;
            }
            let p = AdaptiveThreshold { window_px: 7, offset, wide_window_px: 17 };
            let mut t = Thresholder::default();
            let (mut b, mut wh, mut grey) = (Mask::new(1, 1), Mask::new(1, 1), vec![9u8; 5000]);
            t.apply_rgb(&RgbImage::new(w + 3, h + 2).view(), &mut grey, &p, &mut b, &mut wh);
            t.apply_rgb(&im.view(), &mut grey, &p, &mut b, &mut wh);
            let expect: Vec<u8> = im.as_bytes().chunks_exact(3).map(|q| grey_from_rgb([q[0], q[1], q[2]])).collect();
            proptest::prop_assert_eq!(&grey, &expect);
            let (mut b2, mut w2) = (Mask::new(1, 1), Mask::new(1, 1));
            Thresholder::new(w, h).apply(&expect, w, h, &p, &mut b2, &mut w2);
            proptest::prop_assert_eq!(b.data(), b2.data());
            proptest::prop_assert_eq!(wh.data(), w2.data());
            proptest::prop_assert_eq!(b.size(), (w, h));
        }
    }

    /// A cheap hash for test images: varied levels without an RNG dependency.
    fn mix(seed: u64, i: u64) -> u64 {
        let mut z = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ i.wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z ^= z >> 31;
        z.wrapping_mul(0x94D0_49BB_1331_11EB) >> 17
    }

    #[test]
    fn fixed_levels_split_the_grey_image_globally() {
        use crate::perception::RgbImage;
        // Grey levels 0, 10, …, 250 along a row: below 60 black, above 180 white, the
        // same wherever the pixel is (no local mean).
        let mut im = RgbImage::new(26, 2);
        for (i, px) in im.as_bytes_mut().chunks_exact_mut(3).enumerate() {
            px.fill(((i % 26) * 10) as u8);
        }
        let levels = Threshold::Fixed(FixedThreshold {
            black_below: 60,
            white_above: 180,
        });
        let (mut b, mut wh, mut grey) = (Mask::new(1, 1), Mask::new(1, 1), Vec::new());
        Thresholder::default().apply_rgb_with(&im.view(), &mut grey, &levels, &mut b, &mut wh);
        for y in 0..2 {
            for x in 0..26 {
                assert_eq!(b.get(x, y), x * 10 < 60, "black at grey {}", x * 10);
                assert_eq!(wh.get(x, y), x * 10 > 180, "white at grey {}", x * 10);
            }
        }
        // The adaptive one through the same call is `apply_rgb`.
        let p = AdaptiveThreshold {
            window_px: 7,
            offset: 8,
            wide_window_px: 17,
        };
        let (mut b2, mut w2) = (Mask::new(1, 1), Mask::new(1, 1));
        let mut t = Thresholder::default();
        t.apply_rgb_with(&im.view(), &mut grey, &Threshold::Adaptive(p), &mut b, &mut wh);
        t.apply_rgb(&im.view(), &mut grey, &p, &mut b2, &mut w2);
        assert_eq!((b.data(), wh.data()), (b2.data(), w2.data()));
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
