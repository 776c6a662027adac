//! Camera projection models and mounting poses.
//!
//! Camera frame: +x right in the image, +y down, +z forward along the optical axis.
//! Pixel coordinates: (u, v) = (column, row), with pixel centres at integer + 0.5.
//!
//! * [`Pinhole`]: focal lengths, principal point and Brown radial distortion (k1, k2).
//! * [`Fisheye`]: Scaramuzza's unified omnidirectional model (OCamCalib): a pixel maps to
//!   the ray (x, y, −f(ρ)) with f(ρ) = a0 + a1·ρ + a2·ρ² + … (a0 < 0 in OCamCalib's frame,
//!   whose optical axis is −z; here it is flipped to +z), after an affine correction
//!   [[c, d], [e, 1]] about the distortion centre. Projection inverts f numerically via a
//!   monotonic table of the ray's off-axis angle.

use nalgebra::{Matrix3, Rotation3, Vector3};

/// Pin-hole model with radial distortion.
///
/// # Example
///
/// Without distortion, the point (0.5, −0.2, 2) m projects to
/// (100·0.5/2 + 80, 100·(−0.2)/2 + 60) = (105, 50), and the ray through that pixel points
/// back at it.
///
/// ```
/// use marsupial::perception::Pinhole;
/// use nalgebra::Vector3;
///
/// let cam = Pinhole { fx: 100.0, fy: 100.0, cx: 80.0, cy: 60.0, k1: 0.0, k2: 0.0 };
/// let p = Vector3::new(0.5, -0.2, 2.0);
/// let [u, v] = cam.project(&p).unwrap();
/// assert!((u - 105.0).abs() < 1e-12 && (v - 50.0).abs() < 1e-12);
/// assert!((cam.ray(u, v) - p.normalize()).norm() < 1e-12);
/// assert_eq!(cam.project(&Vector3::new(0.0, 0.0, -1.0)), None, "behind the camera");
///
/// // Barrel distortion (k1 < 0) pulls off-axis points toward the centre, and `ray`
/// // undoes it.
/// let barrel = Pinhole { k1: -0.2, ..cam };
/// let [ud, vd] = barrel.project(&p).unwrap();
/// assert!(ud < u && vd > v);
/// assert!((barrel.ray(ud, vd) - p.normalize()).norm() < 1e-9);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pinhole {
    /// Focal length x, px.
    pub fx: f64,
    /// Focal length y, px.
    pub fy: f64,
    /// Principal point x, px.
    pub cx: f64,
    /// Principal point y, px.
    pub cy: f64,
    /// Radial k1.
    pub k1: f64,
    /// Radial k2.
    pub k2: f64,
}

impl Pinhole {
    /// A camera without distortion, focal length `f` px in both axes, its principal
    /// point the centre of a `width` × `height` image (pixel centres at integers).
    pub fn ideal(f: f64, width: usize, height: usize) -> Self {
        Self {
            fx: f,
            fy: f,
            cx: (width as f64 - 1.0) / 2.0,
            cy: (height as f64 - 1.0) / 2.0,
            k1: 0.0,
            k2: 0.0,
        }
    }

    /// Pixel of a camera-frame point, or `None` behind the camera.
    pub fn project(&self, p: &Vector3<f64>) -> Option<[f64; 2]> {
        if p.z <= 1e-9 {
            return None;
        }
        let (x, y) = (p.x / p.z, p.y / p.z);
        let r2 = x * x + y * y;
        let d = 1.0 + self.k1 * r2 + self.k2 * r2 * r2;
        Some([self.fx * x * d + self.cx, self.fy * y * d + self.cy])
    }

    /// Unit ray through pixel (u, v) (undistorted by fixed-point iteration).
    pub fn ray(&self, u: f64, v: f64) -> Vector3<f64> {
        let (xd, yd) = ((u - self.cx) / self.fx, (v - self.cy) / self.fy);
        let (mut x, mut y) = (xd, yd);
        if self.k1 != 0.0 || self.k2 != 0.0 {
            for _ in 0..20 {
                let r2 = x * x + y * y;
                let d = 1.0 + self.k1 * r2 + self.k2 * r2 * r2;
                x = xd / d;
                y = yd / d;
            }
        }
        Vector3::new(x, y, 1.0).normalize()
    }
}

