//! Grey images in floating point and their pyramids, the input of corner detection and
//! Lucas–Kanade tracking.

use super::corners::Roi;
use crate::perception::image::RgbView;

/// A grey image, one `f32` per pixel (0–255), row-major.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GreyImage {
    width: usize,
    height: usize,
    data: Vec<f32>,
}

impl GreyImage {
    /// A black image.
    pub fn new(width: usize, height: usize) -> Self {
        Self {
            width,
            height,
            data: vec![0.0; width * height],
        }
    }

    /// From row-major values; `None` when `data` is not `width × height` long.
    pub fn from_vec(width: usize, height: usize, data: Vec<f32>) -> Option<Self> {
        (data.len() == width * height).then_some(Self { width, height, data })
    }

    /// Width, px.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height, px.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The pixels, row-major.
    pub fn data(&self) -> &[f32] {
        &self.data
    }

    /// The pixels, row-major, mutable.
    pub fn data_mut(&mut self) -> &mut [f32] {
        &mut self.data
    }

    /// Pixel (x, y); callers keep it in range.
    #[inline]
    pub fn at(&self, x: usize, y: usize) -> f32 {
        self.data[y * self.width + x]
    }

    /// Resizes (keeping the allocation when it is large enough).
    pub fn resize(&mut self, width: usize, height: usize) {
        self.width = width;
        self.height = height;
        self.data.resize(width * height, 0.0);
    }

    /// Writes the luma (R + 2G + B)/4 of `src` into `self`, resized to match.
    pub fn set_from_rgb(&mut self, src: &RgbView<'_>) {
        self.resize(src.width(), src.height());
        for (o, p) in self.data.iter_mut().zip(src.as_bytes().chunks_exact(3)) {
            *o = luma(p);
        }
    }

    /// Bilinear sample at (x, y), pixel centres at integers; `None` outside
    /// [0, w − 1] × [0, h − 1].
    #[inline]
    pub fn sample(&self, x: f64, y: f64) -> Option<f32> {
        if !(x >= 0.0 && y >= 0.0 && x <= (self.width - 1) as f64 && y <= (self.height - 1) as f64) {
            return None;
        }
        let (x0, y0) = (x.floor() as usize, y.floor() as usize);
        let (x1, y1) = ((x0 + 1).min(self.width - 1), (y0 + 1).min(self.height - 1));
        let (fx, fy) = ((x - x0 as f64) as f32, (y - y0 as f64) as f32);
        let top = self.at(x0, y0) * (1.0 - fx) + self.at(x1, y0) * fx;
        let bottom = self.at(x0, y1) * (1.0 - fx) + self.at(x1, y1) * fx;
        Some(top * (1.0 - fy) + bottom * fy)
    }
}

/// The most regions a pyramid built with [`GreyPyramid::build_from_rgb_in`] keeps per
/// level; more than this builds the whole frame.
pub const MAX_REGIONS: usize = 8;

/// The pixels of one pyramid level that hold the image's values: the whole level, or
/// up to [`MAX_REGIONS`] rectangles.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Regions {
    whole: bool,
    rects: [Roi; MAX_REGIONS],
    n: usize,
}

impl Regions {
    const WHOLE: Self = Self {
        whole: true,
        rects: [Roi {
            x0: 0,
            y0: 0,
            x1: 0,
            y1: 0,
        }; MAX_REGIONS],
        n: 0,
    };

    fn rects(&self) -> &[Roi] {
        &self.rects[..self.n]
    }
}

/// A Gaussian pyramid: level 0 the image, each next level blurred with the 5-tap
/// binomial [1 4 6 4 1]/16 in each direction and halved ((w + 1)/2 × (h + 1)/2).
/// Buffers are kept between frames.
///
/// [`GreyPyramid::build_from_rgb_in`] computes only the pixels around a few regions of
/// interest (the AutoKrawler's tread windows), each level's pixels exactly the values
/// the whole-frame build gives there; [`GreyPyramid::covers`] says which pixels those
/// are, and the tracker treats the rest like pixels outside the image.
#[derive(Debug, Clone, Default)]
pub struct GreyPyramid {
    levels: Vec<GreyImage>,
    regions: Vec<Regions>,
    scratch: Vec<f32>,
}

impl GreyPyramid {
    /// A pyramid of `levels` levels (at least 1).
    pub fn new(levels: usize) -> Self {
        Self {
            levels: vec![GreyImage::default(); levels.max(1)],
            regions: vec![Regions::WHOLE; levels.max(1)],
            scratch: Vec::new(),
        }
    }

    /// Level `k` (0 is full resolution).
    pub fn level(&self, k: usize) -> &GreyImage {
        &self.levels[k]
    }

    /// Number of levels.
    pub fn len(&self) -> usize {
        self.levels.len()
    }

