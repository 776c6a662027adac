//! A tag's pose from its four corners, the camera's intrinsics and the tag's size, with
//! its covariance.
//!
//! **Frames.** The *tag frame* has its origin at the tag's centre, +x to the tag's right
//! and +y up as it is printed, +z out of its face towards whoever reads it (OpenCV's
//! ArUco convention); the black border's outer corners are (∓s/2, ±s/2, 0), top-left
//! first and then clockwise as seen (TL, TR, BR, BL), s = the tag's size. The *camera
//! frame* is the pin-hole's: +x right, +y down, +z forward along the optical axis. A
//! [`TagPose`] maps tag points into the camera frame: p_cam = R·p_tag + t. A tag facing
//! the camera upright has R = diag(1, −1, −1).
//!
//! **Method** (ALGORITHMS.md §7). The corners are undistorted onto the normalised image
//! plane ([`Pinhole::ray`]). The homography from the tag's plane to it ([`Homography::fit`],
//! exact with four points) is ∝ [r₁ r₂ t]; its scale is the mean of ‖h₁‖ and ‖h₂‖, the
//! sign puts the tag in front of the camera, and the nearest rotation (SVD) to
//! [r₁ r₂ r₁×r₂] starts Levenberg–Marquardt on the reprojection error in pixels
//! (normalised residuals times fx, fy). A planar square has two minima (the tag tilted
//! one way or its mirror about the line of sight, Schweighofer & Pinz 2006): the start is
//! also reflected about the line of sight and refined, and the lower error wins;
//! [`TagPose::alternative_px`] keeps the other's error when it is a distinct pose.
//!
//! **Covariance.** With J the 8 × 6 Jacobian of the pixel residuals at the optimum, for
//! the perturbation R ← exp(\[δθ\]×)·R, t ← t + δt (δθ in radians about the camera's axes,
//! δt in metres in the camera frame), Σ = σ²·(JᵀJ)⁻¹ for independent corner noise σ px
//! on each coordinate: the first-order covariance of the least-squares pose. Order
//! [δθx, δθy, δθz, δtx, δty, δtz].
//!
//! Simplified: distortion enters through the undistorted corners only; the Jacobian is
//! the ideal pin-hole's at the undistorted points.

use crate::perception::camera_model::Pinhole;
use crate::perception::circles::Homography;
use nalgebra::{Matrix2x3, Matrix3, Matrix6, SMatrix, Vector3, Vector6};

/// A tag's pose in the camera frame (see the module docs for both frames).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TagPose {
    /// Rotation taking tag-frame vectors to the camera frame.
    pub rotation: Matrix3<f64>,
    /// The tag's centre in the camera frame, m.
    pub translation: Vector3<f64>,
    /// Covariance of [δθx, δθy, δθz (rad), δtx, δty, δtz (m)], camera frame.
    pub covariance: Matrix6<f64>,
    /// RMS distance between the corners and the posed tag's, px.
    pub reprojection_px: f64,
    /// RMS reprojection error of the other planar minimum, px, when it is a distinct pose
    /// (its rotation more than 1° away): near 1× `reprojection_px` means ambiguous.
    pub alternative_px: Option<f64>,
}

impl TagPose {
    /// The largest standard deviation of the position over any direction, m (the square
    /// root of the translation block's largest eigenvalue; NaN when it is not finite).
    pub fn position_sigma_m(&self) -> f64 {
        block_sigma(&self.covariance.fixed_view::<3, 3>(3, 3).into_owned())
    }

    /// The largest standard deviation of the rotation about any axis, rad.
    pub fn angle_sigma_rad(&self) -> f64 {
        block_sigma(&self.covariance.fixed_view::<3, 3>(0, 0).into_owned())
    }

    /// True when every number of the pose and its covariance is finite.
    pub fn is_finite(&self) -> bool {
        self.rotation
            .iter()
            .chain(self.translation.iter())
            .chain(self.covariance.iter())
            .all(|v| v.is_finite())
            && self.reprojection_px.is_finite()
    }
}

