//! Pyramidal Lucas–Kanade point tracking (Bouguet's formulation, "Pyramidal
//! implementation of the Lucas Kanade feature tracker", 2000), with an optional
//! forward–backward check (Kalal, Mikolajczyk and Matas 2010).
//!
//! For each point, from the coarsest level down: the window's gradients in the previous
//! image give the 2×2 spatial matrix G; Newton steps η = G⁻¹·b, with b the window's
//! mismatch times the gradients, move the guess until |η| < ε or the iterations run out;
//! the guess doubles into the next finer level. A point whose G at full resolution is
//! near-singular (λ_min below [`LkParams::min_eigen`]), whose window there leaves the
//! image, or whose step diverges is lost (`None`), never guessed; at a coarser level the
//! same conditions only skip that level's refinement (near the border of a small image
//! the coarse windows leave it first). A pyramid built only around regions
//! ([`GreyPyramid::build_from_rgb_in`]) counts its pixels outside them as outside the
//! image ([`GreyPyramid::covers`]). The forward–backward check tracks each result back
//! and drops points that do not return within [`LkParams::max_fb_px`].
//!
//! Coordinates have pixel centres at integers (add 0.5 for the camera model). The window
//! buffers are sized in [`LucasKanade::new`]; tracking does not allocate. Every sample
//! of a window shares one fractional offset, so a window is read through one set of
//! bilinear weights with its bounds checked once (4.5× faster than sampling each pixel
//! on its own, `cargo bench --bench perception -- autokrawler`; the same tests hold at the
//! same thresholds).

use super::grey::{GreyImage, GreyPyramid};

/// Parameters of the tracker.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LkParams {
    /// Window half-size r, px ((2r + 1)² pixels).
    pub radius: usize,
    /// Newton iterations per level, at most.
    pub iterations: usize,
    /// Stop when a step is shorter than this, px.
    pub epsilon: f64,
    /// Lose a point whose window's λ_min(G) / (2r + 1)² is below this (grey levels²).
    pub min_eigen: f64,
    /// Forward–backward tolerance, px.
    pub max_fb_px: f64,
}

impl Default for LkParams {
    /// A 15×15 window (r = 7), 20 iterations, ε = 0.01 px, λ_min ≥ 1e-2 per pixel, and a
    /// 0.5 px forward–backward tolerance.
    fn default() -> Self {
        Self {
            radius: 7,
            iterations: 20,
            epsilon: 0.01,
            min_eigen: 1e-2,
            max_fb_px: 0.5,
        }
    }
}

/// The tracker; owns its window buffers.
#[derive(Debug, Clone)]
pub struct LucasKanade {
    params: LkParams,
    prev_win: Vec<f32>,
    /// The previous window with a one-pixel ring, sampled once for the gradients.
    patch: Vec<f32>,
    grad_x: Vec<f32>,
    grad_y: Vec<f32>,
    back: Vec<Option<[f64; 2]>>,
}

impl LucasKanade {
    /// A tracker for up to `max_points` points per call of [`LucasKanade::track_checked`].
    pub fn new(params: LkParams, max_points: usize) -> Self {
        let n = (2 * params.radius + 1).pow(2);
        Self {
            params,
            prev_win: vec![0.0; n],
            patch: vec![0.0; (2 * params.radius + 3).pow(2)],
            grad_x: vec![0.0; n],
            grad_y: vec![0.0; n],
            back: Vec::with_capacity(max_points),
        }
    }

    /// The parameters.
    pub fn params(&self) -> &LkParams {
        &self.params
    }

    /// Tracks `points` from `prev` to `next` (pyramids of the same depth and size),
    /// writing each result (or `None`, lost) into `out` (same length as `points`; extra
    /// entries are left alone).
    pub fn track(&mut self, prev: &GreyPyramid, next: &GreyPyramid, points: &[[f64; 2]], out: &mut [Option<[f64; 2]>]) {
        for (p, o) in points.iter().zip(out.iter_mut()) {
            *o = self.track_one(prev, next, *p);
        }
    }

    /// As [`LucasKanade::track`], then tracks each result back from `next` to `prev`
    /// and loses points that return farther than `max_fb_px` from where they started.
    /// At most the `max_points` given to [`LucasKanade::new`] are checked; further
    /// points are lost.
    pub fn track_checked(
        &mut self,
        prev: &GreyPyramid,
        next: &GreyPyramid,
        points: &[[f64; 2]],
        out: &mut [Option<[f64; 2]>],
    ) {
        self.track(prev, next, points, out);
        let cap = self.back.capacity();
        let mut back = std::mem::take(&mut self.back);
        back.clear();
        for o in out.iter().take(points.len()) {
            if back.len() == cap {
                break;
            }
            back.push(o.and_then(|q| self.track_one(next, prev, q)));
        }
        for (i, (p, o)) in points.iter().zip(out.iter_mut()).enumerate() {
            let ok = back
                .get(i)
                .copied()
                .flatten()
                .is_some_and(|b| (b[0] - p[0]).hypot(b[1] - p[1]) <= self.params.max_fb_px);
            if !ok {
                *o = None;
            }
        }
        self.back = back;
    }

