//! Shi–Tomasi corners ("Good features to track", Shi and Tomasi 1994): the pixels whose
//! structure tensor's smaller eigenvalue is largest, the points Lucas–Kanade tracks best.
//!
//! Gradients are 3×3 Sobel (÷8); the tensor's entries are summed over a (2b + 1)² box
//! with separable running sums; λ_min = (a + c)/2 − √(((a − c)/2)² + b²). Candidates are
//! the strict 3×3 maxima above `quality` × the strongest response in the region, taken
//! strongest first at least `min_distance` apart, up to `max_corners`. Only a region of
//! interest is processed (the paper's observation windows). Coordinates have pixel
//! centres at integers (add 0.5 for [`crate::perception::camera_model`]).
//!
//! Every buffer is sized in [`ShiTomasi::new`]; [`ShiTomasi::detect`] does not allocate.

use super::grey::GreyImage;

/// Parameters of the corner detector.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CornerParams {
    /// Half-size b of the tensor's summing box, px ((2b + 1)² pixels).
    pub block_radius: usize,
    /// Keep responses above this fraction of the region's strongest, 0–1.
    pub quality: f32,
    /// And above this absolute floor (grey levels² summed over the box).
    pub min_eigen: f32,
    /// Minimum distance between two kept corners, px.
    pub min_distance: f64,
    /// At most this many corners.
    pub max_corners: usize,
}

impl Default for CornerParams {
    /// A 5×5 box, quality 0.05, floor 50, 5 px apart, up to 100 corners.
    fn default() -> Self {
        Self {
            block_radius: 2,
            quality: 0.05,
            min_eigen: 50.0,
            min_distance: 5.0,
            max_corners: 100,
        }
    }
}

/// A region of interest, pixel bounds `[x0, x1) × [y0, y1)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Roi {
    /// First column.
    pub x0: usize,
    /// First row.
    pub y0: usize,
    /// One past the last column.
    pub x1: usize,
    /// One past the last row.
    pub y1: usize,
}

impl Roi {
    /// The whole of a `w × h` image.
    pub fn full(w: usize, h: usize) -> Self {
        Self {
            x0: 0,
            y0: 0,
            x1: w,
            y1: h,
        }
    }

    /// The square of half-size `r` around (cx, cy), clipped to a `w × h` image.
    pub fn around(cx: f64, cy: f64, r: f64, w: usize, h: usize) -> Self {
        let clip = |v: f64, n: usize| v.clamp(0.0, n as f64) as usize;
        Self {
            x0: clip(cx - r, w),
            y0: clip(cy - r, h),
            x1: clip(cx + r + 1.0, w),
            y1: clip(cy + r + 1.0, h),
        }
    }
}

/// The Shi–Tomasi detector for images up to a size; owns every buffer.
#[derive(Debug, Clone)]
pub struct ShiTomasi {
    params: CornerParams,
    /// λ_min over the last region (row-major in the region), 0 where not computed.
    eigen: Vec<f32>,
    gxx: Vec<f32>,
    gxy: Vec<f32>,
    gyy: Vec<f32>,
    tmp: Vec<f32>,
    candidates: Vec<(f32, u32)>,
    corners: Vec<[f64; 2]>,
    region: Roi,
}

impl ShiTomasi {
    /// A detector for images of at most `width × height`.
    pub fn new(width: usize, height: usize, params: CornerParams) -> Self {
        let n = width * height;
        Self {
            params,
            eigen: Vec::with_capacity(n),
            gxx: Vec::with_capacity(n),
            gxy: Vec::with_capacity(n),
            gyy: Vec::with_capacity(n),
            tmp: Vec::with_capacity(n),
            candidates: Vec::with_capacity((width / 2 + 1) * (height / 2 + 1)),
            corners: Vec::with_capacity(params.max_corners),
            region: Roi::full(0, 0),
        }
    }

    /// The parameters.
    pub fn params(&self) -> &CornerParams {
        &self.params
    }

    /// λ_min of the last region, row-major over [`ShiTomasi::region`].
    pub fn eigen(&self) -> &[f32] {
        &self.eigen
    }

    /// The region of the last call (clipped to the image).
    pub fn region(&self) -> Roi {
        self.region
    }

    /// The corners of `image` within `roi`, strongest first.
    pub fn detect(&mut self, image: &GreyImage, roi: Roi) -> &[[f64; 2]] {
        self.response(image, roi);
        self.select();
        &self.corners
    }

