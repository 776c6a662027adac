//! Ray–surface intersection with analytic anti-aliasing, one row of pixels at a time.
//!
//! A [`Surface`] is a primitive moved into the camera frame for one frame, with the
//! constants its kernel needs precomputed. [`hit_row`] intersects it with a row's rays and
//! writes, per pixel, the coverage in [0, 1] (the signed distance from the hit point to
//! the surface's outline, in pixel footprints, plus one half), the local coordinates of
//! the hit, its distance and footprint. The kernels are branch-free (a miss is a coverage
//! of 0), read the rays as contiguous arrays and spend one or two divisions per pixel, so
//! the compiler vectorises them; the shading pass then visits only the covered pixels.
//!
//! [`reference`] is the direct, one-ray-at-a-time form the kernels are tested against.

use super::rays::RowRays;

/// What kind of outline a surface has.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Kind {
    /// Rectangle of half extents `half` along `u` and `v`.
    Rect,
    /// Disc of radius `half[0]`.
    Disc,
    /// Triangle `o`, `o + u`, `o + v`.
    Triangle,
    /// Sphere of radius `half[0]` centred at `o`.
    Sphere,
    /// An unbounded plane (the ground): covers every pixel whose ray meets it.
    Plane,
}

/// A primitive in the camera frame, ready for the row kernels.
#[derive(Debug, Clone, Copy)]
pub(super) struct Surface {
    /// Centre (rect, disc, sphere) or first vertex (triangle).
    pub o: [f32; 3],
    /// First in-plane axis (unit), or the first edge of a triangle.
    pub u: [f32; 3],
    /// Second in-plane axis (unit), or the second edge of a triangle.
    pub v: [f32; 3],
    /// Unit normal (planar kinds).
    pub n: [f32; 3],
    /// Half extents (rect), radius (disc, sphere).
    pub half: [f32; 2],
    /// Outline kind.
    pub kind: Kind,
    /// Smallest |n·r| the footprint uses: a pixel stretches as the surface turns away, up
    /// to 1 / `min_cos` times.
    min_cos: f32,
    /// |n·o|: the plane's distance from the camera (planar kinds), or |o|² (sphere).
    abs_d: f32,
    /// Sign of n·o: a ray hits the plane in front of the camera when n·r has this sign.
    d_sign: f32,
    /// 1 / `abs_d`.
    inv_abs_d: f32,
    /// Triangle constants: e1·e1, e1·e2, e2·e2, 1/den, and the heights over the three
    /// edges (den = (e1·e1)(e2·e2) − (e1·e2)²).
    tri: [f32; 7],
}

#[inline(always)]
pub(super) fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Coverage of a pixel whose centre is `d` footprints inside an edge.
#[inline(always)]
#[allow(
    clippy::manual_clamp,
    reason = "max/min send NaN to 0 and vectorise; clamp keeps NaN"
)]
pub(super) fn cov(d: f32) -> f32 {
    // max/min rather than clamp: they vectorise, and send NaN to 0.
    (0.5 + d).max(0.0).min(1.0)
}

impl Surface {
    /// A planar surface (`Rect`, `Disc`, `Triangle` or `Plane`). `None` when it cannot be seen:
    /// the camera lies in its plane, it is one-sided and seen from behind, or a triangle
    /// is degenerate.
    pub fn planar(
        kind: Kind,
        o: [f32; 3],
        u: [f32; 3],
        v: [f32; 3],
        n: [f32; 3],
        half: [f32; 2],
        two_sided: bool,
    ) -> Option<Self> {
        let d = dot(n, o);
        // One-sided planes face the camera when the camera is on the normal's side.
        if d == 0.0 || (!two_sided && d > 0.0) || !d.is_finite() {
            return None;
        }
        let mut s = Self {
            o,
            u,
            v,
            n,
            half,
            kind,
            min_cos: 0.1,
            abs_d: d.abs(),
            d_sign: d.signum(),
            inv_abs_d: 1.0 / d.abs(),
            tri: [0.0; 7],
        };
        if kind == Kind::Triangle {
            let (d11, d12, d22) = (dot(u, u), dot(u, v), dot(v, v));
            let den = d11 * d22 - d12 * d12;
            if den.abs() < 1e-12 {
                return None;
            }
            let e3 = [v[0] - u[0], v[1] - u[1], v[2] - u[2]];
            let root = den.sqrt();
            s.tri = [
                d11,
                d12,
                d22,
                1.0 / den,
                root / d11.sqrt(),
                root / d22.sqrt(),
                root / dot(e3, e3).sqrt(),
            ];
        }
        Some(s)
    }