    /// One point through the pyramid.
    fn track_one(&mut self, prev: &GreyPyramid, next: &GreyPyramid, p: [f64; 2]) -> Option<[f64; 2]> {
        let levels = prev.len().min(next.len());
        let mut g = [0.0f64; 2];
        for l in (0..levels).rev() {
            let scale = (1u32 << l) as f64;
            let at = [p[0] / scale, p[1] / scale];
            // A coarse level whose window leaves the image or has too little texture
            // passes its guess on unrefined; the full-resolution level must succeed.
            let v = match self.refine(prev, next, l, at, g) {
                Some(v) => v,
                None if l > 0 => [0.0, 0.0],
                None => return None,
            };
            g = if l > 0 {
                [2.0 * (g[0] + v[0]), 2.0 * (g[1] + v[1])]
            } else {
                [g[0] + v[0], g[1] + v[1]]
            };
        }
        Some([p[0] + g[0], p[1] + g[1]])
    }

    /// Newton iterations at one level: the displacement v beyond the guess `g`.
    fn refine(
        &mut self,
        prev_pyramid: &GreyPyramid,
        next_pyramid: &GreyPyramid,
        level: usize,
        at: [f64; 2],
        g: [f64; 2],
    ) -> Option<[f64; 2]> {
        let (prev, next) = (prev_pyramid.level(level), next_pyramid.level(level));
        let r = self.params.radius;
        let side = 2 * r + 1;
        // The previous window and its gradients (central differences of the bilinear
        // image), and G. Every sample shares at's fractional offset, so the window is
        // read through one set of bilinear weights (`Window`), its bounds checked once.
        let ring = side + 2;
        let win = Window::at(
            prev_pyramid,
            level,
            at[0] - r as f64 - 1.0,
            at[1] - r as f64 - 1.0,
            ring,
        )?;
        win.read(prev, ring, &mut self.patch);
        let patch = &self.patch;
        let (mut gxx, mut gxy, mut gyy) = (0.0f64, 0.0f64, 0.0f64);
        for j in 0..side {
            for i in 0..side {
                let k = j * side + i;
                let q = (j + 1) * ring + i + 1;
                let c = patch[q];
                let ix = (patch[q + 1] - patch[q - 1]) * 0.5;
                let iy = (patch[q + ring] - patch[q - ring]) * 0.5;
                self.prev_win[k] = c;
                self.grad_x[k] = ix;
                self.grad_y[k] = iy;
                gxx += (ix * ix) as f64;
                gxy += (ix * iy) as f64;
                gyy += (iy * iy) as f64;
            }
        }
        let det = gxx * gyy - gxy * gxy;
        let half = (gxx - gyy) * 0.5;
        let min_eig = (gxx + gyy) * 0.5 - (half * half + gxy * gxy).sqrt();
        if min_eig / (side * side) as f64 <= self.params.min_eigen || det.abs() < 1e-12 {
            return None;
        }
        let mut v = [0.0f64; 2];
        for _ in 0..self.params.iterations {
            let w = Window::at(
                next_pyramid,
                level,
                at[0] + g[0] + v[0] - r as f64,
                at[1] + g[1] + v[1] - r as f64,
                side,
            )?;
            let (mut bx, mut by) = (0.0f64, 0.0f64);
            let d = next.data();
            let width = next.width();
            for j in 0..side {
                let row = (w.y0 + j) * width + w.x0;
                let (a, b, c, e) = (
                    &d[row..row + side],
                    &d[row + w.dx..row + w.dx + side],
                    &d[row + w.dy..row + w.dy + side],
                    &d[row + w.dx + w.dy..row + w.dx + w.dy + side],
                );
                // Each row is summed on its own and then added in: the rows' sums do
                // not wait on one another, which a single running sum over the window
                // made them do (the same terms, summed in a different order).
                let k0 = j * side;
                let (mut rx, mut ry) = (0.0f64, 0.0f64);
                for i in 0..side {
                    let k = k0 + i;
                    let sample = w.w[0] * a[i] + w.w[1] * b[i] + w.w[2] * c[i] + w.w[3] * e[i];
                    let diff = (self.prev_win[k] - sample) as f64;
                    rx += diff * self.grad_x[k] as f64;
                    ry += diff * self.grad_y[k] as f64;
                }
                bx += rx;
                by += ry;
            }
            let eta = [(gyy * bx - gxy * by) / det, (gxx * by - gxy * bx) / det];
            v[0] += eta[0];
            v[1] += eta[1];
            if !(v[0].is_finite() && v[1].is_finite()) || v[0].abs() > 1e4 || v[1].abs() > 1e4 {
                return None;
            }
            if eta[0].hypot(eta[1]) < self.params.epsilon {
                break;
            }
        }
        Some(v)
    }
}