    /// Always false: a pyramid has at least one level.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Whether every pixel of the inclusive rectangle [x0, x1] × [y0, y1] of level `k`
    /// holds the image's value (inside the image, and inside one computed region when
    /// the last build was restricted to regions).
    pub fn covers(&self, k: usize, x0: usize, y0: usize, x1: usize, y1: usize) -> bool {
        let im = &self.levels[k];
        if x1 >= im.width() || y1 >= im.height() {
            return false;
        }
        let r = &self.regions[k];
        r.whole
            || r.rects()
                .iter()
                .any(|q| q.x0 <= x0 && q.y0 <= y0 && x1 < q.x1 && y1 < q.y1)
    }

    /// Builds every level from `src`'s luma.
    pub fn build_from_rgb(&mut self, src: &RgbView<'_>) {
        self.levels[0].set_from_rgb(src);
        self.build_upper();
    }

    /// Builds every level from a grey image.
    pub fn build_from_grey(&mut self, src: &GreyImage) {
        self.levels[0].resize(src.width(), src.height());
        self.levels[0].data_mut().copy_from_slice(src.data());
        self.build_upper();
    }

    /// Builds only the pixels of each level that `rects` of level 0 determine: level 0
    /// inside the rectangles, each next level where the blur's support lies inside one
    /// rectangle of the level below (or is clamped at the image's edge). Those pixels
    /// hold exactly the whole-frame build's values; the others are left stale and
    /// [`GreyPyramid::covers`] excludes them. More than [`MAX_REGIONS`] rectangles build
    /// the whole frame.
    pub fn build_from_rgb_in(&mut self, src: &RgbView<'_>, rects: &[Roi]) {
        if rects.len() > MAX_REGIONS {
            self.build_from_rgb(src);
            return;
        }
        let (w, h) = (src.width(), src.height());
        let bytes = src.as_bytes();
        let base = &mut self.levels[0];
        base.resize(w, h);
        let mut regions = Regions::default();
        for r in rects {
            let r = Roi {
                x0: r.x0.min(w),
                y0: r.y0.min(h),
                x1: r.x1.min(w),
                y1: r.y1.min(h),
            };
            if r.x0 >= r.x1 || r.y0 >= r.y1 {
                continue;
            }
            for y in r.y0..r.y1 {
                let row = &mut base.data[y * w + r.x0..y * w + r.x1];
                let px = &bytes[3 * (y * w + r.x0)..3 * (y * w + r.x1)];
                for (o, p) in row.iter_mut().zip(px.chunks_exact(3)) {
                    *o = luma(p);
                }
            }
            regions.rects[regions.n] = r;
            regions.n += 1;
        }
        self.regions[0] = regions;
        for k in 1..self.levels.len() {
            let (lower, upper) = self.levels.split_at_mut(k);
            let (src, dst) = (&lower[k - 1], &mut upper[0]);
            let (dw, dh) = (src.width().div_ceil(2).max(1), src.height().div_ceil(2).max(1));
            dst.resize(dw, dh);
            let below = self.regions[k - 1];
            let mut here = Regions::default();
            for r in below.rects() {
                let q = downsample(src, dst, &mut self.scratch, *r);
                if q.x0 < q.x1 && q.y0 < q.y1 {
                    here.rects[here.n] = q;
                    here.n += 1;
                }
            }
            self.regions[k] = here;
        }
    }

    fn build_upper(&mut self) {
        self.regions[0] = Regions::WHOLE;
        for k in 1..self.levels.len() {
            let (lower, upper) = self.levels.split_at_mut(k);
            let (src, dst) = (&lower[k - 1], &mut upper[0]);
            dst.resize(src.width().div_ceil(2).max(1), src.height().div_ceil(2).max(1));
            downsample(src, dst, &mut self.scratch, Roi::full(src.width(), src.height()));
            self.regions[k] = Regions::WHOLE;
        }
    }
}

/// The luma (R + 2G + B)/4 of one RGB pixel.
#[inline]
fn luma(p: &[u8]) -> f32 {
    (p[0] as f32 + 2.0 * p[1] as f32 + p[2] as f32) * 0.25
}

