//! Circle-mark detection (seed 000 §III.A.2): adaptive threshold, black and white blobs
//! filtered by size, eccentricity and Euler number, black/white pairs with coinciding
//! centroids, a local re-threshold for the inner pattern and the rotation, and the centre
//! by an ellipse fit of the black blob's outer perimeter.
//!
//! **The mark** (as the simulator prints it, `sim::scene::CircleMark`; seed 000 Fig. 5
//! shows a similar Curiosity-style design but gives no dimensions, so these are ours),
//! with outer radius R: a white margin out to 1.3 R, a black rim from 0.8 R to R, a white
//! ring from 0.6 R to 0.8 R, and a black core split by a white bar 0.24 R wide through the
//! centre. The bar's direction, −45°, 0°, 45° or 90° from the face's horizontal, is the
//! mark's rotation. The black rim is one blob with one hole (Euler number 0); the white
//! ring and bar are one blob inside it (two holes when resolved, none when the core is
//! lost at range), and both blobs are centred on the mark's centre.
//!
//! **Per frame**, into buffers the detector owns (nothing is allocated after
//! [`CircleDetector::new`] or [`CircleDetector::resize`]):
//! 1. grey levels, then the local-mean threshold ([`AdaptiveThreshold`], a 5-px window for
//!    the thin rims of far marks and a wider one for the pixels it leaves undecided in
//!    the wide black areas of near ones) into a black and a white mask, the black one
//!    labelled 8-connected, the black blobs with their Euler numbers ([`RunIndex`]);
//! 2. black candidates: area within limits, the moment ellipse's axis ratio at least
//!    `min_axis_ratio`, not touching the image border (a cut mark's centre would be
//!    biased), Euler number in `black_euler` (or brought into it by filling its
//!    pinholes, holes of at most `max_pinhole_px`: [`RunIndex::pinholes`]), and its
//!    centroid surrounded by it as a ring surrounds its centre ([`RunIndex::surrounds`]).
//!    A candidate with another in its box that surrounds its centroid is dropped: that
//!    is the dark halo a grey surround makes around a mark's white margin, holding the
//!    mark's rim;
//! 3. white candidates, for each black one: the white mask labelled 4-connected (the
//!    consistent pair: a thin black rim closed only diagonally still holds the white ring
//!    in) inside the black blob's box only, where its partner must lie; area and axis
//!    ratio as for black. Pairs: the white blob's box inside the black blob's box, its
//!    centroid within `max_centroid_offset` of the black blob's equivalent radius, and
//!    the white/black area ratio within `area_ratio`. Each filter is wide; together they
//!    are strong (seed 000);
//! 4. the local threshold: halfway between the mean grey of the pair's black and white
//!    pixels. The black blob's outer perimeter (each row's and column's extreme pixels),
//!    placed to sub-pixel where the grey level crosses that threshold, is fitted with an
//!    ellipse ([`fit_ellipse`]); a poor fit (RMS above `max_fit_rms_px` +
//!    `max_fit_rms_frac` × the minor semi-axis) rejects the pair, which is what removes
//!    squares and other ring-like shapes;
//! 5. the rotation: inside the fitted ellipse, rectified to a unit circle, the pixels of
//!    the core (radius < 0.5) brighter than the local threshold form the bar. The main
//!    axis of their weighted second moments, with the image's y turned up, gives its
//!    direction, rounded to the nearest of the four rotations; when the moments are too
//!    round (`min_bar_anisotropy`, the bar is not resolved) the rotation is unknown;
//! 6. the margin: the grey level just outside the rim must be above the local threshold
//!    (the printed white margin), which rejects the dark "halo" a grey surround makes
//!    around a mark's bright margin.
//!
//! **Coordinates**: pixel (i, j) covers [i, i+1) × [j, j+1), so its centre is
//! (i + 0.5, j + 0.5), the convention of [`crate::perception::camera_model`]. Angles of
//! rotation are counter-clockwise as seen in the image (y up), which is the face's own
//! sense for a camera facing the marks upright.

use super::blobs::RunIndex;
use super::ellipse::{Ellipse, fit_ellipse};
use super::threshold::{AdaptiveThreshold, Threshold, Thresholder};
use crate::perception::components::{Component, Labeler, Run};
use crate::perception::image::RgbView;
use crate::perception::{Mask, VisionError, check_same_size};
use serde::Serialize;

/// One of the four rotations of a mark's bar (seed 000 §III.A.1: "four possible rotations
/// in 45° increments (−45°, 0°, 45°, and 90°)").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub enum MarkRotation {
    /// −45°.
    Minus45,
    /// 0°: the bar along the face's horizontal.
    Zero,
    /// 45°.
    Plus45,
    /// 90°: the bar vertical.
    Ninety,
}

impl MarkRotation {
    /// The four, in the order of their angles.
    pub const ALL: [MarkRotation; 4] = [Self::Minus45, Self::Zero, Self::Plus45, Self::Ninety];

    /// The angle, degrees.
    pub fn degrees(self) -> f64 {
        match self {
            Self::Minus45 => -45.0,
            Self::Zero => 0.0,
            Self::Plus45 => 45.0,
            Self::Ninety => 90.0,
        }
    }