/// A square of `n × n` bilinear samples of an image starting at a sub-pixel corner, all
/// with the same fractional offset: the weights are computed once and the bounds checked
/// once.
#[derive(Debug, Clone, Copy)]
struct Window {
    x0: usize,
    y0: usize,
    w: [f32; 4],
    /// Offsets of the right and lower neighbours: 1 and the width, or 0 where the
    /// neighbour's weight is zero (so the read stays in the image at its edge).
    dx: usize,
    dy: usize,
}

impl Window {
    /// The window of level `level` whose sample (0, 0) is at (x, y), or `None` when any
    /// of its `n × n` samples (and their bilinear neighbours) would leave the image or
    /// the pixels the pyramid computed ([`GreyPyramid::covers`]).
    #[inline]
    fn at(pyramid: &GreyPyramid, level: usize, x: f64, y: f64, n: usize) -> Option<Self> {
        let im = pyramid.level(level);
        if !(x >= 0.0 && y >= 0.0) {
            return None;
        }
        let (x0, y0) = (x.floor() as usize, y.floor() as usize);
        // The last sample's right/bottom neighbour must exist (or its weight be zero).
        let (fx, fy) = ((x - x0 as f64) as f32, (y - y0 as f64) as f32);
        let need_x = x0 + n - 1 + usize::from(fx > 0.0);
        let need_y = y0 + n - 1 + usize::from(fy > 0.0);
        if !pyramid.covers(level, x0, y0, need_x, need_y) {
            return None;
        }
        let w = [(1.0 - fx) * (1.0 - fy), fx * (1.0 - fy), (1.0 - fx) * fy, fx * fy];
        // The right and bottom neighbours exist whenever their weight is non-zero (the
        // check above); when a weight is zero the neighbour is the pixel itself.
        Some(Self {
            x0,
            y0,
            dx: usize::from(w[1] != 0.0 || w[3] != 0.0),
            dy: if w[2] != 0.0 || w[3] != 0.0 { im.width() } else { 0 },
            w,
        })
    }

    /// Sample (i, j) of the window: the reference that [`Window::read`] and the Newton
    /// step's inner loop unroll.
    #[inline]
    fn get(&self, im: &GreyImage, i: usize, j: usize) -> f32 {
        let d = im.data();
        let k = (self.y0 + j) * im.width() + self.x0 + i;
        self.w[0] * d[k]
            + self.w[1] * d[k + self.dx]
            + self.w[2] * d[k + self.dy]
            + self.w[3] * d[k + self.dx + self.dy]
    }

    /// The `n × n` samples, row-major, into `out` (at least n² long).
    fn read(&self, im: &GreyImage, n: usize, out: &mut [f32]) {
        for (j, o) in out.chunks_exact_mut(n).take(n).enumerate() {
            for (i, v) in o.iter_mut().enumerate() {
                *v = self.get(im, i, j);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// A window's samples, read row by row as the tracker reads them, are the image's
        /// bilinear samples ([`GreyImage::sample`], the reference), and a window that
        /// would leave the image is refused.
        #[test]
        fn window_samples_are_bilinear_samples(x in -2.0f64..30.0, y in -2.0f64..30.0, n in 1usize..12, seed in any::<u64>()) {
            let (w, h) = (32, 30);
            let mut s = seed | 1;
            let data: Vec<f32> = (0..w * h)
                .map(|_| {
                    s ^= s << 13;
                    s ^= s >> 7;
                    s ^= s << 17;
                    (s % 256) as f32
                })
                .collect();
            let im = GreyImage::from_vec(w, h, data).expect("size");
            let mut p = GreyPyramid::new(1);
            p.build_from_grey(&im);
            let fits = x >= 0.0 && y >= 0.0 && x + (n - 1) as f64 <= (w - 1) as f64 && y + (n - 1) as f64 <= (h - 1) as f64;
            match Window::at(&p, 0, x, y, n) {
                None => prop_assert!(!fits),
                Some(win) => {
                    prop_assert!(fits);
                    let mut out = vec![0.0; n * n];
                    win.read(p.level(0), n, &mut out);
                    for j in 0..n {
                        for i in 0..n {
                            let want = im.sample(x + i as f64, y + j as f64).expect("inside");
                            prop_assert!((out[j * n + i] - want).abs() < 1e-3, "({}, {}): {} vs {}", i, j, out[j * n + i], want);
                        }
                    }
                }
            }
        }
    }
}
