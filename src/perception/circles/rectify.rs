//! Detections moved onto the lens's ideal pin-hole image, where the face's marks obey a
//! homography, so that the correspondence can label them through a distorting lens.
//!
//! The correspondence ([`super::correspond()`]) fits a homography from the face to the
//! image. A homography maps a plane to a *pin-hole* image; through Axel's 3.5 mm
//! fish-eye (about 90°) the marks bend away from it by several pixels off the centre of
//! the view, more than the closeness gate (0.3 of a mark's projected radius). With 6 or
//! more marks the trimmed refit absorbs that, but with exactly 5 (3 covered) the fit has
//! 2 redundant degrees of freedom, the bend pushes one mark out of its gate, and the
//! frame is refused: 10 of the 36 five-mark frames of `axel-occlusion` were, and all 36
//! are labelled through the lens (README, "axel-occlusion").
//!
//! [`LensPlane`] maps each detection's centre through the camera's model to its ray and
//! back through the model's distortion-free pin-hole ([`CameraModel::ideal_pinhole`]),
//! and each ellipse through the local Jacobian of that map, so the shape check compares
//! like with like. [`correspond_through`] labels on those, then maps the reprojected
//! model back into the camera's own pixels: a [`ModelFit`] from it is in image pixels, as
//! one from [`super::correspond()`] on an undistorted camera is.
//!
//! The seed's correspondence had no distortion model (seed 000 §III.A.3, §V-D); this is
//! ours. A pin-hole camera without distortion is passed through untouched.

use super::correspond::{CorrespondenceError, CorrespondenceParams, MAX_DETECTIONS, ModelFit, correspond};
use super::detect::DetectedMark;
use super::ellipse::Ellipse;
use super::model::CircleModel;
use crate::perception::camera_model::{CameraModel, Pinhole};
use nalgebra::{Matrix2, SymmetricEigen};

/// Half the step of the central differences for an ellipse's Jacobian, px: small
/// against the lens's curvature, large against rounding.
const JACOBIAN_STEP_PX: f64 = 0.5;

/// One camera's lens and a buffer for its detections moved onto the ideal pin-hole
/// image; sized once, so labelling allocates nothing per frame.
#[derive(Debug, Clone)]
pub struct LensPlane {
    camera: CameraModel,
    ideal: Pinhole,
    marks: Vec<DetectedMark>,
}

impl LensPlane {
    /// The plane of `camera`'s ideal pin-hole ([`CameraModel::ideal_pinhole`]).
    pub fn new(camera: CameraModel) -> Self {
        Self {
            ideal: camera.ideal_pinhole(),
            camera,
            marks: Vec::with_capacity(MAX_DETECTIONS),
        }
    }

    /// Image pixel → ideal pin-hole pixel, or `None` for a ray the pin-hole cannot show
    /// (90° or more off its axis).
    pub fn to_ideal(&self, px: [f64; 2]) -> Option<[f64; 2]> {
        self.ideal.project(&self.camera.ray(px[0], px[1]))
    }

    /// Ideal pin-hole pixel → image pixel, or `None` outside the lens's field of view.
    pub fn to_image(&self, px: [f64; 2]) -> Option<[f64; 2]> {
        self.camera.project(&self.ideal.ray(px[0], px[1]))
    }

    /// `marks` moved onto the ideal pin-hole image, index for index. A mark whose centre
    /// the pin-hole cannot show keeps its place with a non-finite centre and no
    /// rotation, which the correspondence never matches. An undistorted pin-hole camera
    /// returns `marks` itself. At most [`MAX_DETECTIONS`] are moved, as many as the
    /// correspondence considers.
    pub fn rectify<'a>(&'a mut self, marks: &'a [DetectedMark]) -> &'a [DetectedMark] {
        if self.camera.is_ideal_pinhole() {
            return marks;
        }
        self.marks.clear();
        for m in marks.iter().take(MAX_DETECTIONS) {
            let moved = self.moved(m).unwrap_or(DetectedMark {
                centre: [f64::NAN; 2],
                ellipse: Ellipse {
                    centre: [f64::NAN; 2],
                    ..m.ellipse
                },
                rotation: None,
                ..*m
            });
            self.marks.push(moved);
        }
        &self.marks
    }

    /// One mark moved: its centre through the map, its ellipse through the map's Jacobian
    /// there (its second-moment matrix E becomes J·E·Jᵀ).
    fn moved(&self, m: &DetectedMark) -> Option<DetectedMark> {
        let c = self.to_ideal(m.centre)?;
        let h = JACOBIAN_STEP_PX;
        let [x0, x1, y0, y1] =
            [[-h, 0.0], [h, 0.0], [0.0, -h], [0.0, h]].map(|d| self.to_ideal([m.centre[0] + d[0], m.centre[1] + d[1]]));
        let (x0, x1, y0, y1) = (x0?, x1?, y0?, y1?);
        let jac = Matrix2::new(
            (x1[0] - x0[0]) / (2.0 * h),
            (y1[0] - y0[0]) / (2.0 * h),
            (x1[1] - x0[1]) / (2.0 * h),
            (y1[1] - y0[1]) / (2.0 * h),
        );
        let ellipse = mapped_ellipse(&m.ellipse, c, &jac)?;
        Some(DetectedMark {
            centre: c,
            ellipse,
            ..*m
        })
    }
}

