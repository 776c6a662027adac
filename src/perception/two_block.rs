//! Bujold's two-block fiducial (seed 004 §IV.B): detector and tracker (detector, colour
//! model and imprinting for one camera's frames; `schemas::TwoBlockSchema` runs it on a
//! tick's inputs).
//!
//! Per frame: segment both colours (SCT ranges from the [`ColorModel`]), label each mask,
//! drop components under `min_component_px`, and test every (left-colour, right-colour)
//! pair:
//!
//! * **order**: the left-colour block lies left of the right-colour block *in the image*.
//!   "Left colour" means the colour that appears on the image's left for this camera
//!   mounting (a 180°-rolled camera swaps the fiducial's sides), so a copy of the fiducial
//!   turned upside down presents its colours in the wrong order and is rejected;
//! * **gap**: the right block's leftmost pixel minus the left block's rightmost pixel is
//!   within `gap_slack_px + max_gap_frac · h` of adjacency (h the blocks' mean height;
//!   proportional so that roll, which tilts the shared edge, is tolerated at any range);
//! * **alignment**: centroids within `max_vertical_frac · h` vertically;
//! * **height**: the taller block at most `max_height_ratio` times the shorter (the blocks
//!   are equally tall on the flap; a real scene's unrelated patches of the two colours
//!   rarely are: a butterfly's wing spots in the real photos paired at 2.7×);
//! * **balance**: the smaller block's pixel count at least `min_count_ratio` of the
//!   larger's (two sweets in a real photo paired at 0.04).
//!
//! Among the surviving pairs the one whose pixel-count ratio is closest to 1 wins; ties go
//! to the larger total, then to the lower component indices, so the choice is
//! deterministic.

use super::cast::{CastCompensator, CastParams};
use super::colour_model::{
    AngleStats, ColorMode, ColorModel, ColorModelParams, Imprinter, SegmentationMode, StatsAccumulator,
};
use super::components::Labeler;
use super::image::RgbView;
use super::sct::Sct;
use super::segment::{ColorRange, Mask, SctRange, Segmenter};
use super::spurs::spur_count;
use super::{VisionError, check_same_size};
use serde::Serialize;

/// The largest share of a block's pixels that can be spurs for the block still to count
/// as solid, with noise on its edge (see `spurs`). A noise fringe is sparse: 1–2.3 % of
/// the red block on run 71 of `bujold-colours`, where it was measured; 5 % is about twice
/// that, chosen once and not swept. A block past it is ragged: a colour model that fits
/// the paint poorly (the static model under light that moved the paint's colours) leaves
/// holes and notches whose spurs are paint, and taking them out biases the count.
pub const MAX_SPUR_SHARE: f64 = 0.05;

/// The smaller block's pixel count over the larger's, in (0, 1]: the balance the pairing
/// limits and prefers, and the ratio a [`Pair`] reports.
fn count_ratio(a: u64, b: u64) -> f64 {
    a.min(b) as f64 / a.max(b) as f64
}

/// Pairing limits (a profile's `[perception]` gives them: `PairLimits::from(&spec)`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairLimits {
    /// Smallest component considered, px.
    pub min_component_px: u64,
    /// Gap tolerance as a fraction of the mean block height.
    pub max_gap_frac: f64,
    /// Gap tolerance in pixels.
    pub gap_slack_px: f64,
    /// Vertical centroid tolerance as a fraction of the mean block height.
    pub max_vertical_frac: f64,
    /// Largest ratio of the taller block's height to the shorter's (≥ 1). The blocks are
    /// equally tall on the flap; perspective alone makes the nearer one at most 1.35×
    /// taller anywhere in the approach zone (0.33 m, 70° off the axis, the 0.18 m flap).
    pub max_height_ratio: f64,
    /// Smallest ratio of the smaller block's pixel count to the larger's, in [0, 1]. The
    /// blocks are equal on the flap; perspective and foreshortening make the smaller at
    /// least 0.45 of the larger anywhere in the approach zone, a block half lost to a
    /// shadow about 0.22.
    pub min_count_ratio: f64,
    /// Largest number of components per colour paired.
    pub max_candidates: usize,
}

/// One accepted block.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Block {
    /// Component index in its colour's labelling.
    pub component: u32,
    /// Pixel count.
    pub count: u64,
    /// Centroid (x, y), px.
    pub centroid: [f64; 2],
    /// Bounding box (x_min, y_min, x_max, y_max), inclusive, px.
    pub bbox: [u32; 4],
}