    /// The same surface with footprints stretched up to 1 / `min_cos` times (default 10).
    pub fn with_min_cos(mut self, min_cos: f32) -> Self {
        self.min_cos = min_cos;
        self
    }

    /// A sphere of `radius` centred at `o` (camera frame).
    pub fn sphere(o: [f32; 3], radius: f32) -> Self {
        let oo = dot(o, o);
        Self {
            o,
            u: [1.0, 0.0, 0.0],
            v: [0.0, 1.0, 0.0],
            n: [0.0, 0.0, 1.0],
            half: [radius; 2],
            kind: Kind::Sphere,
            min_cos: 1.0,
            abs_d: oo,
            d_sign: 1.0,
            inv_abs_d: 1.0 / oo.max(1e-12),
            tri: [0.0; 7],
        }
    }
}

/// Per-pixel results of one row: reusable buffers, as long as the widest row.
#[derive(Debug, Clone, Default)]
pub(super) struct RowHits {
    /// Coverage in [0, 1]; 0 for a miss (the other fields are then meaningless).
    pub cov: Vec<f32>,
    /// Local coordinate along `u` (rect, disc), barycentric s (triangle), or the image-plane
    /// offset from a sphere's centre.
    pub a: Vec<f32>,
    /// Local coordinate along `v`, barycentric q, or the sphere's vertical offset.
    pub b: Vec<f32>,
    /// Distance along the ray, m.
    pub t: Vec<f32>,
    /// The pixel's footprint on the surface, m (grows as the surface turns away).
    pub fp: Vec<f32>,
    /// n·r: which side the ray meets (−1 for spheres).
    pub nr: Vec<f32>,
}

impl RowHits {
    /// Makes room for rows of `n` pixels.
    pub fn reserve_row(&mut self, n: usize) {
        for v in [
            &mut self.cov,
            &mut self.a,
            &mut self.b,
            &mut self.t,
            &mut self.fp,
            &mut self.nr,
        ] {
            if v.len() < n {
                v.resize(n, 0.0);
            }
        }
    }
}

/// One pixel's hit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Hit {
    /// Coverage in [0, 1].
    pub cov: f32,
    /// Local coordinate a.
    pub a: f32,
    /// Local coordinate b.
    pub b: f32,
    /// Distance, m.
    pub t: f32,
    /// Footprint, m.
    pub fp: f32,
    /// n·r.
    pub nr: f32,
}

/// Intersects `s` with every ray of `rays`, writing `hits[..rays.x.len()]`.
pub(super) fn hit_row(s: &Surface, rays: RowRays<'_>, hits: &mut RowHits) {
    row::<true>(s, rays, hits)
}

/// As [`hit_row`], but writes only the coverage: enough for a matte one-colour surface,
/// and about half the work (no footprint division, one array written instead of six).
pub(super) fn cover_row(s: &Surface, rays: RowRays<'_>, hits: &mut RowHits) {
    row::<false>(s, rays, hits)
}