    /// Index 0–3 in [`MarkRotation::ALL`].
    pub fn index(self) -> usize {
        self as usize
    }

    /// The rotation a profile's `rotation_deg` names, or `None` for any other angle.
    pub fn from_degrees(deg: f64) -> Option<Self> {
        Self::ALL.into_iter().find(|r| (r.degrees() - deg).abs() < 1e-9)
    }

    /// The nearest rotation to a bar direction (degrees, taken modulo 180° since a bar
    /// has no head).
    pub fn nearest(deg: f64) -> Self {
        let d = (deg + 67.5).rem_euclid(180.0); // −67.5° → 0
        match (d / 45.0) as usize {
            0 => Self::Minus45,
            1 => Self::Zero,
            2 => Self::Plus45,
            _ => Self::Ninety,
        }
    }
}

/// The detector's thresholds. Seed 000 gives none of them ("chosen empirically from a
/// large data set"); [`CircleParams::for_image`] gives ours, each explained there.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CircleParams {
    /// The first threshold: the local mean ([`Threshold::Adaptive`], the default) or
    /// two global levels ([`Threshold::Fixed`], the paper's comparison).
    pub threshold: Threshold,
    /// Smallest black blob (the rim), px.
    pub min_area_px: u64,
    /// Largest black blob, as a fraction of the image's area.
    pub max_area_frac: f64,
    /// Smallest minor/major axis ratio of a blob's moment ellipse (eccentricity filter).
    pub min_axis_ratio: f64,
    /// Inclusive range of the black blob's Euler number.
    pub black_euler: [i32; 2],
    /// Holes of at most this many pixels are pinholes (sensor noise, not the mark's
    /// shape): a black blob with more holes than `black_euler` allows is taken when
    /// filling its pinholes brings it into the range. 0 fills none.
    pub max_pinhole_px: usize,
    /// Largest distance between the black and white centroids, as a fraction of the black
    /// blob's equivalent radius (half its mean box side).
    pub max_centroid_offset: f64,
    /// Inclusive range of white area / black area.
    pub area_ratio: [f64; 2],
    /// Smallest difference between the pair's mean white and black grey levels.
    pub min_contrast: f64,
    /// Ellipse-fit residual allowance, px.
    pub max_fit_rms_px: f64,
    /// Ellipse-fit residual allowance, as a fraction of the minor semi-axis.
    pub max_fit_rms_frac: f64,
    /// Smallest bar anisotropy (λ₁ − λ₂)/(λ₁ + λ₂) for a rotation to be read.
    pub min_bar_anisotropy: f64,
    /// Largest difference between the bar's measured direction and its rotation's,
    /// degrees: a bar between two rotations is no mark's.
    pub max_bar_error_deg: f64,
    /// Smallest minor semi-axis of the fitted ellipse, px.
    pub min_radius_px: f64,
    /// Report only marks whose bar (and so rotation) was read. The bar is the pattern
    /// that tells a mark from any dark ring around a light disc (a bolt head, a gauge, a
    /// washer); without it the real photos give false marks.
    pub require_rotation: bool,
    /// At most this many marks are reported (the first in raster order of their black
    /// blobs); it bounds the per-frame work and buffers.
    pub max_marks: usize,
}

impl CircleParams {
    /// These parameters for frames `width` wide: the one width-dependent default of
    /// [`CircleParams::for_image`], the adaptive threshold's wide window, recomputed;
    /// every other field kept (a [`Threshold::Fixed`]'s levels do not depend on the
    /// frame's size). What a detector uses when its frames change size.
    pub fn for_width(&self, width: usize) -> Self {
        let mut p = *self;
        if let (Threshold::Adaptive(a), Threshold::Adaptive(d)) = (&mut p.threshold, Self::for_image(width).threshold) {
            a.wide_window_px = d.wide_window_px;
        }
        p
    }

