//! Topology and run lists of labelled components: the Euler number of every component
//! and, for any one of them, its runs, without rescanning the image.
//!
//! **Euler number.** A component's Euler number is its run count minus the number of
//! touching run pairs in consecutive rows (touching as its labeller joins them): runs are
//! intervals (contractible), and each cycle in the graph of touching runs encloses exactly
//! one background region, 4-connected for an 8-connected foreground and 8-connected for a
//! 4-connected one. E = 1 − holes, so a filled disc has E = 1 and a ring E = 0.
//!
//! **Pinholes.** A hole of a few pixels is sensor noise, not shape: a dark blob's pixels
//! that noise lifts over the threshold. In shade, where the camera's gamma stretches dark
//! noise, a printed black ring shows a few of them, nearly all of one pixel (Axel's near
//! marks: [`crate::perception::circles::CircleParams::for_image`]). [`RunIndex::pinholes`]
//! counts the holes of a component up to a size, so that a filter on the Euler number can
//! ask about the holes of the shape.
//!
//! All buffers are sized for the labeller's worst case when built, so indexing never
//! allocates.

use crate::perception::Mask;
use crate::perception::components::{Labeler, Run};

/// Euler numbers and per-component run lists of one labelled mask.
///
/// # Example
///
/// A 5×5 ring (one hole) and a lone pixel: Euler numbers 0 and 1, and the ring's runs
/// listed in raster order.
///
/// ```
/// use marsupial::perception::circles::RunIndex;
/// use marsupial::perception::{Labeler, Mask};
///
/// #[rustfmt::skip]
/// let mask = Mask::from_vec(7, 5, vec![
///     1, 1, 1, 1, 1, 0, 0,
///     1, 0, 0, 0, 1, 0, 0,
///     1, 0, 0, 0, 1, 0, 1,
///     1, 0, 0, 0, 1, 0, 0,
///     1, 1, 1, 1, 1, 0, 0,
/// ]).unwrap();
/// let mut labeler = Labeler::new(7, 5);
/// labeler.label(&mask).unwrap();
/// let mut index = RunIndex::new(7, 5);
/// index.build(&labeler);
/// assert_eq!(index.euler(0), 0, "a ring: one component, one hole");
/// assert_eq!(index.euler(1), 1, "a pixel");
/// assert_eq!(index.runs_of(&labeler, 0).count(), 8);
/// ```
#[derive(Debug, Clone)]
pub struct RunIndex {
    euler: Vec<i32>,
    start: Vec<u32>,
    order: Vec<u32>,
}

impl RunIndex {
    /// An index for masks of `width × height`, with worst-case buffers allocated now.
    pub fn new(width: usize, height: usize) -> Self {
        let max_runs = height * width.div_ceil(2);
        Self {
            euler: Vec::with_capacity(max_runs),
            start: Vec::with_capacity(max_runs + 1),
            order: Vec::with_capacity(max_runs),
        }
    }

    /// Indexes the last labelling of `labeler`: O(runs).
    pub fn build(&mut self, labeler: &Labeler) {
        let runs = labeler.runs();
        let n = labeler.components().len();
        let d = (!labeler.is_four_connected()) as u32;
        self.euler.clear();
        self.euler.resize(n, 0);
        self.start.clear();
        self.start.resize(n + 1, 0);
        for r in runs {
            self.euler[r.label as usize] += 1;
            self.start[r.label as usize + 1] += 1;
        }
        for i in 0..n {
            self.start[i + 1] += self.start[i];
        }
        // Touching run pairs between consecutive rows (both rows sorted by x).
        let mut prev = 0..0usize;
        let mut i = 0;
        while i < runs.len() {
            let y = runs[i].y;
            let mut j = i;
            while j < runs.len() && runs[j].y == y {
                j += 1;
            }
            if prev.end > prev.start && runs[prev.start].y + 1 == y {
                let mut k0 = prev.start;
                for cur in &runs[i..j] {
                    while k0 < prev.end && runs[k0].x1 + d <= cur.x0 {
                        k0 += 1;
                    }
                    let mut k = k0;
                    while k < prev.end && runs[k].x0 < cur.x1 + d {
                        self.euler[cur.label as usize] -= 1;
                        k += 1;
                    }
                }
            }
            prev = i..j;
            i = j;
        }
        // Run lists: a counting sort by label, stable (raster order within a component).
        self.order.clear();
        self.order.resize(runs.len(), 0);
        // `start` doubles as the fill cursors; shifting it back restores the offsets.
        for (ri, r) in runs.iter().enumerate() {
            let l = r.label as usize;
            let at = self.start[l] as usize;
            self.order[at] = ri as u32;
            self.start[l] += 1;
        }
        for l in (1..=n).rev() {
            self.start[l] = self.start[l - 1];
        }
        if n > 0 {
            self.start[0] = 0;
        }
    }