fn row<const FULL: bool>(s: &Surface, rays: RowRays<'_>, hits: &mut RowHits) {
    match s.kind {
        Kind::Rect => each::<FULL>(rays, hits, |r, ia| {
            let (mut h, ok, inv_fp) = plane(s, r, ia);
            let c = cov((s.half[0] - h.a.abs()) * inv_fp) * cov((s.half[1] - h.b.abs()) * inv_fp);
            h.cov = if ok { c } else { 0.0 };
            h
        }),
        Kind::Disc => each::<FULL>(rays, hits, |r, ia| {
            let (mut h, ok, inv_fp) = plane(s, r, ia);
            let c = cov((s.half[0] - (h.a * h.a + h.b * h.b).sqrt()) * inv_fp);
            h.cov = if ok { c } else { 0.0 };
            h
        }),
        Kind::Triangle => each::<FULL>(rays, hits, |r, ia| {
            let (mut h, ok, inv_fp) = plane(s, r, ia);
            let [d11, d12, d22, inv_den, h1, h2, h3] = s.tri;
            let (pd1, pd2) = (h.a, h.b);
            let sb = (d22 * pd1 - d12 * pd2) * inv_den;
            let qb = (d11 * pd2 - d12 * pd1) * inv_den;
            let c = cov(qb * h1 * inv_fp) * cov(sb * h2 * inv_fp) * cov((1.0 - sb - qb) * h3 * inv_fp);
            h.a = sb;
            h.b = qb;
            h.cov = if ok { c } else { 0.0 };
            h
        }),
        Kind::Sphere => each::<FULL>(rays, hits, |r, ia| sphere(s, r, ia)),
        Kind::Plane => each::<FULL>(rays, hits, |r, ia| {
            let (mut h, ok, _) = plane(s, r, ia);
            h.cov = if ok { 1.0 } else { 0.0 };
            h
        }),
    }
}

/// Runs a per-pixel kernel over a row, storing every field (`FULL`) or the coverage only.
/// Every slice is cut to the row's length first, so the loop carries no bounds checks and
/// vectorises.
#[inline(always)]
fn each<const FULL: bool>(rays: RowRays<'_>, hits: &mut RowHits, f: impl Fn([f32; 3], f32) -> Hit) {
    let n = rays.x.len();
    let (rx, ry, rz, ia) = (&rays.x[..n], &rays.y[..n], &rays.z[..n], &rays.inv_ang[..n]);
    let (cov, a, b) = (&mut hits.cov[..n], &mut hits.a[..n], &mut hits.b[..n]);
    let (t, fp, nr) = (&mut hits.t[..n], &mut hits.fp[..n], &mut hits.nr[..n]);
    if !FULL {
        for i in 0..n {
            cov[i] = f([rx[i], ry[i], rz[i]], ia[i]).cov;
        }
        return;
    }
    for i in 0..n {
        let h = f([rx[i], ry[i], rz[i]], ia[i]);
        cov[i] = h.cov;
        a[i] = h.a;
        b[i] = h.b;
        t[i] = h.t;
        fp[i] = h.fp;
        nr[i] = h.nr;
    }
}

/// The plane part of a planar hit: (hit with a = p·u, b = p·v, whether the ray meets the
/// plane in front of the camera, 1 / footprint). The footprint is t·angle / max(|n·r|,
/// min_cos): a pixel stretches as the surface turns away.
#[inline(always)]
fn plane(s: &Surface, r: [f32; 3], inv_ang: f32) -> (Hit, bool, f32) {
    let nr = dot(s.n, r);
    let nr_s = nr * s.d_sign; // > 0 when the hit is in front of the camera
    let t = s.abs_d / nr_s;
    let inv_fp = nr_s.max(s.min_cos) * nr_s * s.inv_abs_d * inv_ang;
    let ok = (nr_s > 1e-6) & (t > 1e-3);
    let p = [r[0] * t - s.o[0], r[1] * t - s.o[1], r[2] * t - s.o[2]];
    let hit = Hit {
        cov: 0.0,
        a: dot(p, s.u),
        b: dot(p, s.v),
        t,
        fp: 1.0 / inv_fp,
        nr,
    };
    (hit, ok, inv_fp)
}

/// A sphere hit: coverage from the ray's distance to the centre; local coordinates are
/// the image-plane offsets from the centre (for textures).
#[inline(always)]
fn sphere(s: &Surface, r: [f32; 3], inv_ang: f32) -> Hit {
    let tc = dot(s.o, r);
    let d2 = (s.abs_d - tc * tc).max(0.0);
    let rad = s.half[0];
    let c = cov((rad - d2.sqrt()) * inv_ang / tc);
    let t = tc - (rad * rad - d2).max(0.0).sqrt();
    let p = [r[0] * t - s.o[0], r[1] * t - s.o[1], r[2] * t - s.o[2]];
    Hit {
        cov: if tc > 0.0 { c } else { 0.0 },
        a: p[0],
        b: -p[1],
        t,
        fp: t / inv_ang,
        nr: -1.0,
    }
}

