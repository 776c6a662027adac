//! The tag families and decoding a sampled cell grid against their codes.
//!
//! A tag of a family is `n × n` cells inside a one-cell white ring, `n` =
//! [`TagFamily::cells`]: a black border one cell wide, and the code's bits inside it. Bit
//! `i` of a code (most significant first) is the cell [`TagFamily::bit_cell`] of the tag
//! seen upright (x right, y down, cell 0 the black border's first); white is 1. These are
//! the AprilRobotics layouts, so a printed AprilTag of the family decodes to its usual id.
//!
//! **Rotations.** A quad's cells are sampled in the order its corners were found, so the
//! tag may sit in it turned by any multiple of 90°. [`TagFamily::decode`] reads the code
//! four ways: for `k` quarter turns clockwise (in the image, y down), the tag's cell
//! (x, y) is the quad's cell rotᵏ(x, y) with rot(x, y) = (n − 1 − y, x), and the tag's
//! corner `j` (0 top-left, then clockwise) is the quad's corner `(j + k) mod 4`.
//!
//! **Matching.** The observed code is compared with every code of the family by
//! Hamming distance (587 × 4 popcounts for tag36h11, about 2 µs: no hash table needed);
//! the nearest within [`TagFamily::max_correctable`] bits wins. A family of minimum
//! distance h corrects ⌊(h − 1)/2⌋ bits and no more: beyond that a misread code could be
//! nearer to another tag's.

use super::codes::{
    TAG16H5_BITS, TAG16H5_CODES, TAG16H5_SHAPE, TAG25H9_BITS, TAG25H9_CODES, TAG25H9_SHAPE, TAG36H11_BITS,
    TAG36H11_CODES, TAG36H11_SHAPE,
};
use serde::{Deserialize, Serialize};

/// The largest family's cells across its black border, which sizes the sampling buffers.
pub const MAX_CELLS: usize = 8;

/// An AprilTag family (the standard square ones with a black border).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize, Default)]
pub enum TagFamily {
    /// 16 bits, distance 5, 30 tags: large cells, easily confused with clutter.
    Tag16h5,
    /// 25 bits, distance 9, 35 tags.
    Tag25h9,
    /// 36 bits, distance 11, 587 tags: the usual choice (and OpenCV's default).
    #[default]
    Tag36h11,
}

/// A code the grid matched.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Decoded {
    /// The tag's id: its code's index in the family.
    pub id: u32,
    /// Bits that differed from the code (corrected).
    pub hamming: u32,
    /// Quarter turns clockwise of the tag in the quad (see the module docs).
    pub rotation: u8,
}

