//! Drawing what the detectors saw: the two-block detector as in seed 004 Fig. 7
//! (segmented pixels of each colour painted in, the accepted blocks bright and boxed),
//! and Axel's circle marks with their ids and the reprojected model
//! ([`paint_circles_overlay`]), with the line, ellipse, cross and digit primitives they
//! are drawn with. For `marsupial detect`: these allocate nothing but are not tuned for speed.

use super::circles::{CircleModel, DetectedMark, Ellipse, ModelFit, ModulePose, RigCamera};
use super::image::{RgbImage, RgbView};
use super::two_block::{Pair, TwoBlockDetector};
use nalgebra::Vector3;

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

/// Colour of a detected circle mark's fitted rim and its id (labelled marks).
pub const MARK_PAINT: [u8; 3] = [0, 255, 0];
/// Colour of a detected mark the correspondence did not label (a false positive).
pub const UNLABELLED_PAINT: [u8; 3] = [255, 0, 0];
/// Colour of the model reprojected through the fit: each mark's rim through the pose
/// (when there is one) and a cross at every reprojected centre.
pub const MODEL_PAINT: [u8; 3] = [255, 0, 255];

/// Draws a straight segment from `a` to `b` (px, pixel centres at i + 0.5), one pixel
/// wide, clipped to the image.
pub fn draw_line(out: &mut RgbImage, a: [f64; 2], b: [f64; 2], colour: [u8; 3]) {
    if !(a.iter().chain(&b).all(|v| v.is_finite())) {
        return;
    }
    let steps = (b[0] - a[0]).abs().max((b[1] - a[1]).abs()).ceil().min(1e5) as usize;
    for k in 0..=steps {
        let t = if steps == 0 { 0.0 } else { k as f64 / steps as f64 };
        let (x, y) = (a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t);
        if x >= 0.0 && y >= 0.0 {
            out.put(x as usize, y as usize, colour);
        }
    }
}

/// Draws an ellipse's outline as a 48-sided polygon.
pub fn draw_ellipse(out: &mut RgbImage, e: &Ellipse, colour: [u8; 3]) {
    let n = 48;
    let step = std::f64::consts::TAU / n as f64;
    for k in 0..n {
        draw_line(out, e.point(k as f64 * step), e.point((k + 1) as f64 * step), colour);
    }
}

/// Draws an upright cross of half-size `r` px at `c`.
pub fn draw_cross(out: &mut RgbImage, c: [f64; 2], r: f64, colour: [u8; 3]) {
    draw_line(out, [c[0] - r, c[1]], [c[0] + r, c[1]], colour);
    draw_line(out, [c[0], c[1] - r], [c[0], c[1] + r], colour);
}

/// 3 × 5 bitmaps of the digits 0–9, one row per entry, bit 2 the leftmost column.
const DIGITS: [[u8; 5]; 10] = [
    [7, 5, 5, 5, 7],
    [2, 6, 2, 2, 7],
    [7, 1, 7, 4, 7],
    [7, 1, 7, 1, 7],
    [5, 5, 7, 1, 1],
    [7, 4, 7, 1, 7],
    [7, 4, 7, 5, 7],
    [7, 1, 1, 1, 1],
    [7, 5, 7, 5, 7],
    [7, 5, 7, 1, 7],
];

