//! Correspondence of detected marks to the module's model (seed 000 §III.A.3).
//!
//! Eight marks could be labelled 8! = 40 320 ways. The rotations split them into four
//! classes (the paper's layout, and ours, has two marks per rotation), so a labelling is
//! fixed by choosing, per class, which of its two model marks each detection of that class
//! is: 2⁴ = **16 hypotheses**, never more. Per class the detections are taken best first
//! (contrast × bar anisotropy) up to the class's size as seeds; bit c of the hypothesis
//! number says whether class c's seeds map to its model marks in order or reversed.
//! Hypotheses that differ only in a class without seeds (or with one model mark) are the
//! same and are tried once.
//!
//! Per hypothesis:
//! 1. fit a homography (face → image) to the seeds: least squares, trimmed when there
//!    are 6 or more;
//! 2. physical constraints (the module cannot be upside down or seen from behind): the
//!    fit must keep the face's handedness, show its up direction within `max_roll_deg`
//!    of the image's up, and put every model mark in front of the camera;
//! 3. reproject the model and match every detection of a compatible rotation (or of an
//!    unknown one) to the nearest reprojected mark within the closeness gate (a multiple
//!    of the mark's projected radius); unmatched detections are false positives,
//!    unmatched marks occlusions;
//! 4. refit on the matches by [`Homography::fit_trimmed`], which never accepts fewer than
//!    5 pairs, then match and refit once more.
//!
//! The kept hypothesis has the most inliers, then the least RMS reprojection error (seed
//! 000 keeps "the permutation with minimal error"; counting inliers first stops a
//! hypothesis that fits 5 marks well from beating one that fits 8). Undetected marks are
//! filled in from the reprojection ([`ModelFit::centre`]).
//!
//! Seed 000 §V-D: "5 of the 11 failures were attributed to a known bug … only 4 were input
//! to the consensus-based homography algorithm"; with 4 points and one false, the fit is
//! exact and wrong. Here a fit needs at least 5 inliers ([`CorrespondenceParams::min_inliers`]
//! is raised to 5 if set lower), so 4 true marks and a false one are refused. Only the
//! ablation switch [`CorrespondenceParams::ablation_four_point_fits`] lowers the floor to
//! 4, to measure that bug (`marsupial pose-trials`).
//!
//! Nothing allocates: at most [`MAX_DETECTIONS`] detections are considered (the first in
//! the detector's order), and every array is fixed.

use super::detect::DetectedMark;
use super::ellipse::Ellipse;
use super::homography::Homography;
use super::model::{CircleModel, MAX_MODEL_MARKS};
use nalgebra::Matrix2;
use serde::Serialize;
use thiserror::Error;

/// Most detections considered per frame.
pub const MAX_DETECTIONS: usize = 64;

/// The search's thresholds (our choices; seed 000 gives no closeness threshold).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CorrespondenceParams {
    /// Fewest inliers accepted; values under 5 count as 5.
    pub min_inliers: usize,
    /// Closeness gate, in projected mark radii (default 0.3: a well-measured centre is
    /// within a pixel, and a tight gate leaves a 5-mark fit little room to bend toward a
    /// false mark). A homography does not model distortion: through a distorting lens,
    /// label with [`super::correspond_through`], which moves the centres onto the lens's
    /// ideal pin-hole image first.
    pub gate_radii: f64,
    /// Smallest gate, px (default 3: far marks are only a few pixels across).
    pub gate_min_px: f64,
    /// Largest angle between the face's up direction and the image's, degrees (default
    /// 60: the rover rolls on rough ground, but never that far).
    pub max_roll_deg: f64,
    /// Largest ratio, either way and along any direction, between a detection's ellipse
    /// and the ellipse the fit predicts for the mark it is matched to (the circle of the
    /// model's radius through the fit's local derivative), default 1.5. With 5 marks a
    /// homography has only 2 redundant degrees of freedom and can bend to take a false
    /// point; the marks' sizes and shapes are a check the positions alone do not give.
    pub max_size_ratio: f64,
    /// **Ablation only** (`marsupial pose-trials`, seed 000 §V-D's bug): accept a
    /// labelling from 4 marks. Four points fit a homography exactly, so a false positive
    /// among them leaves no residual to expose it; with this set `min_inliers` may be 4.
    /// Off by default and never set by a robot's perception: it exists to measure what
    /// the 5-mark floor buys.
    pub ablation_four_point_fits: bool,
}