/// The accepted pair.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Pair {
    /// Block on the image's left.
    pub left: Block,
    /// Block on the image's right.
    pub right: Block,
    /// min(count)/max(count), in (0, 1].
    pub ratio: f64,
}

/// Segments, labels and pairs; owns all scratch buffers.
///
/// # Example
///
/// A 16×8 grey frame with a 4×4 cyan block at x = 4…7 and a 4×4 magenta block right of
/// it at x = 8…11 (rows 2…5): the pair is found with both blocks' counts, centroids and
/// boxes; the same blocks in the other order (the fiducial upside down) are rejected.
///
/// ```
/// use marsupial::perception::{PairLimits, RgbImage, Sct, SctRange, TwoBlockDetector};
///
/// let (cyan, magenta) = ([20, 190, 210], [200, 30, 190]);
/// let frame = |left: [u8; 3], right: [u8; 3]| {
///     let mut im = RgbImage::new(16, 8);
///     im.fill([110, 105, 100]);
///     for y in 2..6 {
///         (4..8).for_each(|x| im.put(x, y, left));
///         (8..12).for_each(|x| im.put(x, y, right));
///     }
///     im
/// };
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
///
/// let im = frame(cyan, magenta);
/// let pair = det.detect(&im.view(), &ranges).unwrap().expect("found");
/// assert_eq!((pair.left.count, pair.right.count, pair.ratio), (16, 16, 1.0));
/// assert_eq!(pair.left.centroid, [5.5, 3.5]);
/// assert_eq!(pair.right.bbox, [8, 2, 11, 5]);
/// assert_eq!(det.masks()[0].count(), 16);
/// // The accepted blocks' colour statistics, for adaptation (fast SCT: within 0.002 rad).
/// let [l, r] = det.measure(&im.view(), &pair).unwrap();
/// assert!((l.mean_b - Sct::from_rgb(cyan).b).abs() < 0.002 && l.sd_b == 0.0);
/// assert!((r.mean_b - Sct::from_rgb(magenta).b).abs() < 0.002);
///
/// let upside_down = frame(magenta, cyan);
/// assert_eq!(det.detect(&upside_down.view(), &ranges).unwrap(), None);
/// ```
#[derive(Debug, Clone)]
pub struct TwoBlockDetector {
    width: usize,
    height: usize,
    limits: PairLimits,
    segmenter: Segmenter,
    masks: [Mask; 2],
    labelers: [Labeler; 2],
    candidates: [Vec<u32>; 2],
}

impl TwoBlockDetector {
    /// A detector for `width × height` frames; every buffer is allocated here.
    pub fn new(width: usize, height: usize, limits: PairLimits) -> Self {
        let max_cand = width * height / (limits.min_component_px.max(1) as usize) + 1;
        Self {
            width,
            height,
            limits,
            segmenter: Segmenter::new(),
            masks: [Mask::new(width, height), Mask::new(width, height)],
            labelers: [Labeler::new(width, height), Labeler::new(width, height)],
            candidates: [Vec::with_capacity(max_cand), Vec::with_capacity(max_cand)],
        }
    }

    /// (width, height) the detector is sized for.
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// Re-sizes for another frame size (allocates; not for the per-frame path).
    pub fn resize(&mut self, width: usize, height: usize) {
        if (width, height) != (self.width, self.height) {
            *self = Self::new(width, height, self.limits);
        }
    }

    /// The pairing limits.
    pub fn limits(&self) -> &PairLimits {
        &self.limits
    }

    /// The masks of the last frame (left colour, right colour).
    pub fn masks(&self) -> &[Mask; 2] {
        &self.masks
    }

    /// The labeller of colour `i` (0 left, 1 right) after the last frame.
    pub fn labeler(&self, i: usize) -> &Labeler {
        &self.labelers[i.min(1)]
    }