    /// Defaults for a `width`-pixel-wide image (our choices; the paper gives none):
    /// * window: 5 px, then width/64 (odd, at least 11 px; 17 px at 1024) for the pixels
    ///   the first leaves in its dead band. The narrow window reaches 2 px either side of
    ///   a rim pixel, no further than the mark's own bright ring inside and white margin
    ///   outside (each 0.2–0.3 R: 1.2–1.8 px for a mark 12 px across, Axel's at 5.5 m), so
    ///   that its mean is the mark's and not the dark core's and module face's around the
    ///   thin rim. A wider window pulls the mean of a far mark's blurred rim pixel down to
    ///   its own grey, the rim falls into the dead band, breaks (Euler number 1, no hole)
    ///   and the mark is lost at the Euler filter: with width/64 alone no mark past 4 m
    ///   was found, with 7 px none past 5 m (measured on rendered frames, each projected
    ///   mark's black blob and its Euler number; `tests/axel_world.rs`). A 3-px window
    ///   keeps rims to 6.5 m but decides the flat inside of near marks by noise (σ ≈ 6
    ///   grey levels), and no mark at 1 m survives it. The narrow window alone leaves the
    ///   middle of a rim wider than about 4 px (Axel's marks nearer than about 1.5 m) in
    ///   its dead band, hollow; the wide one, wider than the rim and ring of a mark at
    ///   docking range, fills it in;
    /// * offset 8 grey levels: above the sensor noise of a flat surface, far below a
    ///   printed mark's black-to-white contrast even in shade;
    /// * black blob from 12 px (a rim about 9 px across) to 5 % of the image;
    /// * axis ratio ≥ 0.2 (a circle seen 78° off its normal);
    /// * black Euler number from −3 to 0 (at least one hole, a few from noise), or brought
    ///   there by filling holes of up to 4 px as pinholes. Sensor noise lifts single
    ///   pixels of a black print over the local threshold, and in shade, where the
    ///   camera's gamma stretches dark noise, the rims of Axel's marks at 1.0–1.2 m under
    ///   the `axel-lighting` shadow show 2.9 such holes each besides the ring, 93 % of
    ///   one pixel and the rest of two or three, and 23 of 83 rims more than −3…0 allows:
    ///   the range alone lost those marks (`tests/circles_render.rs`,
    ///   `under_the_shadow_every_mark_is_found_once_pinholes_are_filled`). The smallest
    ///   mark reported (minor semi-axis 4 px) has a hole of about 14 px, its white ring
    ///   (0.88 R² by the mark's geometry), so 4 px is noise;
    /// * centroids within 0.2 of the radius; white/black area 0.25–4;
    /// * contrast ≥ 40 grey levels (rendered marks in lab light show 90–190);
    /// * fit RMS ≤ 0.35 px + 4 % of the minor semi-axis (a square's best ellipse is off by
    ///   about 10 % of its half-side);
    /// * bar anisotropy ≥ 0.5 (a resolved bar gives about 0.9), and only marks with a
    ///   resolved bar are reported;
    /// * bar direction within 12° of its rotation (rendered marks up to 35° off the
    ///   face's normal read within 6°; a 45° step leaves 22.5°);
    /// * minor semi-axis ≥ 4 px (smaller ones cannot show a bar, and speckle makes them);
    /// * at most 64 marks.
    pub fn for_image(width: usize) -> Self {
        Self {
            threshold: Threshold::Adaptive(AdaptiveThreshold {
                window_px: 5,
                offset: 8,
                wide_window_px: ((width / 64).max(11)) | 1,
            }),
            min_area_px: 12,
            max_area_frac: 0.05,
            min_axis_ratio: 0.2,
            black_euler: [-3, 0],
            max_pinhole_px: 4,
            max_centroid_offset: 0.2,
            area_ratio: [0.25, 4.0],
            min_contrast: 40.0,
            max_fit_rms_px: 0.35,
            max_fit_rms_frac: 0.04,
            min_bar_anisotropy: 0.5,
            max_bar_error_deg: 12.0,
            min_radius_px: 4.0,
            require_rotation: true,
            max_marks: 64,
        }
    }
}

/// A detected circle mark.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DetectedMark {
    /// Centre, px (the fitted ellipse's centre; see the module docs for the convention).
    pub centre: [f64; 2],
    /// The ellipse fitted to the black rim's outer edge.
    pub ellipse: Ellipse,
    /// The bar's rotation, or `None` when the bar is not resolved (reported only when
    /// [`CircleParams::require_rotation`] is off).
    pub rotation: Option<MarkRotation>,
    /// The bar's measured direction, degrees counter-clockwise from the image's +x in the
    /// rectified mark, in [−90, 90).
    pub bar_angle_deg: f64,
    /// The bar moments' anisotropy, 0 (round) to 1 (a line).
    pub bar_anisotropy: f64,
    /// Mean white minus mean black grey level of the pair.
    pub contrast: f64,
    /// RMS distance of the perimeter points from the ellipse, px.
    pub fit_rms_px: f64,
}

/// The circle-mark detector: parameters and every per-frame buffer, sized once.
///
/// # Example
///
/// A frame with no mark (and a degenerate one) returns cleanly.
///
/// ```
/// use marsupial::perception::RgbImage;
/// use marsupial::perception::circles::{CircleDetector, CircleParams};
///
/// let mut det = CircleDetector::new(64, 48, CircleParams::for_image(64));
/// let mut im = RgbImage::new(64, 48);
/// im.fill([90, 90, 90]);
/// assert!(det.detect(&im.view()).unwrap().is_empty());
/// assert!(det.detect(&RgbImage::new(0, 0).view()).is_err(), "empty");
/// assert!(det.detect(&RgbImage::new(8, 8).view()).is_err(), "not the detector's size");
/// ```
#[derive(Debug, Clone)]
pub struct CircleDetector {
    params: CircleParams,
    width: usize,
    height: usize,
    grey: Vec<u8>,
    thresholder: Thresholder,
    masks: [Mask; 2],
    labelers: [Labeler; 2],
    /// Euler numbers and run lists of the black blobs (the white ones need neither: their
    /// Euler number is not filtered, and the few that pair are read by rows).
    index: RunIndex,
    black: Vec<u32>,
    col_top: Vec<u32>,
    col_bot: Vec<u32>,
    points: Vec<[f64; 2]>,
    marks: Vec<DetectedMark>,
    /// The pinhole search's fill ([`RunIndex::pinholes`]).
    fill: Vec<usize>,
}

