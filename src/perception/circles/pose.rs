//! The central module's pose from labelled marks (seed 000 §III.B): stereo triangulation
//! and a rigid fit, with a monocular planar pose as the fallback.
//!
//! **Frames.** The *module frame* is the dock frame of [`super::model`]: its face is the
//! plane x = 0 and looks along +x, and mark j sits at (0, uⱼ, vⱼ) with (uⱼ, vⱼ) its face
//! coordinates. The *rover frame* is the body frame of [`body_from_camera`]: +x forward,
//! +y left, +z up, the origin on the ground under the rover's reference point (where a
//! profile's `[cameras.mount]` offsets are measured from). A [`ModulePose`] maps module
//! points into the rover frame: p_rover = R·p_module + t.
//!
//! **Stereo** ([`stereo_pose`]): for every mark *detected* in both cameras (marks
//! the correspondence filled in from the reprojection are not measurements, and are not
//! used), each camera's model turns the centre into a unit ray ([`CameraModel::ray`], so
//! a distorted or fisheye lens is handled), the mount puts it in the rover frame, and the
//! point is the **midpoint of the two rays' common perpendicular** (ALGORITHMS.md §7: it
//! works on bearing vectors, so it suits any lens; a pixel-space DLT would need a
//! pin-hole). Pairs whose rays pass further apart than
//! [`PoseParams::max_ray_gap_m`], or meet behind a camera, are dropped as mislabelled.
//! The model's 3-D marks are then fitted to the triangulated points by least squares
//! (Kabsch/Umeyama without scale: SVD of the 3 × 3 cross-covariance, the last singular
//! vector's sign chosen so that det R = +1). At least **3 non-collinear** marks are needed:
//! a rigid fit to 2 points leaves the rotation about their line free; the check is on the
//! model's marks, whose spread across their best line must be at least
//! [`PoseParams::min_spread_m`].
//!
//! **Monocular** ([`mono_pose`]): when only one camera sees the module, each detected
//! centre becomes a ray and then the *undistorted normalised* image point (x/z, y/z), so
//! the homography from the face to it is K⁻¹H with K = I and no lens distortion left in
//! it. A normalised DLT ([`Homography::fit`]) gives H ∝ [r₂ r₃ t] (the face's axes are
//! the module's +y and +z); the scale is the mean of ‖h₁‖ and ‖h₂‖, its sign puts the
//! module in front of the camera, r₁ = r₂ × r₃, and the nearest rotation (SVD, det = +1)
//! replaces the three columns. That closed form is only a start (ALGORITHMS.md §7), so
//! Gauss–Newton on the normalised reprojection error refines it. At least 4 detected,
//! non-collinear marks are needed.
//!
//! Both report the RMS **reprojection error** in pixels over the marks used, through each
//! camera's own model (seed 000 reports 8.21 ± 2.4 px for its pose), and a metric residual
//! ([`ModulePose::rms_residual_m`]).
//!
//! Simplified: the planar pose's two-fold ambiguity (IPPE, RPP) is not resolved; the
//! Gauss–Newton refinement starts from the homography's pose and keeps the minimum it
//! reaches, which is right when the face spans a good part of the image (here it does
//! to beyond 3 m) and can be the mirror one when it is small and seen head-on. The rigid
//! fit weights every mark alike, although depth error grows with range squared.
//!
//! Nothing allocates: the fits use fixed-size `nalgebra` matrices and the caller's
//! [`PoseBuffers`].

use super::correspond::ModelFit;
use super::detect::DetectedMark;
use super::homography::Homography;
use super::model::{CircleModel, MAX_MODEL_MARKS};
use crate::perception::camera_model::{CameraModel, MountAngles, body_from_camera};
use nalgebra::{Matrix3, Matrix6, Vector2, Vector3, Vector6};
use serde::Serialize;
use thiserror::Error;

/// One camera of the rig: its lens model and where it sits on the rover, so its rays can
/// be expressed in the rover frame and rover points projected into it.
#[derive(Debug, Clone, PartialEq)]
pub struct RigCamera {
    /// The camera's projection model (distortion included).
    pub model: CameraModel,
    /// Rotation taking camera-frame vectors to the rover frame.
    pub body_from_camera: Matrix3<f64>,
    /// The camera's optical centre in the rover frame, m.
    pub position: Vector3<f64>,
}