impl Default for CorrespondenceParams {
    fn default() -> Self {
        Self {
            min_inliers: 5,
            gate_radii: 0.3,
            gate_min_px: 3.0,
            max_roll_deg: 60.0,
            max_size_ratio: 1.5,
            ablation_four_point_fits: false,
        }
    }
}

/// Why no labelling was accepted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error, Serialize)]
pub enum CorrespondenceError {
    /// Fewer detections than the fewest inliers a fit needs.
    #[error("{found} marks detected, a fit needs {needed}")]
    TooFewMarks {
        /// Detections given.
        found: usize,
        /// Inliers needed.
        needed: usize,
    },
    /// No hypothesis gave enough consistent marks.
    #[error(
        "no labelling fits {needed} marks (best: {best_inliers} of {found} detected, {hypotheses} hypotheses tried)"
    )]
    NoConsistentFit {
        /// Detections given.
        found: usize,
        /// Most marks any hypothesis matched.
        best_inliers: usize,
        /// Inliers needed.
        needed: usize,
        /// Hypotheses tried.
        hypotheses: usize,
    },
}

/// An accepted labelling: the hypothesis, the homography and the inliers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModelFit {
    /// The hypothesis kept, 0–15 (bit c: class c's seeds reversed).
    pub hypothesis: u8,
    /// Distinct hypotheses tried.
    pub hypotheses_tried: u8,
    /// The face → image map fitted to the inliers.
    pub homography: Homography,
    /// Marks matched.
    pub inliers: usize,
    /// RMS distance between the inliers and their reprojected marks, px.
    pub rms_px: f64,
    detection_of: [u8; MAX_MODEL_MARKS],
    projected: [[f64; 2]; MAX_MODEL_MARKS],
    len: usize,
    inlier_mask: u64,
}

const NONE: u8 = u8::MAX;

impl ModelFit {
    /// The detection matched to model mark `j`, if any.
    pub fn detection_of(&self, j: usize) -> Option<usize> {
        self.detection_of[..self.len]
            .get(j)
            .and_then(|&d| (d != NONE).then_some(d as usize))
    }

    /// Whether detection `i` is an inlier (false: a false positive, or beyond
    /// [`MAX_DETECTIONS`]).
    pub fn is_inlier(&self, i: usize) -> bool {
        i < MAX_DETECTIONS && self.inlier_mask & (1 << i) != 0
    }

    /// The model's marks reprojected through the fit, px.
    pub fn projected(&self) -> &[[f64; 2]] {
        &self.projected[..self.len]
    }

    /// Every model mark's image position: the detection where one matched, the
    /// reprojection where the mark was not detected (seed 000 fills these in).
    pub fn centre(&self, marks: &[DetectedMark], j: usize) -> Option<[f64; 2]> {
        if j >= self.len {
            return None;
        }
        Some(
            self.detection_of(j)
                .and_then(|i| marks.get(i))
                .map_or(self.projected[j], |m| m.centre),
        )
    }
}

impl ModelFit {
    /// Moves the fit from the plane it was labelled in into the camera's own pixels
    /// (`to_image` maps a point across, `None` outside the lens's view): the reprojected
    /// model, and the RMS recomputed between each inlier's detection in `marks` (image
    /// pixels) and its mark's reprojection there. Used by
    /// [`super::rectify::correspond_through`].
    pub(super) fn map_to_image(&mut self, marks: &[DetectedMark], to_image: impl Fn([f64; 2]) -> Option<[f64; 2]>) {
        for p in &mut self.projected[..self.len] {
            *p = to_image(*p).unwrap_or([f64::NAN; 2]);
        }
        let mut ss = 0.0;
        for j in 0..self.len {
            if let Some(m) = self.detection_of(j).and_then(|i| marks.get(i)) {
                let p = self.projected[j];
                ss += (m.centre[0] - p[0]).powi(2) + (m.centre[1] - p[1]).powi(2);
            }
        }
        self.rms_px = (ss / self.inliers.max(1) as f64).sqrt();
    }
}