fn block_sigma(b: &Matrix3<f64>) -> f64 {
    if b.iter().any(|v| !v.is_finite()) {
        return f64::NAN;
    }
    let sym = (b + b.transpose()) * 0.5;
    sym.symmetric_eigenvalues().max().max(0.0).sqrt()
}

/// The tag-frame corners of a tag of side `size_m`: TL, TR, BR, BL.
pub fn tag_corners(size_m: f64) -> [Vector3<f64>; 4] {
    let h = 0.5 * size_m;
    [
        Vector3::new(-h, h, 0.0),
        Vector3::new(h, h, 0.0),
        Vector3::new(h, -h, 0.0),
        Vector3::new(-h, -h, 0.0),
    ]
}

fn nearest_rotation(m: &Matrix3<f64>) -> Option<Matrix3<f64>> {
    let svd = m.svd(true, true);
    let (u, vt) = (svd.u?, svd.v_t?);
    let mut r = u * vt;
    if r.determinant() < 0.0 {
        let mut u2 = u;
        u2.column_mut(2).neg_mut();
        r = u2 * vt;
    }
    Some(r)
}

fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// Residuals (px) and Jacobian of the 4 corners at (r, t); `None` when a corner is behind
/// the camera.
fn residuals(
    r: &Matrix3<f64>,
    t: &Vector3<f64>,
    obj: &[Vector3<f64>; 4],
    img: &[[f64; 2]; 4],
    f: (f64, f64),
) -> Option<(SMatrix<f64, 8, 1>, SMatrix<f64, 8, 6>)> {
    let mut res = SMatrix::<f64, 8, 1>::zeros();
    let mut jac = SMatrix::<f64, 8, 6>::zeros();
    for k in 0..4 {
        let rx = r * obj[k];
        let p = rx + t;
        if p.z <= 1e-9 {
            return None;
        }
        let (x, y) = (p.x / p.z, p.y / p.z);
        res[2 * k] = f.0 * (x - img[k][0]);
        res[2 * k + 1] = f.1 * (y - img[k][1]);
        let dp = Matrix2x3::new(f.0 / p.z, 0.0, -f.0 * x / p.z, 0.0, f.1 / p.z, -f.1 * y / p.z);
        let dth = dp * (-skew(&rx));
        jac.fixed_view_mut::<2, 3>(2 * k, 0).copy_from(&dth);
        jac.fixed_view_mut::<2, 3>(2 * k, 3).copy_from(&dp);
    }
    Some((res, jac))
}

/// A refined pose: rotation, translation, RMS reprojection error (px), Jacobian.
type Refined = (Matrix3<f64>, Vector3<f64>, f64, SMatrix<f64, 8, 6>);

/// Levenberg–Marquardt from (r, t): the refined pose, its residual and Jacobian.
fn refine(
    mut r: Matrix3<f64>,
    mut t: Vector3<f64>,
    obj: &[Vector3<f64>; 4],
    img: &[[f64; 2]; 4],
    f: (f64, f64),
) -> Option<Refined> {
    let (mut res, mut jac) = residuals(&r, &t, obj, img, f)?;
    let mut cost = res.norm_squared();
    let mut lambda = 1e-3;
    for _ in 0..50 {
        let jtj = jac.transpose() * jac;
        let g = jac.transpose() * res;
        let mut a = jtj;
        for i in 0..6 {
            a[(i, i)] += lambda * jtj[(i, i)].max(1e-12);
        }
        let Some(step) = a.cholesky().map(|c| c.solve(&(-g))) else {
            lambda *= 10.0;
            continue;
        };
        let dth = Vector3::new(step[0], step[1], step[2]);
        let rn = nalgebra::Rotation3::new(dth).into_inner() * r;
        let tn = t + Vector3::new(step[3], step[4], step[5]);
        match residuals(&rn, &tn, obj, img, f) {
            Some((rs, jc)) if rs.norm_squared() <= cost => {
                let gain = cost - rs.norm_squared();
                (r, t, res, jac, cost) = (rn, tn, rs, jc, rs.norm_squared());
                lambda = (lambda * 0.3).max(1e-9);
                if step.norm() < 1e-12 || gain <= 1e-16 * cost.max(1e-30) {
                    break;
                }
            }
            _ => {
                lambda *= 10.0;
                if lambda > 1e8 {
                    break;
                }
            }
        }
    }
    Some((r, t, (cost / 4.0).sqrt(), jac))
}