/// Scaramuzza omnidirectional model (see the module docs).
///
/// # Example
///
/// With the constant polynomial f(ρ) = −100 a pixel ρ px off centre maps to the ray
/// (x, y, 100): the model reduces to a pin-hole of focal length 100 px, so the point that
/// [`Pinhole`]'s example projects to (105, 50) lands there too (within the inverse table's
/// interpolation).
///
/// ```
/// use marsupial::perception::Fisheye;
/// use nalgebra::Vector3;
///
/// let cam = Fisheye::new(vec![-100.0], [80.0, 60.0], [1.0, 0.0, 0.0], 400.0);
/// assert!((cam.max_angle() - 4f64.atan()).abs() < 1e-9); // ρ up to 400 px
/// assert!((cam.ray(80.0, 60.0) - Vector3::z()).norm() < 1e-12);
/// let [u, v] = cam.project(&Vector3::new(0.5, -0.2, 2.0)).unwrap();
/// assert!((u - 105.0).abs() < 0.01 && (v - 50.0).abs() < 0.01, "({u}, {v})");
/// assert_eq!(cam.project(&Vector3::new(1.0, 0.0, 0.0)), None, "90° off axis: outside");
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Fisheye {
    /// f(ρ) coefficients a0, a1, a2 …
    pub poly: Vec<f64>,
    /// Distortion centre (u, v), px.
    pub center: [f64; 2],
    /// Affine (c, d, e).
    pub affine: [f64; 3],
    /// Table of ρ against the off-axis angle θ, for projection.
    inverse: Vec<(f64, f64)>,
}

impl Fisheye {
    /// Builds the model; the inverse table covers ρ from 0 to `max_rho` px.
    pub fn new(poly: Vec<f64>, center: [f64; 2], affine: [f64; 3], max_rho: f64) -> Self {
        let mut f = Self {
            poly,
            center,
            affine,
            inverse: Vec::new(),
        };
        let n = 2048;
        let mut last = -1.0;
        for i in 0..=n {
            let rho = max_rho * i as f64 / n as f64;
            let theta = rho.atan2(-f.f(rho));
            if theta <= last {
                break; // the polynomial stops being monotonic: beyond the valid field of view
            }
            last = theta;
            f.inverse.push((theta, rho));
        }
        f
    }

    fn f(&self, rho: f64) -> f64 {
        self.poly.iter().rev().fold(0.0, |acc, a| acc * rho + a)
    }

    /// Largest off-axis angle the model covers, rad.
    pub fn max_angle(&self) -> f64 {
        self.inverse.last().map_or(0.0, |t| t.0)
    }

    /// Unit ray through pixel (u, v).
    pub fn ray(&self, u: f64, v: f64) -> Vector3<f64> {
        let [c, d, e] = self.affine;
        let (du, dv) = (u - self.center[0], v - self.center[1]);
        let inv = 1.0 / (c - d * e);
        let (x, y) = (inv * (du - d * dv), inv * (-e * du + c * dv));
        let rho = x.hypot(y);
        Vector3::new(x, y, -self.f(rho)).normalize()
    }

    /// Pixel of a camera-frame point, or `None` outside the modelled field of view.
    pub fn project(&self, p: &Vector3<f64>) -> Option<[f64; 2]> {
        let n = p.x.hypot(p.y);
        let theta = n.atan2(p.z);
        let table = &self.inverse;
        if table.len() < 2 || theta > self.max_angle() {
            return None;
        }
        let i = table.partition_point(|t| t.0 < theta).clamp(1, table.len() - 1);
        let ((t0, r0), (t1, r1)) = (table[i - 1], table[i]);
        let rho = r0 + (r1 - r0) * (theta - t0) / (t1 - t0);
        let (x, y) = if n > 1e-12 {
            (p.x / n * rho, p.y / n * rho)
        } else {
            (0.0, 0.0)
        };
        let [c, d, e] = self.affine;
        Some([c * x + d * y + self.center[0], e * x + y + self.center[1]])
    }
}

