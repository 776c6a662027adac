//! Drawing what the two-block detector saw, as in seed 004 Fig. 7: segmented pixels of
//! each colour painted in, the accepted blocks bright and boxed.

use super::image::{RgbImage, RgbView};
use super::two_block::{Pair, TwoBlockDetector};

/// Paint for the image-left colour's pixels (accepted block / other segmented pixels).
pub const LEFT_PAINT: ([u8; 3], [u8; 3]) = ([0, 255, 0], [0, 110, 0]);
/// Paint for the image-right colour's pixels (accepted block / other segmented pixels).
pub const RIGHT_PAINT: ([u8; 3], [u8; 3]) = ([255, 255, 0], [120, 120, 0]);

/// Copies `frame` into `out` and paints the detector's last segmentation over it: pixels
/// of the accepted blocks in bright green (left) and yellow (right), other segmented
/// pixels of the same colours dimmer, and a white box around the accepted pair.
///
/// # Example
///
/// The pair of [`TwoBlockDetector`]'s example (blocks at x = 4…11, rows 2…5 of a 16×8
/// frame), boxed 2 px outside its bounds (clipped to the frame).
///
/// ```
/// use marsupial::perception::overlay::{LEFT_PAINT, RIGHT_PAINT, paint_overlay};
/// use marsupial::perception::{PairLimits, RgbImage, SctRange, TwoBlockDetector};
///
/// let grey = [110, 105, 100];
/// let mut im = RgbImage::new(16, 8);
/// im.fill(grey);
/// for y in 2..6 {
///     (4..8).for_each(|x| im.put(x, y, [20, 190, 210]));
///     (8..12).for_each(|x| im.put(x, y, [200, 30, 190]));
/// }
/// let d = |deg: f64| deg.to_radians();
/// let ranges = [
///     SctRange { a: [d(30.0), d(60.0)], b: [d(70.0), d(90.0)], min_l: 30.0, min_chroma: 0.0 },
///     SctRange { a: [d(30.0), d(60.0)], b: [d(0.0), d(20.0)], min_l: 30.0, min_chroma: 0.0 },
/// ];
/// let limits = PairLimits {
///     min_component_px: 8,
///     max_gap_frac: 0.5,
///     gap_slack_px: 3.0,
///     max_vertical_frac: 0.5,
///     max_height_ratio: 2.0,
///     min_count_ratio: 0.2,
///     max_candidates: 8,
/// };
/// let mut det = TwoBlockDetector::new(16, 8, limits);
/// let pair = det.detect(&im.view(), &ranges).unwrap().unwrap();
///
/// let mut out = RgbImage::default();
/// paint_overlay(&im.view(), &det, Some(&pair), &mut out);
/// let px = |x, y| out.view().get(x, y).unwrap();
/// assert_eq!(px(5, 3), LEFT_PAINT.0);
/// assert_eq!(px(9, 3), RIGHT_PAINT.0);
/// assert_eq!(px(2, 0), [255, 255, 255]); // box corner: (4 − 2, 2 − 2)
/// assert_eq!(px(13, 7), [255, 255, 255]); // (11 + 2, min(5 + 2, 7))
/// assert_eq!(px(3, 3), grey); // inside the box, off the blocks
///
/// // Without an accepted pair the segmented pixels are painted dim, unboxed.
/// paint_overlay(&im.view(), &det, None, &mut out);
/// assert_eq!(out.view().get(5, 3), Some(LEFT_PAINT.1));
/// assert_eq!(out.view().get(2, 0), Some(grey));
/// ```
pub fn paint_overlay(frame: &RgbView<'_>, detector: &TwoBlockDetector, pair: Option<&Pair>, out: &mut RgbImage) {
    let (w, h) = (frame.width(), frame.height());
    out.resize(w, h);
    out.as_bytes_mut().copy_from_slice(frame.as_bytes());
    if detector.size() != (w, h) {
        return;
    }
    for (c, paint) in [LEFT_PAINT, RIGHT_PAINT].iter().enumerate() {
        let chosen = pair.map(|p| if c == 0 { p.left.component } else { p.right.component });
        for run in detector.labeler(c).runs() {
            let colour = if Some(run.label) == chosen { paint.0 } else { paint.1 };
            for x in run.x0..run.x1 {
                out.put(x as usize, run.y as usize, colour);
            }
        }
    }
    if let Some(p) = pair {
        let x0 = p.left.bbox[0].min(p.right.bbox[0]) as usize;
        let y0 = p.left.bbox[1].min(p.right.bbox[1]) as usize;
        let x1 = p.left.bbox[2].max(p.right.bbox[2]) as usize;
        let y1 = p.left.bbox[3].max(p.right.bbox[3]) as usize;
        let (x0, y0) = (x0.saturating_sub(2), y0.saturating_sub(2));
        let (x1, y1) = ((x1 + 2).min(w - 1), (y1 + 2).min(h - 1));
        for x in x0..=x1 {
            out.put(x, y0, [255, 255, 255]);
            out.put(x, y1, [255, 255, 255]);
        }
        for y in y0..=y1 {
            out.put(x0, y, [255, 255, 255]);
            out.put(x1, y, [255, 255, 255]);
        }
    }
}