/// `e` pushed through a linear map `jac` about its centre, re-centred at `centre`: the
/// second-moment matrix E = R·diag(a², b²)·Rᵀ becomes J·E·Jᵀ, whose eigenvectors and
/// eigenvalues give the new axes. `None` when the result is degenerate or not finite.
fn mapped_ellipse(e: &Ellipse, centre: [f64; 2], jac: &Matrix2<f64>) -> Option<Ellipse> {
    let (s, c) = e.angle.sin_cos();
    let rot = Matrix2::new(c, -s, s, c);
    let m = rot * Matrix2::new(e.semi_major.powi(2), 0.0, 0.0, e.semi_minor.powi(2)) * rot.transpose();
    let mapped = jac * m * jac.transpose();
    let eig = SymmetricEigen::new(mapped);
    let (major, minor) = if eig.eigenvalues[0] >= eig.eigenvalues[1] {
        (0, 1)
    } else {
        (1, 0)
    };
    let (l1, l2) = (eig.eigenvalues[major], eig.eigenvalues[minor]);
    if !(l2 > 0.0 && l1.is_finite()) {
        return None;
    }
    let v = eig.eigenvectors.column(major);
    let mut angle = v[1].atan2(v[0]);
    // Into (−π/2, π/2], as [`Ellipse::angle`] is given.
    if angle <= -std::f64::consts::FRAC_PI_2 {
        angle += std::f64::consts::PI;
    } else if angle > std::f64::consts::FRAC_PI_2 {
        angle -= std::f64::consts::PI;
    }
    Some(Ellipse {
        centre,
        semi_major: l1.sqrt(),
        semi_minor: l2.sqrt(),
        angle,
    })
}