/// A camera model. A profile's `[[cameras]]` entry gives one through
/// `CameraModel::from_spec` (in `profile`).
///
/// # Example
///
/// ```
/// use marsupial::perception::{CameraModel, Pinhole};
/// use nalgebra::Vector3;
///
/// let cam = CameraModel::Pinhole(Pinhole { fx: 100.0, fy: 100.0, cx: 80.0, cy: 60.0, k1: 0.0, k2: 0.0 });
/// // A point one metre ahead, 0.1 m right: 10 px right of the principal point.
/// let [u, v] = cam.project(&Vector3::new(0.1, 0.0, 1.0)).unwrap();
/// assert!((u - 90.0).abs() < 1e-12 && (v - 60.0).abs() < 1e-12);
/// assert!((cam.ray(90.0, 60.0) - Vector3::new(0.1, 0.0, 1.0).normalize()).norm() < 1e-12);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub enum CameraModel {
    /// Pin-hole.
    Pinhole(Pinhole),
    /// Omnidirectional.
    Fisheye(Fisheye),
}

impl CameraModel {
    /// Pixel of a camera-frame point.
    pub fn project(&self, p: &Vector3<f64>) -> Option<[f64; 2]> {
        match self {
            CameraModel::Pinhole(m) => m.project(p),
            CameraModel::Fisheye(m) => m.project(p),
        }
    }

    /// Unit ray through a pixel position.
    pub fn ray(&self, u: f64, v: f64) -> Vector3<f64> {
        match self {
            CameraModel::Pinhole(m) => m.ray(u, v),
            CameraModel::Fisheye(m) => m.ray(u, v),
        }
    }

    /// The distortion-free pin-hole that agrees with this model on its optical axis: a
    /// pin-hole's own intrinsics without k1, k2; a fish-eye's on-axis focal length
    /// (−a0 of its polynomial, since f(ρ) ≈ a0 near the centre) and its distortion
    /// centre. Straight lines stay straight through it, so a homography holds between a
    /// plane and this camera's image (what the circle correspondence fits); it is also
    /// what a pose that ignores the distortion assumes.
    pub fn ideal_pinhole(&self) -> Pinhole {
        match self {
            CameraModel::Pinhole(m) => Pinhole { k1: 0.0, k2: 0.0, ..*m },
            CameraModel::Fisheye(m) => {
                let f = -m.poly.first().copied().unwrap_or(-1.0);
                Pinhole {
                    fx: f,
                    fy: f,
                    cx: m.center[0],
                    cy: m.center[1],
                    k1: 0.0,
                    k2: 0.0,
                }
            }
        }
    }

    /// Whether the model has no distortion (a pin-hole with k1 = k2 = 0), so that its
    /// image already is its [`CameraModel::ideal_pinhole`]'s.
    pub fn is_ideal_pinhole(&self) -> bool {
        matches!(self, CameraModel::Pinhole(m) if m.k1 == 0.0 && m.k2 == 0.0)
    }
}

/// Where a camera looks on its body: the orientation part of a mounting, in degrees as a
/// profile's `[cameras.mount]` gives it (a `&profile::Mount` converts into it).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MountAngles {
    /// Yaw about body +z, degrees (0 looks forward, 180 backward).
    pub yaw_deg: f64,
    /// Pitch, degrees (positive looks down).
    pub pitch_deg: f64,
    /// Roll about the optical axis, degrees (180 turns the image upside down).
    pub roll_deg: f64,
}

impl MountAngles {
    /// True when the image is upside down (roll near ±180°).
    pub fn is_flipped(&self) -> bool {
        let r = self.roll_deg.rem_euclid(360.0);
        (r - 180.0).abs() < 90.0
    }
}

