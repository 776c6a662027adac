//! The pyramid tracker: detector, geometry and the HSV colour model for one camera's
//! frames (`schemas::PyramidSchema` runs it on a tick's inputs).
//!
//! The paper segments with HSV bands an operator tunes, and retunes live when the light
//! changes (seed 001 §II.D); its future work is to replace that operator with the
//! imprint/adapt method of seed 004. Both are here, chosen by `perception.mode`:
//!
//! * **fixed**: the table bands, changed only through [`PyramidTracker::set_bands`]
//!   (the paper's method);
//! * **static**: on departure the robot imprints the bands from the pyramid it is
//!   leaving, and keeps them;
//! * **adaptive**: imprint, then every frame with a pair re-measures both colours from
//!   the accepted blobs and moves the bands toward them; the fallback chain of seed 004
//!   Fig. 5 (adapted → imprinted → table on timeouts) recovers from drift.
//!
//! **Imprinting** happens where the geometry is known: the departing robot stops with the
//! pyramid straight behind at `imprint_distance_m`. The detector runs with the table bands
//! widened by `imprint_widen` (hue and value; saturation kept), and a pair is sampled only
//! when its reading agrees with the known pose (|α| and bearing under 12°, ball distance
//! within 35 %), so a wrong blob elsewhere cannot be imprinted. **Sampling** takes, for
//! the ball, the segmented pixels inside 0.8 of the fitted ellipse (the middle, as seed
//! 004 samples "the middle of each block"), and for the blue edges the segmented pixels
//! of the region's box outside the ellipse. HSV statistics and bands are in [`HsvStats`].

use super::colour_model::{ColorMode, ColorModel, ColorModelParams, SegmentationMode};
use super::hsv::Hsv;
use super::hsv_stats::{HsvAccumulator, HsvLimits, HsvStats, hue_band};
use super::image::RgbView;
use super::pyramid::{PyramidDetector, PyramidPair, PyramidParams};
use super::pyramid_pose::{PyramidGeometry, PyramidPercept};
use super::segment::{HsvRange, Mask};
use super::{VisionError, check_same_size};

/// Largest |α| and |bearing| of a pair accepted for imprinting, rad (12°).
const IMPRINT_ANGLE: f64 = 0.21;
/// Largest relative error of the ball distance of a pair accepted for imprinting.
const IMPRINT_DISTANCE_ERROR: f64 = 0.35;
/// Fewest pixels per colour for statistics.
const MIN_SAMPLES: u64 = 10;

/// Everything a [`PyramidTracker`] needs, in plain numbers. A profile gives them through
/// `PyramidTrackerParams::from_profile` (in `profile`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PyramidTrackerParams {
    /// Frame width, px.
    pub width: usize,
    /// Frame height, px.
    pub height: usize,
    /// The detector's table bands and filters.
    pub detector: PyramidParams,
    /// Camera and pyramid constants.
    pub geometry: PyramidGeometry,
    /// Fixed (table bands only), static (imprint) or adaptive (imprint and adapt).
    pub mode: SegmentationMode,
    /// Fallback-chain timing and blend rate (its `adaptive` flag is replaced by
    /// `mode == Adaptive`; the SCT fields are unused here).
    pub colour: ColorModelParams,
    /// How learned statistics become bands.
    pub limits: HsvLimits,
    /// Camera-to-ball distance at which the departing robot imprints, m.
    pub imprint_distance_m: f64,
    /// The imprint finds the pyramid with the table bands widened by this factor (≥ 1).
    pub imprint_widen: f64,
    /// Frames to imprint on.
    pub imprint_frames: u32,
}