/// One hypothesis's working set, on the stack.
struct Pairs {
    src: [[f64; 2]; MAX_MODEL_MARKS],
    dst: [[f64; 2]; MAX_MODEL_MARKS],
    model: [u8; MAX_MODEL_MARKS],
    det: [u8; MAX_MODEL_MARKS],
    gate: [f64; MAX_MODEL_MARKS],
    keep: [bool; MAX_MODEL_MARKS],
    n: usize,
}

impl Pairs {
    fn new() -> Self {
        Self {
            src: [[0.0; 2]; MAX_MODEL_MARKS],
            dst: [[0.0; 2]; MAX_MODEL_MARKS],
            model: [0; MAX_MODEL_MARKS],
            det: [0; MAX_MODEL_MARKS],
            gate: [0.0; MAX_MODEL_MARKS],
            keep: [true; MAX_MODEL_MARKS],
            n: 0,
        }
    }

    fn push(&mut self, src: [f64; 2], dst: [f64; 2], model: usize, det: usize, gate: f64) {
        if self.n < MAX_MODEL_MARKS {
            let k = self.n;
            (self.src[k], self.dst[k], self.model[k], self.det[k], self.gate[k]) =
                (src, dst, model as u8, det as u8, gate);
            self.keep[k] = true;
            self.n += 1;
        }
    }
}

/// Labels `marks` against `model` (see the module docs).
///
/// # Errors
/// [`CorrespondenceError::TooFewMarks`] with fewer detections than the inliers needed;
/// [`CorrespondenceError::NoConsistentFit`] when no hypothesis reaches them.
pub fn correspond(
    model: &CircleModel,
    marks: &[DetectedMark],
    params: &CorrespondenceParams,
) -> Result<ModelFit, CorrespondenceError> {
    let need = params
        .min_inliers
        .max(if params.ablation_four_point_fits { 4 } else { 5 });
    let marks = &marks[..marks.len().min(MAX_DETECTIONS)];
    if marks.len() < need {
        return Err(CorrespondenceError::TooFewMarks {
            found: marks.len(),
            needed: need,
        });
    }
    // Per class: its model marks in model order, and its seeds best first.
    let mut class_model = [[0u8; MAX_MODEL_MARKS]; 4];
    let mut class_model_n = [0usize; 4];
    for (j, r) in model.rotations().iter().enumerate() {
        let c = r.index();
        class_model[c][class_model_n[c]] = j as u8;
        class_model_n[c] += 1;
    }
    let mut seeds = [[0u8; 2]; 4];
    let mut seeds_n = [0usize; 4];
    let quality = |i: usize| marks[i].contrast * marks[i].bar_anisotropy;
    for (i, m) in marks.iter().enumerate() {
        let Some(r) = m.rotation else { continue };
        let c = r.index();
        let cap = class_model_n[c].min(2);
        // Insert keeping the best `cap`, best first (ties: lower index first).
        let s = &mut seeds[c];
        let n = &mut seeds_n[c];
        let mut at = *n;
        while at > 0 && quality(i) > quality(s[at - 1] as usize) {
            at -= 1;
        }
        if at < cap {
            let end = (*n + 1).min(cap);
            for k in (at + 1..end).rev() {
                s[k] = s[k - 1];
            }
            s[at] = i as u8;
            *n = end;
        }
    }
    let mut best: Option<ModelFit> = None;
    let mut best_inliers = 0;
    let mut tried = 0u8;
    for hyp in 0u8..16 {
        // A bit that changes nothing repeats a hypothesis already tried.
        if (0..4).any(|c| hyp & (1 << c) != 0 && (seeds_n[c] == 0 || class_model_n[c] < 2)) {
            continue;
        }
        tried += 1;
        let mut p = Pairs::new();
        for c in 0..4 {
            let k = class_model_n[c];
            for s in 0..seeds_n[c] {
                let j = if hyp & (1 << c) != 0 {
                    class_model[c][k - 1 - s]
                } else {
                    class_model[c][s]
                } as usize;
                let i = seeds[c][s] as usize;
                p.push(model.centres()[j], marks[i].centre, j, i, 0.0);
            }
        }
        if p.n < 4 {
            continue;
        }
        // The seeds' least-squares fit; when it does not verify, the fits leaving one
        // seed out (a false positive can take a seed's place in its class).
        let mut fit = None;
        for leave in std::iter::once(None).chain((0..p.n).map(Some)) {
            if leave.is_some() && p.n < 5 {
                break;
            }
            let mut keep = [true; MAX_MODEL_MARKS];
            if let Some(k) = leave {
                keep[k] = false;
            }
            let Some(h) = Homography::fit_fast(&p.src[..p.n], &p.dst[..p.n], &keep[..p.n]) else {
                continue;
            };
            if let Some(f) = verify(h, model, marks, params, need, &mut best_inliers) {
                fit = Some(f);
                break;
            }
        }
        let Some((h, m, keep, count)) = fit else { continue };
        let mut out = ModelFit {
            hypothesis: hyp,
            hypotheses_tried: 0,
            homography: h,
            inliers: count,
            rms_px: 0.0,
            detection_of: [NONE; MAX_MODEL_MARKS],
            projected: [[0.0; 2]; MAX_MODEL_MARKS],
            len: model.len(),
            inlier_mask: 0,
        };
        let mut ss = 0.0;
        for k in (0..m.n).filter(|&k| keep[k]) {
            out.detection_of[m.model[k] as usize] = m.det[k];
            out.inlier_mask |= 1 << m.det[k];
            ss += h.transfer_error(m.src[k], m.dst[k]).powi(2);
        }
        out.rms_px = (ss / count as f64).sqrt();
        for (j, c) in model.centres().iter().enumerate() {
            out.projected[j] = h.apply(*c).unwrap_or([f64::NAN; 2]);
        }
        let better = best
            .as_ref()
            .is_none_or(|b| count > b.inliers || (count == b.inliers && out.rms_px < b.rms_px));
        if better {
            best = Some(out);
        }
    }
    match best {
        Some(mut b) => {
            b.hypotheses_tried = tried;
            Ok(b)
        }
        None => Err(CorrespondenceError::NoConsistentFit {
            found: marks.len(),
            best_inliers,
            needed: need,
            hypotheses: tried as usize,
        }),
    }
}

