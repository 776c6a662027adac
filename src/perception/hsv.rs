//! HSV colour space (RAPOSA segments in HSV, seed 001 §II.C).
//!
//! H in degrees [0, 360) (red 0, green 120, blue 240), S and V in [0, 1], V = max/255.
//! Greys (max = min), including black, have H = 0 and S = 0: their hue is undefined, and
//! HSV segmentation should bound S from below to exclude them.

use super::image::RgbView;
use super::{VisionError, check_same_size};

/// One pixel in HSV.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hsv {
    /// Hue, degrees in [0, 360).
    pub h: f32,
    /// Saturation in [0, 1].
    pub s: f32,
    /// Value in [0, 1].
    pub v: f32,
}

impl Hsv {
    /// HSV of an 8-bit RGB pixel.
    ///
    /// ```
    /// use marsupial::perception::Hsv;
    /// let orange = Hsv::from_rgb([255, 128, 0]);
    /// assert!((orange.h - 30.117647).abs() < 1e-4 && orange.s == 1.0 && orange.v == 1.0);
    /// ```
    #[inline]
    pub fn from_rgb(rgb: [u8; 3]) -> Hsv {
        let [r, g, b] = rgb.map(f32::from);
        let max = r.max(g).max(b);
        let min = r.min(g).min(b);
        let d = max - min;
        let v = max / 255.0;
        if d <= 0.0 {
            return Hsv { h: 0.0, s: 0.0, v };
        }
        let s = d / max;
        let h = if max == r {
            60.0 * ((g - b) / d)
        } else if max == g {
            60.0 * ((b - r) / d + 2.0)
        } else {
            60.0 * ((r - g) / d + 4.0)
        };
        let h = if h < 0.0 { h + 360.0 } else { h };
        Hsv {
            h: if h >= 360.0 { 0.0 } else { h },
            s,
            v,
        }
    }
}

/// A whole frame in HSV, quantised like OpenCV: H in 2° steps (0–179), S and V 0–255.
#[derive(Debug, Clone, Default)]
pub struct HsvPlanes {
    width: usize,
    height: usize,
    /// Hue / 2, 0–179.
    pub h: Vec<u8>,
    /// Saturation × 255.
    pub s: Vec<u8>,
    /// Value × 255.
    pub v: Vec<u8>,
}

impl HsvPlanes {
    /// Planes for a `width × height` frame.
    pub fn new(width: usize, height: usize) -> Self {
        let n = width * height;
        Self {
            width,
            height,
            h: vec![0; n],
            s: vec![0; n],
            v: vec![0; n],
        }
    }

    /// (width, height).
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }
}

/// Converts a frame to quantised HSV (rounding to the nearest step; H = 360° wraps to 0).
///
/// # Errors
/// [`VisionError::SizeMismatch`] when `dst` was made for another size.
///
/// # Example
///
/// A 3×1 frame: orange (H = 30.1°, stored as 15), dark green (H = 120°, stored as 60;
/// V = 100/255) and a dark grey (no hue, no saturation).
///
/// ```
/// use marsupial::perception::{HsvPlanes, RgbImage, hsv_from_rgb};
///
/// let im = RgbImage::from_raw(3, 1, vec![255, 128, 0, 0, 100, 0, 10, 10, 10]).unwrap();
/// let mut planes = HsvPlanes::new(3, 1);
/// hsv_from_rgb(&im.view(), &mut planes).unwrap();
/// assert_eq!(planes.h, vec![15, 60, 0]);
/// assert_eq!(planes.s, vec![255, 255, 0]);
/// assert_eq!(planes.v, vec![255, 100, 10]);
/// ```
pub fn hsv_from_rgb(src: &RgbView<'_>, dst: &mut HsvPlanes) -> Result<(), VisionError> {
    check_same_size((src.width(), src.height()), dst.size())?;
    for (i, px) in src.as_bytes().chunks_exact(3).enumerate() {
        let p = Hsv::from_rgb([px[0], px[1], px[2]]);
        let h = (p.h / 2.0 + 0.5) as u16;
        dst.h[i] = if h >= 180 { 0 } else { h as u8 };
        dst.s[i] = (p.s * 255.0 + 0.5) as u8;
        dst.v[i] = (p.v * 255.0 + 0.5) as u8;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_colours() {
        let h = |c| Hsv::from_rgb(c).h;
        assert_eq!(h([255, 0, 0]), 0.0);
        assert_eq!(h([0, 255, 0]), 120.0);
        assert_eq!(h([0, 0, 255]), 240.0);
        assert_eq!(h([0, 255, 255]), 180.0);
        assert_eq!(h([255, 0, 255]), 300.0);
        assert_eq!(h([255, 255, 0]), 60.0);
        assert!((h([255, 0, 1]) - 359.7647).abs() < 1e-3);
        let black = Hsv::from_rgb([0, 0, 0]);
        assert_eq!((black.h, black.s, black.v), (0.0, 0.0, 0.0));
        let grey = Hsv::from_rgb([128, 128, 128]);
        assert_eq!((grey.h, grey.s), (0.0, 0.0));
        let sat = Hsv::from_rgb([255, 255, 254]);
        assert!(sat.s > 0.0 && sat.s < 0.01 && sat.v == 1.0);
    }

    #[test]
    fn frame_error_is_bounded_over_the_cube() {
        // On all 2²⁴ colours, the quantised planes are within half a step of the exact
        // (f64, rational) values: 1° of hue with wrap-around, half a level of saturation,
        // and V is max(r, g, b) itself. No slack: the exact values lie at least 1/510 of a
        // step from a rounding tie unless on it, far beyond f32's error (< 1e-4 step), so
        // rounding the f32 values never lands on the wrong side.
        crate::perception::image::for_each_cube_slab(|_, slab| {
            let mut p = HsvPlanes::new(slab.width(), slab.height());
            hsv_from_rgb(&slab.view(), &mut p).unwrap();
            for (n, px) in slab.as_bytes().chunks_exact(3).enumerate() {
                let [r, g, b] = [px[0], px[1], px[2]].map(f64::from);
                let (max, min) = (r.max(g).max(b), r.min(g).min(b));
                let d = max - min;
                let h = if d == 0.0 {
                    0.0
                } else if max == r {
                    (60.0 * (g - b) / d).rem_euclid(360.0)
                } else if max == g {
                    60.0 * (b - r) / d + 120.0
                } else {
                    60.0 * (r - g) / d + 240.0
                };
                let s = if max == 0.0 { 0.0 } else { 255.0 * d / max };
                let dh = (f64::from(p.h[n]) * 2.0 - h).abs();
                assert!(dh.min(360.0 - dh) <= 1.0, "{px:?}: H {h}, plane {}", p.h[n]);
                assert!(
                    (f64::from(p.s[n]) - s).abs() <= 0.5,
                    "{px:?}: S·255 {s}, plane {}",
                    p.s[n]
                );
                assert_eq!(f64::from(p.v[n]), max, "{px:?}");
            }
        });
    }

    #[test]
    fn frame_quantisation() {
        let im = crate::perception::RgbImage::from_raw(3, 1, vec![255, 0, 1, 0, 0, 255, 10, 10, 10]).unwrap();
        let mut p = HsvPlanes::new(3, 1);
        hsv_from_rgb(&im.view(), &mut p).unwrap();
        assert_eq!(p.h, vec![0, 120, 0]); // 359.8° rounds to 180 → wraps to 0
        assert_eq!(p.s, vec![255, 255, 0]);
        assert_eq!(p.v[2], 10);
    }
}