const BLACK: usize = 0;
const WHITE: usize = 1;

impl CircleDetector {
    /// A detector for `width × height` frames, every buffer allocated now.
    pub fn new(width: usize, height: usize, params: CircleParams) -> Self {
        let max_runs = height * width.div_ceil(2);
        Self {
            params,
            width,
            height,
            grey: Vec::with_capacity(width * height),
            thresholder: Thresholder::new(width, height),
            masks: [Mask::new(width, height), Mask::new(width, height)],
            labelers: [Labeler::new(width, height), Labeler::new_four_connected(width, height)],
            index: RunIndex::new(width, height),
            black: Vec::with_capacity(max_runs),
            col_top: Vec::with_capacity(width),
            col_bot: Vec::with_capacity(width),
            points: Vec::with_capacity(2 * (width + height)),
            marks: Vec::with_capacity(params.max_marks),
            fill: Vec::with_capacity(params.max_pinhole_px.min(width * height) + 1),
        }
    }

    /// Resizes for frames of another size (allocates; not a per-frame call).
    pub fn resize(&mut self, width: usize, height: usize) {
        *self = Self::new(width, height, self.params);
    }

    /// (width, height) the detector is sized for.
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// The parameters.
    pub fn params(&self) -> &CircleParams {
        &self.params
    }

    /// The black (index 0) and white (1) masks of the last frame, for overlays and tests.
    pub fn masks(&self) -> &[Mask; 2] {
        &self.masks
    }

    /// The marks of the last [`CircleDetector::detect`] call.
    pub fn marks(&self) -> &[DetectedMark] {
        &self.marks
    }

    /// Detects the circle marks in `view`, in raster order of their black rims.
    ///
    /// # Errors
    /// [`VisionError::EmptyImage`] for a frame without pixels;
    /// [`VisionError::SizeMismatch`] when it is not the detector's size. Pixel content
    /// never errs: a frame without marks gives an empty list.
    pub fn detect(&mut self, view: &RgbView<'_>) -> Result<&[DetectedMark], VisionError> {
        if view.is_empty() {
            return Err(VisionError::EmptyImage);
        }
        check_same_size((self.width, self.height), (view.width(), view.height()))?;
        self.marks.clear();
        let (w, h) = (self.width, self.height);
        let [black_mask, white_mask] = &mut self.masks;
        self.thresholder
            .apply_rgb_with(view, &mut self.grey, &self.params.threshold, black_mask, white_mask);
        self.labelers[BLACK].label(&self.masks[BLACK])?;
        self.index.build(&self.labelers[BLACK]);
        let p = self.params;
        let max_area = (p.max_area_frac * (w * h) as f64) as u64;
        self.black.clear();
        for (i, c) in self.labelers[BLACK].components().iter().enumerate() {
            let inside = c.bbox[0] > 0 && c.bbox[1] > 0 && (c.bbox[2] as usize) + 1 < w && (c.bbox[3] as usize) + 1 < h;
            if c.count < p.min_area_px || c.count > max_area || !inside || axis_ratio(c) < p.min_axis_ratio {
                continue;
            }
            let mut e = self.index.euler(i);
            if e < p.black_euler[0] {
                let pinholes = self.index.pinholes(
                    &self.labelers[BLACK],
                    &self.masks[BLACK],
                    i,
                    p.max_pinhole_px,
                    &mut self.fill,
                );
                e += pinholes as i32;
            }
            // A mark's rim surrounds its centroid (in its hole). The ground's ring-like
            // blobs mostly do not, and dropping them halves the area the costlier partner
            // search labels (on Axel's rendered 1024-px frames at 1.5 and 3 m).
            if !(p.black_euler[0]..=p.black_euler[1]).contains(&e) {
                continue;
            }
            let (cx, cy) = c.centroid();
            if self.index.surrounds(&self.labelers[BLACK], i, cx as u32, cy as u32) {
                self.black.push(i as u32);
            }
        }
        // A candidate that holds another around its own centre is the dark halo that a
        // grey surround makes around a mark's white margin, holding the whole mark: the
        // mark's rim lies in its box and surrounds its centroid. (A rim's box can hold
        // the two halves of its core, hollow when they are wider than the threshold's
        // window, but neither surrounds the mark's centre: the bar splits them there.)
        let (labeler, index) = (&self.labelers[BLACK], &self.index);
        let comps = labeler.components();
        let halo = |outer: usize, inner: usize| {
            let (a, b) = (comps[outer].bbox, comps[inner].bbox);
            let holds = outer != inner && a[0] <= b[0] && a[1] <= b[1] && a[2] >= b[2] && a[3] >= b[3];
            holds && {
                let (cx, cy) = comps[outer].centroid();
                index.surrounds(labeler, inner, cx as u32, cy as u32)
            }
        };
        const OUTER: u32 = 1 << 31; // a flag on the label (labels are fewer than 2³¹ pixels)
        for k in 0..self.black.len() {
            let outer = self.black[k] as usize;
            if self.black.iter().any(|&j| halo(outer, (j & !OUTER) as usize)) {
                self.black[k] |= OUTER;
            }
        }
        self.black.retain(|&j| j & OUTER == 0);
        for bi in 0..self.black.len() {
            if self.marks.len() >= p.max_marks {
                break;
            }
            let b = self.black[bi] as usize;
            let bc = self.labelers[BLACK].components()[b];
            let Some(wl) = self.partner(&bc)? else { continue };
            if let Some(m) = self.refine(b, wl) {
                self.marks.push(m);
            }
        }
        Ok(&self.marks)
    }

