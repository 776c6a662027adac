//! RAPOSA's pyramid detector (seed 001 §II.D): HSV segmentation, ellipses on the orange
//! guide, bounding regions on the blue edges, and the pair filters.
//!
//! Per frame:
//!
//! 1. **Segment** both colours with the operator's HSV bands ([`Segmenter`], one HSV
//!    conversion per pixel for both bands). The bands can be changed between frames with
//!    [`PyramidDetector::set_bands`], as the paper's operator retunes them live.
//! 2. **Orange blobs → ellipses** from second moments; filtered first by area
//!    (`min_ellipse_px`), then by axis ratio, then by fill (blob pixels over the fitted
//!    ellipse's area, which rejects ragged shapes the paper's least-squares fit would
//!    also reject).
//! 3. **Blue blobs → bounding regions**, not minimum-area rectangles: a partly detected
//!    or occluded edge still spans the right box. Blue blobs whose boxes nearly touch are
//!    merged when the gap between their boxes is under 0.8 of the taller one (the ball in
//!    front can split the painted edges; a whole pyramid is about as wide as it is tall).
//! 4. **Pair filters**, scaled by the blue height `g` (that is, by distance): the blue
//!    height against the height the ball's size predicts, the ellipse centre's vertical
//!    offset from the blue centre, its horizontal offset against what the geometry allows
//!    (`m/h·g` beyond the half width), the ellipse/rectangle area ratio, and the tracking
//!    ball around the previous ellipse. If more than one pair survives, the tests run
//!    again with every tolerance multiplied by `tighten`; if that leaves none, the loose
//!    survivors stand (a single bad detection is never thrown away by strict limits).
//!    Remaining ties go to the pair with the smallest summed normalised deviation.
//!
//! Without a pair the best ellipse alone (same area, shape and tracking tests, largest
//! first) and the largest blue region are reported, for the state selection of
//! seed 001 §II.D. All buffers are allocated in [`PyramidDetector::new`].

use super::components::{Component, Labeler};
use super::image::RgbView;
use super::segment::{ColorRange, HsvRange, Mask, Segmenter};
use super::{VisionError, check_same_size};
use serde::Serialize;

/// An ellipse fitted to a blob by its second moments.
///
/// # Example
///
/// A filled 4×2 rectangle. Each side of n pixels has variance (n² − 1)/12 plus the
/// 1/12 of a unit pixel, n²/12, so the semi-axes are 2·n/√12 = n/√3: 4/√3 and 2/√3, in the
/// ratio of the sides.
///
/// ```
/// use marsupial::perception::{Ellipse, Labeler, Mask};
/// use std::f64::consts::PI;
///
/// let mut mask = Mask::new(6, 4);
/// for y in 1..3 {
///     for x in 1..5 {
///         mask.set(x, y, true);
///     }
/// }
/// let mut labeler = Labeler::new(6, 4);
/// let e = Ellipse::from_component(&labeler.label(&mask).unwrap()[0]);
/// assert_eq!((e.centre, e.count), ([2.5, 1.5], 8));
/// assert!((e.semi_major - 4.0 / 3f64.sqrt()).abs() < 1e-12);
/// assert!((e.semi_minor - 2.0 / 3f64.sqrt()).abs() < 1e-12);
/// assert!((e.axis_ratio() - 2.0).abs() < 1e-12 && e.angle.abs() < 1e-12);
/// // 8 px over π·a·b = 8π/3.
/// assert!((e.fill() - 3.0 / PI).abs() < 1e-12);
/// assert!((e.equivalent_diameter() - 2.0 * (8.0 / PI).sqrt()).abs() < 1e-12);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Ellipse {
    /// Centre (x, y), px.
    pub centre: [f64; 2],
    /// Semi-major axis, px.
    pub semi_major: f64,
    /// Semi-minor axis, px.
    pub semi_minor: f64,
    /// Angle of the major axis from the image x axis, rad.
    pub angle: f64,
    /// Blob pixels.
    pub count: u64,
    /// Blob bounding box (x_min, y_min, x_max, y_max), inclusive.
    pub bbox: [u32; 4],
}

