//! Reading a quad's cells: the projective map from the tag's square onto the quad, the
//! grey of every cell, and the checks that it is a tag's border at all.
//!
//! The map sends the unit square (the black border's outer edge, u right, v down in
//! cells / n) onto the four corners in order (Heckbert's closed form, 1989: exact for four
//! points, no solve). Each cell's grey is the mean of four bilinear samples at a quarter
//! cell either side of its centre, so a sample landing on a cell's antialiased edge does
//! not decide it alone.
//!
//! The border decides the threshold: the black ring's mean and the white ring's mean
//! (the cells just outside) give the tag's own black and white levels, and a bit is
//! white when its cell is above their midpoint. A quad is refused before decoding when
//! those levels are less than the contrast apart, when more than the allowed border cells
//! are on the wrong side of the midpoint, or when the data cells are, on average, too
//! close to the midpoint (the *margin*, in half-contrasts: 1 for cells exactly at the
//! black and white levels, 0 for a uniform grey).

use super::family::{MAX_CELLS, TagFamily};
use super::quad::bilinear;

/// The projective map of the unit square onto a quad (corners for (0,0), (1,0), (1,1),
/// (0,1)).
#[derive(Debug, Clone, Copy)]
pub(super) struct SquareMap {
    m: [f64; 8],
}

impl SquareMap {
    /// Heckbert's square-to-quad map, or `None` for a degenerate quad.
    pub(super) fn new(c: &[[f64; 2]; 4]) -> Option<Self> {
        let [[x0, y0], [x1, y1], [x2, y2], [x3, y3]] = *c;
        let (dx1, dx2, dx3) = (x1 - x2, x3 - x2, x0 - x1 + x2 - x3);
        let (dy1, dy2, dy3) = (y1 - y2, y3 - y2, y0 - y1 + y2 - y3);
        let den = dx1 * dy2 - dx2 * dy1;
        if den.abs() < 1e-12 || !den.is_finite() {
            return None;
        }
        let g = (dx3 * dy2 - dx2 * dy3) / den;
        let h = (dx1 * dy3 - dx3 * dy1) / den;
        Some(Self {
            m: [
                x1 - x0 + g * x1,
                x3 - x0 + h * x3,
                x0,
                y1 - y0 + g * y1,
                y3 - y0 + h * y3,
                y0,
                g,
                h,
            ],
        })
    }

    /// The image of (u, v).
    pub(super) fn apply(&self, u: f64, v: f64) -> [f64; 2] {
        let m = &self.m;
        let w = m[6] * u + m[7] * v + 1.0;
        [(m[0] * u + m[1] * v + m[2]) / w, (m[3] * u + m[4] * v + m[5]) / w]
    }
}

/// What the cells of a quad showed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct CellRead {
    /// 1 where a cell is white, quad order `grid[y][x]`.
    pub grid: [[u8; MAX_CELLS]; MAX_CELLS],
    /// White ring's mean grey minus the black ring's.
    pub contrast: f64,
    /// Mean distance of the data cells from the midpoint, in half-contrasts.
    pub margin: f64,
    /// Border and ring cells on the wrong side of the midpoint.
    pub border_errors: u32,
}

/// The limits a quad's cells must meet to be decoded.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct CellLimits {
    pub min_contrast: f64,
    pub max_border_errors: u32,
    pub min_margin: f64,
}