impl RigCamera {
    /// A camera with `model`, mounted at `position_m` (rover frame, m) and turned by
    /// `mount` (see [`body_from_camera`]). A profile's `[[cameras]]` entry gives one
    /// through `RigCamera::from_profile` (in `profile`).
    pub fn new(model: CameraModel, mount: impl Into<MountAngles>, position_m: [f64; 3]) -> Self {
        Self {
            model,
            body_from_camera: body_from_camera(mount),
            position: Vector3::from(position_m),
        }
    }

    /// The unit ray through pixel `px`, in the rover frame.
    pub fn ray(&self, px: [f64; 2]) -> Vector3<f64> {
        self.body_from_camera * self.model.ray(px[0], px[1])
    }

    /// The pixel of a rover-frame point, or `None` outside the model's field of view.
    pub fn project(&self, p: &Vector3<f64>) -> Option<[f64; 2]> {
        self.model
            .project(&(self.body_from_camera.transpose() * (p - self.position)))
    }
}

/// Which measurement a pose came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum PoseSource {
    /// Triangulated from both cameras of the rig (cameras 0 and 1).
    Stereo,
    /// The planar pose from one camera's image; `camera` is its index in the rig.
    Mono {
        /// Rig index of the camera used.
        camera: usize,
    },
}

/// The module's pose in the rover frame (see the module docs for both frames), with how
/// it was measured and how well the measurements agree with it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModulePose {
    /// Rotation taking module-frame vectors to the rover frame.
    pub rotation: Matrix3<f64>,
    /// The module frame's origin in the rover frame, m.
    pub translation: Vector3<f64>,
    /// Stereo or mono (and which camera).
    pub source: PoseSource,
    /// Marks the pose was computed from.
    pub marks_used: usize,
    /// Metric residual, m. Stereo: RMS distance between the triangulated marks and the
    /// posed model's. Mono: RMS distance between the posed model's marks and the rays
    /// through their detections.
    pub rms_residual_m: f64,
    /// RMS distance between the detected centres and the posed model's marks projected
    /// through each camera used, px (both cameras' detections for stereo).
    pub reprojection_px: f64,
}

impl ModulePose {
    /// The module origin's forward offset in the rover frame, m.
    pub fn x(&self) -> f64 {
        self.translation.x
    }

    /// The module origin's leftward offset in the rover frame, m.
    pub fn y(&self) -> f64 {
        self.translation.y
    }

    /// Direction of the module's +x axis (the way its face looks) in the rover frame,
    /// radians counter-clockwise from rover +x: about ±π when the rover faces the face.
    pub fn heading(&self) -> f64 {
        self.rotation[(1, 0)].atan2(self.rotation[(0, 0)])
    }

    /// The rover's planar pose in the module frame, (x m, y m, heading rad): what a
    /// planner working in polar coordinates about the module (seed 000 §IV) needs.
    pub fn rover_in_module(&self) -> [f64; 3] {
        let rt = self.rotation.transpose();
        let p = -(rt * self.translation);
        [p.x, p.y, rt[(1, 0)].atan2(rt[(0, 0)])]
    }

    /// Where model point `m` (module frame) lies in the rover frame.
    pub fn apply(&self, m: &Vector3<f64>) -> Vector3<f64> {
        self.rotation * m + self.translation
    }
}

/// Why no pose was computed.
#[derive(Debug, Clone, Copy, PartialEq, Error, Serialize)]
pub enum PoseError {
    /// Fewer usable marks than the method needs (stereo: detected in both cameras and
    /// triangulated; mono: detected and in front of the camera).
    #[error("{found} usable marks, the pose needs {needed}")]
    TooFewMarks {
        /// Marks usable.
        found: usize,
        /// Marks needed.
        needed: usize,
    },
    /// The usable marks lie (nearly) on a line: the rotation about it is not determined.
    #[error("the usable marks are collinear (spread {spread_m:.4} m across their line, need {needed_m} m)")]
    Collinear {
        /// RMS distance of the model's marks from their best line, m.
        spread_m: f64,
        /// The least accepted ([`PoseParams::min_spread_m`]).
        needed_m: f64,
    },
    /// Observations and model disagree in size, or a number is not finite.
    #[error("bad input: {what}")]
    BadInput {
        /// What is wrong.
        what: &'static str,
    },
    /// The fit is numerically degenerate (no homography, a singular decomposition, or
    /// the module posed behind the camera).
    #[error("degenerate pose fit: {what}")]
    Degenerate {
        /// Which step failed.
        what: &'static str,
    },
}