    /// The white blob that pairs with black blob `bc`, if any: inside its box, the
    /// centroids close, the areas in proportion; the closest such centroid (of equally
    /// close ones, the leftmost). Only the white mask inside `bc`'s box is labelled: a
    /// partner lies strictly inside that box, and a blob of the box clear of its border is
    /// the frame's own blob ([`Labeler::label_box`]), so the frame's white mask (as many
    /// runs and blobs as the black one, from the ground's texture) is never labelled whole.
    /// The white labeller then holds this box's blobs, which [`CircleDetector::refine`]
    /// reads.
    fn partner(&mut self, bc: &Component) -> Result<Option<usize>, VisionError> {
        let p = &self.params;
        let (bx, by) = bc.centroid();
        let radius = (bc.width() + bc.height()) as f64 / 4.0;
        let tol = (p.max_centroid_offset * radius).max(1.0);
        let max_area = (p.max_area_frac * (self.width * self.height) as f64) as u64;
        let min_white = ((p.min_area_px as f64 * p.area_ratio[0]) as u64).max(1);
        let mut best: Option<(f64, f64, usize)> = None;
        let comps = self.labelers[WHITE].label_box(&self.masks[WHITE], bc.bbox)?;
        for (wi, wc) in comps.iter().enumerate() {
            if wc.bbox[0] <= bc.bbox[0]
                || wc.bbox[1] <= bc.bbox[1]
                || wc.bbox[2] >= bc.bbox[2]
                || wc.bbox[3] >= bc.bbox[3]
                || wc.count < min_white
                || wc.count > max_area
            {
                continue;
            }
            let (wx, wy) = wc.centroid();
            if wx < bx - tol || wx > bx + tol || axis_ratio(wc) < p.min_axis_ratio {
                continue;
            }
            let d = (wx - bx).hypot(wy - by);
            let ratio = wc.count as f64 / bc.count as f64;
            if d <= tol
                && ratio >= p.area_ratio[0]
                && ratio <= p.area_ratio[1]
                && best.is_none_or(|(bd, bwx, _)| d < bd || (d == bd && wx < bwx))
            {
                best = Some((d, wx, wi));
            }
        }
        Ok(best.map(|(_, _, i)| i))
    }

    /// Mean grey level over component `label` of mask `k`: the black blob's runs from
    /// the index, the white blob's from the rows of its box (the labeller's runs are in
    /// raster order).
    fn mean_grey(&self, k: usize, label: usize) -> f64 {
        let (mut s, mut n) = (0u64, 0u64);
        let mut add = |r: &Run| {
            let row = &self.grey[r.y as usize * self.width..][r.x0 as usize..r.x1 as usize];
            s += row.iter().map(|&g| g as u64).sum::<u64>();
            n += row.len() as u64;
        };
        if k == BLACK {
            self.index.runs_of(&self.labelers[k], label).for_each(&mut add);
        } else {
            let lab = &self.labelers[k];
            let [_, y0, _, y1] = lab.components()[label].bbox;
            let runs = lab.runs();
            let from = runs.partition_point(|r| r.y < y0);
            runs[from..]
                .iter()
                .take_while(|r| r.y <= y1)
                .filter(|r| r.label as usize == label)
                .for_each(&mut add);
        }
        s as f64 / n.max(1) as f64
    }

