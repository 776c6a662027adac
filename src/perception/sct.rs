//! The Spherical Coordinate Transform (Umbaugh; seed 004 §IV.A).
//!
//! L = √(r² + g² + b²), angle A = acos(b / L), angle B = atan(g / r).
//! We compute the equivalent, better-conditioned forms A = atan2(√(r² + g²), b) and
//! B = atan2(g, r) (ALGORITHMS §3), which are defined everywhere: black (0, 0, 0) maps to
//! A = B = 0 with L = 0, and pure blue (r = g = 0) to B = 0. Both angles lie in [0, π/2]
//! for 8-bit RGB, so they never wrap. Dark pixels carry no usable chromaticity; the
//! segmenter gates them out with a minimum L.

use super::fastmath::atan2_pos;
use super::image::RgbView;
use super::{VisionError, check_same_size};

/// Quantisation of angles into `u8` bins: 256 bins over [0, π/2] (≈ 0.35° per bin).
pub const ANGLE_BINS_PER_RAD: f32 = 255.0 / std::f32::consts::FRAC_PI_2;

/// One pixel in SCT space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sct {
    /// Brightness √(r² + g² + b²), 0 to 441.7 for 8-bit input.
    pub l: f64,
    /// Angle between the colour vector and the blue axis, radians in [0, π/2].
    pub a: f64,
    /// Angle of the colour's projection onto the r-g plane from the red axis, radians in [0, π/2].
    pub b: f64,
}

impl Sct {
    /// Exact SCT of an 8-bit RGB pixel (double precision).
    ///
    /// ```
    /// use marsupial::perception::Sct;
    /// let grey = Sct::from_rgb([100, 100, 100]);
    /// assert!((grey.a.to_degrees() - 54.7356).abs() < 1e-3);
    /// assert!((grey.b.to_degrees() - 45.0).abs() < 1e-9);
    /// ```
    pub fn from_rgb(rgb: [u8; 3]) -> Sct {
        let [r, g, b] = rgb.map(f64::from);
        let rg = r.hypot(g);
        Sct {
            l: (r * r + g * g + b * b).sqrt(),
            a: rg.atan2(b),
            b: g.atan2(r),
        }
    }

    /// Fast SCT (f32, polynomial arctangent): angles within 0.00151 rad of [`Sct::from_rgb`].
    ///
    /// ```
    /// use marsupial::perception::Sct;
    /// // L = √(30² + 40² + 120²) = 130, A = atan(50/120), B = atan(40/30).
    /// let (l, a, b) = Sct::from_rgb_fast([30, 40, 120]);
    /// assert_eq!(l, 130.0);
    /// assert!((a as f64 - (50f64 / 120.0).atan()).abs() < 0.0015);
    /// assert!((b as f64 - (40f64 / 30.0).atan()).abs() < 0.0015);
    /// ```
    #[inline]
    pub fn from_rgb_fast(rgb: [u8; 3]) -> (f32, f32, f32) {
        let [r, g, b] = rgb.map(f32::from);
        let rg2 = r * r + g * g;
        let rg = rg2.sqrt();
        ((rg2 + b * b).sqrt(), atan2_pos(rg, b), atan2_pos(g, r))
    }
}

/// A whole frame in SCT space, quantised: L as `u16` (rounded), A and B as `u8` bins of
/// [`ANGLE_BINS_PER_RAD`]. Buffers are reused across frames.
#[derive(Debug, Clone, Default)]
pub struct SctPlanes {
    width: usize,
    height: usize,
    /// Brightness per pixel.
    pub l: Vec<u16>,
    /// Angle A per pixel, in bins.
    pub a: Vec<u8>,
    /// Angle B per pixel, in bins.
    pub b: Vec<u8>,
}

impl SctPlanes {
    /// Planes for a `width × height` frame.
    pub fn new(width: usize, height: usize) -> Self {
        let n = width * height;
        Self {
            width,
            height,
            l: vec![0; n],
            a: vec![0; n],
            b: vec![0; n],
        }
    }

    /// (width, height).
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }
}