/// The pose's thresholds (our choices; seed 000 gives none).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseParams {
    /// Largest distance between a mark's two rays at their closest, m (default 0.05:
    /// a 1-px error at 5 m moves a ray about 1 cm, a mislabelled mark tens of cm).
    pub max_ray_gap_m: f64,
    /// Least RMS distance of the used marks (on the face) from their best-fitting line,
    /// m (default 0.03, a third of a mark's diameter).
    pub min_spread_m: f64,
    /// Gauss–Newton iterations refining the monocular pose (default 10; it converges in
    /// 3–4 from the homography's pose).
    pub mono_iterations: usize,
}

impl Default for PoseParams {
    fn default() -> Self {
        Self {
            max_ray_gap_m: 0.05,
            min_spread_m: 0.03,
            mono_iterations: 10,
        }
    }
}

/// Each model mark's measured image centre in one camera, or none: the input of the pose.
/// Only *detected* marks belong here (not correspondence's filled-in reprojections).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MarkObservations {
    centres: [[f64; 2]; MAX_MODEL_MARKS],
    seen: [bool; MAX_MODEL_MARKS],
    len: usize,
}

impl MarkObservations {
    /// No mark seen, for a model of `len` marks (at most [`MAX_MODEL_MARKS`]).
    pub fn new(len: usize) -> Self {
        Self {
            centres: [[0.0; 2]; MAX_MODEL_MARKS],
            seen: [false; MAX_MODEL_MARKS],
            len: len.min(MAX_MODEL_MARKS),
        }
    }

    /// The detected marks a correspondence labelled: mark j's centre is that of
    /// `marks[fit.detection_of(j)]`; undetected marks stay unseen.
    pub fn from_fit(fit: &ModelFit, marks: &[DetectedMark]) -> Self {
        let mut o = Self::new(fit.projected().len());
        for j in 0..o.len {
            if let Some(m) = fit.detection_of(j).and_then(|i| marks.get(i)) {
                o.set(j, Some(m.centre));
            }
        }
        o
    }

    /// Sets (or clears) mark `j`'s centre, px; ignored beyond the model's length.
    pub fn set(&mut self, j: usize, centre: Option<[f64; 2]>) {
        if j < self.len {
            self.seen[j] = centre.is_some();
            self.centres[j] = centre.unwrap_or([0.0; 2]);
        }
    }

    /// Mark `j`'s centre, px, if seen.
    pub fn get(&self, j: usize) -> Option<[f64; 2]> {
        (j < self.len && self.seen[j]).then(|| self.centres[j])
    }

    /// Number of model marks these observations are for.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True for a model of no marks.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Marks seen.
    pub fn count(&self) -> usize {
        self.seen[..self.len].iter().filter(|s| **s).count()
    }
}

/// The pose's working set, owned by the caller and reused from frame to frame; after a
/// call it holds what the fit used (for inspection and tests).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseBuffers {
    mark: [usize; MAX_MODEL_MARKS],
    model: [Vector3<f64>; MAX_MODEL_MARKS],
    measured: [Vector3<f64>; MAX_MODEL_MARKS],
    image: [Vector2<f64>; MAX_MODEL_MARKS],
    n: usize,
}

impl Default for PoseBuffers {
    fn default() -> Self {
        Self::new()
    }
}

impl PoseBuffers {
    /// Empty buffers.
    pub fn new() -> Self {
        Self {
            mark: [0; MAX_MODEL_MARKS],
            model: [Vector3::zeros(); MAX_MODEL_MARKS],
            measured: [Vector3::zeros(); MAX_MODEL_MARKS],
            image: [Vector2::zeros(); MAX_MODEL_MARKS],
            n: 0,
        }
    }

    /// The model marks the last fit used, by index.
    pub fn marks(&self) -> &[usize] {
        &self.mark[..self.n]
    }

    /// The last stereo fit's triangulated mark centres (rover frame, m), in the order of
    /// [`PoseBuffers::marks`]; after a mono fit, the unit rays (camera frame).
    pub fn measured(&self) -> &[Vector3<f64>] {
        &self.measured[..self.n]
    }

    fn push(&mut self, j: usize, model: Vector3<f64>, measured: Vector3<f64>, image: Vector2<f64>) {
        if self.n < MAX_MODEL_MARKS {
            let k = self.n;
            self.mark[k] = j;
            self.model[k] = model;
            self.measured[k] = measured;
            self.image[k] = image;
            self.n += 1;
        }
    }
}