/// RAPOSA's pyramid perception for one camera. Allocates only in [`PyramidTracker::new`].
///
/// # Example
///
/// The scene of [`PyramidDetector`]'s example (a 16 px blue frame around an orange disc
/// of radius 5 in a 40×30 frame) seen by a camera with f = 160 px, in fixed mode: the
/// 10 cm blue edges are 160·0.1/16 = 1 m away. Retuning the orange band to green, as the
/// paper's operator might, loses the ball.
///
/// ```
/// use marsupial::perception::{
///     ColorModelParams, HsvLimits, HsvRange, PyramidGeometry, PyramidParams, PyramidTracker,
///     PyramidTrackerParams, RgbImage, SegmentationMode,
/// };
///
/// let mut im = RgbImage::new(40, 30);
/// im.fill([120, 118, 115]);
/// for y in 6..22 {
///     for x in 10..26 {
///         if (x as f64 - 18.0).hypot(y as f64 - 14.0) <= 5.0 {
///             im.put(x, y, [235, 120, 20]);
///         } else if x < 12 || x >= 24 || y < 8 || y >= 20 {
///             im.put(x, y, [20, 60, 220]);
///         }
///     }
/// }
/// let params = PyramidTrackerParams {
///     width: 40,
///     height: 30,
///     detector: PyramidParams::default(),
///     geometry: PyramidGeometry { f_px: 160.0, principal: [20.0, 15.0], h: 0.1, m: 0.16, ball_diameter: 0.07 },
///     mode: SegmentationMode::Fixed,
///     colour: ColorModelParams {
///         n_sd: 4.0,
///         sd_floor: 0.01,
///         sd_ceiling: 0.2,
///         min_l: 20.0,
///         min_chroma: 0.0,
///         timeout1: 2.0,
///         timeout2: 5.0,
///         adaptive: false,
///         adapt_rate: 1.0,
///     },
///     limits: HsvLimits { n_sd: 4.0, hue_sd_deg: [1.0, 20.0], sv_sd: [0.01, 0.1], min_s: 0.2, min_v: 0.05 },
///     imprint_distance_m: 1.0,
///     imprint_widen: 1.5,
///     imprint_frames: 3,
/// };
/// let mut t = PyramidTracker::new(&params);
/// let p = t.process(&im.view(), 0.1).unwrap();
/// let v = p.view.expect("ball seen");
/// assert!(p.detection.pair.is_some());
/// assert!((v.blue_distance_m.unwrap() - 1.0).abs() < 1e-9);
/// // The ball is half a pixel right of the blue centre: a small negative α.
/// assert!(v.alpha.unwrap() < 0.0 && v.alpha.unwrap() > -0.1);
/// assert_eq!(t.bands()[0], PyramidParams::default().orange, "fixed: the table bands");
///
/// let green = HsvRange { h: [100.0, 140.0], s: [0.4, 1.0], v: [0.2, 1.0] };
/// t.set_bands(green, t.bands()[1]);
/// assert!(t.process(&im.view(), 0.2).unwrap().view.is_none());
/// ```
#[derive(Debug, Clone)]
pub struct PyramidTracker {
    detector: PyramidDetector,
    geometry: PyramidGeometry,
    mode: SegmentationMode,
    table: [HsvRange; 2],
    model: ColorModel<[HsvStats; 2]>,
    limits: HsvLimits,
    imprint_distance: f64,
    imprint_widen: f64,
    imprint_frames: u32,
    imprint_acc: [HsvAccumulator; 2],
    imprinted_frames: u32,
}

impl PyramidTracker {
    /// Builds the tracker; the colour model starts on the detector's table bands.
    pub fn new(p: &PyramidTrackerParams) -> Self {
        let table = [p.detector.orange, p.detector.blue];
        let params = ColorModelParams {
            adaptive: p.mode == SegmentationMode::Adaptive,
            ..p.colour
        };
        Self {
            detector: PyramidDetector::new(p.width, p.height, &p.detector, p.geometry.shape()),
            geometry: p.geometry,
            mode: p.mode,
            table,
            model: ColorModel::new(table.map(|b| HsvStats::from_band(&b, p.limits.n_sd)), params),
            limits: p.limits,
            imprint_distance: p.imprint_distance_m,
            imprint_widen: p.imprint_widen,
            imprint_frames: p.imprint_frames,
            imprint_acc: [HsvAccumulator::default(); 2],
            imprinted_frames: 0,
        }
    }

    /// The geometry constants.
    pub fn geometry(&self) -> &PyramidGeometry {
        &self.geometry
    }

    /// The detector (masks, tracking state).
    pub fn detector(&self) -> &PyramidDetector {
        &self.detector
    }

    /// The colour model (mode, imprinted and adapted statistics).
    pub fn model(&self) -> &ColorModel<[HsvStats; 2]> {
        &self.model
    }