/// Verifies a hypothesis's first homography: twice, match the detections to the
/// reprojected model and refit on the matches (trimmed, at least `need` of them). The
/// final fit must still meet the physical constraints.
fn verify(
    mut h: Homography,
    model: &CircleModel,
    marks: &[DetectedMark],
    params: &CorrespondenceParams,
    need: usize,
    best_inliers: &mut usize,
) -> Option<(Homography, Pairs, [bool; MAX_MODEL_MARKS], usize)> {
    let mut out = None;
    for _round in 0..2 {
        if !upright(&h, model, params) {
            return None;
        }
        let m = match_marks(&h, model, marks, params);
        *best_inliers = (*best_inliers).max(m.n.min(need - 1));
        let mut keep = m.keep;
        let (refit, count) =
            Homography::trimmed_with_floor(&m.src[..m.n], &m.dst[..m.n], &mut keep[..m.n], need, |k| m.gate[k])?;
        h = refit;
        out = Some((m, keep, count));
    }
    let (m, keep, count) = out?;
    *best_inliers = (*best_inliers).max(count);
    upright(&h, model, params).then_some((h, m, keep, count))
}

/// The physical constraints: handedness kept (the face seen from the front), the face's up
/// within `max_roll_deg` of the image's up (image y grows downwards), every mark in front.
fn upright(h: &Homography, model: &CircleModel, params: &CorrespondenceParams) -> bool {
    let n = model.len() as f64;
    let c = model
        .centres()
        .iter()
        .fold([0.0, 0.0], |a, p| [a[0] + p[0] / n, a[1] + p[1] / n]);
    let Some(j) = h.jacobian(c) else { return false };
    // Face (u right, v up) → image (x right, y down) flips handedness: det < 0.
    if j.determinant() >= 0.0 {
        return false;
    }
    let up = [j[(0, 1)], -j[(1, 1)]];
    let tilt = up[0].atan2(up[1]).to_degrees().abs();
    if tilt > params.max_roll_deg {
        return false;
    }
    let w = |p: [f64; 2]| h.0[(2, 0)] * p[0] + h.0[(2, 1)] * p[1] + h.0[(2, 2)];
    let s = w(c).signum();
    model.centres().iter().all(|p| w(*p) * s > 0.0)
}