impl Ellipse {
    /// The moment ellipse of a component: a uniform ellipse with semi-axes a, b has
    /// variances a²/4 and b²/4 along its axes, so the semi-axes are twice the square roots
    /// of the covariance's eigenvalues.
    pub fn from_component(c: &Component) -> Ellipse {
        let (mxx, myy, mxy) = c.central_moments();
        // A one-pixel-wide blob has zero variance across it; a pixel is a unit square
        // (variance 1/12), which keeps the axes finite.
        let (mxx, myy) = (mxx + 1.0 / 12.0, myy + 1.0 / 12.0);
        let mean = (mxx + myy) / 2.0;
        let diff = ((mxx - myy) / 2.0).hypot(mxy);
        let (l1, l2) = (mean + diff, (mean - diff).max(1e-12));
        Ellipse {
            centre: c.centroid().into(),
            semi_major: 2.0 * l1.sqrt(),
            semi_minor: 2.0 * l2.sqrt(),
            angle: 0.5 * (2.0 * mxy).atan2(mxx - myy),
            count: c.count,
            bbox: c.bbox,
        }
    }

    /// Major over minor axis (≥ 1).
    pub fn axis_ratio(&self) -> f64 {
        self.semi_major / self.semi_minor.max(1e-9)
    }

    /// Blob pixels over the fitted ellipse's area π·a·b (≈ 1 for a filled ellipse).
    pub fn fill(&self) -> f64 {
        self.count as f64 / (std::f64::consts::PI * self.semi_major * self.semi_minor).max(1e-9)
    }

    /// Diameter of the circle with the blob's area, px.
    pub fn equivalent_diameter(&self) -> f64 {
        2.0 * (self.count as f64 / std::f64::consts::PI).sqrt()
    }
}

/// The bounding region of one or more blue blobs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct BlueRegion {
    /// (x_min, y_min, x_max, y_max), inclusive.
    pub bbox: [u32; 4],
    /// Blue pixels inside.
    pub count: u64,
}

impl BlueRegion {
    /// Width, px.
    pub fn width(&self) -> f64 {
        (self.bbox[2] - self.bbox[0] + 1) as f64
    }

    /// Height g, px.
    pub fn height(&self) -> f64 {
        (self.bbox[3] - self.bbox[1] + 1) as f64
    }

    /// Centre (x, y) of the box, px (pixel centres; the box spans x_min − ½ … x_max + ½).
    pub fn centre(&self) -> [f64; 2] {
        [
            (self.bbox[0] + self.bbox[2]) as f64 / 2.0,
            (self.bbox[1] + self.bbox[3]) as f64 / 2.0,
        ]
    }

    fn gap_to(&self, o: &BlueRegion) -> f64 {
        let gx = (o.bbox[0] as f64 - self.bbox[2] as f64).max(self.bbox[0] as f64 - o.bbox[2] as f64);
        let gy = (o.bbox[1] as f64 - self.bbox[3] as f64).max(self.bbox[1] as f64 - o.bbox[3] as f64);
        gx.max(gy).max(0.0)
    }

    fn merge(&mut self, o: &BlueRegion) {
        self.bbox = [
            self.bbox[0].min(o.bbox[0]),
            self.bbox[1].min(o.bbox[1]),
            self.bbox[2].max(o.bbox[2]),
            self.bbox[3].max(o.bbox[3]),
        ];
        self.count += o.count;
    }
}

/// An accepted (ellipse, blue region) pair.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PyramidPair {
    /// The orange guide.
    pub ellipse: Ellipse,
    /// The blue edges.
    pub blue: BlueRegion,
    /// Summed normalised deviation from the ideal (lower is better).
    pub score: f64,
}

/// One frame's result.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PyramidDetection {
    /// The chosen pair.
    pub pair: Option<PyramidPair>,
    /// The chosen ellipse: the pair's, or the best ellipse alone.
    pub ellipse: Option<Ellipse>,
    /// The chosen blue region: the pair's, or the largest alone.
    pub blue: Option<BlueRegion>,
    /// Pairs that passed the loose filters.
    pub candidates: u32,
}

/// The target's proportions the pair filters check against.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PyramidShape {
    /// Blue height over ball diameter, h / D.
    pub size_ratio: f64,
    /// Ball-to-blue offset over blue height, m / h.
    pub offset_ratio: f64,
}

