//! Quads from black components: the outer contour, its four corners, and sub-pixel edges.
//!
//! AprilTag 3 clusters the edge pixels between black and white regions and fits lines to
//! them. Ours is simpler and does the same job for a tag's black border, whose black
//! region (the border and the black data cells that touch it) is one 8-connected
//! component:
//!
//! 1. **Contour.** Moore-neighbour tracing from the component's first pixel (top-most,
//!    then left-most; its west neighbour is clear), clockwise in the image (y down), at
//!    pixel centres, stopping when the first step repeats (Jacob's criterion) or at a
//!    length cap.
//! 2. **Corners.** The contour point farthest from the contour's mean, the one farthest
//!    from it, and the two farthest from their chord on either side: the corners of any
//!    convex quad. The quad is kept only when every stretch of contour between two
//!    corners lies within `1 + 0.04·side` px of its chord (straight sides), the corners
//!    turn one way (convex), and the shortest side is long enough.
//! 3. **Edges.** Along each side, 4–32 profiles across the edge find where the grey
//!    crosses the midpoint of its two ends (the profile's inner end in the black border,
//!    its outer one in the white ring), to a quarter pixel by linear interpolation; a
//!    total-least-squares line through the crossings is the side, and neighbouring sides
//!    meet at the refined corners. The midpoint crossing is unbiased under a symmetric
//!    blur, and is what gives the pose its accuracy: the traced contour runs half a
//!    pixel inside the true edge.

/// Grey at (x, y) by bilinear interpolation, the nearest edge pixel outside the image.
pub(super) fn bilinear(grey: &[u8], w: usize, h: usize, x: f64, y: f64) -> f64 {
    if w == 0 || h == 0 || !x.is_finite() || !y.is_finite() {
        return 0.0;
    }
    let xc = x.clamp(0.0, (w - 1) as f64);
    let yc = y.clamp(0.0, (h - 1) as f64);
    let (x0, y0) = (xc.floor() as usize, yc.floor() as usize);
    let (x1, y1) = ((x0 + 1).min(w - 1), (y0 + 1).min(h - 1));
    let (fx, fy) = (xc - x0 as f64, yc - y0 as f64);
    let g = |x: usize, y: usize| grey[y * w + x] as f64;
    let top = g(x0, y0) * (1.0 - fx) + g(x1, y0) * fx;
    let bot = g(x0, y1) * (1.0 - fx) + g(x1, y1) * fx;
    top * (1.0 - fy) + bot * fy
}

/// The 8 neighbours, clockwise in the image (y down) from east.
const DIRS: [(i32, i32); 8] = [(1, 0), (1, 1), (0, 1), (-1, 1), (-1, 0), (-1, -1), (0, -1), (1, -1)];

fn dir_index(dx: i32, dy: i32) -> usize {
    DIRS.iter().position(|&d| d == (dx, dy)).unwrap_or(4)
}

/// Traces the outer contour of the 8-connected component of `mask` (1 = set) that
/// starts at `start` (its top-most, then left-most pixel) into `out`, clockwise. Returns
/// false (and a partial contour) when it would exceed `max_len` points.
pub(super) fn trace_contour(
    mask: &[u8],
    w: usize,
    h: usize,
    start: (u32, u32),
    max_len: usize,
    out: &mut Vec<[f64; 2]>,
) -> bool {
    out.clear();
    let set = |x: i32, y: i32| {
        x >= 0 && y >= 0 && (x as usize) < w && (y as usize) < h && mask[y as usize * w + x as usize] != 0
    };
    let s = (start.0 as i32, start.1 as i32);
    if !set(s.0, s.1) {
        return false;
    }
    out.push([s.0 as f64, s.1 as f64]);
    let (mut p, mut back) = (s, 4usize);
    let mut first: Option<(i32, i32)> = None;
    loop {
        let mut step = None;
        for i in 1..=8 {
            let d = (back + i) % 8;
            let q = (p.0 + DIRS[d].0, p.1 + DIRS[d].1);
            if set(q.0, q.1) {
                step = Some((q, d));
                break;
            }
        }
        let Some((q, d)) = step else { return true }; // a single pixel
        if p == s {
            match first {
                None => first = Some(q),
                Some(f) if f == q => {
                    out.pop(); // the start, reached again
                    return true;
                }
                Some(_) => {}
            }
        }
        // The last clear neighbour examined, seen from q.
        let c = DIRS[(d + 7) % 8];
        back = dir_index(p.0 + c.0 - q.0, p.1 + c.1 - q.1);
        p = q;
        if out.len() >= max_len {
            return false;
        }
        out.push([p.0 as f64, p.1 as f64]);
    }
}

