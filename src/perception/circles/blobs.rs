//! Topology and run lists of labelled components: the Euler number of every component
//! and, for any one of them, its runs, without rescanning the image.
//!
//! **Euler number.** A component's Euler number is its run count minus the number of
//! touching run pairs in consecutive rows (touching as its labeller joins them): runs are
//! intervals (contractible), and each cycle in the graph of touching runs encloses exactly
//! one background region, 4-connected for an 8-connected foreground and 8-connected for a
//! 4-connected one. E = 1 − holes, so a filled disc has E = 1 and a ring E = 0.
//!
//! All buffers are sized for the labeller's worst case when built, so indexing never
//! allocates.

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

    /// The runs of component `label` of `labeler` (the labelling this index was built
    /// from), in raster order; none for an unknown label.
    pub fn runs_of<'a>(&'a self, labeler: &'a Labeler, label: usize) -> impl Iterator<Item = &'a Run> + 'a {
        let (a, b) = match (self.start.get(label), self.start.get(label + 1)) {
            (Some(&a), Some(&b)) => (a as usize, b as usize),
            _ => (0, 0),
        };
        let runs = labeler.runs();
        self.order
            .get(a..b)
            .unwrap_or(&[])
            .iter()
            .filter_map(move |&i| runs.get(i as usize))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::perception::Mask;

    /// Holes by flood-filling the background (4-connected, or 8-connected when `eight`)
    /// from outside: the slow reference for one-component masks.
    fn holes_reference(mask: &Mask, eight: bool) -> i32 {
        let (w, h) = mask.size();
        let (pw, ph) = (w + 2, h + 2);
        let fg = |x: usize, y: usize| x >= 1 && y >= 1 && x <= w && y <= h && mask.get(x - 1, y - 1);
        let mut seen = vec![false; pw * ph];
        let mut regions = 0;
        for sy in 0..ph {
            for sx in 0..pw {
                if fg(sx, sy) || seen[sy * pw + sx] {
                    continue;
                }
                regions += 1;
                let mut stack = vec![(sx, sy)];
                seen[sy * pw + sx] = true;
                while let Some((x, y)) = stack.pop() {
                    let mut push = |nx: usize, ny: usize| {
                        if nx < pw && ny < ph && !fg(nx, ny) && !seen[ny * pw + nx] {
                            seen[ny * pw + nx] = true;
                            stack.push((nx, ny));
                        }
                    };
                    push(x + 1, y);
                    push(x.wrapping_sub(1), y);
                    push(x, y + 1);
                    push(x, y.wrapping_sub(1));
                    if eight {
                        push(x + 1, y + 1);
                        push(x.wrapping_sub(1), y + 1);
                        push(x + 1, y.wrapping_sub(1));
                        push(x.wrapping_sub(1), y.wrapping_sub(1));
                    }
                }
            }
        }
        regions - 1 // the outside
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