    /// Local threshold, perimeter fit and rotation of the pair (black `b`, white `wl`).
    fn refine(&mut self, b: usize, wl: usize) -> Option<DetectedMark> {
        let p = self.params;
        let (mb, mw) = (self.mean_grey(BLACK, b), self.mean_grey(WHITE, wl));
        let contrast = mw - mb;
        if contrast < p.min_contrast {
            return None;
        }
        let t = (mb + mw) / 2.0;
        let bc = self.labelers[BLACK].components()[b];
        let (x0, bw) = (bc.bbox[0] as usize, bc.width() as usize);
        self.col_top.clear();
        self.col_top.resize(bw, u32::MAX);
        self.col_bot.clear();
        self.col_bot.resize(bw, 0);
        self.points.clear();
        let w = self.width;
        let g = |x: usize, y: usize| self.grey[y * w + x] as f64;
        // Sub-pixel position of the crossing of t between an inner (dark) pixel centre and
        // the next outer one, as a fraction of the step.
        let cross = |gi: f64, go: f64| {
            if go > gi {
                ((t - gi) / (go - gi)).clamp(0.0, 1.0)
            } else {
                0.5
            }
        };
        let mut row_y = u32::MAX;
        let (mut left, mut right) = (0usize, 0usize);
        let runs = self.index.runs_of(&self.labelers[BLACK], b);
        for r in runs {
            if r.y != row_y {
                if row_y != u32::MAX {
                    let y = row_y as usize;
                    self.points
                        .push([left as f64 + 0.5 - cross(g(left, y), g(left - 1, y)), y as f64 + 0.5]);
                    self.points
                        .push([right as f64 + 0.5 + cross(g(right, y), g(right + 1, y)), y as f64 + 0.5]);
                }
                row_y = r.y;
                left = r.x0 as usize;
            }
            right = r.x1 as usize - 1;
            for x in r.x0 as usize..r.x1 as usize {
                let c = x - x0;
                self.col_top[c] = self.col_top[c].min(r.y);
                self.col_bot[c] = self.col_bot[c].max(r.y);
            }
        }
        if row_y != u32::MAX {
            let y = row_y as usize;
            self.points
                .push([left as f64 + 0.5 - cross(g(left, y), g(left - 1, y)), y as f64 + 0.5]);
            self.points
                .push([right as f64 + 0.5 + cross(g(right, y), g(right + 1, y)), y as f64 + 0.5]);
        }
        for c in 0..bw {
            let (top, bot) = (self.col_top[c] as usize, self.col_bot[c] as usize);
            if self.col_top[c] == u32::MAX {
                continue;
            }
            let x = x0 + c;
            self.points
                .push([x as f64 + 0.5, top as f64 + 0.5 - cross(g(x, top), g(x, top - 1))]);
            self.points
                .push([x as f64 + 0.5, bot as f64 + 0.5 + cross(g(x, bot), g(x, bot + 1))]);
        }
        let fit = fit_ellipse(&self.points)?;
        let e = fit.ellipse;
        if fit.rms > p.max_fit_rms_px + p.max_fit_rms_frac * e.semi_minor
            || e.semi_minor < p.min_radius_px
            || e.semi_minor < p.min_axis_ratio * e.semi_major
            || e.semi_major > (self.width.max(self.height)) as f64
        {
            return None;
        }
        if !self.white_margin(&e, t) {
            return None;
        }
        let (bar_angle_deg, bar_anisotropy) = self.bar(&e, t, mw);
        let rotation = Some(MarkRotation::nearest(bar_angle_deg)).filter(|r| {
            let off = (bar_angle_deg - r.degrees() + 90.0).rem_euclid(180.0) - 90.0;
            bar_anisotropy >= p.min_bar_anisotropy && off.abs() <= p.max_bar_error_deg
        });
        if p.require_rotation && rotation.is_none() {
            return None;
        }
        Some(DetectedMark {
            centre: e.centre,
            ellipse: e,
            rotation,
            bar_angle_deg,
            bar_anisotropy,
            contrast,
            fit_rms_px: fit.rms,
        })
    }

    /// Whether the printed white margin surrounds the rim: the mean grey level on the
    /// ellipse grown to 1.15 of its size (halfway across the margin) is above the local
    /// threshold. A grey surround darker than the bright margin otherwise thresholds as a
    /// black ring around the mark, paired with the margin (a "halo").
    fn white_margin(&self, e: &Ellipse, t: f64) -> bool {
        let grown = Ellipse {
            semi_major: 1.15 * e.semi_major,
            semi_minor: 1.15 * e.semi_minor,
            ..*e
        };
        let (mut s, mut n) = (0.0, 0.0);
        for k in 0..16 {
            let q = grown.point(k as f64 * std::f64::consts::TAU / 16.0);
            if q[0] >= 0.0 && q[1] >= 0.0 && (q[0] as usize) < self.width && (q[1] as usize) < self.height {
                s += self.grey[q[1] as usize * self.width + q[0] as usize] as f64;
                n += 1.0;
            }
        }
        n >= 8.0 && s / n > t
    }

    /// Direction (degrees, y up, in [−90, 90)) and anisotropy of the bright pixels in the
    /// mark's core (rectified radius < 0.5), each weighted by how far it lies above the
    /// local threshold `t` toward the white level `white`.
    fn bar(&self, e: &Ellipse, t: f64, white: f64) -> (f64, f64) {
        let reach = 0.5 * e.semi_major + 1.0;
        let (w, h) = (self.width as f64, self.height as f64);
        let xa = (e.centre[0] - reach).floor().clamp(0.0, w) as usize;
        let xb = (e.centre[0] + reach).ceil().clamp(0.0, w) as usize;
        let ya = (e.centre[1] - reach).floor().clamp(0.0, h) as usize;
        let yb = (e.centre[1] + reach).ceil().clamp(0.0, h) as usize;
        let span = (white - t).max(1.0);
        let (mut sw, mut sx, mut sy, mut sxx, mut sxy, mut syy) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        for y in ya..yb {
            for x in xa..xb {
                let q = e.rectify([x as f64 + 0.5, y as f64 + 0.5]);
                let (qx, qy) = (q[0], -q[1]);
                if qx * qx + qy * qy >= 0.25 {
                    continue;
                }
                let wt = ((self.grey[y * self.width + x] as f64 - t) / span).clamp(0.0, 1.0);
                sw += wt;
                sx += wt * qx;
                sy += wt * qy;
                sxx += wt * qx * qx;
                sxy += wt * qx * qy;
                syy += wt * qy * qy;
            }
        }
        if sw <= 0.0 {
            return (0.0, 0.0);
        }
        let (mx, my) = (sx / sw, sy / sw);
        let (m20, m02, m11) = (sxx / sw - mx * mx, syy / sw - my * my, sxy / sw - mx * my);
        let tr = m20 + m02;
        if tr <= 0.0 {
            return (0.0, 0.0);
        }
        let an = ((m20 - m02).powi(2) + 4.0 * m11 * m11).sqrt() / tr;
        let mut deg = (0.5 * (2.0 * m11).atan2(m20 - m02)).to_degrees();
        if deg >= 90.0 {
            deg -= 180.0;
        }
        (deg, an)
    }
}