    /// Finds the fiducial in `view` with `ranges` (left colour, right colour).
    ///
    /// # Errors
    /// [`VisionError::EmptyImage`] for a frame with no pixel; [`VisionError::SizeMismatch`]
    /// when the frame is not the detector's size.
    pub fn detect(&mut self, view: &RgbView<'_>, ranges: &[SctRange; 2]) -> Result<Option<Pair>, VisionError> {
        if view.is_empty() {
            return Err(VisionError::EmptyImage);
        }
        check_same_size((self.width, self.height), (view.width(), view.height()))?;
        let cr = [ColorRange::Sct(ranges[0]), ColorRange::Sct(ranges[1])];
        self.segmenter.segment(view, &cr, &mut self.masks)?;
        for c in 0..2 {
            let comps = self.labelers[c].label(&self.masks[c])?;
            let cand = &mut self.candidates[c];
            cand.clear();
            cand.extend(
                comps
                    .iter()
                    .enumerate()
                    .filter(|(_, k)| k.count >= self.limits.min_component_px)
                    .map(|(i, _)| i as u32),
            );
            if cand.len() > self.limits.max_candidates {
                cand.sort_unstable_by(|&a, &b| comps[b as usize].count.cmp(&comps[a as usize].count).then(a.cmp(&b)));
                cand.truncate(self.limits.max_candidates);
                cand.sort_unstable();
            }
        }
        let (lc, rc) = (self.labelers[0].components(), self.labelers[1].components());
        let lim = self.limits;
        let mut best: Option<(f64, u64, Pair)> = None;
        for &li in &self.candidates[0] {
            let l = &lc[li as usize];
            let (lx, ly) = l.centroid();
            for &ri in &self.candidates[1] {
                let r = &rc[ri as usize];
                let (rx, ry) = r.centroid();
                if lx >= rx {
                    continue;
                }
                let h = (l.height() + r.height()) as f64 / 2.0;
                let gap = r.bbox[0] as f64 - l.bbox[2] as f64;
                if (gap - 1.0).abs() > lim.gap_slack_px + lim.max_gap_frac * h {
                    continue;
                }
                if (ly - ry).abs() > lim.max_vertical_frac * h {
                    continue;
                }
                let (hl, hr) = (l.height() as f64, r.height() as f64);
                if hl.max(hr) > lim.max_height_ratio * hl.min(hr) {
                    continue;
                }
                let ratio = count_ratio(l.count, r.count);
                if ratio < lim.min_count_ratio {
                    continue;
                }
                let total = l.count + r.count;
                let better = match &best {
                    None => true,
                    Some((br, bt, _)) => (1.0 - ratio) < (1.0 - br) || ((1.0 - ratio) == (1.0 - br) && total > *bt),
                };
                if better {
                    let block = |i: u32, k: &super::components::Component, (x, y): (f64, f64)| Block {
                        component: i,
                        count: k.count,
                        centroid: [x, y],
                        bbox: k.bbox,
                    };
                    best = Some((
                        ratio,
                        total,
                        Pair {
                            left: block(li, l, (lx, ly)),
                            right: block(ri, r, (rx, ry)),
                            ratio,
                        },
                    ));
                }
            }
        }
        Ok(best.map(|(_, _, p)| self.without_spurs(p)))
    }

    /// `pair` with each block's spurs taken out of its count and the ratio recomputed:
    /// noise pixels touching a solid block are not paint (`spurs`). A block whose spurs
    /// are more than [`MAX_SPUR_SHARE`] of its pixels is not solid but ragged, and its
    /// spurs are its own paint: its count stays as detected. The blocks' boxes and
    /// centroids, and the pairing that chose them, are left as detected.
    fn without_spurs(&self, mut pair: Pair) -> Pair {
        for (c, block) in [&mut pair.left, &mut pair.right].into_iter().enumerate() {
            let runs = self.labelers[c].runs().iter().filter(|r| r.label == block.component);
            let spurs = spur_count(&self.masks[c], runs);
            if (spurs as f64) <= MAX_SPUR_SHARE * block.count as f64 {
                block.count = block.count.saturating_sub(spurs).max(1);
            }
        }
        pair.ratio = count_ratio(pair.left.count, pair.right.count);
        pair
    }