/// Writes `n` in decimal with its top-left corner at `at` (px), each font pixel a
/// `scale` × `scale` square (at least 1), the digits 4 font pixels apart.
///
/// ```
/// use marsupial::perception::RgbImage;
/// use marsupial::perception::overlay::draw_number;
///
/// let mut im = RgbImage::new(12, 8);
/// draw_number(&mut im, [1.0, 1.0], 17, 1, [255, 0, 0]);
/// let px = |x, y| im.view().get(x, y).unwrap();
/// assert_eq!(px(2, 1), [255, 0, 0]); // the 1's top
/// assert_eq!(px(1, 1), [0, 0, 0]);
/// assert_eq!(px(5, 1), [255, 0, 0]); // the 7's bar
/// assert_eq!(px(7, 5), [255, 0, 0]); // the 7's stem
/// ```
pub fn draw_number(out: &mut RgbImage, at: [f64; 2], n: usize, scale: usize, colour: [u8; 3]) {
    if !(at[0].is_finite() && at[1].is_finite()) {
        return;
    }
    let s = scale.max(1) as f64;
    let digits = n.checked_ilog10().unwrap_or(0) + 1;
    for d in 0..digits {
        let digit = (n / 10usize.pow(digits - 1 - d)) % 10;
        let x0 = at[0] + 4.0 * s * d as f64;
        for (row, bits) in DIGITS[digit].iter().enumerate() {
            for col in 0..3 {
                if bits & (4 >> col) == 0 {
                    continue;
                }
                let (px, py) = (x0 + col as f64 * s, at[1] + row as f64 * s);
                for dy in 0..scale.max(1) {
                    for dx in 0..scale.max(1) {
                        let (x, y) = (px + dx as f64, py + dy as f64);
                        if x >= 0.0 && y >= 0.0 {
                            out.put(x as usize, y as usize, colour);
                        }
                    }
                }
            }
        }
    }
}

/// What the circle-fiducial pipeline saw in one frame, for [`paint_circles_overlay`].
#[derive(Debug, Clone, Copy)]
pub struct CirclesDrawing<'a> {
    /// The detector's marks.
    pub marks: &'a [DetectedMark],
    /// The model the correspondence labelled them against.
    pub model: &'a CircleModel,
    /// The accepted labelling, if any.
    pub fit: Option<&'a ModelFit>,
    /// The module's pose and the camera it was measured through, if any.
    pub pose: Option<(&'a ModulePose, &'a RigCamera)>,
}

/// Copies `frame` into `out` and draws the circle marks over it (seed 000 Fig. 4's
/// view): each detection's fitted rim, green with its model id beside it when the
/// correspondence labelled it, red when it did not; then the model reprojected in
/// magenta: every mark's rim projected through the pose and the camera's lens model
/// (when there is a pose) and a cross at every centre the homography reprojects
/// (undetected marks included, as the correspondence fills them in). Text is a 3 × 5
/// pixel font scaled with the image (1 px per 512 px of width).
pub fn paint_circles_overlay(frame: &RgbView<'_>, drawing: &CirclesDrawing<'_>, out: &mut RgbImage) {
    let (w, h) = (frame.width(), frame.height());
    out.resize(w, h);
    out.as_bytes_mut().copy_from_slice(frame.as_bytes());
    let scale = (w / 512).max(1);
    let model = drawing.model;
    if let Some((pose, cam)) = drawing.pose {
        let n = 48;
        for c in model.centres() {
            let rim = |k: usize| {
                let t = k as f64 * std::f64::consts::TAU / n as f64;
                let m = Vector3::new(
                    0.0,
                    c[0] + model.radius_m() * t.cos(),
                    c[1] + model.radius_m() * t.sin(),
                );
                cam.project(&pose.apply(&m))
            };
            for k in 0..n {
                if let (Some(a), Some(b)) = (rim(k), rim(k + 1)) {
                    draw_line(out, a, b, MODEL_PAINT);
                }
            }
        }
    }
    if let Some(fit) = drawing.fit {
        for p in fit.projected() {
            draw_cross(out, *p, 4.0 * scale as f64, MODEL_PAINT);
        }
    }
    for (i, m) in drawing.marks.iter().enumerate() {
        let id = drawing
            .fit
            .and_then(|f| (0..model.len()).find(|&j| f.detection_of(j) == Some(i)));
        let colour = if id.is_some() { MARK_PAINT } else { UNLABELLED_PAINT };
        draw_ellipse(out, &m.ellipse, colour);
        if let Some(j) = id {
            let e = &m.ellipse;
            let at = [
                e.centre[0] + e.semi_major + 2.0 * scale as f64,
                e.centre[1] - e.semi_major,
            ];
            draw_number(out, at, j, scale, colour);
        }
    }
}