fn dist2(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)
}

/// Signed distance of `p` from the line a → b (positive to the right of travel in a
/// y-down image, i.e. inside a clockwise polygon).
fn side(a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> f64 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let l = dx.hypot(dy).max(1e-12);
    (dx * (p[1] - a[1]) - dy * (p[0] - a[0])) / l
}

/// The four corners of a contour that is a convex quad with straight sides, in contour
/// (clockwise) order, or `None`; the shortest side must be at least `min_side_px`.
pub(super) fn quad_corners(contour: &[[f64; 2]], min_side_px: f64) -> Option<[[f64; 2]; 4]> {
    let n = contour.len();
    if n < 8 {
        return None;
    }
    let (mut mx, mut my) = (0.0, 0.0);
    for p in contour {
        mx += p[0];
        my += p[1];
    }
    let m = [mx / n as f64, my / n as f64];
    let far = |from: [f64; 2]| {
        (0..n)
            .max_by(|&a, &b| dist2(contour[a], from).total_cmp(&dist2(contour[b], from)))
            .unwrap_or(0)
    };
    let i0 = far(m);
    let i2 = far(contour[i0]);
    let (a, b) = (contour[i0], contour[i2]);
    let by_side = |i: &usize, j: &usize| side(a, b, contour[*i]).total_cmp(&side(a, b, contour[*j]));
    let i1 = (0..n).max_by(by_side)?;
    let i3 = (0..n).min_by(by_side)?;
    let mut idx = [i0, i1, i2, i3];
    idx.sort_unstable();
    if idx.windows(2).any(|w| w[0] == w[1]) {
        return None;
    }
    let c = idx.map(|i| contour[i]);
    for k in 0..4 {
        let (p, q) = (c[k], c[(k + 1) % 4]);
        let len = dist2(p, q).sqrt();
        if len < min_side_px || side(p, q, c[(k + 2) % 4]) <= 0.0 {
            return None; // short, or not clockwise and convex
        }
        let tol = 1.0 + 0.04 * len;
        let (s, e) = (idx[k], if k == 3 { idx[0] + n } else { idx[k + 1] });
        if (s..=e).any(|i| side(p, q, contour[i % n]).abs() > tol) {
            return None;
        }
    }
    Some(c)
}

/// A line through `p` along unit `d`.
#[derive(Debug, Clone, Copy)]
struct Line {
    p: [f64; 2],
    d: [f64; 2],
}

fn intersect(l: Line, m: Line) -> Option<[f64; 2]> {
    let den = l.d[0] * m.d[1] - l.d[1] * m.d[0];
    if den.abs() < 1e-9 {
        return None;
    }
    let t = ((m.p[0] - l.p[0]) * m.d[1] - (m.p[1] - l.p[1]) * m.d[0]) / den;
    Some([l.p[0] + t * l.d[0], l.p[1] + t * l.d[1]])
}