/// Mark j of the model as a module-frame point (0, u, v).
fn model_point(model: &CircleModel, j: usize) -> Vector3<f64> {
    let [u, v] = model.centres()[j];
    Vector3::new(0.0, u, v)
}

/// RMS distance of the model points `pts` (on the face x = 0) from their best line.
fn spread_across_line(pts: &[Vector3<f64>]) -> f64 {
    let n = pts.len() as f64;
    if pts.is_empty() {
        return 0.0;
    }
    let (mu, mv) = pts.iter().fold((0.0, 0.0), |a, p| (a.0 + p.y / n, a.1 + p.z / n));
    let (mut suu, mut suv, mut svv) = (0.0, 0.0, 0.0);
    for p in pts {
        let (du, dv) = (p.y - mu, p.z - mv);
        suu += du * du / n;
        suv += du * dv / n;
        svv += dv * dv / n;
    }
    // Smaller eigenvalue of the 2 × 2 covariance.
    let half_tr = 0.5 * (suu + svv);
    let det = suu * svv - suv * suv;
    let lmin = half_tr - (half_tr * half_tr - det).max(0.0).sqrt();
    lmin.max(0.0).sqrt()
}

/// The rotation nearest `m` (Frobenius), with det = +1.
fn nearest_rotation(m: &Matrix3<f64>) -> Option<Matrix3<f64>> {
    let svd = m.svd(true, true);
    let (u, vt) = (svd.u?, svd.v_t?);
    let mut d = Matrix3::identity();
    if (u * vt).determinant() < 0.0 {
        // Flip the direction of least singular value.
        let k = svd.singular_values.imin();
        d[(k, k)] = -1.0;
    }
    let r = u * d * vt;
    r.iter().all(|x| x.is_finite()).then_some(r)
}

/// The least-squares rigid motion (R, t) with measured ≈ R·model + t (Kabsch; no scale).
/// `None` when the points do not fix a rotation (rank of the cross-covariance below 2).
///
/// Public so the property tests (and anyone with 3-D correspondences) can call it;
/// needs at least 3 non-collinear pairs.
pub fn rigid_fit(model: &[Vector3<f64>], measured: &[Vector3<f64>]) -> Option<(Matrix3<f64>, Vector3<f64>)> {
    if model.len() != measured.len() || model.len() < 3 {
        return None;
    }
    let n = model.len() as f64;
    let cm = model.iter().sum::<Vector3<f64>>() / n;
    let cp = measured.iter().sum::<Vector3<f64>>() / n;
    // H = Σ (m − m̄)(p − p̄)ᵀ = U Σ Vᵀ; R = V D Uᵀ.
    let mut h = Matrix3::zeros();
    for (m, p) in model.iter().zip(measured) {
        h += (m - cm) * (p - cp).transpose();
    }
    if !h.iter().all(|x| x.is_finite()) {
        return None;
    }
    let svd = h.svd(true, true);
    let (u, vt) = (svd.u?, svd.v_t?);
    let s = svd.singular_values;
    let (smax, smin) = (s.max(), s.min());
    let smid = s.sum() - smax - smin;
    if smax.is_nan() || smax <= 0.0 || smid <= 1e-9 * smax {
        return None;
    }
    let v = vt.transpose();
    let ut = u.transpose();
    let mut d = Matrix3::identity();
    if (v * ut).determinant() < 0.0 {
        let k = s.imin();
        d[(k, k)] = -1.0;
    }
    let r = v * d * ut;
    let t = cp - r * cm;
    (r.iter().chain(t.iter()).all(|x| x.is_finite())).then_some((r, t))
}

/// Midpoint of the common perpendicular of the rays o₁ + s·d₁ and o₂ + t·d₂ (unit d),
/// and the rays' distance there; `None` when they are (nearly) parallel or meet behind
/// either origin.
fn ray_midpoint(
    o1: &Vector3<f64>,
    d1: &Vector3<f64>,
    o2: &Vector3<f64>,
    d2: &Vector3<f64>,
) -> Option<(Vector3<f64>, f64)> {
    let w = o1 - o2;
    let b = d1.dot(d2);
    let (dd, e) = (d1.dot(&w), d2.dot(&w));
    let den = 1.0 - b * b;
    if den.is_nan() || den < 1e-10 {
        return None;
    }
    let s = (b * e - dd) / den;
    let t = (e - b * dd) / den;
    if s <= 0.0 || t <= 0.0 {
        return None;
    }
    let p1 = o1 + d1 * s;
    let p2 = o2 + d2 * t;
    Some(((p1 + p2) * 0.5, (p1 - p2).norm()))
}