    /// SCT statistics of the pixels of each accepted block (fast SCT path), for
    /// adaptation. `view` must be the frame `pair` was detected in. Blocks larger than
    /// [`MAX_ADAPT_SAMPLES`] pixels are sampled at a fixed stride (every k-th pixel in raster
    /// order), which keeps the cost bounded near the dock; the estimates of a few thousand
    /// samples are within a few percent of the full-block ones.
    pub fn measure(&self, view: &RgbView<'_>, pair: &Pair) -> Option<[AngleStats; 2]> {
        let mut acc = [StatsAccumulator::default(); 2];
        let bytes = view.as_bytes();
        let w = view.width();
        for (c, block) in [pair.left, pair.right].iter().enumerate() {
            // The component's whole count, spurs included: those are the pixels sampled.
            let pixels = self.labelers[c]
                .components()
                .get(block.component as usize)
                .map_or(block.count, |k| k.count);
            let stride = pixels.div_ceil(MAX_ADAPT_SAMPLES).max(1) as usize;
            let mut k = 0usize;
            for run in self.labelers[c].runs().iter().filter(|r| r.label == block.component) {
                let row = run.y as usize * w;
                let len = (run.x1 - run.x0) as usize;
                // First sampled column of this run, continuing the stride across runs.
                let mut x = run.x0 as usize + (stride - k % stride) % stride;
                k += len;
                while x < run.x1 as usize {
                    let i = (row + x) * 3;
                    if let Some(px) = bytes.get(i..i + 3) {
                        let (_, a, b) = Sct::from_rgb_fast([px[0], px[1], px[2]]);
                        acc[c].push(a as f64, b as f64);
                    }
                    x += stride;
                }
            }
        }
        Some([acc[0].finish()?, acc[1].finish()?])
    }
}

/// Largest number of pixels per block sampled for adaptation.
pub const MAX_ADAPT_SAMPLES: u64 = 2048;

/// What the two-block perceptual schema reports each frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TwoBlockPercept {
    /// Capture time of the frame, s.
    pub stamp: f64,
    /// A valid pair was found.
    pub found: bool,
    /// Pixels of the image-left block.
    pub left_px: u64,
    /// Pixels of the image-right block.
    pub right_px: u64,
    /// left_px + right_px.
    pub total_px: u64,
    /// min/max of the two counts in [0, 1] (0 when not found).
    pub ratio: f64,
    /// Centroid of the image-left block (x, y), px.
    pub left_centroid: [f64; 2],
    /// Centroid of the image-right block (x, y), px.
    pub right_centroid: [f64; 2],
    /// Horizontal offset of the pair's midpoint from the image centre, px (positive:
    /// right of centre in the image as delivered, i.e. after any 180° flip).
    pub offset_px: f64,
    /// Bounding box of the image-left block (x_min, y_min, x_max, y_max), px.
    pub left_bbox: [u32; 4],
    /// Bounding box of the image-right block, px.
    pub right_bbox: [u32; 4],
    /// Statistics that segmented this frame.
    pub mode: ColorMode,
    /// Frame size (width, height).
    pub image_size: (usize, usize),
}

impl TwoBlockPercept {
    /// A "not found" percept.
    pub fn not_found(stamp: f64, mode: ColorMode, image_size: (usize, usize)) -> Self {
        Self {
            stamp,
            found: false,
            left_px: 0,
            right_px: 0,
            total_px: 0,
            ratio: 0.0,
            left_centroid: [0.0; 2],
            right_centroid: [0.0; 2],
            offset_px: 0.0,
            left_bbox: [0; 4],
            right_bbox: [0; 4],
            mode,
            image_size,
        }
    }
}

/// Everything a [`TwoBlockTracker`] needs, in plain numbers. A profile gives them through
/// `TwoBlockParams::from_profile` (in `profile`); an embedder without profiles fills
/// them in directly.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TwoBlockParams {
    /// Frame width, px.
    pub width: usize,
    /// Frame height, px.
    pub height: usize,
    /// Nominal sRGB paint of the block on the image's left, then on its right, as this
    /// camera delivers the image (a 180°-rolled camera swaps the fiducial's sides): the
    /// table defaults of the colour model.
    pub colours: [[u8; 3]; 2],
    /// SD of the table defaults on both SCT angles, rad.
    pub table_sd: f64,
    /// Pairing limits.
    pub limits: PairLimits,
    /// Colour model tuning; its `adaptive` flag is replaced by `mode == Adaptive`.
    pub colour: ColorModelParams,
    /// Adaptive, static or fixed segmentation (fixed installs no imprint).
    pub mode: SegmentationMode,
    /// Where the image-left and image-right blocks appear as the robot leaves the dock:
    /// (x0, y0, x1, y1) as fractions of the frame's width and height.
    pub imprint_rects: [[f64; 4]; 2],
    /// Fraction of each imprint rectangle (per side, centred) that is sampled, in (0, 1].
    pub imprint_sample_frac: f64,
    /// Frames to imprint on.
    pub imprint_frames: u32,
    /// Compensation of fast colour casts before segmentation ([`CastCompensator`]).
    pub cast: CastParams,
}