/// Blurs `src` with [1 4 6 4 1]/16 (edges clamped) and keeps every other pixel, into
/// `dst` (already sized (w + 1)/2 × (h + 1)/2), at the pixels whose blur reads only
/// pixels of `r` (a region of `src` holding its values; the image's edge clamps as in
/// the whole image). Returns the rectangle of `dst` written.
fn downsample(src: &GreyImage, dst: &mut GreyImage, scratch: &mut Vec<f32>, r: Roi) -> Roi {
    let (w, h) = (src.width(), src.height());
    let (dw, dh) = (dst.width(), dst.height());
    // Output pixel d reads source 2d − 2 ..= 2d + 2 (clamped to the image): it needs
    // 2d − 2 ≥ r.0 unless r starts at the edge, and 2d + 2 < r.1 unless r ends there.
    let span = |lo: usize, hi: usize, n: usize, dn: usize| {
        let a = if lo == 0 { 0 } else { (lo + 2).div_ceil(2) };
        let b = if hi >= n {
            dn
        } else {
            (hi.saturating_sub(1) / 2).min(dn)
        };
        (a, b.max(a))
    };
    let (x0, x1) = span(r.x0, r.x1, w, dw);
    let (y0, y1) = span(r.y0, r.y1, h, dh);
    let out = Roi { x0, y0, x1, y1 };
    if x0 >= x1 || y0 >= y1 {
        return out;
    }
    let k = [1.0f32, 4.0, 6.0, 4.0, 1.0];
    // Horizontal pass at the kept columns, on the rows the vertical pass reads.
    scratch.resize(dw * h, 0.0);
    let (ry0, ry1) = ((2 * y0).saturating_sub(2), (2 * (y1 - 1) + 3).min(h));
    for y in ry0..ry1 {
        let row = &src.data()[y * w..(y + 1) * w];
        for dx in x0..x1 {
            let x = (2 * dx) as isize;
            let mut s = 0.0;
            for (i, kk) in k.iter().enumerate() {
                let xi = (x + i as isize - 2).clamp(0, w as isize - 1) as usize;
                s += kk * row[xi];
            }
            scratch[y * dw + dx] = s / 16.0;
        }
    }
    let data = dst.data_mut();
    for dy in y0..y1 {
        let y = (2 * dy) as isize;
        for dx in x0..x1 {
            let mut s = 0.0;
            for (i, kk) in k.iter().enumerate() {
                let yi = (y + i as isize - 2).clamp(0, h as isize - 1) as usize;
                s += kk * scratch[yi * dw + dx];
            }
            data[dy * dw + dx] = s / 16.0;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::perception::RgbImage;
    use proptest::prelude::*;

    proptest! {
        /// Built around a few rectangles, every pixel the pyramid says it covers (and
        /// every pixel of the rectangles at level 0) equals the whole-frame build's, on
        /// random images of odd and even sizes with rectangles touching the edges.
        #[test]
        fn regions_hold_the_whole_frame_values(
            w in 1usize..70,
            h in 1usize..70,
            rects in proptest::collection::vec((0usize..75, 0usize..75, 0usize..50, 0usize..50), 0..5),
            seed in any::<u64>(),
        ) {
            let mut s = seed | 1;
            let bytes: Vec<u8> = (0..w * h * 3)
                .map(|_| {
                    s ^= s << 13;
                    s ^= s >> 7;
                    s ^= s << 17;
                    (s >> 24) as u8
                })
                .collect();
            let img = RgbImage::from_raw(w, h, bytes).expect("size");
            let rects: Vec<Roi> = rects.iter().map(|&(x, y, rw, rh)| Roi { x0: x, y0: y, x1: x + rw, y1: y + rh }).collect();
            let mut whole = GreyPyramid::new(3);
            whole.build_from_rgb(&img.view());
            let mut part = GreyPyramid::new(3);
            // Stale values from another image must not matter.
            part.build_from_rgb(&RgbImage::new(w, h).view());
            part.build_from_rgb_in(&img.view(), &rects);
            for r in &rects {
                for y in r.y0.min(h)..r.y1.min(h) {
                    for x in r.x0.min(w)..r.x1.min(w) {
                        prop_assert!(part.covers(0, x, y, x, y));
                    }
                }
            }
            for k in 0..3 {
                let (a, b) = (whole.level(k), part.level(k));
                prop_assert_eq!((a.width(), a.height()), (b.width(), b.height()));
                for y in 0..a.height() {
                    for x in 0..a.width() {
                        if part.covers(k, x, y, x, y) {
                            prop_assert_eq!(a.at(x, y).to_bits(), b.at(x, y).to_bits(), "level {} ({}, {})", k, x, y);
                        }
                    }
                }
            }
        }
    }

    /// A rectangle well inside a large image keeps most of its area at the coarser
    /// levels (the region shrinks by the blur's reach, not more).
    #[test]
    fn regions_shrink_by_the_blur_only() {
        let img = RgbImage::new(200, 200);
        let mut p = GreyPyramid::new(3);
        p.build_from_rgb_in(
            &img.view(),
            &[Roi {
                x0: 50,
                y0: 50,
                x1: 150,
                y1: 150,
            }],
        );
        assert!(p.covers(1, 26, 26, 73, 73));
        assert!(!p.covers(1, 25, 26, 73, 73));
        assert!(p.covers(2, 14, 14, 35, 35));
        assert!(!p.covers(2, 0, 0, 1, 1));
    }
}
