//! Axle roll ψ and drop d from each axle's plate-marker pair (seed 003 §V-A).
//!
//! Each marker centre is back-projected through the camera model (for the AutoKrawler,
//! the Scaramuzza fisheye) to a ray from the camera, turned into the body frame, and
//! intersected with its axle's plane: the paper's y = +c (front) or −c (rear), which in
//! our frame (x forward, y left, z up; paper (x, y, z) = ours (−y, x, z)) is x = ±c with
//! c half the wheelbase. ψ is the directed angle of the difference vector (left minus
//! right) from the lateral axis, positive when the left marker is higher (our roll about
//! +x, the paper's about its y); d is the camera's height above the pair's midpoint, the
//! axle's roll centre.

use crate::perception::camera_model::CameraModel;
use nalgebra::{Matrix3, Point3, Vector3};

/// What the back-projection needs: the camera, where it sits on the body, and the axles'
/// planes.
#[derive(Debug, Clone)]
pub struct AxleGeometry {
    /// The camera's projection model (pixel → unit ray in the camera frame).
    pub model: CameraModel,
    /// Rotation taking camera-frame vectors to the body frame.
    pub body_from_camera: Matrix3<f64>,
    /// The camera's centre in the body frame, m.
    pub camera: Point3<f64>,
    /// The axles' planes x = `axle_x[0]` (front) and `axle_x[1]` (rear), body frame, m:
    /// the paper's ±c.
    pub axle_x: [f64; 2],
}

/// One axle's roll and drop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxlePose {
    /// Roll ψ, rad, positive lifting the left side.
    pub roll: f64,
    /// Vertical distance from the camera down to the marker pair's midpoint, m.
    pub drop: f64,
    /// The two marker centres (left, right) on the axle's plane, body frame, m.
    pub markers: [Point3<f64>; 2],
}

impl AxleGeometry {
    /// Where the ray through pixel `at` meets the plane x = `plane_x` (body frame), or
    /// `None` when the ray runs parallel to it or meets it behind the camera.
    pub fn on_plane(&self, at: [f64; 2], plane_x: f64) -> Option<Point3<f64>> {
        let ray: Vector3<f64> = self.body_from_camera * self.model.ray(at[0], at[1]);
        if ray.x.abs() < 1e-12 {
            return None;
        }
        let t = (plane_x - self.camera.x) / ray.x;
        (t > 0.0).then(|| self.camera + ray * t)
    }

    /// Roll and drop of `axle` (0 front, 1 rear) from its left and right plate markers'
    /// pixel centres; `None` when either ray misses the plane.
    pub fn axle_pose(&self, axle: usize, left: [f64; 2], right: [f64; 2]) -> Option<AxlePose> {
        let plane = self.axle_x[axle];
        let (l, r) = (self.on_plane(left, plane)?, self.on_plane(right, plane)?);
        let v = l - r;
        let mid = nalgebra::center(&l, &r);
        Some(AxlePose {
            roll: v.z.atan2(v.y),
            drop: self.camera.z - mid.z,
            markers: [l, r],
        })
    }
}