/// Rotation taking camera-frame vectors to the body frame, for a mount.
///
/// With yaw = pitch = roll = 0 the camera looks along body +x with image right = body −y
/// and image down = body −z. Then: yaw about body +z, pitch about the body's (yawed) +y
/// (positive looks down), roll about the optical axis (180° turns the image upside down).
///
/// # Example
///
/// A forward camera, and a rear camera rolled upside down (Bujold's): the rear camera
/// looks along body −x, and its image right is body −y again.
///
/// ```
/// use marsupial::perception::{MountAngles, body_from_camera};
/// use nalgebra::Vector3;
///
/// let fwd = body_from_camera(MountAngles::default());
/// assert!((fwd * Vector3::z() - Vector3::x()).norm() < 1e-12, "optical axis: body +x");
/// assert!((fwd * Vector3::x() + Vector3::y()).norm() < 1e-12, "image right: body −y");
///
/// let rear = MountAngles { yaw_deg: 180.0, pitch_deg: 0.0, roll_deg: 180.0 };
/// assert!(rear.is_flipped() && !MountAngles::default().is_flipped());
/// let r = body_from_camera(rear);
/// assert!((r * Vector3::z() + Vector3::x()).norm() < 1e-12, "optical axis: body −x");
/// assert!((r * Vector3::x() + Vector3::y()).norm() < 1e-12, "image right: body −y");
/// ```
pub fn body_from_camera(mount: impl Into<MountAngles>) -> Matrix3<f64> {
    let mount = mount.into();
    let r0 = Matrix3::new(0.0, 0.0, 1.0, -1.0, 0.0, 0.0, 0.0, -1.0, 0.0);
    let yaw = Rotation3::from_axis_angle(&Vector3::z_axis(), mount.yaw_deg.to_radians());
    let pitch = Rotation3::from_axis_angle(&Vector3::y_axis(), mount.pitch_deg.to_radians());
    let roll = Rotation3::from_axis_angle(&Vector3::z_axis(), mount.roll_deg.to_radians());
    yaw.matrix() * pitch.matrix() * r0 * roll.matrix()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pinhole_round_trip_with_distortion() {
        let m = Pinhole {
            fx: 300.0,
            fy: 310.0,
            cx: 160.0,
            cy: 120.0,
            k1: -0.2,
            k2: 0.05,
        };
        for (u, v) in [(160.0, 120.0), (10.0, 5.0), (300.0, 230.0)] {
            let r = m.ray(u, v);
            let p = m.project(&(r * 3.0)).unwrap();
            assert!((p[0] - u).abs() < 1e-6 && (p[1] - v).abs() < 1e-6, "{p:?}");
        }
        assert!(m.project(&Vector3::new(0.0, 0.0, -1.0)).is_none());
    }

    #[test]
    fn fisheye_round_trip() {
        let m = Fisheye::new(
            vec![-175.0, 0.0, 1.6e-3, -1.2e-6, 2.5e-9],
            [320.0, 240.0],
            [1.0, 0.0, 0.0],
            800.0,
        );
        assert!(m.max_angle() > 1.5, "{}", m.max_angle());
        for (u, v) in [(320.0, 240.0), (100.0, 50.0), (600.0, 400.0), (330.0, 260.0)] {
            let r = m.ray(u, v);
            let p = m.project(&r).unwrap();
            assert!((p[0] - u).abs() < 0.05 && (p[1] - v).abs() < 0.05, "({u},{v}) → {p:?}");
        }
        let axis = m.ray(320.0, 240.0);
        assert!((axis - Vector3::z()).norm() < 1e-12);
    }

    #[test]
    fn mounts() {
        let fwd = body_from_camera(MountAngles::default());
        assert!((fwd * Vector3::z() - Vector3::x()).norm() < 1e-12);
        assert!(
            (fwd * Vector3::x() + Vector3::y()).norm() < 1e-12,
            "image right is body −y"
        );
        let back = body_from_camera(MountAngles {
            yaw_deg: 180.0,
            roll_deg: 180.0,
            ..Default::default()
        });
        assert!((back * Vector3::z() + Vector3::x()).norm() < 1e-12, "looks backwards");
        // Rolled 180°: image right is body −y again when looking backwards, image down is up.
        assert!((back * Vector3::x() + Vector3::y()).norm() < 1e-12);
        assert!((back * Vector3::y() - Vector3::z()).norm() < 1e-12);
        let down = body_from_camera(MountAngles {
            pitch_deg: 30.0,
            ..Default::default()
        });
        assert!((down * Vector3::z()).z < -0.49);
    }
}