/// Reads the cells of `family`'s tag through `map`; `None` when the limits refuse it.
pub(super) fn read_cells(
    grey: &[u8],
    w: usize,
    h: usize,
    map: &SquareMap,
    family: TagFamily,
    lim: &CellLimits,
) -> Option<CellRead> {
    let n = family.cells() as isize;
    // Grey of cell (x, y), x and y from -1 (the white ring) to n (the ring again).
    let cell = |x: isize, y: isize| {
        let mut s = 0.0;
        for (ox, oy) in [(0.25, 0.25), (0.75, 0.25), (0.25, 0.75), (0.75, 0.75)] {
            let p = map.apply((x as f64 + ox) / n as f64, (y as f64 + oy) / n as f64);
            s += bilinear(grey, w, h, p[0], p[1]);
        }
        0.25 * s
    };
    let mut vals = [[0.0f64; MAX_CELLS + 2]; MAX_CELLS + 2];
    let (mut black, mut nb, mut white, mut nw) = (0.0, 0.0, 0.0, 0.0);
    for y in -1..=n {
        for x in -1..=n {
            let v = cell(x, y);
            vals[(y + 1) as usize][(x + 1) as usize] = v;
            let ring = x == -1 || y == -1 || x == n || y == n;
            let border = !ring && (x == 0 || y == 0 || x == n - 1 || y == n - 1);
            if ring {
                white += v;
                nw += 1.0;
            } else if border {
                black += v;
                nb += 1.0;
            }
        }
    }
    let (black, white) = (black / nb, white / nw);
    let contrast = white - black;
    // NaN (no cells read) fails too.
    if contrast.is_nan() || contrast < lim.min_contrast {
        return None;
    }
    let mid = 0.5 * (black + white);
    let mut read = CellRead {
        grid: [[0; MAX_CELLS]; MAX_CELLS],
        contrast,
        margin: 0.0,
        border_errors: 0,
    };
    let mut margin = 0.0;
    for y in -1..=n {
        for x in -1..=n {
            let v = vals[(y + 1) as usize][(x + 1) as usize];
            let ring = x == -1 || y == -1 || x == n || y == n;
            let border = !ring && (x == 0 || y == 0 || x == n - 1 || y == n - 1);
            if ring {
                read.border_errors += (v <= mid) as u32;
            } else if border {
                read.border_errors += (v >= mid) as u32;
            } else {
                read.grid[y as usize][x as usize] = (v > mid) as u8;
                margin += (v - mid).abs();
            }
        }
    }
    if read.border_errors > lim.max_border_errors {
        return None;
    }
    let data = ((n - 2) * (n - 2)) as f64;
    read.margin = margin / data / (0.5 * contrast);
    (read.margin >= lim.min_margin).then_some(read)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_square_map_sends_the_unit_square_onto_the_corners() {
        let c = [[10.0, 12.0], [40.0, 8.0], [44.0, 50.0], [6.0, 41.0]];
        let m = SquareMap::new(&c).unwrap();
        for (uv, q) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)].iter().zip(&c) {
            let p = m.apply(uv.0, uv.1);
            assert!((p[0] - q[0]).abs() < 1e-9 && (p[1] - q[1]).abs() < 1e-9);
        }
        assert!(SquareMap::new(&[[0.0, 0.0]; 4]).is_none());
    }

    #[test]
    fn an_upright_tag_reads_its_own_grid() {
        // tag36h11 id 0 drawn axis-aligned, 10 px per cell, ring included, on grey.
        let fam = TagFamily::Tag36h11;
        let g = fam.cell_grid(0).unwrap();
        let (w, h) = (120usize, 120usize);
        let mut im = vec![128u8; w * h];
        for y in 0..100 {
            for x in 0..100 {
                let (cx, cy) = (x / 10, y / 10);
                let white = cx == 0 || cy == 0 || cx == 9 || cy == 9 || g[cy - 1][cx - 1] == 1;
                im[(y + 10) * w + x + 10] = if white { 220 } else { 30 };
            }
        }
        // The black border's outer corners (pixel edges at 19.5 and 99.5).
        let c = [[19.5, 19.5], [99.5, 19.5], [99.5, 99.5], [19.5, 99.5]];
        let lim = CellLimits {
            min_contrast: 30.0,
            max_border_errors: 0,
            min_margin: 0.5,
        };
        let r = read_cells(&im, w, h, &SquareMap::new(&c).unwrap(), fam, &lim).unwrap();
        assert_eq!(r.grid, g);
        assert_eq!(r.border_errors, 0);
        assert!((r.contrast - 190.0).abs() < 1e-9 && (r.margin - 1.0).abs() < 1e-9);
        // The same quad over a flat image has no contrast.
        assert!(read_cells(&[128; 120 * 120], w, h, &SquareMap::new(&c).unwrap(), fam, &lim).is_none());
    }
}
