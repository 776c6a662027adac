//! A block's spurs: its pixels with fewer than two of their four neighbours set in the
//! colour's mask.
//!
//! A painted block seen by the camera is a solid region: every pixel inside it has four
//! set neighbours and every pixel on its edge at least two (one along the edge, one
//! inward), even at a corner. A pixel with one set neighbour or none is a spur: sensor
//! noise in a dark area next to the block whose hue happens to fall in the colour's
//! range (under a warm low sun, the flap's black border reads as a very dark red). The
//! labeller joins such pixels to the block they touch, and each one counts toward the
//! block's size and so toward the ratio cue (run 71 of `bujold-colours`: 23 to 46 of
//! about 2,000 red pixels a frame near the dock, against about 5 of cyan's).
//!
//! The detector leaves the mask and its components as they are (pruning the mask itself
//! breaks the ragged blocks of a poorly fitting colour model apart, measured on
//! `bujold-robustness`'s static mode), and takes a block's spurs out of its count only,
//! the count the ratio cue compares, and only while they are a small share of it
//! (`two_block::MAX_SPUR_SHARE`): past that the block is ragged and its spurs are paint.

use super::components::Run;
use super::segment::Mask;

/// How many pixels of the runs `runs` (one component's, from the labeller of `mask`) have
/// fewer than two of their four neighbours set in `mask`. Runs are maximal, so a pixel's
/// left and right neighbours are set exactly when it is not its run's first or last.
pub fn spur_count<'a>(mask: &Mask, runs: impl Iterator<Item = &'a Run>) -> u64 {
    let (w, h) = mask.size();
    let d = mask.data();
    let mut n = 0;
    for run in runs {
        let y = run.y as usize;
        let (x0, x1) = (run.x0 as usize, run.x1 as usize);
        for x in x0..x1.min(w) {
            let up = y > 0 && d[(y - 1) * w + x] != 0;
            let down = y + 1 < h && d[(y + 1) * w + x] != 0;
            let set = u8::from(x > x0) + u8::from(x + 1 < x1) + u8::from(up) + u8::from(down);
            if set < 2 {
                n += 1;
            }
        }
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::perception::components::Labeler;
    use proptest::prelude::*;

    /// The definition, pixel by pixel: spurs of component `label`.
    fn reference(mask: &Mask, labeler: &Labeler, label: u32) -> u64 {
        let (w, h) = mask.size();
        let mut n = 0;
        for run in labeler.runs().iter().filter(|r| r.label == label) {
            for x in run.x0 as usize..run.x1 as usize {
                let y = run.y as usize;
                let set = [
                    y > 0 && mask.get(x, y - 1),
                    y + 1 < h && mask.get(x, y + 1),
                    x > 0 && mask.get(x - 1, y),
                    x + 1 < w && mask.get(x + 1, y),
                ]
                .iter()
                .filter(|&&b| b)
                .count();
                if set < 2 {
                    n += 1;
                }
            }
        }
        n
    }

    #[test]
    fn a_block_has_no_spurs_until_something_sticks_out() {
        let (w, h) = (12, 10);
        let mut m = Mask::new(w, h);
        for y in 2..8 {
            for x in 3..9 {
                m.set(x, y, true);
            }
        }
        let mut lab = Labeler::new(w, h);
        lab.label(&m).unwrap();
        assert_eq!(spur_count(&m, lab.runs().iter()), 0);
        m.set(5, 1, true); // one pixel on the top edge
        m.set(9, 8, true); // one diagonal to the bottom-right corner (8-connected)
        lab.label(&m).unwrap();
        assert_eq!(lab.components().len(), 1);
        assert_eq!(spur_count(&m, lab.runs().iter()), 2);
    }

    proptest! {
        #[test]
        fn matches_the_definition(w in 1usize..40, h in 1usize..30, bits in proptest::collection::vec(0u8..4, 1200)) {
            let data: Vec<u8> = (0..w * h).map(|i| u8::from(bits[i % bits.len()] != 0)).collect();
            let m = Mask::from_vec(w, h, data).unwrap();
            let mut lab = Labeler::new(w, h);
            let n = lab.label(&m).unwrap().len() as u32;
            for label in 0..n {
                let got = spur_count(&m, lab.runs().iter().filter(|r| r.label == label));
                prop_assert_eq!(got, reference(&m, &lab, label));
            }
        }
    }
}