/// The pyramid detector's bands, shape and pair filters, in plain numbers. A profile's
/// `[perception.pyramid]` gives them (`PyramidParams::from(&spec)` in `profile`);
/// [`Default`] holds the values tuned for RAPOSA (seed 001 §II.D), which are also the
/// profile's defaults.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PyramidParams {
    /// The orange guide's HSV band.
    pub orange: HsvRange,
    /// The blue edges' HSV band.
    pub blue: HsvRange,
    /// Smallest orange blob kept as an ellipse, px (the range limit: seed 001 §III).
    pub min_ellipse_px: u32,
    /// Largest ellipse axis ratio (major / minor) kept.
    pub max_axis_ratio: f64,
    /// Smallest fill of the fitted ellipse (blob pixels / π·a·b); rejects ragged blobs.
    pub min_fill: f64,
    /// Smallest blue blob kept, px.
    pub min_blue_px: u32,
    /// Loose pair limits; when several pairs pass, the same tests run again with every
    /// tolerance multiplied by `tighten` (in (0, 1]).
    pub tighten: f64,
    /// Largest relative deviation of the blue height from the height the ball's size
    /// predicts (1 allows a factor of 2 either way).
    pub max_size_dev: f64,
    /// Largest vertical offset of the ellipse centre from the blue region's centre, in
    /// blue heights.
    pub max_vertical_dev: f64,
    /// Slack on the horizontal offset the geometry allows, as a fraction of it.
    pub max_horizontal_dev: f64,
    /// Ellipse pixels / blue bounding-box area: [lo, hi].
    pub area_ratio: [f64; 2],
    /// Radius of the tracking ball around the previous ellipse, px (paper: 20).
    pub tracking_ball_px: f64,
    /// The tracking ball is dropped after this many frames without a detection.
    pub tracking_reset_frames: u32,
    /// At most this many blobs per colour are considered (the largest), bounding time in
    /// clutter.
    pub max_candidates: u32,
}

impl Default for PyramidParams {
    fn default() -> Self {
        Self {
            orange: HsvRange {
                h: [8.0, 45.0],
                s: [0.45, 1.0],
                v: [0.25, 1.0],
            },
            blue: HsvRange {
                h: [200.0, 250.0],
                s: [0.40, 1.0],
                v: [0.12, 1.0],
            },
            min_ellipse_px: 40,
            max_axis_ratio: 2.5,
            min_fill: 0.7,
            min_blue_px: 20,
            tighten: 0.5,
            max_size_dev: 1.0,
            max_vertical_dev: 0.6,
            max_horizontal_dev: 0.5,
            area_ratio: [0.08, 6.0],
            tracking_ball_px: 20.0,
            tracking_reset_frames: 5,
            max_candidates: 16,
        }
    }
}