/// Bujold's close-dock perception for one camera: detector + colour model (+ imprinting).
/// Allocates only in [`TwoBlockTracker::new`].
///
/// # Example
///
/// The frame of [`TwoBlockDetector`]'s example (4×4 cyan and magenta blocks side by side
/// in a 16×8 frame): imprint on it as on departure, track it, then lose the camera.
///
/// ```
/// use marsupial::perception::{
///     CastParams, ColorMode, ColorModelParams, PairLimits, RgbImage, SegmentationMode, TwoBlockParams, TwoBlockTracker,
/// };
///
/// let (cyan, magenta) = ([20, 190, 210], [200, 30, 190]);
/// let mut im = RgbImage::new(16, 8);
/// im.fill([110, 105, 100]);
/// for y in 2..6 {
///     (4..8).for_each(|x| im.put(x, y, cyan));
///     (8..12).for_each(|x| im.put(x, y, magenta));
/// }
/// let params = TwoBlockParams {
///     width: 16,
///     height: 8,
///     colours: [cyan, magenta],
///     table_sd: 0.05,
///     limits: PairLimits {
///         min_component_px: 8,
///         max_gap_frac: 0.5,
///         gap_slack_px: 3.0,
///         max_vertical_frac: 0.5,
///         max_height_ratio: 2.0,
///         min_count_ratio: 0.2,
///         max_candidates: 8,
///     },
///     colour: ColorModelParams {
///         n_sd: 4.0,
///         sd_floor: 0.01,
///         sd_ceiling: 0.2,
///         min_l: 20.0,
///         min_chroma: 0.05,
///         timeout1: 2.0,
///         timeout2: 5.0,
///         adaptive: true,
///         adapt_rate: 1.0,
///     },
///     mode: SegmentationMode::Adaptive,
///     // Exactly the two blocks, sampled whole.
///     imprint_rects: [[0.25, 0.25, 0.5, 0.75], [0.5, 0.25, 0.75, 0.75]],
///     imprint_sample_frac: 1.0,
///     imprint_frames: 1,
///     cast: CastParams::OFF,
/// };
/// let mut t = TwoBlockTracker::new(&params);
/// assert_eq!(t.model().mode(), ColorMode::Table);
/// t.imprint_frame(&im.view());
/// assert!(t.finish_imprint(0.0));
/// assert_eq!(t.model().mode(), ColorMode::Imprinted);
///
/// let p = t.process(&im.view(), 0.1).unwrap();
/// assert!(p.found);
/// assert_eq!((p.left_px, p.right_px, p.total_px), (16, 16, 32));
/// // Pair midpoint (5.5 + 9.5)/2 = 7.5: half a pixel left of the image centre.
/// assert_eq!(p.offset_px, -0.5);
/// assert_eq!(p.mode, ColorMode::Imprinted); // what segmented this frame…
/// assert_eq!(t.model().mode(), ColorMode::Adapted); // …and the next adapts to it
///
/// // The camera falls silent: 2.4 s without the fiducial exceeds timeout 1.
/// assert!(!t.no_frame(2.5).found);
/// assert_eq!(t.model().mode(), ColorMode::Imprinted);
/// ```
#[derive(Debug, Clone)]
pub struct TwoBlockTracker {
    detector: TwoBlockDetector,
    model: ColorModel,
    imprinter: Imprinter,
    imprint_frames: u32,
    /// `fixed` segmentation: imprints are not installed.
    fixed: bool,
    last_pair: Option<Pair>,
    cast: CastCompensator,
}

impl TwoBlockTracker {
    /// Builds the tracker; the colour model starts on the table defaults of `p.colours`.
    pub fn new(p: &TwoBlockParams) -> Self {
        let table = p.colours.map(|rgb| AngleStats::nominal(rgb, p.table_sd));
        let params = ColorModelParams {
            adaptive: p.mode == SegmentationMode::Adaptive,
            ..p.colour
        };
        Self {
            detector: TwoBlockDetector::new(p.width, p.height, p.limits),
            model: ColorModel::new(table, params),
            imprinter: Imprinter::new(p.imprint_rects, p.imprint_sample_frac, params.min_l, params.min_chroma),
            imprint_frames: p.imprint_frames,
            fixed: p.mode == SegmentationMode::Fixed,
            last_pair: None,
            cast: CastCompensator::new(p.cast, p.width, p.height),
        }
    }