fn check_lengths(model: &CircleModel, obs: &MarkObservations) -> Result<(), PoseError> {
    if obs.len() != model.len() {
        return Err(PoseError::BadInput {
            what: "observations are for a different number of marks than the model",
        });
    }
    if (0..obs.len())
        .filter_map(|j| obs.get(j))
        .any(|c| !c[0].is_finite() || !c[1].is_finite())
    {
        return Err(PoseError::BadInput {
            what: "an observed centre is not finite",
        });
    }
    Ok(())
}

fn check_spread(buf: &PoseBuffers, params: &PoseParams) -> Result<(), PoseError> {
    let spread = spread_across_line(&buf.model[..buf.n]);
    if spread.is_nan() || spread < params.min_spread_m {
        return Err(PoseError::Collinear {
            spread_m: spread,
            needed_m: params.min_spread_m,
        });
    }
    Ok(())
}

/// Sum of squared pixel reprojection errors and the count, of pose (r, t) through `cam`
/// for the marks `obs` saw.
fn reprojection_ss(
    model: &CircleModel,
    cam: &RigCamera,
    obs: &MarkObservations,
    only: &[usize],
    r: &Matrix3<f64>,
    t: &Vector3<f64>,
) -> (f64, usize) {
    let (mut ss, mut n) = (0.0, 0);
    for &j in only {
        let Some(c) = obs.get(j) else { continue };
        let q = cam.project(&(r * model_point(model, j) + t));
        let e2 = q.map_or(f64::INFINITY, |q| (q[0] - c[0]).powi(2) + (q[1] - c[1]).powi(2));
        ss += e2;
        n += 1;
    }
    (ss, n)
}

/// The module's pose from the marks both cameras of a stereo rig detected (see the
/// module docs): midpoint triangulation, then the least-squares rigid fit.
///
/// `obs[k]` are camera `cams[k]`'s observations. `buf` is overwritten with the marks
/// used and their triangulated points.
///
/// # Errors
/// [`PoseError::BadInput`] for observations not sized to the model or non-finite;
/// [`PoseError::TooFewMarks`] with fewer than 3 marks seen by both cameras and
/// triangulated; [`PoseError::Collinear`] when they lie on a line;
/// [`PoseError::Degenerate`] when the fit fails numerically.
pub fn stereo_pose(
    model: &CircleModel,
    cams: [&RigCamera; 2],
    obs: [&MarkObservations; 2],
    params: &PoseParams,
    buf: &mut PoseBuffers,
) -> Result<ModulePose, PoseError> {
    check_lengths(model, obs[0])?;
    check_lengths(model, obs[1])?;
    buf.n = 0;
    for j in 0..model.len() {
        let (Some(a), Some(b)) = (obs[0].get(j), obs[1].get(j)) else {
            continue;
        };
        let (da, db) = (cams[0].ray(a), cams[1].ray(b));
        let Some((p, gap)) = ray_midpoint(&cams[0].position, &da, &cams[1].position, &db) else {
            continue;
        };
        if gap <= params.max_ray_gap_m {
            buf.push(j, model_point(model, j), p, Vector2::zeros());
        }
    }
    if buf.n < 3 {
        return Err(PoseError::TooFewMarks {
            found: buf.n,
            needed: 3,
        });
    }
    check_spread(buf, params)?;
    let (r, t) = rigid_fit(&buf.model[..buf.n], &buf.measured[..buf.n]).ok_or(PoseError::Degenerate {
        what: "rigid fit (SVD)",
    })?;
    let ss: f64 = (0..buf.n)
        .map(|k| (r * buf.model[k] + t - buf.measured[k]).norm_squared())
        .sum();
    let used = buf.marks();
    let (s0, n0) = reprojection_ss(model, cams[0], obs[0], used, &r, &t);
    let (s1, n1) = reprojection_ss(model, cams[1], obs[1], used, &r, &t);
    Ok(ModulePose {
        rotation: r,
        translation: t,
        source: PoseSource::Stereo,
        marks_used: buf.n,
        rms_residual_m: (ss / buf.n as f64).sqrt(),
        reprojection_px: ((s0 + s1) / (n0 + n1) as f64).sqrt(),
    })
}

/// [r]× such that [r]× v = r × v.
fn skew(r: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -r.z, r.y, r.z, 0.0, -r.x, -r.y, r.x, 0.0)
}