/// Converts a frame to SCT with the fast path. Each angle is within 0.00151 rad plus half a
/// bin (0.0031 rad) of the exact value.
///
/// # Errors
/// [`VisionError::SizeMismatch`] when `dst` was made for another size.
///
/// # Example
///
/// A 2×2 frame of red, green, blue and black. Red and green lie on the r-g plane
/// (A = π/2, the last bin), blue on the blue axis (A = 0); B is 0 for red and π/2 for
/// green. Black is L = 0 with both angles 0.
///
/// ```
/// use marsupial::perception::{RgbImage, SctPlanes, VisionError, sct_from_rgb};
///
/// let im = RgbImage::from_raw(2, 2, vec![255, 0, 0, 0, 255, 0, 0, 0, 255, 0, 0, 0]).unwrap();
/// let mut planes = SctPlanes::new(2, 2);
/// sct_from_rgb(&im.view(), &mut planes).unwrap();
/// assert_eq!(planes.l, vec![255, 255, 255, 0]);
/// assert_eq!(planes.a, vec![255, 255, 0, 0]);
/// assert_eq!(planes.b, vec![0, 255, 0, 0]);
/// // Planes sized for another frame are refused.
/// assert!(matches!(
///     sct_from_rgb(&im.view(), &mut SctPlanes::new(3, 2)),
///     Err(VisionError::SizeMismatch { .. })
/// ));
/// ```
pub fn sct_from_rgb(src: &RgbView<'_>, dst: &mut SctPlanes) -> Result<(), VisionError> {
    check_same_size((src.width(), src.height()), dst.size())?;
    for (i, px) in src.as_bytes().chunks_exact(3).enumerate() {
        let (l, a, b) = Sct::from_rgb_fast([px[0], px[1], px[2]]);
        dst.l[i] = (l + 0.5) as u16;
        dst.a[i] = (a * ANGLE_BINS_PER_RAD + 0.5) as u8;
        dst.b[i] = (b * ANGLE_BINS_PER_RAD + 0.5) as u8;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    #[test]
    fn known_colours() {
        let deg = |s: Sct| (s.a.to_degrees(), s.b.to_degrees());
        let close = |(a, b): (f64, f64), (ea, eb): (f64, f64)| (a - ea).abs() < 1e-9 && (b - eb).abs() < 1e-9;
        assert!(close(deg(Sct::from_rgb([255, 0, 0])), (90.0, 0.0)));
        assert!(close(deg(Sct::from_rgb([0, 255, 0])), (90.0, 90.0)));
        assert!(close(deg(Sct::from_rgb([0, 0, 255])), (0.0, 0.0)));
        assert!(close(deg(Sct::from_rgb([0, 255, 255])), (45.0, 90.0))); // cyan
        assert!(close(deg(Sct::from_rgb([255, 0, 255])), (45.0, 0.0))); // magenta
        assert!(close(deg(Sct::from_rgb([255, 255, 0])), (90.0, 45.0))); // yellow
        let black = Sct::from_rgb([0, 0, 0]);
        assert_eq!((black.l, black.a, black.b), (0.0, 0.0, 0.0));
        let white = Sct::from_rgb([255, 255, 255]);
        assert!((white.l - 441.6729559300637).abs() < 1e-9);
        assert!((white.a - (2f64.sqrt()).atan()).abs() < 1e-12);
    }

    #[test]
    fn intensity_invariant() {
        let a = Sct::from_rgb([40, 80, 20]);
        let b = Sct::from_rgb([120, 240, 60]);
        assert!((a.a - b.a).abs() < 1e-12 && (a.b - b.b).abs() < 1e-12);
        assert!((b.l / a.l - 3.0).abs() < 1e-12);
    }

    #[test]
    fn fast_path_error_is_bounded_over_the_cube() {
        // All 2²⁴ colours: the angles within the documented 0.00151 rad of the f64 ones and
        // inside [0, π/2]; L is one f32 square root of an exact integer (< 2²⁴), so it is
        // the exact L correctly rounded, within half an f32 ulp.
        let worst = std::sync::Mutex::new(0.0f64);
        crate::perception::image::for_each_cube_slab(|_, slab| {
            let mut w = 0.0f64;
            for px in slab.as_bytes().chunks_exact(3) {
                let rgb = [px[0], px[1], px[2]];
                let e = Sct::from_rgb(rgb);
                let (l, a, bb) = Sct::from_rgb_fast(rgb);
                assert!((l as f64 - e.l).abs() <= e.l * f64::from(f32::EPSILON) / 2.0, "{rgb:?}");
                w = w.max((a as f64 - e.a).abs()).max((bb as f64 - e.b).abs());
                assert!(
                    (0.0..=FRAC_PI_2 as f32).contains(&a) && (0.0..=FRAC_PI_2 as f32).contains(&bb),
                    "{rgb:?}"
                );
            }
            let mut worst = worst.lock().unwrap();
            *worst = worst.max(w);
        });
        let worst = *worst.lock().unwrap();
        assert!(worst <= 0.00151, "{worst}");
    }

    #[test]
    fn frame_conversion_matches_per_pixel() {
        let mut im = crate::perception::RgbImage::new(4, 2);
        let colours = [
            [0, 0, 0],
            [255, 255, 255],
            [0, 255, 255],
            [255, 0, 255],
            [12, 200, 7],
            [1, 0, 0],
            [0, 0, 1],
            [90, 90, 90],
        ];
        for (i, c) in colours.iter().enumerate() {
            im.put(i % 4, i / 4, *c);
        }
        let mut planes = SctPlanes::new(4, 2);
        sct_from_rgb(&im.view(), &mut planes).unwrap();
        for (i, c) in colours.iter().enumerate() {
            let e = Sct::from_rgb(*c);
            let half_bin = 0.5 / ANGLE_BINS_PER_RAD as f64;
            assert!(
                (planes.a[i] as f64 / ANGLE_BINS_PER_RAD as f64 - e.a).abs() <= 0.00151 + half_bin,
                "{c:?}"
            );
            assert!(
                (planes.b[i] as f64 / ANGLE_BINS_PER_RAD as f64 - e.b).abs() <= 0.00151 + half_bin,
                "{c:?}"
            );
            assert!((planes.l[i] as f64 - e.l).abs() <= 0.5 + 1e-3);
        }
        assert!(sct_from_rgb(&im.view(), &mut SctPlanes::new(3, 3)).is_err());
    }
}