    /// The segmentation mode.
    pub fn mode(&self) -> SegmentationMode {
        self.mode
    }

    /// The (orange, blue) bands the next frame is segmented with.
    pub fn bands(&self) -> [HsvRange; 2] {
        match self.model.mode() {
            ColorMode::Table => self.table,
            _ => self.model.current().map(|s| s.band(&self.limits)),
        }
    }

    /// Retunes the (orange, blue) table bands from the next frame on, as the paper's
    /// operator does; forgets any imprint and adaptation.
    pub fn set_bands(&mut self, orange: HsvRange, blue: HsvRange) {
        self.table = [orange, blue];
        let n = self.limits.n_sd;
        self.model = ColorModel::new(self.table.map(|b| HsvStats::from_band(&b, n)), *self.model.params());
    }

    /// Forgets the tracked ellipse (after the robot moved blind).
    pub fn reset_tracking(&mut self) {
        self.detector.reset_tracking();
    }

    /// No frame arrived by `now` (the camera is silent): the colour model counts it
    /// toward its timeouts, and the percept is "nothing seen" at the detector's size.
    pub fn no_frame(&mut self, now: f64) -> PyramidPercept {
        self.model.update(now, None);
        PyramidPercept::not_found(now, self.detector.size())
    }

    /// Tells the colour model whether the robot expects the pyramid in view
    /// ([`ColorModel::set_looking`]): turning away must not discard a good imprint.
    pub fn set_looking(&mut self, looking: bool, now: f64) {
        self.model.set_looking(looking, now);
    }

    /// Camera-to-ball distance at which the departing robot should imprint, m.
    pub fn imprint_distance(&self) -> f64 {
        self.imprint_distance
    }

    /// Frames to imprint on (`imprint_frames` of the params).
    pub fn imprint_frames_wanted(&self) -> u32 {
        self.imprint_frames
    }

    /// Samples one departure frame, taken with the pyramid straight behind at
    /// [`imprint_distance`](Self::imprint_distance). Returns whether the frame held a pair
    /// where the geometry says and was sampled.
    ///
    /// # Errors
    /// [`VisionError::SizeMismatch`] for a frame of the wrong size.
    pub fn imprint_frame(&mut self, view: &RgbView<'_>) -> Result<bool, VisionError> {
        let [o, b] = self.table.map(|r| widen(&r, self.imprint_widen));
        self.detector.set_bands(o, b);
        let det = self.detector.detect(view);
        self.detector.reset_tracking();
        let det = det?;
        let Some((pair, v)) = det.pair.zip(self.geometry.view(&det)) else {
            return Ok(false);
        };
        let agrees = v.alpha.is_some_and(|a| a.abs() <= IMPRINT_ANGLE)
            && v.bearing.abs() <= IMPRINT_ANGLE
            && (v.ball_distance_m / self.imprint_distance - 1.0).abs() <= IMPRINT_DISTANCE_ERROR;
        if agrees {
            sample_pair(view, &pair, self.detector.masks(), &mut self.imprint_acc);
            self.imprinted_frames += 1;
        }
        Ok(agrees)
    }

    /// Installs the imprint gathered so far and switches to it; false (and no change)
    /// when no frame was sampled, either colour gave under 10 pixels, or the mode is
    /// `fixed`. Resets the imprint for the next departure.
    pub fn finish_imprint(&mut self, now: f64) -> bool {
        let stats = finish_both(&self.imprint_acc).filter(|_| self.imprinted_frames > 0);
        self.imprint_acc.iter_mut().for_each(HsvAccumulator::clear);
        self.imprinted_frames = 0;
        match stats {
            Some(s) if self.mode != SegmentationMode::Fixed => {
                tracing::info!(
                    target: "marsupial::perception",
                    orange = ?s[0],
                    blue = ?s[1],
                    "pyramid colours imprinted"
                );
                self.model.imprint(s, now);
                true
            }
            _ => false,
        }
    }