    /// Computes λ_min over `roi` (clipped to the image) into [`ShiTomasi::eigen`].
    /// Pixels within 1 + b of the image border get 0 (their box leaves the image).
    pub fn response(&mut self, image: &GreyImage, roi: Roi) {
        let (w, h) = (image.width(), image.height());
        let roi = Roi {
            x0: roi.x0.min(w),
            y0: roi.y0.min(h),
            x1: roi.x1.min(w).max(roi.x0.min(w)),
            y1: roi.y1.min(h).max(roi.y0.min(h)),
        };
        self.region = roi;
        let (rw, rh) = (roi.x1 - roi.x0, roi.y1 - roi.y0);
        let b = self.params.block_radius;
        self.eigen.clear();
        self.eigen.resize(rw * rh, 0.0);
        if rw == 0 || rh == 0 {
            return;
        }
        // Gradient products over the region grown by b (kept inside the Sobel's reach).
        let m = 1 + b;
        let gx0 = roi.x0.saturating_sub(b).max(1);
        let gy0 = roi.y0.saturating_sub(b).max(1);
        let gx1 = (roi.x1 + b).min(w.saturating_sub(1));
        let gy1 = (roi.y1 + b).min(h.saturating_sub(1));
        if gx1 <= gx0 || gy1 <= gy0 {
            return;
        }
        let (gw, gh) = (gx1 - gx0, gy1 - gy0);
        for buf in [&mut self.gxx, &mut self.gxy, &mut self.gyy] {
            buf.clear();
            buf.resize(gw * gh, 0.0);
        }
        let d = image.data();
        for y in gy0..gy1 {
            for x in gx0..gx1 {
                let p = |dx: isize, dy: isize| d[(y as isize + dy) as usize * w + (x as isize + dx) as usize];
                let ix = ((p(1, -1) + 2.0 * p(1, 0) + p(1, 1)) - (p(-1, -1) + 2.0 * p(-1, 0) + p(-1, 1))) / 8.0;
                let iy = ((p(-1, 1) + 2.0 * p(0, 1) + p(1, 1)) - (p(-1, -1) + 2.0 * p(0, -1) + p(1, -1))) / 8.0;
                let i = (y - gy0) * gw + (x - gx0);
                self.gxx[i] = ix * ix;
                self.gxy[i] = ix * iy;
                self.gyy[i] = iy * iy;
            }
        }
        // Box sums along rows (in place, through tmp); the column sums follow per pixel.
        row_box(&mut self.gxx, &mut self.tmp, gw, gh, b);
        row_box(&mut self.gxy, &mut self.tmp, gw, gh, b);
        row_box(&mut self.gyy, &mut self.tmp, gw, gh, b);
        // Column sums and the eigenvalue, at region pixels whose box fits the products.
        for y in roi.y0..roi.y1 {
            for x in roi.x0..roi.x1 {
                if x < m || y < m || x + m >= w || y + m >= h {
                    continue;
                }
                let (cx, cy) = (x - gx0, y - gy0);
                let (mut a, mut bb, mut c) = (0.0f32, 0.0f32, 0.0f32);
                for yy in cy - b..=cy + b {
                    let i = yy * gw + cx;
                    a += self.gxx[i];
                    bb += self.gxy[i];
                    c += self.gyy[i];
                }
                let half = (a - c) * 0.5;
                self.eigen[(y - roi.y0) * rw + (x - roi.x0)] = (a + c) * 0.5 - (half * half + bb * bb).sqrt();
            }
        }
    }

    /// The strongest candidates, at least `min_distance` apart.
    fn select(&mut self) {
        let roi = self.region;
        let (rw, rh) = (roi.x1 - roi.x0, roi.y1 - roi.y0);
        self.candidates.clear();
        self.corners.clear();
        let strongest = self.eigen.iter().copied().fold(0.0f32, f32::max);
        let floor = (self.params.quality * strongest).max(self.params.min_eigen);
        if strongest <= 0.0 {
            return;
        }
        let e = &self.eigen;
        for y in 1..rh.saturating_sub(1) {
            for x in 1..rw.saturating_sub(1) {
                let v = e[y * rw + x];
                if v <= floor {
                    continue;
                }
                // Strict maximum over the 3×3 neighbourhood (ties: the first in raster
                // order wins, so a flat plateau gives one candidate).
                let mut is_max = true;
                'n: for dy in 0..3 {
                    for dx in 0..3 {
                        if dx == 1 && dy == 1 {
                            continue;
                        }
                        let u = e[(y + dy - 1) * rw + x + dx - 1];
                        let before = dy == 0 || (dy == 1 && dx == 0);
                        if u > v || (before && u == v) {
                            is_max = false;
                            break 'n;
                        }
                    }
                }
                if is_max && self.candidates.len() < self.candidates.capacity() {
                    self.candidates.push((v, (y * rw + x) as u32));
                }
            }
        }
        self.candidates
            .sort_unstable_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        let d2 = self.params.min_distance * self.params.min_distance;
        for &(_, i) in &self.candidates {
            if self.corners.len() == self.params.max_corners {
                break;
            }
            let (x, y) = ((i as usize % rw + roi.x0) as f64, (i as usize / rw + roi.y0) as f64);
            if self
                .corners
                .iter()
                .all(|c| (c[0] - x).powi(2) + (c[1] - y).powi(2) >= d2)
            {
                self.corners.push([x, y]);
            }
        }
    }
}

/// Replaces each row of `buf` (`gw × gh`) by its sums over 2b + 1 neighbours, at the
/// columns b..gw − b (others 0), through `tmp`.
fn row_box(buf: &mut Vec<f32>, tmp: &mut Vec<f32>, gw: usize, gh: usize, b: usize) {
    tmp.clear();
    tmp.resize(gw * gh, 0.0);
    if gw > 2 * b {
        for y in 0..gh {
            let row = &buf[y * gw..(y + 1) * gw];
            let mut s: f32 = row[..2 * b + 1].iter().sum();
            tmp[y * gw + b] = s;
            for x in b + 1..gw - b {
                s += row[x + b] - row[x - b - 1];
                tmp[y * gw + x] = s;
            }
        }
    }
    std::mem::swap(buf, tmp);
}
