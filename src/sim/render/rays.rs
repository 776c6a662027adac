//! The camera's per-pixel rays, computed once when a renderer is built.
//!
//! Stored as separate arrays per component (structure of arrays) so the row kernels in
//! [`super::hits`] read them as contiguous runs of `f32`, which the compiler turns into
//! vector code. Any camera model (pin-hole with distortion, fisheye) becomes the same table.

use crate::perception::camera_model::CameraModel;

/// Unit rays in the camera frame and each pixel's angular size, row-major.
#[derive(Debug, Clone)]
pub(super) struct RayTable {
    width: usize,
    /// Ray x components.
    pub x: Vec<f32>,
    /// Ray y components.
    pub y: Vec<f32>,
    /// Ray z components (along the optical axis for a pin-hole camera).
    pub z: Vec<f32>,
    /// Angular size of the pixel, rad.
    pub ang: Vec<f32>,
    /// 1 / `ang`: turns a distance into pixel footprints without a division per pixel.
    pub inv_ang: Vec<f32>,
}

/// One row's span of the ray table.
#[derive(Debug, Clone, Copy)]
pub(super) struct RowRays<'a> {
    /// Ray x components.
    pub x: &'a [f32],
    /// Ray y components.
    pub y: &'a [f32],
    /// Ray z components.
    pub z: &'a [f32],
    /// Angular pixel size, rad.
    pub ang: &'a [f32],
    /// Its inverse.
    pub inv_ang: &'a [f32],
}

impl RayTable {
    /// The rays through the centres of a `width × height` image of `model`.
    pub fn new(model: &CameraModel, width: usize, height: usize) -> Self {
        let n = width * height;
        let mut t = Self {
            width,
            x: Vec::with_capacity(n),
            y: Vec::with_capacity(n),
            z: Vec::with_capacity(n),
            ang: Vec::with_capacity(n),
            inv_ang: Vec::with_capacity(n),
        };
        for yy in 0..height {
            for xx in 0..width {
                let (u, v) = (xx as f64 + 0.5, yy as f64 + 0.5);
                let r = model.ray(u, v);
                let r1 = model.ray(u + 1.0, v);
                let ang = r.angle(&r1).max(1e-5) as f32;
                t.x.push(r.x as f32);
                t.y.push(r.y as f32);
                t.z.push(r.z as f32);
                t.ang.push(ang);
                t.inv_ang.push(1.0 / ang);
            }
        }
        t
    }

    /// Pixels `x0..x1` of row `y`.
    #[inline]
    pub fn row(&self, y: usize, x0: usize, x1: usize) -> RowRays<'_> {
        let (s, e) = (y * self.width + x0, y * self.width + x1);
        RowRays {
            x: &self.x[s..e],
            y: &self.y[s..e],
            z: &self.z[s..e],
            ang: &self.ang[s..e],
            inv_ang: &self.inv_ang[s..e],
        }
    }
}
