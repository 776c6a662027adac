//! Where RAPOSA's memory gets its percept: the perception source the profile's
//! `[fiducial]` kind selects.
//!
//! * `pyramid` fiducial: the [pyramid perceptual schema](PyramidSchema) (seed 001), as
//!   RAPOSA runs it.
//! * `two_block` fiducial: Bujold's [two-block schema](TwoBlockSchema) (seed 004)
//!   through [`TwoBlockCues`], which reports what the seven states read in the same
//!   [`PyramidPercept`] the pyramid schema fills.
//!
//! **Which of RAPOSA's cues a two-block flap gives.** The states read the percept's
//! [`PyramidView`] (and state 4 the raw blue region). [`TwoBlockCues`] fills the view from
//! the two-block pair ([`FiducialView`]):
//!
//! | RAPOSA cue (pyramid) | two-block equivalent |
//! |---|---|
//! | target seen (an ellipse) | a pair accepted (both blocks, aligned, gap within limits) |
//! | `dev_px` (ellipse centre − image centre) | the pair's midpoint, as −f·tan(bearing), so its sign means what it means on RAPOSA's upright camera whatever the mount (Bujold's is rolled 180°); `dev_px[1]` the blocks' mean centroid row as delivered |
//! | `bearing` | the pair's bearing in the robot frame |
//! | `ball_distance_m` (d = f·h/g − m·cos α with a pair) | camera to flap, d = f·h/H from the blocks' mean height |
//! | `area_px` and A₁ (the ball's area at 1 m) for v = K_lin·√(A₁/A) | both blocks' pixels, and A₁ = f²·w·h, the flap's area at 1 m |
//! | `alpha` from the quadratic in K = c·h/g (pairs only) | the block-ratio viewing angle sin α ≈ 4·d·(L − R)/(3·(L + R)·w): the median of the last `alpha_window_frames` frames whose blocks are at least `reliable_height_px` tall (`[robot.shared]`, as Bujold's repositioning decides), reported once that many were seen in a row; until then `None`, as a lone ellipse gives, and the selector chooses state 1 or 3 |
//! | `alpha_saturated` (K past the quadratic's peak, 73°) | the ratio's sin α clipped at 1 |
//!
//! With no equivalent:
//!
//! * **the blue band alone** (state 4): the flap is one object, so `detection` stays
//!   empty and state 4 is never selected; the fiducial is either a pair or nothing
//!   (state 5);
//! * **the ellipse without a pair** (states 1 and 3 with α unknown): only by the size
//!   rule above, never because half the target is hidden;
//! * **`blue_distance_m`** (camera to the blue edges): `None`;
//! * **the ellipse's shape filters and tracking ball**: the two-block pair rules
//!   (component size, gap, vertical alignment, ratio closest to 1) stand in for them;
//!   [`Source::reset`] forgets the α window where the pyramid forgets its tracked ellipse.
//!   The median stands in for the tracking ball's robustness: the adaptive segmentation
//!   sometimes blooms one block into the dark pouch beside it for a frame or a few,
//!   which reads as α = ±80° at the size of a near flap; one such frame must not start a
//!   region-II manoeuvre.
//!
//! The two cues behave oppositely with range: the pyramid's α is lost close (the blue
//! edges leave its 25° window, the paper's dead zone) and holds far; the block ratio's α
//! is noisy far (two pixels are ±35° at 1.3 m) and good close.

use crate::behaviors::bujold::tuning::BujoldTuning;
use crate::behaviors::common::median::MedianWindow;
use crate::perception::two_block_pose::{FiducialView, TwoBlockGeometry};
use crate::perception::{PyramidDetection, PyramidPercept, PyramidView, RgbView, TwoBlockPercept};
use crate::profile::{Profile, PyramidSpec, SegmentationMode, TwoBlockSpec};
use crate::schemas::{Inputs, PerceptualSchema, PyramidSchema, TwoBlockSchema};