/// Labels `marks`, detected in the image of `lens`'s camera, against `model`: the
/// correspondence of [`super::correspond()`] on the marks moved onto the lens's ideal
/// pin-hole image (see the module docs). The fit's reprojected model
/// ([`ModelFit::projected`], so the filled-in centres) and its RMS are in the camera's own
/// pixels; its homography maps the face onto the ideal pin-hole image.
///
/// # Errors
/// As [`super::correspond()`].
pub fn correspond_through(
    model: &CircleModel,
    marks: &[DetectedMark],
    lens: &mut LensPlane,
    params: &CorrespondenceParams,
) -> Result<ModelFit, CorrespondenceError> {
    if lens.camera.is_ideal_pinhole() {
        return correspond(model, marks, params);
    }
    let mut fit = correspond(model, lens.rectify(marks), params)?;
    fit.map_to_image(marks, |p| lens.to_image(p));
    Ok(fit)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::perception::circles::RigCamera;
    use crate::perception::circles::correspond::tests::axel_model;
    use crate::perception::{Fisheye, MountAngles};
    use nalgebra::Vector3;

    /// A 90° fish-eye like Axel's: ρ = f·θ-ish through a polynomial f(ρ) = a0 + a2·ρ².
    fn fisheye() -> CameraModel {
        CameraModel::Fisheye(Fisheye::new(
            vec![-650.0, 0.0, 4.0e-4],
            [512.0, 384.0],
            [1.0, 0.0, 0.0],
            700.0,
        ))
    }

    #[test]
    fn a_mapped_ellipse_is_the_image_of_the_circle() {
        // Under a shear-and-scale J, a circle of radius 2 maps to the ellipse whose
        // second-moment matrix is 4·J·Jᵀ.
        let e = Ellipse {
            centre: [0.0, 0.0],
            semi_major: 2.0,
            semi_minor: 2.0,
            angle: 0.0,
        };
        let jac = Matrix2::new(2.0, 1.0, 0.0, 1.0);
        let m = mapped_ellipse(&e, [5.0, 6.0], &jac).unwrap();
        let want = SymmetricEigen::new(jac * jac.transpose() * 4.0).eigenvalues;
        let (hi, lo) = (want.max(), want.min());
        assert!((m.semi_major - hi.sqrt()).abs() < 1e-9 && (m.semi_minor - lo.sqrt()).abs() < 1e-9);
        assert_eq!(m.centre, [5.0, 6.0]);
        // A rotation keeps the axes and turns the angle.
        let e = Ellipse {
            semi_minor: 1.0,
            angle: 0.3,
            ..e
        };
        let (s, c) = 0.5f64.sin_cos();
        let m = mapped_ellipse(&e, [0.0, 0.0], &Matrix2::new(c, -s, s, c)).unwrap();
        assert!((m.semi_major - 2.0).abs() < 1e-9 && (m.semi_minor - 1.0).abs() < 1e-9);
        assert!((m.angle - 0.8).abs() < 1e-9, "{}", m.angle);
        assert!(mapped_ellipse(&e, [0.0, 0.0], &Matrix2::zeros()).is_none());
    }

    #[test]
    fn the_ideal_plane_round_trips_and_an_undistorted_pinhole_is_untouched() {
        let lens = LensPlane::new(fisheye());
        for p in [[512.0, 384.0], [100.0, 80.0], [900.0, 700.0], [520.0, 60.0]] {
            let q = lens.to_ideal(p).unwrap();
            let back = lens.to_image(q).unwrap();
            assert!(
                (back[0] - p[0]).hypot(back[1] - p[1]) < 0.05,
                "{p:?} → {q:?} → {back:?}"
            );
        }
        let pin = CameraModel::Pinhole(Pinhole {
            fx: 500.0,
            fy: 500.0,
            cx: 320.0,
            cy: 240.0,
            k1: 0.0,
            k2: 0.0,
        });
        let mut lens = LensPlane::new(pin);
        let marks = [DetectedMark {
            centre: [3.0, 4.0],
            ellipse: Ellipse {
                centre: [3.0, 4.0],
                semi_major: 2.0,
                semi_minor: 1.0,
                angle: 0.0,
            },
            rotation: None,
            bar_angle_deg: 0.0,
            bar_anisotropy: 0.0,
            contrast: 0.0,
            fit_rms_px: 0.0,
        }];
        assert!(std::ptr::eq(lens.rectify(&marks), &marks[..]));
    }

    /// Five of the eight marks seen through a fish-eye, near the top of the view where it
    /// bends most: labelled through the lens, while the plain correspondence on the same
    /// pixels refuses it (the bend pushes a mark out of its gate). Every filled-in mark
    /// lands on the true image of its mark.
    #[test]
    fn five_marks_through_a_fisheye_are_labelled_through_the_lens() {
        let model = axel_model();
        let cam = RigCamera::new(fisheye(), MountAngles::default(), [0.0; 3]);
        // The face 1.6 m ahead, well above the axis and to the side, turned 20° about
        // the vertical: camera frame x right, y down, z forward.
        let (s, c) = 20f64.to_radians().sin_cos();
        let face_at = |uv: [f64; 2]| Vector3::new(-0.55 + c * uv[0], -0.95 - uv[1], 1.6 + s * uv[0]);
        let image = |uv: [f64; 2]| cam.model.project(&face_at(uv)).unwrap();
        let mark = |j: usize| {
            let uv = model.centres()[j];
            let r = model.radius_m();
            let pts: Vec<[f64; 2]> = (0..48)
                .map(|k| {
                    let t = k as f64 / 48.0 * std::f64::consts::TAU;
                    image([uv[0] + r * t.cos(), uv[1] + r * t.sin()])
                })
                .collect();
            let e = crate::perception::circles::fit_ellipse(&pts).unwrap().ellipse;
            DetectedMark {
                centre: image(uv),
                ellipse: e,
                rotation: Some(model.rotations()[j]),
                bar_angle_deg: 0.0,
                bar_anisotropy: 0.8,
                contrast: 100.0,
                fit_rms_px: 0.1,
            }
        };
        let mut refused_plain = 0;
        let mut tried = 0;
        // Every set of 3 covered marks that leaves 5 of 8.
        for a in 0..8 {
            for b in a + 1..8 {
                for d in b + 1..8 {
                    let seen: Vec<DetectedMark> = (0..8).filter(|j| ![a, b, d].contains(j)).map(mark).collect();
                    tried += 1;
                    let mut lens = LensPlane::new(fisheye());
                    let fit = correspond_through(&model, &seen, &mut lens, &CorrespondenceParams::default())
                        .unwrap_or_else(|e| panic!("covered {a} {b} {d}: {e}"));
                    assert_eq!(fit.inliers, 5);
                    for j in 0..8 {
                        let p = fit.projected()[j];
                        let t = image(model.centres()[j]);
                        assert!((p[0] - t[0]).hypot(p[1] - t[1]) < 0.5, "mark {j}: {p:?} against {t:?}");
                    }
                    assert!(fit.rms_px < 0.2, "{}", fit.rms_px);
                    if correspond(&model, &seen, &CorrespondenceParams::default()).is_err() {
                        refused_plain += 1;
                    }
                }
            }
        }
        // The bend is real: without the lens some of these frames are refused.
        assert!(refused_plain > 0, "0 of {tried} refused without the lens");
    }
}