/// The pose of a tag of side `size_m` whose corners (TL, TR, BR, BL as the tag is
/// printed, px) are `corners`, seen through `camera`, with corner noise `sigma_px`.
/// `None` when the corners give no homography, or the tag would be behind the camera.
pub fn tag_pose(corners: &[[f64; 2]; 4], camera: &Pinhole, size_m: f64, sigma_px: f64) -> Option<TagPose> {
    if !(size_m > 0.0 && size_m.is_finite()) || corners.iter().flatten().any(|v| !v.is_finite()) {
        return None;
    }
    let obj = tag_corners(size_m);
    let mut img = [[0.0; 2]; 4];
    for (i, c) in corners.iter().enumerate() {
        let ray = camera.ray(c[0], c[1]);
        if ray.z <= 1e-9 {
            return None;
        }
        img[i] = [ray.x / ray.z, ray.y / ray.z];
    }
    let src = obj.map(|p| [p.x, p.y]);
    let h = Homography::fit(&src, &img, &[])?.0;
    let (h1, h2, h3) = (
        h.column(0).into_owned(),
        h.column(1).into_owned(),
        h.column(2).into_owned(),
    );
    let mut scale = 2.0 / (h1.norm() + h2.norm());
    if h3.z * scale < 0.0 {
        scale = -scale;
    }
    let (r1, r2) = (h1 * scale, h2 * scale);
    let r0 = nearest_rotation(&Matrix3::from_columns(&[r1, r2, r1.cross(&r2)]))?;
    let t0 = h3 * scale;
    let f = (camera.fx, camera.fy);
    let a = refine(r0, t0, &obj, &img, f);
    // The mirror start: the tag's normal reflected about the line of sight.
    let v = t0.normalize();
    let n1 = r0.column(2).into_owned();
    let n2 = v * (2.0 * n1.dot(&v)) - n1;
    let axis = n1.cross(&n2);
    let b = if axis.norm() > 1e-9 {
        let ang = n1.dot(&n2).clamp(-1.0, 1.0).acos();
        let rot = nalgebra::Rotation3::new(axis.normalize() * ang).into_inner();
        refine(rot * r0, t0, &obj, &img, f)
    } else {
        None
    };
    let (best, other) = match (a, b) {
        (Some(a), Some(b)) if b.2 < a.2 => (b, Some(a)),
        (Some(a), b) => (a, b),
        (None, Some(b)) => (b, None),
        (None, None) => return None,
    };
    let alternative_px = other.and_then(|o| {
        let d = nalgebra::Rotation3::from_matrix_unchecked(best.0.transpose() * o.0).angle();
        (d > 1f64.to_radians()).then_some(o.2)
    });
    let jtj = best.3.transpose() * best.3;
    let covariance = jtj
        .try_inverse()
        .map_or(Matrix6::repeat(f64::NAN), |inv| inv * (sigma_px * sigma_px));
    Some(TagPose {
        rotation: best.0,
        translation: best.1,
        covariance,
        reprojection_px: best.2,
        alternative_px,
    })
}

/// The pixels of the corners (TL, TR, BR, BL) of a tag of side `size_m` posed at
/// (`rotation`, `translation`) in front of `camera`: the forward model the fit inverts.
/// `None` when a corner is behind the camera.
pub fn project_corners(
    camera: &Pinhole,
    rotation: &Matrix3<f64>,
    translation: &Vector3<f64>,
    size_m: f64,
) -> Option<[[f64; 2]; 4]> {
    let obj = tag_corners(size_m);
    let mut out = [[0.0; 2]; 4];
    for (o, p) in out.iter_mut().zip(&obj) {
        *o = camera.project(&(rotation * p + translation))?;
    }
    Some(out)
}

/// The standard deviations of the six pose parameters (square roots of the covariance's
/// diagonal, in its order): what a log or a filter's measurement noise wants.
pub fn sigmas(pose: &TagPose) -> Vector6<f64> {
    pose.covariance.diagonal().map(|v| v.max(0.0).sqrt())
}