/// Whether `e` agrees with the predicted ellipse whose matrix (the second-moment form
/// J·Jᵀ·R², image px²) is `pred`: both generalised eigenvalues of (pred, E), the squared
/// scale ratios along the principal directions, within [1/t², t²].
fn same_shape(pred: &Matrix2<f64>, e: &Ellipse, t: f64) -> bool {
    let (s, c) = e.angle.sin_cos();
    let rot = Matrix2::new(c, -s, s, c);
    let det_e = rot * Matrix2::new(e.semi_major.powi(2), 0.0, 0.0, e.semi_minor.powi(2)) * rot.transpose();
    let Some(inv) = pred.try_inverse() else { return false };
    let m = inv * det_e;
    let (tr, det) = (m.trace(), m.determinant());
    let disc = (tr * tr / 4.0 - det).max(0.0).sqrt();
    let (l1, l2) = (tr / 2.0 + disc, tr / 2.0 - disc);
    let (lo, hi) = (1.0 / (t * t), t * t);
    l1.is_finite() && l2.is_finite() && l1 <= hi && l2 >= lo
}

/// Matches detections to the reprojected model: repeatedly the closest (mark, detection)
/// pair within the mark's gate, of compatible rotation, both still free.
fn match_marks(h: &Homography, model: &CircleModel, marks: &[DetectedMark], params: &CorrespondenceParams) -> Pairs {
    let mut proj = [[f64::NAN; 2]; MAX_MODEL_MARKS];
    let mut gate = [0.0; MAX_MODEL_MARKS];
    let mut shape = [Matrix2::zeros(); MAX_MODEL_MARKS];
    for (j, c) in model.centres().iter().enumerate() {
        if let (Some(q), Some(jac)) = (h.apply(*c), h.jacobian(*c)) {
            proj[j] = q;
            let r = model.radius_m();
            shape[j] = jac * jac.transpose() * (r * r);
            gate[j] = (params.gate_radii * jac.determinant().abs().sqrt() * r).max(params.gate_min_px);
        }
    }
    let mut used_model = [false; MAX_MODEL_MARKS];
    let mut used_det = 0u64;
    let mut out = Pairs::new();
    loop {
        let mut pick: Option<(f64, usize, usize)> = None;
        for j in (0..model.len()).filter(|&j| !used_model[j]) {
            for (i, m) in marks.iter().enumerate() {
                if used_det & (1 << i) != 0 || m.rotation.is_some_and(|r| r != model.rotations()[j]) {
                    continue;
                }
                if !same_shape(&shape[j], &m.ellipse, params.max_size_ratio) {
                    continue;
                }
                let d = (m.centre[0] - proj[j][0]).hypot(m.centre[1] - proj[j][1]);
                if d <= gate[j] && pick.is_none_or(|(b, _, _)| d < b) {
                    pick = Some((d, j, i));
                }
            }
        }
        let Some((_, j, i)) = pick else { break };
        used_model[j] = true;
        used_det |= 1 << i;
        out.push(model.centres()[j], marks[i].centre, j, i, gate[j]);
    }
    out
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::perception::circles::MarkRotation;
    use MarkRotation::*;

    /// The layout of `profiles/axel.toml`.
    pub(crate) fn axel_model() -> CircleModel {
        let m = [
            ([-0.38, 0.85], Zero),
            ([-0.10, 0.92], Plus45),
            ([0.22, 0.88], Ninety),
            ([0.40, 0.70], Minus45),
            ([-0.42, 0.50], Ninety),
            ([-0.05, 0.60], Zero),
            ([0.30, 0.45], Plus45),
            ([0.05, 0.32], Minus45),
        ];
        CircleModel::new(0.05, &m).unwrap()
    }

    /// A frontal view: 400 px per metre, the face's centre near the image's, turned a
    /// little (`skew` adds perspective).
    fn view(skew: f64) -> Homography {
        Homography(nalgebra::Matrix3::new(
            400.0, 10.0, 320.0, 5.0, -400.0, 500.0, skew, 0.0, 1.0,
        ))
    }

    fn mark_at(p: [f64; 2], rot: Option<MarkRotation>) -> DetectedMark {
        sized_mark_at(p, rot, 20.0)
    }

    fn sized_mark_at(p: [f64; 2], rot: Option<MarkRotation>, r: f64) -> DetectedMark {
        DetectedMark {
            centre: p,
            ellipse: Ellipse {
                centre: p,
                semi_major: r,
                semi_minor: r,
                angle: 0.0,
            },
            rotation: rot,
            bar_angle_deg: rot.map_or(0.0, |r| r.degrees()),
            bar_anisotropy: 0.8,
            contrast: 150.0,
            fit_rms_px: 0.1,
        }
    }

    fn observe(model: &CircleModel, h: &Homography, which: &[usize]) -> Vec<DetectedMark> {
        which
            .iter()
            .map(|&j| {
                // The ellipse the circle's local affine image makes: axes from J's SVD.
                let c = model.centres()[j];
                let svd = h.jacobian(c).unwrap().svd(true, false);
                let u = svd.u.unwrap();
                let r = model.radius_m();
                let mut m = sized_mark_at(h.apply(c).unwrap(), Some(model.rotations()[j]), 1.0);
                m.ellipse.semi_major = svd.singular_values[0] * r;
                m.ellipse.semi_minor = svd.singular_values[1] * r;
                m.ellipse.angle = u[(1, 0)].atan2(u[(0, 0)]);
                m
            })
            .collect()
    }

    #[test]
    fn all_eight_marks_in_any_order_are_labelled() {
        let model = axel_model();
        for skew in [0.0, 0.3, -0.4] {
            let h = view(skew);
            let order = [5, 2, 7, 0, 3, 6, 1, 4];
            let marks = observe(&model, &h, &order);
            let fit = correspond(&model, &marks, &Default::default()).unwrap();
            assert_eq!(fit.inliers, 8);
            assert!(fit.rms_px < 1e-6, "{}", fit.rms_px);
            assert!(fit.hypotheses_tried <= 16);
            for (i, &j) in order.iter().enumerate() {
                assert_eq!(fit.detection_of(j), Some(i));
            }
        }
    }

    #[test]
    fn occlusions_and_a_false_positive_with_five_true_marks() {
        let model = axel_model();
        let h = view(0.2);
        let mut marks = observe(&model, &h, &[0, 2, 3, 5, 6]);
        // A false mark of a plausible rotation between the true ones.
        marks.insert(2, mark_at([400.0, 250.0], Some(Zero)));
        let fit = correspond(&model, &marks, &Default::default()).unwrap();
        assert_eq!(fit.inliers, 5);
        assert!(!fit.is_inlier(2), "the false positive is an outlier");
        // Occluded marks are filled in from the reprojection.
        for j in [1, 4, 7] {
            assert_eq!(fit.detection_of(j), None);
            let truth = h.apply(model.centres()[j]).unwrap();
            let c = fit.centre(&marks, j).unwrap();
            assert!((c[0] - truth[0]).hypot(c[1] - truth[1]) < 1e-6);
        }
    }

    #[test]
    fn four_true_marks_and_one_false_positive_are_refused() {
        // Seed 000 §V-D: the field failure. A false mark anywhere on a 20-px grid over the
        // image, of every rotation and two sizes, beside 4 true marks: never a fit, unless
        // it lies within 3 radii of where an undetected mark of its rotation belongs (it
        // then stands in for that mark, and the 4 true marks keep their labels: 5 points
        // leave a homography 2 redundant degrees of freedom, not enough to tell).
        let model = axel_model();
        let h = view(0.1);
        let detected = [0, 2, 3, 6];
        let (mut refused, mut stood_in) = (0, 0);
        for rot in MarkRotation::ALL.map(Some).into_iter().chain([None]) {
            for gx in 0..32 {
                for gy in 0..24 {
                    for r in [8.0, 20.0] {
                        let mut marks = observe(&model, &h, &detected);
                        let p = [gx as f64 * 20.0 + 7.0, gy as f64 * 20.0 + 3.0];
                        marks.push(sized_mark_at(p, rot, r));
                        let near = (0..8).filter(|j| !detected.contains(j)).any(|j| {
                            let q = h.apply(model.centres()[j]).unwrap();
                            let radius = h.jacobian(model.centres()[j]).unwrap().determinant().abs().sqrt() * 0.05;
                            rot.is_none_or(|r| r == model.rotations()[j])
                                && (p[0] - q[0]).hypot(p[1] - q[1]) < 3.0 * radius
                        });
                        match correspond(&model, &marks, &Default::default()) {
                            Err(CorrespondenceError::NoConsistentFit { needed: 5, .. }) => refused += 1,
                            Ok(fit) if near => {
                                for (i, &j) in detected.iter().enumerate() {
                                    assert_eq!(fit.detection_of(j), Some(i), "{rot:?} at {p:?}");
                                }
                                stood_in += 1;
                            }
                            got => panic!("{rot:?} at {p:?} r {r}: {got:?}"),
                        }
                    }
                }
            }
        }
        assert!(
            refused > 7500 && stood_in < 100,
            "refused {refused}, stood in {stood_in}"
        );
        // Four alone are too few to try.
        let marks = observe(&model, &h, &[0, 2, 3, 6]);
        assert_eq!(
            correspond(&model, &marks, &Default::default()),
            Err(CorrespondenceError::TooFewMarks { found: 4, needed: 5 })
        );
        // min_inliers cannot be lowered below 5.
        let p = CorrespondenceParams {
            min_inliers: 4,
            ..Default::default()
        };
        assert!(matches!(
            correspond(&model, &marks, &p),
            Err(CorrespondenceError::TooFewMarks { needed: 5, .. })
        ));
        // The four-point ablation (seed 000's bug) takes them, and its fit is exact
        // whatever the labelling: no residual is left to tell a wrong one.
        let p = CorrespondenceParams {
            min_inliers: 4,
            ablation_four_point_fits: true,
            ..Default::default()
        };
        let fit = correspond(&model, &marks, &p).expect("a four-point fit");
        assert_eq!(fit.inliers, 4);
        assert!(fit.rms_px < 1e-6, "{}", fit.rms_px);
    }

    #[test]
    fn a_mirrored_or_upside_down_module_is_not_accepted() {
        let model = axel_model();
        // Upside down: the face's v maps to image down.
        let flipped = Homography(nalgebra::Matrix3::new(
            -400.0, 0.0, 320.0, 0.0, 400.0, 100.0, 0.0, 0.0, 1.0,
        ));
        let marks = observe(&model, &flipped, &[0, 1, 2, 3, 4, 5, 6, 7]);
        assert!(correspond(&model, &marks, &Default::default()).is_err());
        // Mirrored (seen from behind).
        let mirrored = Homography(nalgebra::Matrix3::new(
            -400.0, 0.0, 320.0, 0.0, -400.0, 500.0, 0.0, 0.0, 1.0,
        ));
        let marks = observe(&model, &mirrored, &[0, 1, 2, 3, 4, 5, 6, 7]);
        assert!(correspond(&model, &marks, &Default::default()).is_err());
    }

    #[test]
    fn unresolved_rotations_still_count_as_inliers() {
        let model = axel_model();
        let h = view(0.0);
        let mut marks = observe(&model, &h, &[0, 1, 2, 3, 4, 5, 6, 7]);
        for m in marks.iter_mut().skip(5) {
            m.rotation = None;
        }
        let fit = correspond(&model, &marks, &Default::default()).unwrap();
        assert_eq!(fit.inliers, 8);
    }

    #[test]
    fn garbage_never_panics() {
        let model = axel_model();
        let p = CorrespondenceParams::default();
        assert!(correspond(&model, &[], &p).is_err());
        let same = vec![mark_at([10.0, 10.0], Some(Zero)); 9];
        assert!(correspond(&model, &same, &p).is_err());
        let nan = vec![mark_at([f64::NAN, 1.0], Some(Ninety)); 8];
        assert!(correspond(&model, &nan, &p).is_err());
        let many: Vec<DetectedMark> = (0..200)
            .map(|k| {
                mark_at(
                    [(k * 37 % 640) as f64, (k * 91 % 480) as f64],
                    Some(MarkRotation::ALL[k % 4]),
                )
            })
            .collect();
        let _ = correspond(&model, &many, &p);
    }
}