    /// Euler number (1 − holes) of component `label`; 1 for an unknown label.
    pub fn euler(&self, label: usize) -> i32 {
        self.euler.get(label).copied().unwrap_or(1)
    }

    /// Whether pixel (`x`, `y`) belongs to component `label` of `labeler` (the labelling
    /// this index was built from): a binary search of its runs, O(log runs).
    pub fn contains(&self, labeler: &Labeler, label: usize, x: u32, y: u32) -> bool {
        let order = self.order_of(label);
        let runs = labeler.runs();
        // The component's runs are in raster order and disjoint, so (y, x1) rises too.
        let k = order.partition_point(|&i| runs.get(i as usize).is_some_and(|r| (r.y, r.x1) <= (y, x)));
        order
            .get(k)
            .and_then(|&i| runs.get(i as usize))
            .is_some_and(|r| r.y == y && r.x0 <= x)
    }

    /// The number of holes of component `label` of `labeler` with at most `max_px`
    /// pixels each, `mask` being the mask it labelled (`0` is background). A hole is a
    /// background region (4-connected for an 8-connected labelling, 8-connected for a
    /// 4-connected one) that the component encloses, and a pinhole one that holds no
    /// other component; `E + pinholes` is the Euler number the component would have with
    /// those holes filled.
    ///
    /// Only the pixels next to the component's runs are read. The pixel after each run
    /// that could be the first in raster order of its region starts a fill that gives up
    /// past `max_px` pixels, held in `fill` (reserve `max_px + 1` to keep it from
    /// allocating), so the cost is O(runs × `max_px`²).
    pub fn pinholes(&self, labeler: &Labeler, mask: &Mask, label: usize, max_px: usize, fill: &mut Vec<usize>) -> u32 {
        let Some(c) = labeler.components().get(label) else {
            return 0;
        };
        if max_px == 0 || mask.size() != labeler.size() {
            return 0;
        }
        let w = mask.width();
        let data = mask.data();
        let background_eight = labeler.is_four_connected();
        let [x0, y0, x1, y1] = c.bbox.map(|v| v as usize);
        let inside = |j: usize| {
            let (x, y) = (j % w, j / w);
            x > x0 && x < x1 && y > y0 && y < y1
        };
        // The pixels joined to `j` (all in the image when `j` is inside the box).
        let neighbours = |j: usize| {
            let n = if background_eight { 8 } else { 4 };
            [j - 1, j + 1, j - w, j + w, j - w - 1, j - w + 1, j + w - 1, j + w + 1]
                .into_iter()
                .take(n)
        };
        let mut count = 0;
        // A region's first pixel in raster order has a foreground pixel to its left, and
        // for a hole of this component that pixel is the end of one of its runs.
        for r in self.runs_of(labeler, label) {
            let (x, y) = (r.x1 as usize, r.y as usize);
            if x >= x1 || y <= y0 || y >= y1 {
                continue;
            }
            let i = y * w + x;
            // The pixels before it in raster order that would join it are foreground.
            let first = data[i] == 0
                && data[i - w] != 0
                && (!background_eight || (data[i - w - 1] != 0 && data[i - w + 1] != 0));
            if !first {
                continue;
            }
            fill.clear();
            fill.push(i);
            let mut head = 0;
            let mut small = true;
            'fill: while head < fill.len() {
                let j = fill[head];
                head += 1;
                // A region that reaches the box's edge is not enclosed by the
                // component (whose pixels all lie in the box).
                if !inside(j) {
                    small = false;
                    break;
                }
                for k in neighbours(j) {
                    if data[k] == 0 && !fill.contains(&k) {
                        if fill.len() == max_px {
                            small = false;
                            break 'fill;
                        }
                        fill.push(k);
                    }
                }
            }
            // Counted once, from its first pixel, when every foreground pixel
            // around it is this component's (not an island of another inside it).
            let enclosed = || {
                fill.iter().all(|&j| {
                    neighbours(j)
                        .filter(|&k| data[k] != 0)
                        .all(|k| self.contains(labeler, label, (k % w) as u32, (k / w) as u32))
                })
            };
            if small && fill.iter().all(|&j| j >= i) && enclosed() {
                count += 1;
            }
        }
        count
    }

    /// Whether component `label` surrounds pixel (`x`, `y`) as a ring surrounds its
    /// centre: the pixel is not the component's, and the component has pixels to its
    /// left and right in its row and above and below in its column. One pass over the
    /// component's runs. (A necessary condition for the pixel to lie in one of its holes,
    /// and cheap: a filter ahead of costlier tests.)
    pub fn surrounds(&self, labeler: &Labeler, label: usize, x: u32, y: u32) -> bool {
        let (mut left, mut right, mut above, mut below) = (false, false, false, false);
        for r in self.runs_of(labeler, label) {
            if r.y == y {
                if r.x0 <= x && x < r.x1 {
                    return false;
                }
                left |= r.x1 <= x;
                right |= r.x0 > x;
            } else if r.x0 <= x && x < r.x1 {
                above |= r.y < y;
                below |= r.y > y;
            }
        }
        left && right && above && below
    }

    /// This component's run indices, in raster order.
    fn order_of(&self, label: usize) -> &[u32] {
        match (self.start.get(label), self.start.get(label + 1)) {
            (Some(&a), Some(&b)) => self.order.get(a as usize..b as usize).unwrap_or(&[]),
            _ => &[],
        }
    }

    /// The runs of component `label` of `labeler` (the labelling this index was built
    /// from), in raster order; none for an unknown label.
    pub fn runs_of<'a>(&'a self, labeler: &'a Labeler, label: usize) -> impl Iterator<Item = &'a Run> + 'a {
        let runs = labeler.runs();
        self.order_of(label).iter().filter_map(move |&i| runs.get(i as usize))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::perception::Mask;

    /// A background region of the mask padded by one background pixel all round.
    struct Region {
        /// Background pixels in it.
        size: usize,
        /// Whether it reaches the padding (is not enclosed).
        outside: bool,
        /// The foreground pixels joined to it, as indices into the unpadded mask.
        border: Vec<usize>,
    }

    /// Every background region of the padded mask by flood fill (4-connected, or
    /// 8-connected when `eight`): the slow reference the index is checked against.
    fn background_regions(mask: &Mask, eight: bool) -> Vec<Region> {
        let (w, h) = mask.size();
        let (pw, ph) = (w as i64 + 2, h as i64 + 2);
        let fg = |x: i64, y: i64| {
            x >= 1 && y >= 1 && x <= w as i64 && y <= h as i64 && mask.get(x as usize - 1, y as usize - 1)
        };
        let steps: &[(i64, i64)] = &[(1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (-1, 1), (1, -1), (-1, -1)];
        let steps = if eight { steps } else { &steps[..4] };
        let mut seen = vec![false; (pw * ph) as usize];
        let mut regions = Vec::new();
        for sy in 0..ph {
            for sx in 0..pw {
                if fg(sx, sy) || seen[(sy * pw + sx) as usize] {
                    continue;
                }
                let mut region = Region {
                    size: 0,
                    outside: false,
                    border: Vec::new(),
                };
                let mut stack = vec![(sx, sy)];
                seen[(sy * pw + sx) as usize] = true;
                while let Some((x, y)) = stack.pop() {
                    region.size += 1;
                    region.outside |= x == 0 || y == 0 || x == pw - 1 || y == ph - 1;
                    for &(dx, dy) in steps {
                        let (nx, ny) = (x + dx, y + dy);
                        if nx < 0 || ny < 0 || nx >= pw || ny >= ph {
                            continue;
                        }
                        if fg(nx, ny) {
                            region.border.push(((ny - 1) * w as i64 + nx - 1) as usize);
                        } else if !seen[(ny * pw + nx) as usize] {
                            seen[(ny * pw + nx) as usize] = true;
                            stack.push((nx, ny));
                        }
                    }
                }
                regions.push(region);
            }
        }
        regions
    }

    /// Holes of a one-component mask: its enclosed background regions.
    fn holes_reference(mask: &Mask, eight: bool) -> i32 {
        background_regions(mask, eight).iter().filter(|r| !r.outside).count() as i32
    }

    #[test]
    fn euler_numbers_match_a_flood_fill_on_random_single_blobs() {
        let mut s = 0x2545F4914F6CDD1Du64;
        let mut next = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s
        };
        let (w, h) = (9, 8);
        let mut checked = 0;
        for _ in 0..3000 {
            let data: Vec<u8> = (0..w * h).map(|_| (next() % 100 < 60) as u8).collect();
            let mask = Mask::from_vec(w, h, data).unwrap();
            for four in [false, true] {
                let mut lab = if four {
                    Labeler::new_four_connected(w, h)
                } else {
                    Labeler::new(w, h)
                };
                let n = lab.label(&mask).unwrap().len();
                if n != 1 {
                    continue;
                }
                let mut idx = RunIndex::new(w, h);
                idx.build(&lab);
                assert_eq!(
                    idx.euler(0),
                    1 - holes_reference(&mask, four),
                    "four {four}: {:?}",
                    mask.data()
                );
                assert_eq!(idx.runs_of(&lab, 0).count(), lab.runs().len());
                checked += 1;
            }
        }
        assert!(checked > 100, "{checked}");
    }

    /// Pinholes from the flood fill: the enclosed regions of at most `max_px` pixels whose
    /// every joined foreground pixel is `label`'s.
    fn pinholes_reference(mask: &Mask, lab: &Labeler, label: usize, max_px: usize) -> u32 {
        let w = mask.width();
        let mut owner = vec![u32::MAX; w * mask.height()];
        for r in lab.runs() {
            for x in r.x0..r.x1 {
                owner[r.y as usize * w + x as usize] = r.label;
            }
        }
        background_regions(mask, lab.is_four_connected())
            .iter()
            .filter(|r| !r.outside && r.size <= max_px && r.border.iter().all(|&i| owner[i] == label as u32))
            .count() as u32
    }

    proptest::proptest! {
        /// Pinhole counts and pixel membership agree with the flood fill on random masks,
        /// for both connectivities, every component and every size limit up to 6.
        #[test]
        fn pinholes_match_a_flood_fill(
            bits in proptest::collection::vec(proptest::bool::weighted(0.7), 11 * 9),
            four in proptest::bool::ANY,
            max_px in 0usize..7,
        ) {
            let (w, h) = (11, 9);
            let mask = Mask::from_vec(w, h, bits.iter().map(|&b| b as u8).collect()).unwrap();
            let mut lab = if four { Labeler::new_four_connected(w, h) } else { Labeler::new(w, h) };
            let n = lab.label(&mask).unwrap().len();
            let mut idx = RunIndex::new(w, h);
            idx.build(&lab);
            let mut fill = Vec::with_capacity(max_px + 1);
            for l in 0..n {
                proptest::prop_assert_eq!(
                    idx.pinholes(&lab, &mask, l, max_px, &mut fill),
                    pinholes_reference(&mask, &lab, l, max_px),
                    "label {} of {}, four {}, max {}", l, n, four, max_px
                );
            }
            let owner = |x: u32, y: u32| lab.runs().iter().find(|r| r.y == y && r.x0 <= x && x < r.x1).map(|r| r.label as usize);
            for y in 0..h as u32 {
                for x in 0..w as u32 {
                    for l in 0..n {
                        proptest::prop_assert_eq!(idx.contains(&lab, l, x, y), owner(x, y) == Some(l), "({}, {}) in {}", x, y, l);
                    }
                }
            }
            proptest::prop_assert!(!idx.contains(&lab, n + 3, 0, 0));
        }
    }

    #[test]
    fn a_ring_surrounds_its_centre_and_a_bar_does_not() {
        #[rustfmt::skip]
        let mask = Mask::from_vec(9, 6, vec![
            0, 1, 1, 1, 1, 0, 0, 0, 0,
            1, 1, 0, 0, 1, 1, 0, 0, 0,
            1, 0, 0, 0, 0, 1, 0, 1, 1,
            1, 1, 0, 0, 1, 1, 0, 0, 0,
            0, 1, 1, 1, 1, 0, 0, 0, 0,
            0, 0, 0, 0, 0, 0, 0, 0, 0,
        ]).unwrap();
        let mut lab = Labeler::new(9, 6);
        lab.label(&mask).unwrap();
        let mut idx = RunIndex::new(9, 6);
        idx.build(&lab);
        assert!(idx.surrounds(&lab, 0, 2, 2) && idx.surrounds(&lab, 0, 3, 2));
        assert!(!idx.surrounds(&lab, 0, 1, 1), "its own pixel");
        assert!(!idx.surrounds(&lab, 0, 6, 2), "outside, to its right");
        assert!(!idx.surrounds(&lab, 1, 6, 2), "a bar surrounds nothing");
        assert!(!idx.surrounds(&lab, 7, 2, 2), "an unknown label");
    }

    #[test]
    fn a_pitted_ring_has_its_pinholes_counted_and_its_hole_not() {
        // A 9×9 ring (a 3×3 hole) with a 1-pixel and a 2-pixel pinhole in its band.
        let mut mask = Mask::new(11, 11);
        for y in 1..10 {
            for x in 1..10 {
                let hole = (4..7).contains(&x) && (4..7).contains(&y);
                mask.set(x, y, !hole);
            }
        }
        mask.set(2, 2, false);
        mask.set(7, 8, false);
        mask.set(8, 8, false);
        let mut lab = Labeler::new(11, 11);
        lab.label(&mask).unwrap();
        let mut idx = RunIndex::new(11, 11);
        idx.build(&lab);
        let mut fill = Vec::with_capacity(16);
        assert_eq!(idx.euler(0), -2, "three holes");
        assert_eq!(idx.pinholes(&lab, &mask, 0, 1, &mut fill), 1);
        assert_eq!(idx.pinholes(&lab, &mask, 0, 2, &mut fill), 2);
        assert_eq!(
            idx.pinholes(&lab, &mask, 0, 8, &mut fill),
            2,
            "the 9-pixel hole is the ring's"
        );
        assert_eq!(idx.pinholes(&lab, &mask, 0, 9, &mut fill), 3);
        assert_eq!(idx.pinholes(&lab, &mask, 0, 0, &mut fill), 0);
        assert_eq!(idx.pinholes(&lab, &mask, 5, 4, &mut fill), 0, "an unknown label");
    }

    /// The two cases random masks rarely draw: a small hole holding an island of another
    /// component (4-connected foreground: the island's four background neighbours form
    /// one 8-connected region of 4 px) is no pinhole, and an L-shaped hole whose second
    /// row starts left of its first is counted once.
    #[test]
    fn a_hole_round_an_island_is_no_pinhole_and_an_l_shaped_one_counts_once() {
        #[rustfmt::skip]
        let island = Mask::from_vec(5, 5, vec![
            1, 1, 1, 1, 1,
            1, 1, 0, 1, 1,
            1, 0, 1, 0, 1,
            1, 1, 0, 1, 1,
            1, 1, 1, 1, 1,
        ]).unwrap();
        let mut lab = Labeler::new_four_connected(5, 5);
        assert_eq!(lab.label(&island).unwrap().len(), 2, "the ring and the island");
        let mut idx = RunIndex::new(5, 5);
        idx.build(&lab);
        let mut fill = Vec::with_capacity(8);
        let ring = lab.runs()[0].label as usize;
        assert_eq!(idx.pinholes(&lab, &island, ring, 4, &mut fill), 0);
        #[rustfmt::skip]
        let l_shape = Mask::from_vec(5, 4, vec![
            1, 1, 1, 1, 1,
            1, 1, 0, 1, 1,
            1, 0, 0, 1, 1,
            1, 1, 1, 1, 1,
        ]).unwrap();
        let mut lab = Labeler::new(5, 4);
        lab.label(&l_shape).unwrap();
        let mut idx = RunIndex::new(5, 4);
        idx.build(&lab);
        assert_eq!(idx.pinholes(&lab, &l_shape, 0, 3, &mut fill), 1);
        assert_eq!(idx.pinholes(&lab, &l_shape, 0, 2, &mut fill), 0, "3 px is more than 2");
    }

    #[test]
    fn run_lists_partition_the_runs_by_label() {
        #[rustfmt::skip]
        let mask = Mask::from_vec(6, 3, vec![
            1, 0, 1, 0, 1, 1,
            1, 0, 1, 0, 0, 0,
            1, 1, 0, 0, 1, 0,
        ]).unwrap();
        let mut lab = Labeler::new(6, 3);
        let n = lab.label(&mask).unwrap().len();
        let mut idx = RunIndex::new(6, 3);
        idx.build(&lab);
        let mut total = 0;
        for l in 0..n {
            for r in idx.runs_of(&lab, l) {
                assert_eq!(r.label as usize, l);
                total += 1;
            }
        }
        assert_eq!(total, lab.runs().len());
        assert_eq!(idx.runs_of(&lab, 99).count(), 0);
        assert_eq!(idx.euler(99), 1);
    }
}