/// Refines a clockwise quad's corners to the grey image's edges (see the module docs);
/// `None` when a side has too few clear crossings or a corner moves too far (more than
/// 2 px plus a tenth of the side), which is not a tag's border.
pub(super) fn refine_corners(grey: &[u8], w: usize, h: usize, c: [[f64; 2]; 4]) -> Option<[[f64; 2]; 4]> {
    let mut lines = [Line {
        p: [0.0; 2],
        d: [0.0; 2],
    }; 4];
    let mut shortest = f64::INFINITY;
    for k in 0..4 {
        let (a, b) = (c[k], c[(k + 1) % 4]);
        let len = dist2(a, b).sqrt();
        shortest = shortest.min(len);
        let d = [(b[0] - a[0]) / len, (b[1] - a[1]) / len];
        let n = [d[1], -d[0]]; // outward for a clockwise quad in a y-down image
        let r = (0.06 * len).clamp(1.5, 5.0);
        let samples = ((len / 2.0) as usize).clamp(4, 32);
        let (mut sx, mut sy, mut sxx, mut syy, mut sxy, mut cnt) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        for i in 0..samples {
            let t = 0.1 + 0.8 * (i as f64 + 0.5) / samples as f64;
            let p = [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
            let at = |s: f64| bilinear(grey, w, h, p[0] + s * n[0], p[1] + s * n[1]);
            let (inner, outer) = (at(-r), at(r));
            if outer - inner < 8.0 {
                continue;
            }
            let mid = 0.5 * (inner + outer);
            let (mut s, mut prev) = (-r, inner);
            while s < r {
                let g = at(s + 0.25);
                if prev < mid && g >= mid {
                    let e = s + 0.25 * (mid - prev) / (g - prev);
                    let q = [p[0] + e * n[0], p[1] + e * n[1]];
                    sx += q[0];
                    sy += q[1];
                    sxx += q[0] * q[0];
                    syy += q[1] * q[1];
                    sxy += q[0] * q[1];
                    cnt += 1.0;
                    break;
                }
                prev = g;
                s += 0.25;
            }
        }
        if cnt < 3.0 {
            return None;
        }
        let (mx, my) = (sx / cnt, sy / cnt);
        let (cxx, cyy, cxy) = (sxx / cnt - mx * mx, syy / cnt - my * my, sxy / cnt - mx * my);
        // The principal direction of the crossings' scatter.
        let ang = 0.5 * (2.0 * cxy).atan2(cxx - cyy);
        let mut ld = [ang.cos(), ang.sin()];
        if ld[0] * d[0] + ld[1] * d[1] < 0.0 {
            ld = [-ld[0], -ld[1]];
        }
        lines[k] = Line { p: [mx, my], d: ld };
    }
    let mut out = [[0.0; 2]; 4];
    let max_move = 2.0 + 0.1 * shortest;
    for k in 0..4 {
        let q = intersect(lines[(k + 3) % 4], lines[k])?;
        if !(q[0].is_finite() && q[1].is_finite()) || dist2(q, c[k]).sqrt() > max_move {
            return None;
        }
        out[k] = q;
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square_mask(w: usize, h: usize, x0: usize, y0: usize, s: usize) -> Vec<u8> {
        let mut m = vec![0u8; w * h];
        for y in y0..y0 + s {
            for x in x0..x0 + s {
                m[y * w + x] = 1;
            }
        }
        m
    }

    #[test]
    fn a_square_traces_clockwise_and_gives_its_corners() {
        let m = square_mask(20, 20, 3, 4, 10);
        let mut c = Vec::new();
        assert!(trace_contour(&m, 20, 20, (3, 4), 1000, &mut c));
        assert_eq!(c.len(), 36, "the 36 boundary pixels of a 10 × 10 square, once each");
        assert_eq!(c[1], [4.0, 4.0], "first step east along the top");
        let q = quad_corners(&c, 5.0).unwrap();
        assert_eq!(q, [[3.0, 4.0], [12.0, 4.0], [12.0, 13.0], [3.0, 13.0]]);
        assert!(quad_corners(&c, 10.0).is_none(), "sides of 9 px are too short");
        assert!(!trace_contour(&m, 20, 20, (3, 4), 10, &mut c), "length cap");
    }

    #[test]
    fn an_l_shape_and_a_single_pixel_are_not_quads() {
        let mut m = square_mask(20, 20, 2, 2, 12);
        for y in 2..8 {
            for x in 8..14 {
                m[y * 20 + x] = 0;
            }
        }
        let mut c = Vec::new();
        assert!(trace_contour(&m, 20, 20, (2, 2), 1000, &mut c));
        assert!(quad_corners(&c, 3.0).is_none());
        let one = square_mask(5, 5, 2, 2, 1);
        assert!(trace_contour(&one, 5, 5, (2, 2), 100, &mut c));
        assert_eq!(c.len(), 1);
        assert!(quad_corners(&c, 1.0).is_none());
        assert!(!trace_contour(&one, 5, 5, (0, 0), 100, &mut c), "start not set");
    }

    #[test]
    fn refinement_moves_the_corners_onto_the_true_edges() {
        // A black square on white with its edges at x = 10.0 and 30.0, y = 8.0 and 28.0
        // (pixel centres at integers, so pixel 10 is the first black one and the edge is
        // at 9.5 … the area from 9.5 to 29.5): sharp edges, the crossing is exact.
        let (w, h) = (40usize, 36usize);
        let mut g = vec![230u8; w * h];
        for y in 8..28 {
            for x in 10..30 {
                g[y * w + x] = 20;
            }
        }
        let rough = [[10.0, 8.0], [29.0, 8.0], [29.0, 27.0], [10.0, 27.0]];
        let r = refine_corners(&g, w, h, rough).unwrap();
        let truth = [[9.5, 7.5], [29.5, 7.5], [29.5, 27.5], [9.5, 27.5]];
        for (a, b) in r.iter().zip(&truth) {
            assert!(dist2(*a, *b).sqrt() < 0.05, "{a:?} vs {b:?}");
        }
        // A flat image has no edges to refine to.
        assert!(refine_corners(&[128; 40 * 36], w, h, rough).is_none());
        assert_eq!(bilinear(&[], 0, 0, 1.0, 1.0), 0.0);
    }
}
