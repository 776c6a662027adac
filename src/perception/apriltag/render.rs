//! A reference renderer: a tag drawn through a pin-hole camera with antialiasing.
//!
//! For tests and benches (and as the simplest model of what a camera sees): each pixel
//! near the tag's image is split into `supersample²` sub-pixels, each sub-pixel's ray is
//! cut with the tag's plane, and the cell it lands in (black or white, the white ring
//! included) or the frame's own pixel (outside the tag) is averaged. Rays go through
//! [`Pinhole::ray`], so a distorting lens is rendered as the detector will undo it. The
//! frames are those of [`super::pose`]: the tag's +z out of its face, p_cam = R·p_tag + t.

use super::family::TagFamily;
use super::pose::tag_corners;
use crate::perception::RgbImage;
use crate::perception::camera_model::Pinhole;
use nalgebra::{Matrix3, Vector3};

/// Grey of the tag's black cells (not 0: printed black reflects some light).
pub const INK: u8 = 25;
/// Grey of the tag's white cells and ring.
pub const PAPER: u8 = 225;

/// Which tag to draw, and how finely.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TagSprite {
    /// The tag's family.
    pub family: TagFamily,
    /// The tag's id in its family.
    pub id: u32,
    /// Side of the black border, m (the white ring adds a cell each side).
    pub size_m: f64,
    /// Sub-pixels per pixel side (1–16; 4 is smooth enough for sub-pixel tests).
    pub supersample: usize,
}

/// Draws `tag` into `image` at pose (`rotation`, `translation`), camera frame. Returns
/// false (and draws nothing) when the id is not in the family or the tag is not in
/// front of the camera.
pub fn draw_tag(
    image: &mut RgbImage,
    camera: &Pinhole,
    tag: &TagSprite,
    rotation: &Matrix3<f64>,
    translation: &Vector3<f64>,
) -> bool {
    let (family, size_m, supersample) = (tag.family, tag.size_m, tag.supersample);
    let Some(grid) = family.cell_grid(tag.id) else {
        return false;
    };
    let n = family.cells() as f64;
    let cell = size_m / n;
    // The outer corners of the white ring bound the pixels to visit.
    let ring = tag_corners(size_m + 2.0 * cell);
    let (mut x0, mut y0, mut x1, mut y1) = (f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY);
    for c in &ring {
        let Some(p) = camera.project(&(rotation * c + translation)) else {
            return false;
        };
        x0 = x0.min(p[0]);
        y0 = y0.min(p[1]);
        x1 = x1.max(p[0]);
        y1 = y1.max(p[1]);
    }
    let (w, h) = (image.width(), image.height());
    if w == 0 || h == 0 || x1 < 0.0 || y1 < 0.0 || x0 >= w as f64 || y0 >= h as f64 {
        return true;
    }
    let normal = rotation.column(2).into_owned();
    let rt = rotation.transpose();
    let ss = supersample.clamp(1, 16);
    let (px0, py0) = ((x0 - 2.0).max(0.0) as usize, (y0 - 2.0).max(0.0) as usize);
    let (px1, py1) = (((x1 + 2.0) as usize).min(w - 1), ((y1 + 2.0) as usize).min(h - 1));
    let nd = n as isize;
    for py in py0..=py1 {
        for px in px0..=px1 {
            let bg = image.view().get(px, py).unwrap_or([0; 3]);
            let mut acc = [0u32; 3];
            for sy in 0..ss {
                for sx in 0..ss {
                    let u = px as f64 - 0.5 + (sx as f64 + 0.5) / ss as f64;
                    let v = py as f64 - 0.5 + (sy as f64 + 0.5) / ss as f64;
                    let d = camera.ray(u, v);
                    let den = normal.dot(&d);
                    let mut colour = bg;
                    if den.abs() > 1e-12 {
                        let lam = normal.dot(translation) / den;
                        if lam > 0.0 {
                            let q = rt * (d * lam - translation);
                            // Cell coordinates: x right, y down from the border's corner.
                            let cx = ((q.x + 0.5 * size_m) / cell).floor() as isize;
                            let cy = ((0.5 * size_m - q.y) / cell).floor() as isize;
                            if (-1..=nd).contains(&cx) && (-1..=nd).contains(&cy) {
                                let inside = (0..nd).contains(&cx) && (0..nd).contains(&cy);
                                let white = !inside || grid[cy as usize][cx as usize] == 1;
                                colour = [if white { PAPER } else { INK }; 3];
                            }
                        }
                    }
                    for k in 0..3 {
                        acc[k] += colour[k] as u32;
                    }
                }
            }
            let m = (ss * ss) as u32;
            image.put(px, py, acc.map(|a| ((a + m / 2) / m) as u8));
        }
    }
    true
}