/// RAPOSA's perception source (see the module docs). Boxed: built once, kept for the
/// robot's life.
#[derive(Debug, Clone)]
pub enum Source {
    /// The pyramid schema (seed 001).
    Pyramid(Box<PyramidSchema>),
    /// Bujold's two-block schema through the adapter.
    TwoBlock(Box<TwoBlockCues>),
}

impl Source {
    /// The source for the profile's `[fiducial]`: the pyramid when it has one, else the
    /// two-block flap.
    ///
    /// # Errors
    /// A message naming what the profile lacks.
    pub fn from_profile(profile: &Profile, two_block: &BujoldTuning) -> Result<Self, String> {
        if profile.fiducial.get::<PyramidSpec>().is_some() {
            return PyramidSchema::from_profile(profile, 0)
                .map(|s| Source::Pyramid(Box::new(s)))
                .map_err(|e| e.to_string());
        }
        if profile.fiducial.get::<TwoBlockSpec>().is_some() {
            return TwoBlockCues::from_profile(profile, two_block).map(|c| Source::TwoBlock(Box::new(c)));
        }
        Err(format!(
            "needs a fiducial of kind `pyramid` or `two_block`, and the profile's is `{}`",
            profile.fiducial.kind()
        ))
    }

    /// This tick's percept; `looking` is false while the robot looks away on purpose (the
    /// colour model's fallback clock pauses).
    pub fn perceive(&mut self, inputs: &Inputs<'_>, looking: bool) -> PyramidPercept {
        match self {
            Source::Pyramid(s) => {
                s.set_looking(looking, inputs.now);
                s.perceive(inputs)
            }
            Source::TwoBlock(c) => c.perceive(inputs, looking),
        }
    }

    /// Forgets tracking (the pyramid's tracked ellipse, the two-block α window): the robot
    /// moved blind or starts anew.
    pub fn reset(&mut self) {
        match self {
            Source::Pyramid(s) => s.reset(),
            Source::TwoBlock(c) => c.alpha_window.clear(),
        }
    }

    /// Focal length, px.
    pub fn f_px(&self) -> f64 {
        match self {
            Source::Pyramid(s) => s.geometry().f_px,
            Source::TwoBlock(c) => c.geometry.fx,
        }
    }

    /// Camera-to-target distance from the target's pixel area, √(A₁/A), m.
    pub fn distance_from_area(&self, area_px: f64) -> f64 {
        match self {
            Source::Pyramid(s) => s.geometry().distance_from_area(area_px),
            Source::TwoBlock(c) => (c.area_1m_px / area_px.max(1e-9)).sqrt(),
        }
    }

    /// Frame size, px.
    pub fn image_size(&self) -> (usize, usize) {
        match self {
            Source::Pyramid(s) => s.detector().size(),
            Source::TwoBlock(c) => c.schema.detector().size(),
        }
    }

    /// The segmentation mode.
    pub fn mode(&self) -> SegmentationMode {
        match self {
            Source::Pyramid(s) => s.mode(),
            Source::TwoBlock(c) => c.mode,
        }
    }

    /// Camera-to-target distance at which the departing robot imprints, m.
    pub fn imprint_distance(&self) -> f64 {
        match self {
            Source::Pyramid(s) => s.imprint_distance(),
            Source::TwoBlock(c) => c.imprint_distance,
        }
    }

    /// Frames to imprint on.
    pub fn imprint_frames_wanted(&self) -> u32 {
        match self {
            Source::Pyramid(s) => s.imprint_frames_wanted(),
            Source::TwoBlock(c) => c.schema.imprint_frames_wanted(),
        }
    }

    /// Samples one departure frame (the pyramid's checks the pair's geometry; the
    /// two-block's samples the profile's rectangles).
    pub fn imprint_frame(&mut self, view: &RgbView<'_>) {
        match self {
            Source::Pyramid(s) => {
                let _ = s.imprint_frame(view);
            }
            Source::TwoBlock(c) => c.schema.imprint_frame(view),
        }
    }

    /// Installs the imprint; false when it failed.
    pub fn finish_imprint(&mut self, now: f64) -> bool {
        match self {
            Source::Pyramid(s) => s.finish_imprint(now),
            Source::TwoBlock(c) => c.schema.finish_imprint(now),
        }
    }
}