/// The module's planar pose from one camera's detected marks (see the module docs):
/// homography on undistorted normalised coordinates, decomposed, then refined by
/// Gauss–Newton. `camera` is the camera's index in the rig, recorded in the result.
///
/// `buf` is overwritten with the marks used and their unit rays (camera frame).
///
/// # Errors
/// [`PoseError::BadInput`] for observations not sized to the model or non-finite;
/// [`PoseError::TooFewMarks`] with fewer than 4 marks in front of the camera;
/// [`PoseError::Collinear`] when they lie on a line; [`PoseError::Degenerate`] when the
/// homography or its decomposition fails or puts the module behind the camera.
pub fn mono_pose(
    model: &CircleModel,
    cam: &RigCamera,
    camera: usize,
    obs: &MarkObservations,
    params: &PoseParams,
    buf: &mut PoseBuffers,
) -> Result<ModulePose, PoseError> {
    check_lengths(model, obs)?;
    buf.n = 0;
    for j in 0..model.len() {
        let Some(c) = obs.get(j) else { continue };
        let ray = cam.model.ray(c[0], c[1]);
        if !(ray.z > 1e-6 && ray.iter().all(|x| x.is_finite())) {
            continue; // at or beyond 90° off axis: no normalised image point
        }
        buf.push(
            j,
            model_point(model, j),
            ray,
            Vector2::new(ray.x / ray.z, ray.y / ray.z),
        );
    }
    if buf.n < 4 {
        return Err(PoseError::TooFewMarks {
            found: buf.n,
            needed: 4,
        });
    }
    check_spread(buf, params)?;
    // Face (u, v) → normalised image (x, y).
    let mut src = [[0.0; 2]; MAX_MODEL_MARKS];
    let mut dst = [[0.0; 2]; MAX_MODEL_MARKS];
    for k in 0..buf.n {
        src[k] = [buf.model[k].y, buf.model[k].z];
        dst[k] = [buf.image[k].x, buf.image[k].y];
    }
    let h = Homography::fit(&src[..buf.n], &dst[..buf.n], &[])
        .ok_or(PoseError::Degenerate { what: "homography" })?
        .0;
    let (h1, h2, h3) = (
        h.column(0).into_owned(),
        h.column(1).into_owned(),
        h.column(2).into_owned(),
    );
    let norm = 0.5 * (h1.norm() + h2.norm());
    if norm.is_nan() || norm < 1e-12 {
        return Err(PoseError::Degenerate {
            what: "homography scale",
        });
    }
    let lambda = if h3.z < 0.0 { -1.0 / norm } else { 1.0 / norm };
    let (ry, rz) = (h1 * lambda, h2 * lambda);
    let approx = Matrix3::from_columns(&[ry.cross(&rz), ry, rz]);
    let mut r = nearest_rotation(&approx).ok_or(PoseError::Degenerate {
        what: "rotation from the homography",
    })?;
    let mut t = h3 * lambda;
    // Gauss–Newton on the normalised reprojection error; the rotation is updated on the
    // left, R ← exp([ω]×)·R, so ∂X/∂ω = −[R·m]× and ∂X/∂t = I.
    for _ in 0..params.mono_iterations {
        let mut jtj = Matrix6::<f64>::zeros();
        let mut jte = Vector6::<f64>::zeros();
        for k in 0..buf.n {
            let rm = r * buf.model[k];
            let x = rm + t;
            if x.z <= 1e-9 {
                return Err(PoseError::Degenerate {
                    what: "a mark behind the camera",
                });
            }
            let iz = 1.0 / x.z;
            let e = Vector2::new(x.x * iz, x.y * iz) - buf.image[k];
            // ∂(x/z, y/z)/∂X.
            let dp = nalgebra::Matrix2x3::new(iz, 0.0, -x.x * iz * iz, 0.0, iz, -x.y * iz * iz);
            let dw = dp * (-skew(&rm));
            let mut jac = nalgebra::Matrix2x6::<f64>::zeros();
            jac.fixed_view_mut::<2, 3>(0, 0).copy_from(&dw);
            jac.fixed_view_mut::<2, 3>(0, 3).copy_from(&dp);
            jtj += jac.transpose() * jac;
            jte += jac.transpose() * e;
        }
        let Some(chol) = jtj.cholesky() else { break };
        let step = -chol.solve(&jte);
        if !step.iter().all(|x| x.is_finite()) {
            break;
        }
        let w = Vector3::new(step[0], step[1], step[2]);
        r = nalgebra::Rotation3::new(w).matrix() * r;
        t += Vector3::new(step[3], step[4], step[5]);
        if step.norm() < 1e-12 {
            break;
        }
    }
    let mut ss = 0.0;
    for k in 0..buf.n {
        let x = r * buf.model[k] + t;
        if x.z <= 1e-9 || !x.iter().all(|v| v.is_finite()) {
            return Err(PoseError::Degenerate {
                what: "a mark behind the camera",
            });
        }
        // Distance from the point to the ray through its detection.
        let d = buf.measured[k];
        ss += (x - d * x.dot(&d)).norm_squared();
    }
    let rotation = cam.body_from_camera * r;
    let translation = cam.body_from_camera * t + cam.position;
    let (sp, np) = reprojection_ss(model, cam, obs, &buf.mark[..buf.n], &rotation, &translation);
    Ok(ModulePose {
        rotation,
        translation,
        source: PoseSource::Mono { camera },
        marks_used: buf.n,
        rms_residual_m: (ss / buf.n as f64).sqrt(),
        reprojection_px: (sp / np as f64).sqrt(),
    })
}

