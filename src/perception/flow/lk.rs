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
//! the coarse windows leave it first). The forward–backward check tracks each result back
//! and drops points that do not return within [`LkParams::max_fb_px`].
//!
//! Coordinates have pixel centres at integers (add 0.5 for the camera model). The window
//! buffers are sized in [`LucasKanade::new`]; tracking does not allocate.

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
            let v = match self.refine(prev.level(l), next.level(l), at, g) {
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
    fn refine(&mut self, prev: &GreyImage, next: &GreyImage, at: [f64; 2], g: [f64; 2]) -> Option<[f64; 2]> {
        let r = self.params.radius as isize;
        let side = (2 * r + 1) as usize;
        // The previous window and its gradients (central differences of the bilinear
        // image), and G.
        let (mut gxx, mut gxy, mut gyy) = (0.0f64, 0.0f64, 0.0f64);
        for dy in -r..=r {
            for dx in -r..=r {
                let (x, y) = (at[0] + dx as f64, at[1] + dy as f64);
                let i = (dy + r) as usize * side + (dx + r) as usize;
                let c = prev.sample(x, y)?;
                let ix = (prev.sample(x + 1.0, y)? - prev.sample(x - 1.0, y)?) * 0.5;
                let iy = (prev.sample(x, y + 1.0)? - prev.sample(x, y - 1.0)?) * 0.5;
                self.prev_win[i] = c;
                self.grad_x[i] = ix;
                self.grad_y[i] = iy;
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
            let (mut bx, mut by) = (0.0f64, 0.0f64);
            for dy in -r..=r {
                for dx in -r..=r {
                    let i = (dy + r) as usize * side + (dx + r) as usize;
                    let q = next.sample(at[0] + g[0] + v[0] + dx as f64, at[1] + g[1] + v[1] + dy as f64)?;
                    let diff = (self.prev_win[i] - q) as f64;
                    bx += diff * self.grad_x[i] as f64;
                    by += diff * self.grad_y[i] as f64;
                }
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