/// The direct form: one ray, divisions where the formulas have them, early returns for
/// misses. The kernels must agree with it.
#[cfg(test)]
pub(super) fn reference(s: &Surface, two_sided: bool, r: [f32; 3], ang: f32) -> Option<Hit> {
    if s.kind == Kind::Sphere {
        let tc = dot(s.o, r);
        if tc <= 0.0 {
            return None;
        }
        let d2 = (dot(s.o, s.o) - tc * tc).max(0.0);
        let rad = s.half[0];
        let c = cov((rad - d2.sqrt()) / (tc * ang));
        if c <= 0.0 {
            return None;
        }
        let t = tc - (rad * rad - d2).max(0.0).sqrt();
        let p = [r[0] * t - s.o[0], r[1] * t - s.o[1], r[2] * t - s.o[2]];
        return Some(Hit {
            cov: c,
            a: p[0],
            b: -p[1],
            t,
            fp: t * ang,
            nr: -1.0,
        });
    }
    let nr = dot(s.n, r);
    if nr.abs() < 1e-6 || (!two_sided && nr > 0.0) {
        return None;
    }
    let t = dot(s.n, s.o) / nr;
    if t <= 1e-3 {
        return None;
    }
    let p = [r[0] * t - s.o[0], r[1] * t - s.o[1], r[2] * t - s.o[2]];
    let fp = t * ang / nr.abs().max(s.min_cos);
    let (a, b) = (dot(p, s.u), dot(p, s.v));
    let (c, a, b) = match s.kind {
        Kind::Rect => (cov((s.half[0] - a.abs()) / fp) * cov((s.half[1] - b.abs()) / fp), a, b),
        Kind::Disc => (cov((s.half[0] - (a * a + b * b).sqrt()) / fp), a, b),
        Kind::Plane => (1.0, a, b),
        _ => {
            let (e1, e2) = (s.u, s.v);
            let (d11, d12, d22) = (dot(e1, e1), dot(e1, e2), dot(e2, e2));
            let den = d11 * d22 - d12 * d12;
            let sb = (d22 * a - d12 * b) / den;
            let qb = (d11 * b - d12 * a) / den;
            let e3 = [e2[0] - e1[0], e2[1] - e1[1], e2[2] - e1[2]];
            let (h1, h2, h3) = (
                den.sqrt() / d11.sqrt(),
                den.sqrt() / d22.sqrt(),
                den.sqrt() / dot(e3, e3).sqrt(),
            );
            let c = cov(qb * h1 / fp) * cov(sb * h2 / fp) * cov((1.0 - sb - qb) * h3 / fp);
            (c, sb, qb)
        }
    };
    Some(Hit {
        cov: c,
        a,
        b,
        t,
        fp,
        nr,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::rng::Rng;

    fn unit(v: [f32; 3]) -> [f32; 3] {
        let l = dot(v, v).sqrt();
        v.map(|c| c / l)
    }

    fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    }

    fn random_surface(rng: &mut Rng, kind: Kind) -> Option<(Surface, bool)> {
        let mut f = |lo: f64, hi: f64| rng.range(lo, hi) as f32;
        let o = [f(-1.0, 1.0), f(-1.0, 1.0), f(0.3, 4.0)];
        if kind == Kind::Sphere {
            return Some((Surface::sphere(o, f(0.02, 0.5)), true));
        }
        let u = unit([f(-1.0, 1.0), f(-1.0, 1.0), f(-1.0, 1.0)]);
        let w = [f(-1.0, 1.0), f(-1.0, 1.0), f(-1.0, 1.0)];
        let v = unit(cross(cross(u, w), u));
        let two_sided = f(0.0, 1.0) < 0.5;
        let s = match kind {
            Kind::Triangle => {
                let (e1, e2) = (
                    u.map(|c| c * 0.4),
                    [
                        v[0] * 0.3 + u[0] * 0.1,
                        v[1] * 0.3 + u[1] * 0.1,
                        v[2] * 0.3 + u[2] * 0.1,
                    ],
                );
                Surface::planar(kind, o, e1, e2, unit(cross(e1, e2)), [0.0; 2], two_sided)
            }
            _ => Surface::planar(kind, o, u, v, cross(u, v), [f(0.02, 0.6), f(0.02, 0.6)], two_sided),
        };
        s.map(|s| (s, two_sided))
    }

    /// The vectorised kernels agree with the direct form on random surfaces and rays,
    /// to float rounding, including at the anti-aliased edges.
    #[test]
    fn row_kernels_match_the_reference() {
        let mut rng = Rng::new(7);
        let n = 64;
        let mut hits = RowHits::default();
        hits.reserve_row(n);
        let mut edge_pixels = 0;
        for case in 0..500 {
            let kind = [Kind::Rect, Kind::Disc, Kind::Triangle, Kind::Sphere, Kind::Plane][case % 5];
            let Some((s, two_sided)) = random_surface(&mut rng, kind) else {
                continue;
            };
            // Rays fanning across the surface's centre, 1–4 mrad apart.
            let ang = rng.range(0.001, 0.004) as f32;
            let c = unit(s.o);
            let side = unit(cross(c, [0.3, 1.0, 0.1]));
            let (mut x, mut y, mut z, mut a, mut ia) = (vec![], vec![], vec![], vec![], vec![]);
            for i in 0..n {
                let k = (i as f32 - n as f32 / 2.0) * ang * rng.range(1.0, 8.0) as f32;
                let r = unit([c[0] + k * side[0], c[1] + k * side[1], c[2] + k * side[2]]);
                x.push(r[0]);
                y.push(r[1]);
                z.push(r[2]);
                a.push(ang);
                ia.push(1.0 / ang);
            }
            let rays = RowRays {
                x: &x,
                y: &y,
                z: &z,
                ang: &a,
                inv_ang: &ia,
            };
            hit_row(&s, rays, &mut hits);
            let full_cov = hits.cov[..n].to_vec();
            cover_row(&s, rays, &mut hits);
            assert_eq!(hits.cov[..n], full_cov[..], "coverage-only pass");
            for i in 0..n {
                let want = reference(&s, two_sided, [x[i], y[i], z[i]], ang);
                let got = hits.cov[i];
                match want {
                    None => assert!(got <= 1e-4, "case {case} {kind:?} px {i}: miss but coverage {got}"),
                    Some(h) => {
                        assert!(
                            (got - h.cov).abs() < 2e-3,
                            "case {case} {kind:?} px {i}: {got} vs {}",
                            h.cov
                        );
                        if got > 0.0 && got < 1.0 {
                            edge_pixels += 1;
                        }
                        if h.cov > 1e-3 {
                            let tol = 1e-4 * (1.0 + h.t.abs());
                            assert!((hits.t[i] - h.t).abs() < tol, "case {case} t {} vs {}", hits.t[i], h.t);
                            assert!((hits.a[i] - h.a).abs() < tol * 10.0 && (hits.b[i] - h.b).abs() < tol * 10.0);
                            assert!(
                                (hits.fp[i] - h.fp).abs() <= 1e-4 * h.fp,
                                "fp {} vs {}",
                                hits.fp[i],
                                h.fp
                            );
                            assert_eq!(hits.nr[i].signum(), h.nr.signum());
                        }
                    }
                }
            }
        }
        assert!(
            edge_pixels > 200,
            "the cases must exercise anti-aliased edges ({edge_pixels})"
        );
    }

    #[test]
    fn a_one_sided_plane_seen_from_behind_or_edge_on_is_culled() {
        let (x, y, z) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]);
        let rect = |o: [f32; 3], two_sided| Surface::planar(Kind::Rect, o, x, y, z, [0.5; 2], two_sided);
        // Camera at the origin, plane 1 m ahead with its normal pointing away: its back.
        assert!(rect(z, false).is_none());
        assert!(rect(z, true).is_some());
        // The camera in the plane.
        assert!(rect(x, true).is_none());
        // A degenerate triangle.
        let sliver = Surface::planar(Kind::Triangle, z, x, [2.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0; 2], true);
        assert!(sliver.is_none());
    }
}