/// The pose from whatever the rig saw: [`stereo_pose`] when both cameras saw enough
/// common marks, otherwise [`mono_pose`] from the camera that detected more marks
/// (camera 0 on a tie), so losing the module from one camera near the dock does not lose
/// the pose.
///
/// # Errors
/// The mono fallback's error when neither works (or the stereo error when neither camera
/// alone has 4 marks).
pub fn module_pose(
    model: &CircleModel,
    cams: [&RigCamera; 2],
    obs: [&MarkObservations; 2],
    params: &PoseParams,
    buf: &mut PoseBuffers,
) -> Result<ModulePose, PoseError> {
    let stereo = stereo_pose(model, cams, obs, params, buf);
    if stereo.is_ok() {
        return stereo;
    }
    let k = if obs[1].count() > obs[0].count() { 1 } else { 0 };
    match mono_pose(model, cams[k], k, obs[k], params, buf) {
        Ok(p) => Ok(p),
        Err(PoseError::TooFewMarks { .. }) if matches!(stereo, Err(PoseError::Collinear { .. })) => stereo,
        Err(e) => Err(e),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::perception::camera_model::Pinhole;
    use nalgebra::Rotation3;

    fn cam(y: f64) -> RigCamera {
        RigCamera::new(
            CameraModel::Pinhole(Pinhole {
                fx: 512.0,
                fy: 512.0,
                cx: 512.0,
                cy: 384.0,
                k1: 0.0,
                k2: 0.0,
            }),
            MountAngles {
                pitch_deg: 5.0,
                ..Default::default()
            },
            [0.0, y, 0.35],
        )
    }

    fn model() -> CircleModel {
        use super::super::detect::MarkRotation::*;
        CircleModel::new(
            0.05,
            &[
                ([-0.38, 0.85], Zero),
                ([-0.10, 0.92], Plus45),
                ([0.22, 0.88], Ninety),
                ([0.40, 0.70], Minus45),
                ([-0.42, 0.50], Ninety),
                ([-0.05, 0.60], Zero),
                ([0.30, 0.45], Plus45),
                ([0.05, 0.32], Minus45),
            ],
        )
        .unwrap()
    }

    /// The module 2 m ahead, facing the rover, turned 10°.
    fn truth() -> (Matrix3<f64>, Vector3<f64>) {
        let r = Rotation3::from_axis_angle(&Vector3::z_axis(), std::f64::consts::PI + 0.17);
        (*r.matrix(), Vector3::new(2.0, 0.1, 0.0))
    }

    fn observe(m: &CircleModel, c: &RigCamera, r: &Matrix3<f64>, t: &Vector3<f64>) -> MarkObservations {
        let mut o = MarkObservations::new(m.len());
        for j in 0..m.len() {
            o.set(j, c.project(&(r * model_point(m, j) + t)));
        }
        o
    }

    #[test]
    fn exact_observations_give_the_exact_pose_stereo_and_mono() {
        let m = model();
        let (l, rt) = (cam(0.175), cam(-0.175));
        let (r, t) = truth();
        let (ol, or) = (observe(&m, &l, &r, &t), observe(&m, &rt, &r, &t));
        assert_eq!(ol.count(), 8);
        let mut buf = PoseBuffers::new();
        let p = stereo_pose(&m, [&l, &rt], [&ol, &or], &PoseParams::default(), &mut buf).unwrap();
        assert!(
            (p.rotation - r).norm() < 1e-9 && (p.translation - t).norm() < 1e-9,
            "{p:?}"
        );
        assert_eq!((p.marks_used, p.source), (8, PoseSource::Stereo));
        assert!(p.reprojection_px < 1e-6 && p.rms_residual_m < 1e-9);
        assert!((p.heading() - wrap(std::f64::consts::PI + 0.17)).abs() < 1e-9);
        let q = mono_pose(&m, &rt, 1, &or, &PoseParams::default(), &mut buf).unwrap();
        assert!(
            (q.rotation - r).norm() < 1e-9 && (q.translation - t).norm() < 1e-9,
            "{q:?}"
        );
        assert_eq!(q.source, PoseSource::Mono { camera: 1 });
        // The rover in the module frame: the inverse.
        let [x, y, h] = p.rover_in_module();
        let back = r.transpose() * (Vector3::zeros() - t);
        assert!((x - back.x).abs() < 1e-9 && (y - back.y).abs() < 1e-9);
        assert!((h - wrap(-(std::f64::consts::PI + 0.17))).abs() < 1e-9);
    }

    fn wrap(a: f64) -> f64 {
        (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
    }

    #[test]
    fn degenerate_input_is_refused_with_a_typed_error() {
        let m = model();
        let (l, rt) = (cam(0.175), cam(-0.175));
        let (r, t) = truth();
        let (full_l, full_r) = (observe(&m, &l, &r, &t), observe(&m, &rt, &r, &t));
        let mut buf = PoseBuffers::new();
        let params = PoseParams::default();
        // Two common marks only.
        let mut ol = MarkObservations::new(8);
        ol.set(0, full_l.get(0));
        ol.set(1, full_l.get(1));
        ol.set(2, full_l.get(2));
        let mut or = MarkObservations::new(8);
        or.set(1, full_r.get(1));
        or.set(2, full_r.get(2));
        or.set(3, full_r.get(3));
        assert_eq!(
            stereo_pose(&m, [&l, &rt], [&ol, &or], &params, &mut buf),
            Err(PoseError::TooFewMarks { found: 2, needed: 3 })
        );
        // Three collinear model marks: a model with marks 0, 1, 2 on a line.
        use super::super::detect::MarkRotation::*;
        let line = CircleModel::new(
            0.05,
            &[
                ([-0.4, 0.5], Zero),
                ([0.0, 0.5], Plus45),
                ([0.4, 0.5], Ninety),
                ([0.2, 0.9], Minus45),
                ([-0.2, 0.9], Zero),
            ],
        )
        .unwrap();
        let (a, b) = (observe(&line, &l, &r, &t), observe(&line, &rt, &r, &t));
        let mut a3 = MarkObservations::new(5);
        let mut b3 = MarkObservations::new(5);
        for j in 0..3 {
            a3.set(j, a.get(j));
            b3.set(j, b.get(j));
        }
        assert!(matches!(
            stereo_pose(&line, [&l, &rt], [&a3, &b3], &params, &mut buf),
            Err(PoseError::Collinear { .. })
        ));
        assert!(matches!(
            mono_pose(&line, &l, 0, &a3, &params, &mut buf),
            Err(PoseError::TooFewMarks { found: 3, needed: 4 })
        ));
        // Wrong size and NaN.
        assert!(matches!(
            stereo_pose(&m, [&l, &rt], [&a, &b], &params, &mut buf),
            Err(PoseError::BadInput { .. })
        ));
        let mut nan = full_l;
        nan.set(4, Some([f64::NAN, 1.0]));
        assert!(matches!(
            mono_pose(&m, &l, 0, &nan, &params, &mut buf),
            Err(PoseError::BadInput { .. })
        ));
        // A mislabelled mark in one camera is dropped by the ray gap, not fitted.
        let mut swapped = full_r;
        swapped.set(0, full_r.get(7));
        let p = stereo_pose(&m, [&l, &rt], [&full_l, &swapped], &params, &mut buf).unwrap();
        assert_eq!(p.marks_used, 7);
        assert!(!buf.marks().contains(&0));
        // Fallback: nothing common, the camera with more marks alone.
        let empty = MarkObservations::new(8);
        let p = module_pose(&m, [&l, &rt], [&empty, &full_r], &params, &mut buf).unwrap();
        assert_eq!(p.source, PoseSource::Mono { camera: 1 });
        assert!(matches!(
            module_pose(&m, [&l, &rt], [&empty, &empty], &params, &mut buf),
            Err(PoseError::TooFewMarks { .. })
        ));
    }
}