/// The pyramid detector. Allocates only in [`PyramidDetector::new`].
///
/// # Example
///
/// A 40×30 grey frame with a square blue frame (16 px, bars 2 px wide) and an orange disc
/// of radius 5 (81 px) inside it, detected with the default (RAPOSA) bands and filters.
/// Without the blue frame the ellipse is still reported, alone.
///
/// ```
/// use marsupial::perception::{PyramidDetector, PyramidParams, PyramidShape, RgbImage};
///
/// let (orange, blue) = ([235, 120, 20], [20, 60, 220]);
/// let scene = |with_blue: bool| {
///     let mut im = RgbImage::new(40, 30);
///     im.fill([120, 118, 115]);
///     for y in 6..22 {
///         for x in 10..26 {
///             let bar = x < 12 || x >= 24 || y < 8 || y >= 20;
///             let in_disc = (x as f64 - 18.0).hypot(y as f64 - 14.0) <= 5.0;
///             if in_disc {
///                 im.put(x, y, orange);
///             } else if bar && with_blue {
///                 im.put(x, y, blue);
///             }
///         }
///     }
///     im
/// };
/// // Ball 7 cm, blue edges 10 cm; the ball sits 16 cm from the edges' midpoint.
/// let shape = PyramidShape { size_ratio: 0.10 / 0.07, offset_ratio: 1.6 };
/// let mut det = PyramidDetector::new(40, 30, &PyramidParams::default(), shape);
///
/// let d = det.detect(&scene(true).view()).unwrap();
/// let pair = d.pair.expect("pair");
/// assert_eq!(d.candidates, 1);
/// assert_eq!((pair.ellipse.centre, pair.ellipse.count), ([18.0, 14.0], 81));
/// assert!(pair.ellipse.axis_ratio() < 1.0 + 1e-9);
/// assert_eq!(pair.blue.bbox, [10, 6, 25, 21]);
/// assert_eq!((pair.blue.height(), pair.blue.centre()), (16.0, [17.5, 13.5]));
/// assert_eq!(det.masks()[1].count(), 16 * 16 - 12 * 12);
/// assert_eq!(det.tracked(), Some([18.0, 14.0])); // the next frame looks near here
///
/// let d = det.detect(&scene(false).view()).unwrap();
/// assert!(d.pair.is_none() && d.blue.is_none());
/// assert_eq!(d.ellipse.map(|e| e.count), Some(81));
/// ```
#[derive(Debug, Clone)]
pub struct PyramidDetector {
    width: usize,
    height: usize,
    params: PyramidParams,
    shape: PyramidShape,
    bands: [HsvRange; 2],
    segmenter: Segmenter,
    masks: [Mask; 2],
    labelers: [Labeler; 2],
    ellipses: Vec<Ellipse>,
    blues: Vec<BlueRegion>,
    order: Vec<u32>,
    survivors: Vec<PyramidPair>,
    previous: Option<[f64; 2]>,
    missed: u32,
}

impl PyramidDetector {
    /// A detector for `width × height` frames.
    pub fn new(width: usize, height: usize, params: &PyramidParams, shape: PyramidShape) -> Self {
        let n = params.max_candidates as usize;
        Self {
            width,
            height,
            params: *params,
            shape,
            bands: [params.orange, params.blue],
            segmenter: Segmenter::new(),
            masks: [Mask::new(width, height), Mask::new(width, height)],
            labelers: [Labeler::new(width, height), Labeler::new(width, height)],
            ellipses: Vec::with_capacity(n),
            blues: Vec::with_capacity(n),
            order: Vec::with_capacity(width * height / 2 + 1),
            survivors: Vec::with_capacity(n * n),
            previous: None,
            missed: 0,
        }
    }

    /// (width, height).
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// The current (orange, blue) bands.
    pub fn bands(&self) -> [HsvRange; 2] {
        self.bands
    }

    /// Replaces the HSV bands from the next frame on (live operator tuning).
    pub fn set_bands(&mut self, orange: HsvRange, blue: HsvRange) {
        self.bands = [orange, blue];
    }

    /// The (orange, blue) masks of the last frame.
    pub fn masks(&self) -> &[Mask; 2] {
        &self.masks
    }

    /// Centre of the ellipse the tracking ball is around, if any.
    pub fn tracked(&self) -> Option<[f64; 2]> {
        self.previous
    }

    /// Forgets the tracked ellipse (e.g. after the robot moved blind).
    pub fn reset_tracking(&mut self) {
        self.previous = None;
        self.missed = 0;
    }

    /// Detects the pyramid in `view`.
    ///
    /// # Errors
    /// [`VisionError::SizeMismatch`] when the frame is not the detector's size.
    pub fn detect(&mut self, view: &RgbView<'_>) -> Result<PyramidDetection, VisionError> {
        check_same_size((self.width, self.height), (view.width(), view.height()))?;
        self.segmenter
            .segment(view, &self.bands.map(ColorRange::Hsv), &mut self.masks)?;
        self.collect_ellipses()?;
        self.collect_blues()?;
        let det = self.choose();
        match det.ellipse {
            Some(e) => {
                self.previous = Some(e.centre);
                self.missed = 0;
            }
            None => {
                self.missed += 1;
                if self.missed > self.params.tracking_reset_frames {
                    self.previous = None;
                }
            }
        }
        Ok(det)
    }