impl TagFamily {
    /// The family's codes, by id.
    pub fn codes(self) -> &'static [u64] {
        match self {
            Self::Tag16h5 => &TAG16H5_CODES,
            Self::Tag25h9 => &TAG25H9_CODES,
            Self::Tag36h11 => &TAG36H11_CODES,
        }
    }

    fn bits(self) -> &'static [(u8, u8)] {
        match self {
            Self::Tag16h5 => &TAG16H5_BITS,
            Self::Tag25h9 => &TAG25H9_BITS,
            Self::Tag36h11 => &TAG36H11_BITS,
        }
    }

    fn shape(self) -> (u32, u32, u32) {
        match self {
            Self::Tag16h5 => TAG16H5_SHAPE,
            Self::Tag25h9 => TAG25H9_SHAPE,
            Self::Tag36h11 => TAG36H11_SHAPE,
        }
    }

    /// Bits per code.
    pub fn bit_count(self) -> usize {
        self.shape().0 as usize
    }

    /// The family's minimum Hamming distance between codes (over rotations too).
    pub fn min_distance(self) -> u32 {
        self.shape().1
    }

    /// Cells across the black border's outer edge (8 for tag36h11): the tag's size in
    /// cells without its white ring.
    pub fn cells(self) -> usize {
        self.shape().2 as usize
    }

    /// The most bits a decode may correct: ⌊(h − 1)/2⌋.
    pub fn max_correctable(self) -> u32 {
        (self.min_distance() - 1) / 2
    }

    /// The cell (x right, y down) of code bit `i` (0 the most significant), or `None`
    /// past the code's length.
    pub fn bit_cell(self, i: usize) -> Option<(usize, usize)> {
        self.bits().get(i).map(|&(x, y)| (x as usize, y as usize))
    }

    /// The cells of tag `id` seen upright, row-major `n × n` (1 white, 0 black): what a
    /// printer draws inside the white ring. `None` for an id the family lacks.
    pub fn cell_grid(self, id: u32) -> Option<[[u8; MAX_CELLS]; MAX_CELLS]> {
        let code = *self.codes().get(id as usize)?;
        let nb = self.bit_count();
        let mut g = [[0u8; MAX_CELLS]; MAX_CELLS];
        for (i, &(x, y)) in self.bits().iter().enumerate() {
            g[y as usize][x as usize] = ((code >> (nb - 1 - i)) & 1) as u8;
        }
        Some(g)
    }

    /// Decodes a quad's sampled cells (`grid[y][x]`, 1 white, quad order, see the module
    /// docs): the nearest code over the four rotations, if within `max_hamming` bits
    /// (clamped to [`TagFamily::max_correctable`]). Ties go to the lower distance found
    /// first (rotation 0 first, then the lower id).
    pub fn decode(self, grid: &[[u8; MAX_CELLS]; MAX_CELLS], max_hamming: u32) -> Option<Decoded> {
        let n = self.cells();
        let nb = self.bit_count();
        let limit = max_hamming.min(self.max_correctable());
        let mut best: Option<Decoded> = None;
        for k in 0..4u8 {
            let mut code = 0u64;
            for &(x, y) in self.bits() {
                let (mut qx, mut qy) = (x as usize, y as usize);
                for _ in 0..k {
                    (qx, qy) = (n - 1 - qy, qx);
                }
                code = (code << 1) | u64::from(grid[qy][qx] & 1);
            }
            let mask = if nb >= 64 { u64::MAX } else { (1u64 << nb) - 1 };
            for (id, &c) in self.codes().iter().enumerate() {
                let d = ((c ^ code) & mask).count_ones();
                if d <= limit && best.is_none_or(|b| d < b.hamming) {
                    best = Some(Decoded {
                        id: id as u32,
                        hamming: d,
                        rotation: k,
                    });
                }
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Turns an upright grid by `k` quarter turns clockwise, as a quad would see it.
    fn turned(g: &[[u8; MAX_CELLS]; MAX_CELLS], n: usize, k: u8) -> [[u8; MAX_CELLS]; MAX_CELLS] {
        let mut out = *g;
        for _ in 0..k {
            let prev = out;
            for y in 0..n {
                for x in 0..n {
                    // Tag cell (x, y) lands on quad cell (n - 1 - y, x).
                    out[x][n - 1 - y] = prev[y][x];
                }
            }
        }
        out
    }

    #[test]
    fn every_code_of_every_family_decodes_to_its_id_in_every_rotation() {
        for fam in [TagFamily::Tag16h5, TagFamily::Tag25h9, TagFamily::Tag36h11] {
            let n = fam.cells();
            for id in 0..fam.codes().len() as u32 {
                let g = fam.cell_grid(id).unwrap();
                // The border is black.
                let border: u32 = (0..n)
                    .map(|i| u32::from(g[0][i] + g[n - 1][i] + g[i][0] + g[i][n - 1]))
                    .sum();
                assert_eq!(border, 0);
                for k in 0..4 {
                    let d = fam.decode(&turned(&g, n, k), 0).unwrap();
                    assert_eq!((d.id, d.hamming, d.rotation), (id, 0, k), "{fam:?}");
                }
            }
        }
    }

    #[test]
    fn corrects_up_to_its_limit_and_no_more() {
        let fam = TagFamily::Tag36h11;
        assert_eq!(fam.max_correctable(), 5);
        let mut g = fam.cell_grid(7).unwrap();
        for (i, limit) in [(0usize, 2u32), (1, 2)] {
            let (x, y) = fam.bit_cell(i).unwrap();
            g[y][x] ^= 1;
            assert_eq!(fam.decode(&g, limit).unwrap().id, 7);
        }
        assert_eq!(fam.decode(&g, 2).unwrap().hamming, 2);
        let (x, y) = fam.bit_cell(2).unwrap();
        g[y][x] ^= 1;
        assert!(fam.decode(&g, 2).is_none(), "3 errors with a limit of 2");
        assert_eq!(fam.decode(&g, 3).unwrap().id, 7);
        assert_eq!(fam.bit_cell(36), None);
        assert_eq!(fam.cell_grid(587), None);
    }

    #[test]
    fn blank_grids_decode_to_nothing() {
        for fam in [TagFamily::Tag25h9, TagFamily::Tag36h11] {
            assert!(fam.decode(&[[0; MAX_CELLS]; MAX_CELLS], 2).is_none());
            assert!(fam.decode(&[[1; MAX_CELLS]; MAX_CELLS], 2).is_none());
        }
    }
}