/// Bujold's two-block perceptual schema, reporting RAPOSA's cues (see the module docs).
#[derive(Debug, Clone)]
pub struct TwoBlockCues {
    /// The two-block schema (colour model, imprint, adaptation).
    pub schema: TwoBlockSchema,
    /// Camera and flap geometry.
    pub geometry: TwoBlockGeometry,
    /// Segmentation mode.
    pub mode: SegmentationMode,
    /// Camera-to-flap distance of the departure's imprint, m.
    pub imprint_distance: f64,
    /// α is measured on blocks at least this tall, px.
    pub reliable_height_px: f64,
    /// The flap's pixel area at 1 m, A₁ = f²·w·h.
    pub area_1m_px: f64,
    /// The raw α of the last reliable frames in a row, rad: α is their median once full.
    pub alpha_window: MedianWindow,
}

impl TwoBlockCues {
    /// From a profile with a two-block fiducial and a camera; the α window from
    /// `tuning` (`[robot.two_block]`, its defaults when absent).
    ///
    /// # Errors
    /// A message naming what the profile lacks.
    pub fn from_profile(profile: &Profile, tuning: &BujoldTuning) -> Result<Self, String> {
        let fid = *profile.fiducial.require::<TwoBlockSpec>()?;
        let cam = profile.cameras.first().ok_or("needs a camera")?;
        let schema = TwoBlockSchema::from_profile(profile, 0).map_err(|e| e.to_string())?;
        let geometry = TwoBlockGeometry::new(cam, &fid);
        Ok(Self {
            schema,
            geometry,
            mode: profile.perception.mode,
            imprint_distance: profile.perception.imprint.at_distance_m,
            reliable_height_px: tuning.reliable_height_px,
            area_1m_px: geometry.fx * geometry.fx * fid.width_m * fid.height_m,
            alpha_window: MedianWindow::new(tuning.alpha_window_frames),
        })
    }

    /// This tick's percept in RAPOSA's terms.
    pub fn perceive(&mut self, inputs: &Inputs<'_>, looking: bool) -> PyramidPercept {
        self.schema.model_mut().set_looking(looking, inputs.now);
        let p = self.schema.perceive(inputs);
        let view = self.view(&p);
        PyramidPercept {
            stamp: p.stamp,
            detection: PyramidDetection {
                pair: None,
                ellipse: None,
                blue: None,
                candidates: 0,
            },
            view,
            image_size: p.image_size,
        }
    }

    /// The view RAPOSA's states read, from one two-block percept (`None` when no pair was
    /// found); feeds the α window.
    pub fn view(&mut self, p: &TwoBlockPercept) -> Option<PyramidView> {
        let v = FiducialView::from_percept(p, &self.geometry)?;
        // A smaller flap breaks the run of reliable frames (the robot is far, or was moved).
        if v.height_px >= self.reliable_height_px {
            self.alpha_window.push(v.alpha);
        } else {
            self.alpha_window.clear();
        }
        let alpha = self.alpha_window.full_median();
        let row = (p.left_centroid[1] + p.right_centroid[1]) / 2.0 - p.image_size.1 as f64 / 2.0;
        tracing::trace!(target: "marsupial::behavior", now = p.stamp, d = v.distance, height_px = v.height_px, raw_alpha_deg = v.alpha.to_degrees(), alpha_deg = alpha.map(f64::to_degrees), bearing_deg = v.bearing.to_degrees(), left_px = p.left_px, right_px = p.right_px, left_bbox = ?p.left_bbox, right_bbox = ?p.right_bbox, mode = %p.mode, "two-block cues");
        Some(PyramidView {
            blue_distance_m: None,
            ball_distance_m: v.distance,
            alpha,
            alpha_saturated: alpha.is_some() && v.sin_alpha(&self.geometry).abs() >= 1.0,
            bearing: v.bearing,
            dev_px: [-self.geometry.fx * v.bearing.tan(), row],
            area_px: p.total_px,
        })
    }
}