    /// Processes one frame: segment with the current bands, detect, adapt.
    ///
    /// # Errors
    /// [`VisionError::SizeMismatch`] for a frame of the wrong size.
    pub fn process(&mut self, view: &RgbView<'_>, stamp: f64) -> Result<PyramidPercept, VisionError> {
        check_same_size(self.detector.size(), (view.width(), view.height()))?;
        let [o, b] = self.bands();
        self.detector.set_bands(o, b);
        let detection = self.detector.detect(view)?;
        let measured = match (&detection.pair, self.mode) {
            (Some(pair), SegmentationMode::Adaptive) => {
                let mut acc = [HsvAccumulator::default(); 2];
                sample_pair(view, pair, self.detector.masks(), &mut acc);
                finish_both(&acc)
            }
            _ => None,
        };
        match (&detection.pair, measured) {
            (_, Some(m)) => self.model.update(stamp, Some(m)),
            // A pair too small to measure still counts as seen for the timeouts.
            (Some(_), None) => self.model.restart_clock(stamp),
            (None, _) => self.model.update(stamp, None),
        }
        Ok(PyramidPercept {
            stamp,
            detection,
            view: self.geometry.view(&detection),
            image_size: self.detector.size(),
        })
    }
}

/// Both colours' statistics, when each has at least [`MIN_SAMPLES`] pixels.
fn finish_both(acc: &[HsvAccumulator; 2]) -> Option<[HsvStats; 2]> {
    let [o, b] = [acc[0].finish()?, acc[1].finish()?];
    (o.n >= MIN_SAMPLES && b.n >= MIN_SAMPLES).then_some([o, b])
}

/// `band` with its hue half-width multiplied and its V lower bound divided by `factor`
/// (hue capped at the whole circle). Saturation is kept: it is what separates paint from
/// a scene a coloured light tints (grey ground under dusk light and a daylight white
/// balance reaches S ≈ 0.35 at an orange hue).
fn widen(band: &HsvRange, factor: f64) -> HsvRange {
    // With one SD per half-width, the statistics' hue SD is the band's half-width.
    let hue = HsvStats::from_band(band, 1.0);
    HsvRange {
        h: hue_band(hue.mean_h_deg, hue.sd_h_deg * factor),
        s: band.s,
        v: [band.v[0] / factor as f32, band.v[1]],
    }
}

/// Adds the pair's pixels to `acc`: (orange) segmented pixels inside 0.8 of the ellipse;
/// (blue) segmented pixels of the blue box outside the ellipse.
fn sample_pair(view: &RgbView<'_>, pair: &PyramidPair, masks: &[Mask; 2], acc: &mut [HsvAccumulator; 2]) {
    let e = &pair.ellipse;
    let (c, s) = (e.angle.cos(), e.angle.sin());
    let inside = |x: usize, y: usize, scale: f64| {
        let (dx, dy) = (x as f64 - e.centre[0], y as f64 - e.centre[1]);
        let (u, v) = (dx * c + dy * s, -dx * s + dy * c);
        let (a, b) = ((e.semi_major * scale).max(0.5), (e.semi_minor * scale).max(0.5));
        (u / a).powi(2) + (v / b).powi(2) <= 1.0
    };
    let mut add = |k: usize, bbox: [u32; 4], keep: &dyn Fn(usize, usize) -> bool| {
        for y in bbox[1] as usize..=bbox[3] as usize {
            for x in bbox[0] as usize..=bbox[2] as usize {
                if masks[k].get(x, y)
                    && keep(x, y)
                    && let Some(px) = view.get(x, y)
                {
                    acc[k].push(&Hsv::from_rgb(px));
                }
            }
        }
    };
    add(0, e.bbox, &|x, y| inside(x, y, 0.8));
    add(1, pair.blue.bbox, &|x, y| !inside(x, y, 1.0));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn widen_scales_hue_and_lower_bounds() {
        let b = HsvRange {
            h: [200.0, 250.0],
            s: [0.4, 1.0],
            v: [0.12, 1.0],
        };
        let w = widen(&b, 2.0);
        assert_eq!(w.h, [175.0, 275.0]);
        assert_eq!(w.s, b.s);
        assert!((w.v[0] - 0.06).abs() < 1e-6);
        let red = widen(&HsvRange { h: [350.0, 30.0], ..b }, 2.0);
        assert_eq!(red.h, [330.0, 50.0]);
        assert_eq!(widen(&b, 10.0).h, [0.0, 360.0]);
        assert_eq!(widen(&b, 1.0), b);
    }
}
