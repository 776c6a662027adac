//! Grey conversion and the tiled min/max threshold that finds a tag's black border.
//!
//! As in AprilTag 3 (Wang & Olson 2016, §III-A): the frame is cut into square tiles of
//! [`TileThreshold::tile_px`]; each tile's grey minimum and maximum are taken, then
//! spread over its 3 × 3 tile neighbourhood (the least minimum and the greatest maximum),
//! so that a tile on one side of an edge still sees the other side. A pixel is **black**
//! when its tile's range is at least [`TileThreshold::min_contrast`] and its grey is at
//! most the range's midpoint. Flat tiles (range below the contrast) are neither: a plain
//! wall, or a saturated window, makes no black areas to fit quads to.
//!
//! Cost: one pass for the tiles' extremes, one over the tiles, one over the pixels; no
//! allocation once the buffers have grown to the frame's size. Pixels in a last partial
//! row or column of tiles use that partial tile's extremes.
//!
//! Grey is the luma approximation (R + 2G + B)/4 of [`grey_from_rgb`], as the circle
//! detector's.

use crate::perception::Mask;
use crate::perception::circles::grey_from_rgb;
use crate::perception::image::RgbView;

/// The tiled threshold's parameters.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TileThreshold {
    /// Tile side, px (at least 2; default 4, AprilTag 3's).
    pub tile_px: usize,
    /// Least grey range of a pixel's 3 × 3 tiles for it to be black (default 20).
    pub min_contrast: u8,
}

impl Default for TileThreshold {
    fn default() -> Self {
        Self {
            tile_px: 4,
            min_contrast: 20,
        }
    }
}

/// Writes the grey image of `rgb` into `grey` (resized to the frame, row-major).
pub fn grey_into(rgb: &RgbView<'_>, grey: &mut Vec<u8>) {
    grey.clear();
    grey.extend(
        rgb.as_bytes()
            .chunks_exact(3)
            .map(|p| grey_from_rgb([p[0], p[1], p[2]])),
    );
}

/// The threshold's reusable tile buffers.
#[derive(Debug, Clone, Default)]
pub struct TileThresholder {
    lo: Vec<u8>,
    hi: Vec<u8>,
    lo3: Vec<u8>,
    hi3: Vec<u8>,
}

impl TileThresholder {
    /// Thresholds the `width × height` grey image `grey` into `black` (resized; 1 where
    /// black). A `grey` shorter than `width × height` gives an empty mask.
    pub fn apply(&mut self, grey: &[u8], width: usize, height: usize, p: &TileThreshold, black: &mut Mask) {
        if grey.len() < width * height || width == 0 || height == 0 {
            black.reset(0, 0);
            return;
        }
        black.resize_for_overwrite(width, height);
        let t = p.tile_px.max(2);
        let (tw, th) = (width.div_ceil(t), height.div_ceil(t));
        for b in [&mut self.lo, &mut self.hi, &mut self.lo3, &mut self.hi3] {
            b.clear();
        }
        self.lo.resize(tw * th, 255);
        self.hi.resize(tw * th, 0);
        for y in 0..height {
            let row = &grey[y * width..(y + 1) * width];
            let trow = (y / t) * tw;
            for (tx, chunk) in row.chunks(t).enumerate() {
                let (mut mn, mut mx) = (255u8, 0u8);
                for &g in chunk {
                    mn = mn.min(g);
                    mx = mx.max(g);
                }
                let k = trow + tx;
                self.lo[k] = self.lo[k].min(mn);
                self.hi[k] = self.hi[k].max(mx);
            }
        }
        self.lo3.resize(tw * th, 255);
        self.hi3.resize(tw * th, 0);
        for ty in 0..th {
            for tx in 0..tw {
                let (mut mn, mut mx) = (255u8, 0u8);
                for ny in ty.saturating_sub(1)..(ty + 2).min(th) {
                    for nx in tx.saturating_sub(1)..(tx + 2).min(tw) {
                        mn = mn.min(self.lo[ny * tw + nx]);
                        mx = mx.max(self.hi[ny * tw + nx]);
                    }
                }
                self.lo3[ty * tw + tx] = mn;
                self.hi3[ty * tw + tx] = mx;
            }
        }
        let out = black.data_mut();
        for y in 0..height {
            let row = &grey[y * width..(y + 1) * width];
            let orow = &mut out[y * width..(y + 1) * width];
            let trow = (y / t) * tw;
            for (tx, (gc, oc)) in row.chunks(t).zip(orow.chunks_mut(t)).enumerate() {
                let (mn, mx) = (self.lo3[trow + tx], self.hi3[trow + tx]);
                let (mid, flat) = (((mn as u16 + mx as u16) / 2) as u8, mx - mn < p.min_contrast);
                for (g, o) in gc.iter().zip(oc.iter_mut()) {
                    *o = (!flat && *g <= mid) as u8;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The obvious reference: each pixel's 3 × 3 tile window scanned pixel by pixel.
    fn reference(grey: &[u8], w: usize, h: usize, p: &TileThreshold) -> Vec<u8> {
        let t = p.tile_px.max(2);
        let mut out = vec![0u8; w * h];
        for y in 0..h {
            for x in 0..w {
                let (tx, ty) = (x / t, y / t);
                let (x0, y0) = (tx.saturating_sub(1) * t, ty.saturating_sub(1) * t);
                let (x1, y1) = (((tx + 2) * t).min(w), ((ty + 2) * t).min(h));
                let (mut mn, mut mx) = (255u8, 0u8);
                for yy in y0..y1 {
                    for xx in x0..x1 {
                        mn = mn.min(grey[yy * w + xx]);
                        mx = mx.max(grey[yy * w + xx]);
                    }
                }
                let mid = ((mn as u16 + mx as u16) / 2) as u8;
                out[y * w + x] = (mx - mn >= p.min_contrast && grey[y * w + x] <= mid) as u8;
            }
        }
        out
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// On random images (blocks of random levels, so both flat and edged tiles
        /// occur), the tiled threshold equals the per-pixel reference.
        #[test]
        fn tiled_threshold_matches_the_reference(
            w in 1usize..40, h in 1usize..40, tile in 2usize..7, contrast in 0u8..60,
            block in 1usize..9, seed in any::<u64>(),
        ) {
            let mut s = seed | 1;
            let mut next = || { s ^= s << 13; s ^= s >> 7; s ^= s << 17; (s >> 24) as u8 };
            let levels: Vec<u8> = (0..w.div_ceil(block) * h.div_ceil(block)).map(|_| next()).collect();
            let grey: Vec<u8> = (0..w * h)
                .map(|i| levels[(i / w / block) * w.div_ceil(block) + (i % w) / block])
                .collect();
            let p = TileThreshold { tile_px: tile, min_contrast: contrast };
            let mut m = Mask::default();
            TileThresholder::default().apply(&grey, w, h, &p, &mut m);
            prop_assert_eq!(m.data(), &reference(&grey, w, h, &p)[..]);
        }
    }

    #[test]
    fn flat_and_degenerate_frames_have_no_black() {
        let mut m = Mask::default();
        let mut th = TileThresholder::default();
        let p = TileThreshold::default();
        for level in [0u8, 128, 255] {
            th.apply(&[level; 64], 8, 8, &p, &mut m);
            assert_eq!(m.count(), 0);
        }
        th.apply(&[], 0, 0, &p, &mut m);
        assert_eq!(m.size(), (0, 0));
        th.apply(&[0; 3], 2, 2, &p, &mut m);
        assert_eq!(m.size(), (0, 0), "short buffer");
    }
}