/// Minor/major axis ratio of a component's moment ellipse (1 for a disc or a square).
fn axis_ratio(c: &Component) -> f64 {
    let (a, b, m) = c.central_moments();
    let root = ((a - b).powi(2) + 4.0 * m * m).sqrt();
    let (l1, l2) = ((a + b + root) / 2.0, (a + b - root) / 2.0);
    if l1 <= 0.0 { 1.0 } else { (l2.max(0.0) / l1).sqrt() }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::perception::RgbImage;

    /// Draws a mark of the simulator's pattern, supersampled 4×4, centred at (cx, cy)
    /// with radius r px, its bar at `rot_deg` (counter-clockwise, y up), squashed
    /// horizontally by `squash` (a view turned about the vertical axis).
    pub(crate) fn draw_mark(im: &mut RgbImage, cx: f64, cy: f64, r: f64, rot_deg: f64, squash: f64) {
        let (s, c) = rot_deg.to_radians().sin_cos();
        let reach = 1.4 * r;
        let (w, h) = (im.width(), im.height());
        for y in ((cy - reach).floor().max(0.0) as usize)..((cy + reach).ceil().min(h as f64) as usize) {
            for x in ((cx - reach).floor().max(0.0) as usize)..((cx + reach).ceil().min(w as f64) as usize) {
                let mut acc = 0.0;
                let mut inside_any = false;
                for sy in 0..4 {
                    for sx in 0..4 {
                        let px = x as f64 + (sx as f64 + 0.5) / 4.0;
                        let py = y as f64 + (sy as f64 + 0.5) / 4.0;
                        let (a, b) = ((px - cx) / squash, -(py - cy));
                        let rr = a.hypot(b);
                        if rr < 1.3 * r {
                            inside_any = true;
                        }
                        let off_bar = (b * c - a * s).abs();
                        let black =
                            rr < r && !(0.6 * r..0.8 * r).contains(&rr) && !(rr < 0.6 * r && off_bar < 0.12 * r);
                        acc += if rr >= 1.3 * r {
                            im.view().get(x, y).map_or(0.0, |p| p[1] as f64)
                        } else if black {
                            12.0
                        } else {
                            220.0
                        };
                    }
                }
                if inside_any {
                    let v = (acc / 16.0).round() as u8;
                    im.put(x, y, [v, v, v]);
                }
            }
        }
    }

    fn detector(w: usize, h: usize) -> CircleDetector {
        CircleDetector::new(w, h, CircleParams::for_image(w))
    }

    #[test]
    fn nearest_rotation_wraps_around_the_half_turn() {
        assert_eq!(MarkRotation::nearest(0.0), MarkRotation::Zero);
        assert_eq!(MarkRotation::nearest(-80.0), MarkRotation::Ninety);
        assert_eq!(MarkRotation::nearest(85.0), MarkRotation::Ninety);
        assert_eq!(MarkRotation::nearest(-50.0), MarkRotation::Minus45);
        assert_eq!(MarkRotation::nearest(130.0), MarkRotation::Minus45);
        assert_eq!(MarkRotation::nearest(30.0), MarkRotation::Plus45);
        assert_eq!(MarkRotation::from_degrees(45.0), Some(MarkRotation::Plus45));
        assert_eq!(MarkRotation::from_degrees(30.0), None);
    }

    #[test]
    fn drawn_marks_are_found_with_their_rotation_and_centre() {
        for (k, rot) in MarkRotation::ALL.into_iter().enumerate() {
            for (r, squash) in [(30.0, 1.0), (12.0, 1.0), (20.0, 0.6), (8.0, 1.0)] {
                let (w, h) = (200, 150);
                let mut im = RgbImage::new(w, h);
                im.fill([120, 120, 120]);
                let (cx, cy) = (97.3 + k as f64, 71.6);
                draw_mark(&mut im, cx, cy, r, rot.degrees(), squash);
                let mut det = detector(w, h);
                let marks = det.detect(&im.view()).unwrap();
                assert_eq!(marks.len(), 1, "{rot:?} r {r} squash {squash}: {marks:?}");
                let m = marks[0];
                let err = (m.centre[0] - cx).hypot(m.centre[1] - cy);
                assert!(err < 0.1, "{rot:?} r {r}: centre off by {err:.3} px");
                if r >= 12.0 {
                    assert_eq!(m.rotation, Some(rot), "r {r} squash {squash}: {m:?}");
                }
            }
        }
    }

    /// A rim pitted with one- and two-pixel holes (noise in shade) has more holes than
    /// the Euler range allows: found with its pinholes filled, lost without. A hole of
    /// five pixels is no pinhole, so a rim with six of them stays rejected.
    #[test]
    fn a_pitted_rim_is_found_once_its_pinholes_are_filled() {
        let (w, h) = (200, 150);
        let (cx, cy, r) = (100.0, 75.0, 30.0);
        let pitted = |hole: &[(usize, usize)]| {
            let mut im = RgbImage::new(w, h);
            im.fill([200, 200, 200]);
            draw_mark(&mut im, cx, cy, r, 0.0, 1.0);
            // Eight holes round the rim's middle (0.9 R), away from the bar.
            for k in 0..8 {
                let t = (22.5 + 45.0 * k as f64).to_radians();
                let (x, y) = ((cx + 0.9 * r * t.cos()) as usize, (cy + 0.9 * r * t.sin()) as usize);
                for &(dx, dy) in hole {
                    im.put(x + dx, y + dy, [220, 220, 220]);
                }
            }
            im
        };
        let unfilled = CircleParams {
            max_pinhole_px: 0,
            ..CircleParams::for_image(w)
        };
        for hole in [&[(0, 0)][..], &[(0, 0), (1, 0)]] {
            let im = pitted(hole);
            let marks = detector(w, h).detect(&im.view()).unwrap().to_vec();
            assert_eq!(marks.len(), 1, "{} px pinholes: {marks:?}", hole.len());
            assert!((marks[0].centre[0] - cx).hypot(marks[0].centre[1] - cy) < 0.2);
            let mut bare = CircleDetector::new(w, h, unfilled);
            assert!(bare.detect(&im.view()).unwrap().is_empty(), "eight holes fail −3…0");
        }
        let im = pitted(&[(0, 0), (1, 0), (0, 1), (1, 1), (2, 0)]);
        assert!(
            detector(w, h).detect(&im.view()).unwrap().is_empty(),
            "five-pixel holes"
        );
    }

    #[test]
    fn a_black_ring_without_its_white_partner_or_a_square_frame_is_no_mark() {
        let (w, h) = (120, 100);
        let mut im = RgbImage::new(w, h);
        im.fill([200, 200, 200]);
        // A square frame with a white square inside: a black blob with a hole, a
        // coinciding white partner, but no ellipse.
        for y in 20..60 {
            for x in 20..60 {
                let edge = !(26..54).contains(&x) || !(26..54).contains(&y);
                let v = if edge { 10 } else { 230 };
                im.put(x, y, [v, v, v]);
            }
        }
        // A plain black disc: no hole.
        for y in 60..90 {
            for x in 70..100 {
                if ((x as f64 - 85.0).powi(2) + (y as f64 - 75.0).powi(2)) < 144.0 {
                    im.put(x, y, [10, 10, 10]);
                }
            }
        }
        let mut det = detector(w, h);
        assert!(det.detect(&im.view()).unwrap().is_empty());
    }

    #[test]
    fn bad_frames_return_cleanly() {
        let mut det = detector(16, 12);
        assert_eq!(det.detect(&RgbImage::new(0, 0).view()), Err(VisionError::EmptyImage));
        assert!(matches!(
            det.detect(&RgbImage::new(4, 4).view()),
            Err(VisionError::SizeMismatch { .. })
        ));
        // All black, all white, noise, a single pixel.
        let mut im = RgbImage::new(16, 12);
        assert!(det.detect(&im.view()).unwrap().is_empty());
        im.fill([255, 255, 255]);
        assert!(det.detect(&im.view()).unwrap().is_empty());
        for (i, b) in im.as_bytes_mut().iter_mut().enumerate() {
            *b = (i * 7919 % 251) as u8;
        }
        assert!(det.detect(&im.view()).is_ok());
        let mut tiny = CircleDetector::new(1, 1, CircleParams::for_image(1));
        assert!(tiny.detect(&RgbImage::new(1, 1).view()).unwrap().is_empty());
        let mut line = CircleDetector::new(3, 1, CircleParams::for_image(3));
        assert!(line.detect(&RgbImage::new(3, 1).view()).unwrap().is_empty());
    }

    #[test]
    fn for_width_recomputes_only_the_wide_window() {
        let tuned = CircleParams {
            min_contrast: 25.0,
            ..CircleParams::for_image(640)
        };
        let at_1024 = tuned.for_width(1024);
        assert_eq!(
            at_1024,
            CircleParams {
                min_contrast: 25.0,
                ..CircleParams::for_image(1024)
            }
        );
        let fixed = CircleParams {
            threshold: Threshold::Fixed(super::super::FixedThreshold {
                black_below: 70,
                white_above: 150,
            }),
            ..tuned
        };
        assert_eq!(fixed.for_width(1024), fixed);
    }
}