    /// Indices of the largest components of colour `k` with at least `min` pixels, in
    /// decreasing size (ties by index), at most `max_candidates`.
    fn largest(&mut self, k: usize, min: u64) {
        let comps = self.labelers[k].components();
        self.order.clear();
        self.order
            .extend((0..comps.len() as u32).filter(|&i| comps[i as usize].count >= min));
        self.order
            .sort_unstable_by(|&a, &b| comps[b as usize].count.cmp(&comps[a as usize].count).then(a.cmp(&b)));
        self.order.truncate(self.params.max_candidates as usize);
    }

    fn collect_ellipses(&mut self) -> Result<(), VisionError> {
        self.labelers[0].label(&self.masks[0])?;
        self.largest(0, self.params.min_ellipse_px as u64);
        self.ellipses.clear();
        let comps = self.labelers[0].components();
        for &i in &self.order {
            let e = Ellipse::from_component(&comps[i as usize]);
            if e.axis_ratio() <= self.params.max_axis_ratio && e.fill() >= self.params.min_fill {
                self.ellipses.push(e);
            }
        }
        Ok(())
    }

    fn collect_blues(&mut self) -> Result<(), VisionError> {
        self.labelers[1].label(&self.masks[1])?;
        self.largest(1, self.params.min_blue_px as u64);
        self.blues.clear();
        let comps = self.labelers[1].components();
        for &i in &self.order {
            let c = &comps[i as usize];
            self.blues.push(BlueRegion {
                bbox: c.bbox,
                count: c.count,
            });
        }
        // Merge regions that nearly touch, until nothing changes.
        let mut merged = true;
        while merged {
            merged = false;
            'outer: for i in 0..self.blues.len() {
                for j in i + 1..self.blues.len() {
                    let (a, b) = (self.blues[i], self.blues[j]);
                    let reach = (0.8 * a.height().max(b.height())).max(2.0);
                    if a.gap_to(&b) <= reach {
                        self.blues[i].merge(&b);
                        self.blues.swap_remove(j);
                        merged = true;
                        break 'outer;
                    }
                }
            }
        }
        self.blues
            .sort_unstable_by(|a, b| b.count.cmp(&a.count).then(a.bbox.cmp(&b.bbox)));
        Ok(())
    }

    fn in_ball(&self, e: &Ellipse) -> bool {
        self.previous
            .is_none_or(|p| (e.centre[0] - p[0]).hypot(e.centre[1] - p[1]) <= self.params.tracking_ball_px)
    }

    /// Pair test at tolerance scale `t` (1 loose, `tighten` tight): the normalised
    /// deviation, or `None` when a limit is exceeded.
    fn pair_score(&self, e: &Ellipse, b: &BlueRegion, t: f64) -> Option<f64> {
        let s = &self.params;
        let g = b.height();
        // Size: the blue height against the ball's diameter.
        let size = (g / (self.shape.size_ratio * e.equivalent_diameter())).ln().abs();
        let size_lim = (1.0 + s.max_size_dev * t).ln();
        // Vertical offset, in blue heights.
        let c = b.centre();
        let dy = (e.centre[1] - c[1]).abs();
        let dy_lim = s.max_vertical_dev * t * g + 1.0;
        // Horizontal offset against the largest the geometry allows.
        let dx = (e.centre[0] - c[0]).abs();
        let dx_lim = (b.width() / 2.0 + self.shape.offset_ratio * g) * (1.0 + s.max_horizontal_dev * t) + 1.0;
        // Area ratio, in log space around the range's geometric centre.
        let ratio = e.count as f64 / (b.width() * g);
        let (lo, hi) = (s.area_ratio[0].ln(), s.area_ratio[1].ln());
        let (mid, half) = ((lo + hi) / 2.0, (hi - lo) / 2.0 * t.max(1e-3));
        let area = (ratio.ln() - mid).abs();
        let ok = size <= size_lim && dy <= dy_lim && dx <= dx_lim && area <= half;
        ok.then(|| size / size_lim + dy / dy_lim + dx / dx_lim + area / half)
    }

    fn choose(&mut self) -> PyramidDetection {
        self.survivors.clear();
        for e in &self.ellipses {
            if !self.in_ball(e) {
                continue;
            }
            for b in &self.blues {
                if let Some(score) = self.pair_score(e, b, 1.0) {
                    self.survivors.push(PyramidPair {
                        ellipse: *e,
                        blue: *b,
                        score,
                    });
                }
            }
        }
        let candidates = self.survivors.len() as u32;
        let mut best: Option<PyramidPair> = None;
        let consider = |best: &mut Option<PyramidPair>, p: PyramidPair| {
            if best.is_none_or(|b| p.score < b.score) {
                *best = Some(p);
            }
        };
        if self.survivors.len() > 1 {
            let t = self.params.tighten;
            for p in &self.survivors {
                if let Some(score) = self.pair_score(&p.ellipse, &p.blue, t) {
                    consider(&mut best, PyramidPair { score, ..*p });
                }
            }
        }
        if best.is_none() {
            for p in &self.survivors {
                consider(&mut best, *p);
            }
        }
        match best {
            Some(p) => PyramidDetection {
                pair: Some(p),
                ellipse: Some(p.ellipse),
                blue: Some(p.blue),
                candidates,
            },
            None => PyramidDetection {
                pair: None,
                ellipse: self.ellipses.iter().find(|e| self.in_ball(e)).copied(),
                blue: self.blues.first().copied(),
                candidates,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::perception::RgbImage;

    const ORANGE: [u8; 3] = [235, 120, 20];
    const BLUE: [u8; 3] = [20, 60, 220];

    fn shape() -> PyramidShape {
        PyramidShape {
            size_ratio: 0.10 / 0.07,
            offset_ratio: 1.6,
        }
    }

    fn disc(im: &mut RgbImage, cx: f64, cy: f64, r: f64, c: [u8; 3]) {
        for y in 0..im.height() {
            for x in 0..im.width() {
                if (x as f64 - cx).hypot(y as f64 - cy) <= r {
                    im.put(x, y, c);
                }
            }
        }
    }

    fn frame(im: &mut RgbImage, x0: usize, y0: usize, side: usize, bar: usize) {
        for y in y0..y0 + side {
            for x in x0..x0 + side {
                let edge = x < x0 + bar || x >= x0 + side - bar || y < y0 + bar || y >= y0 + side - bar;
                if edge {
                    im.put(x, y, BLUE);
                }
            }
        }
    }

    fn grey(w: usize, h: usize) -> RgbImage {
        let mut im = RgbImage::new(w, h);
        for y in 0..h {
            for x in 0..w {
                im.put(x, y, [120, 118, 115]);
            }
        }
        im
    }

    #[test]
    fn moment_ellipse_of_a_disc_and_a_bar() {
        let mut im = grey(80, 60);
        disc(&mut im, 40.0, 30.0, 10.0, ORANGE);
        let mut d = PyramidDetector::new(80, 60, &PyramidParams::default(), shape());
        let det = d.detect(&im.view()).unwrap();
        let e = det.ellipse.expect("disc found");
        assert!((e.centre[0] - 40.0).abs() < 0.1 && (e.centre[1] - 30.0).abs() < 0.1);
        assert!((e.semi_major - 10.0).abs() < 0.6 && (e.semi_minor - 10.0).abs() < 0.6);
        assert!(e.axis_ratio() < 1.05 && (e.fill() - 1.0).abs() < 0.08);
        // A long thin bar fails the axis-ratio test.
        let mut im = grey(80, 60);
        for x in 10..70 {
            for y in 28..32 {
                im.put(x, y, ORANGE);
            }
        }
        let det = d.detect(&im.view()).unwrap();
        assert!(det.ellipse.is_none());
    }

    #[test]
    fn finds_the_pair_and_rejects_a_mismatched_one() {
        let mut im = grey(160, 120);
        frame(&mut im, 60, 40, 30, 4);
        disc(&mut im, 75.0, 56.0, 10.0, ORANGE);
        let mut d = PyramidDetector::new(160, 120, &PyramidParams::default(), shape());
        let det = d.detect(&im.view()).unwrap();
        let p = det.pair.expect("pair");
        assert_eq!(p.blue.bbox, [60, 40, 89, 69]);
        assert!((p.ellipse.centre[0] - 75.0).abs() < 0.5);
        // A ball far too big for the blue: the size test fails; ellipse and blue are still
        // reported alone.
        let mut im = grey(160, 120);
        frame(&mut im, 60, 40, 12, 3);
        disc(&mut im, 120.0, 60.0, 25.0, ORANGE);
        d.reset_tracking();
        let det = d.detect(&im.view()).unwrap();
        assert!(det.pair.is_none());
        assert!(det.ellipse.is_some() && det.blue.is_some());
    }

    #[test]
    fn tracking_ball_ignores_far_jumps_and_resets() {
        let spec = PyramidParams::default();
        let mut d = PyramidDetector::new(160, 120, &spec, shape());
        let mut a = grey(160, 120);
        disc(&mut a, 40.0, 60.0, 8.0, ORANGE);
        assert!(d.detect(&a.view()).unwrap().ellipse.is_some());
        let mut b = grey(160, 120);
        disc(&mut b, 120.0, 60.0, 8.0, ORANGE);
        assert!(
            d.detect(&b.view()).unwrap().ellipse.is_none(),
            "80 px jump is outside the ball"
        );
        for _ in 0..spec.tracking_reset_frames {
            d.detect(&b.view()).unwrap();
        }
        assert!(
            d.detect(&b.view()).unwrap().ellipse.is_some(),
            "ball dropped after misses"
        );
    }

    #[test]
    fn several_pairs_are_separated_by_the_tight_pass() {
        // A true pair and a decoy ball beside the blue at the edge of the loose limits.
        let mut im = grey(200, 120);
        frame(&mut im, 80, 40, 30, 4);
        disc(&mut im, 95.0, 55.0, 10.0, ORANGE);
        disc(&mut im, 150.0, 70.0, 10.0, ORANGE);
        let mut d = PyramidDetector::new(200, 120, &PyramidParams::default(), shape());
        let det = d.detect(&im.view()).unwrap();
        assert!(det.candidates >= 2, "{}", det.candidates);
        assert!((det.pair.unwrap().ellipse.centre[0] - 95.0).abs() < 0.5);
    }

    #[test]
    fn split_blue_edges_merge_into_one_region() {
        let mut im = grey(160, 120);
        // Two vertical bars with a gap (the ball hides the middle).
        for y in 40..70 {
            for x in (60..64).chain(86..90) {
                im.put(x, y, BLUE);
            }
        }
        disc(&mut im, 75.0, 55.0, 10.0, ORANGE);
        let mut d = PyramidDetector::new(160, 120, &PyramidParams::default(), shape());
        let det = d.detect(&im.view()).unwrap();
        assert_eq!(det.blue.unwrap().bbox, [60, 40, 89, 69]);
    }

    #[test]
    fn live_band_change_takes_effect() {
        let mut im = grey(80, 60);
        disc(&mut im, 40.0, 30.0, 10.0, [40, 200, 40]); // green
        let mut d = PyramidDetector::new(80, 60, &PyramidParams::default(), shape());
        assert!(d.detect(&im.view()).unwrap().ellipse.is_none());
        let [_, blue] = d.bands();
        d.set_bands(
            HsvRange {
                h: [100.0, 140.0],
                s: [0.4, 1.0],
                v: [0.2, 1.0],
            },
            blue,
        );
        assert!(d.detect(&im.view()).unwrap().ellipse.is_some());
    }

    #[test]
    fn segmentation_matches_the_reference_over_the_cube() {
        // All 2²⁴ colours, no tolerance.
        let spec = PyramidParams::default();
        crate::perception::image::for_each_cube_slab(|_, slab| {
            let mut d = PyramidDetector::new(slab.width(), slab.height(), &spec, shape());
            d.detect(&slab.view()).unwrap();
            let [o, b] = d.masks();
            for (idx, px) in slab.as_bytes().chunks_exact(3).enumerate() {
                let rgb = [px[0], px[1], px[2]];
                assert_eq!(o.data()[idx] != 0, spec.orange.contains(rgb), "{rgb:?}");
                assert_eq!(b.data()[idx] != 0, spec.blue.contains(rgb), "{rgb:?}");
            }
        });
    }

    #[test]
    fn wrong_size_is_an_error() {
        let mut d = PyramidDetector::new(80, 60, &PyramidParams::default(), shape());
        assert!(matches!(
            d.detect(&RgbImage::new(40, 30).view()),
            Err(VisionError::SizeMismatch { .. })
        ));
    }
}