    /// The colour model.
    pub fn model(&self) -> &ColorModel {
        &self.model
    }

    /// The colour model, mutable (e.g. to switch static/adaptive).
    pub fn model_mut(&mut self) -> &mut ColorModel {
        &mut self.model
    }

    /// The detector (masks and components of the last frame).
    pub fn detector(&self) -> &TwoBlockDetector {
        &self.detector
    }

    /// The detector, mutable (e.g. to resize for a differently sized image file).
    pub fn detector_mut(&mut self) -> &mut TwoBlockDetector {
        &mut self.detector
    }

    /// The colour-cast compensator (its gains show what the last frame was corrected by).
    pub fn cast(&self) -> &CastCompensator {
        &self.cast
    }

    /// The pair accepted in the last frame.
    pub fn last_pair(&self) -> Option<&Pair> {
        self.last_pair.as_ref()
    }

    /// Frames to imprint on (`imprint_frames` of the params).
    pub fn imprint_frames_wanted(&self) -> u32 {
        self.imprint_frames
    }

    /// Samples one well-aligned frame for imprinting.
    /// The frame is corrected with the cast gains of the last processed frame.
    pub fn imprint_frame(&mut self, view: &RgbView<'_>) {
        let view = self.cast.reapply(*view);
        self.imprinter.add_frame(&view);
    }

    /// Installs the imprint gathered so far; false (and no change) when too few bright
    /// pixels were sampled or the segmentation mode is `fixed` (table values only).
    /// Resets the imprinter for the next departure.
    pub fn finish_imprint(&mut self, now: f64) -> bool {
        let done = self.imprinter.finish().filter(|_| !self.fixed);
        self.imprinter.clear();
        match done {
            Some(stats) => {
                tracing::debug!(
                    target: "marsupial::perception",
                    now,
                    left_a_deg = stats[0].mean_a.to_degrees(),
                    left_b_deg = stats[0].mean_b.to_degrees(),
                    left_sd_deg = stats[0].sd_a.max(stats[0].sd_b).to_degrees(),
                    right_a_deg = stats[1].mean_a.to_degrees(),
                    right_b_deg = stats[1].mean_b.to_degrees(),
                    right_sd_deg = stats[1].sd_a.max(stats[1].sd_b).to_degrees(),
                    "imprinted"
                );
                self.model.imprint(stats, now);
                true
            }
            None => false,
        }
    }

    /// No frame arrived by `now` (the camera is silent): the colour model counts it
    /// toward its timeouts, and the percept is "not found" at the detector's size.
    pub fn no_frame(&mut self, now: f64) -> TwoBlockPercept {
        self.model.update(now, None);
        TwoBlockPercept::not_found(now, self.model.mode(), self.detector.size())
    }

    /// Runs the tracker on one frame taken at `stamp`: compensate a fast colour cast
    /// ([`CastCompensator`]), detect with the current ranges, adapt, and report.
    ///
    /// # Errors
    /// As [`TwoBlockDetector::detect`].
    pub fn process(&mut self, view: &RgbView<'_>, stamp: f64) -> Result<TwoBlockPercept, VisionError> {
        let mode = self.model.mode();
        let ranges = self.model.ranges();
        let size = (view.width(), view.height());
        let view = &self.cast.correct(*view, stamp);
        let pair = self.detector.detect(view, &ranges)?;
        self.last_pair = pair;
        let Some(pair) = pair else {
            self.model.update(stamp, None);
            return Ok(TwoBlockPercept::not_found(stamp, mode, size));
        };
        let measured = self.detector.measure(view, &pair);
        self.model.update(stamp, measured);
        let mid = (pair.left.centroid[0] + pair.right.centroid[0]) / 2.0;
        Ok(TwoBlockPercept {
            stamp,
            found: true,
            left_px: pair.left.count,
            right_px: pair.right.count,
            total_px: pair.left.count + pair.right.count,
            ratio: pair.ratio,
            left_centroid: pair.left.centroid,
            right_centroid: pair.right.centroid,
            offset_px: mid - size.0 as f64 / 2.0,
            left_bbox: pair.left.bbox,
            right_bbox: pair.right.bbox,
            mode,
            image_size: size,
        })
    }
}
