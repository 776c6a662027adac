//! Rescaling a camera's frame to the profile camera's size, so that a camera running
//! another mode (a 1280×720 webcam for a 640×360 profile) feeds perception the frames, and
//! the intrinsics, it was set up for.
//!
//! **Intrinsics.** A camera mode of the same aspect ratio sees the same field of view
//! through the whole sensor (UVC and V4L2 modes bin or scale; they do not crop), so its
//! intrinsics are the profile's scaled by `frame / profile`: fx, cx by the width ratio,
//! fy, cy by the height ratio. Resampling the frame by the inverse ratio brings them back
//! to the profile's exactly; so perception, the lens model and the behaviors keep using
//! the profile camera's intrinsics and pixel units unchanged. (The distortion
//! coefficients, in normalised coordinates, do not change with scale.)
//!
//! **Aspect ratio.** A frame of another aspect ratio is refused
//! ([`PixelError::Aspect`]): stretching it would bend every bearing, and cropping would
//! guess where the mode's window lies on the sensor, which only the camera knows. The
//! ratios must agree within half a pixel: the frame's height, scaled by the width ratio,
//! is the profile's within ±0.5 px (1920×1080 for 640×360, 320×240 for 640×480; not 1100×800
//! for 1024×768).
//!
//! **Resampling: area averaging.** Each output pixel is the mean of the source over its
//! footprint, source pixels weighted by how much of them it covers. Down-scaling by any
//! factor then averages every source pixel once (no aliasing); up-scaling blends the two
//! source pixels an output pixel straddles. Separable: a horizontal pass into a scratch
//! row buffer, then a vertical one, with weights computed once per size.

use super::pixels::PixelError;
use crate::perception::{RgbImage, RgbView};

/// One output index's source span: the first source index and the weights of the
/// source indices from there (they sum to 1).
#[derive(Debug, Clone, Default, PartialEq)]
struct Taps {
    first: Vec<usize>,
    /// Offsets into `weights`: output index i's weights are `weights[start[i]..start[i + 1]]`.
    start: Vec<usize>,
    weights: Vec<f32>,
}

impl Taps {
    /// Area weights mapping `from` source pixels onto `to` output pixels.
    fn area(from: usize, to: usize) -> Self {
        let scale = from as f64 / to as f64;
        let mut t = Taps::default();
        t.start.push(0);
        for i in 0..to {
            let (a, b) = (i as f64 * scale, (i + 1) as f64 * scale);
            let first = (a.floor() as usize).min(from - 1);
            let last = ((b.ceil() as usize).max(first + 1)).min(from);
            t.first.push(first);
            for j in first..last {
                let cover = (b.min((j + 1) as f64) - a.max(j as f64)).max(0.0);
                t.weights.push((cover / scale) as f32);
            }
            t.start.push(t.weights.len());
        }
        t
    }

    fn of(&self, i: usize) -> (usize, &[f32]) {
        (self.first[i], &self.weights[self.start[i]..self.start[i + 1]])
    }
}

/// Whether a `from` frame has the aspect ratio of a `to` camera, within half a pixel.
///
/// # Example
///
/// ```
/// use marsupial::msgs::rescale::same_aspect;
///
/// assert!(same_aspect((1920, 1080), (640, 360)));
/// assert!(!same_aspect((1100, 800), (1024, 768)));
/// ```
pub fn same_aspect(from: (usize, usize), to: (usize, usize)) -> bool {
    let (fw, fh, tw, th) = (from.0 as u128, from.1 as u128, to.0 as u128, to.1 as u128);
    // |fh · tw / fw − th| ≤ ½  ⇔  2 |fh · tw − th · fw| ≤ fw
    fw > 0 && 2 * (fh * tw).abs_diff(th * fw) <= fw
}

/// Rescales frames to a camera's size by area averaging, keeping its weights and scratch
/// row between frames: a loop whose frames keep one size allocates only on the first.
#[derive(Debug, Clone, Default)]
pub struct Rescaler {
    sizes: ((usize, usize), (usize, usize)),
    x: Taps,
    y: Taps,
    /// Horizontally resampled source rows, `from.1 × to.0 × 3`.
    mid: Vec<f32>,
}

impl Rescaler {
    /// An empty rescaler; its weights are made for the first pair of sizes it sees.
    pub fn new() -> Self {
        Self::default()
    }

    /// Rescales `src` into `out` (the camera's size, which `out` already has). A `src` of
    /// `out`'s size is copied.
    ///
    /// # Errors
    /// [`PixelError::Aspect`] when the aspect ratios differ ([`same_aspect`]),
    /// [`PixelError::Size`] for an empty image (`out` is then left as it was).
    ///
    /// # Example
    ///
    /// ```
    /// use marsupial::msgs::rescale::Rescaler;
    /// use marsupial::perception::RgbImage;
    ///
    /// let mut src = RgbImage::new(4, 2);
    /// src.put(0, 0, [200, 0, 0]);
    /// src.put(1, 1, [100, 0, 0]);
    /// let mut out = RgbImage::new(2, 1);
    /// Rescaler::new().fill(&src.view(), &mut out).unwrap();
    /// assert_eq!(&out.as_bytes()[..3], &[75, 0, 0]); // (200 + 100) / 4
    /// assert!(Rescaler::new().fill(&src.view(), &mut RgbImage::new(2, 2)).is_err());
    /// ```
    pub fn fill(&mut self, src: &RgbView<'_>, out: &mut RgbImage) -> Result<(), PixelError> {
        let from = (src.width(), src.height());
        let to = (out.width(), out.height());
        for (w, h) in [from, to] {
            if w == 0 || h == 0 {
                return Err(PixelError::Size {
                    width: w.try_into().unwrap_or(u32::MAX),
                    height: h.try_into().unwrap_or(u32::MAX),
                });
            }
        }
        if !same_aspect(from, to) {
            return Err(PixelError::Aspect {
                width: from.0,
                height: from.1,
                camera_width: to.0,
                camera_height: to.1,
            });
        }
        if from == to {
            out.as_bytes_mut().copy_from_slice(src.as_bytes());
            return Ok(());
        }
        if self.sizes != (from, to) || self.x.first.len() != to.0 {
            self.x = Taps::area(from.0, to.0);
            self.y = Taps::area(from.1, to.1);
            self.sizes = (from, to);
        }
        self.mid.clear();
        self.mid.resize(from.1 * to.0 * 3, 0.0);
        let src = src.as_bytes();
        for (row, mid) in src.chunks_exact(from.0 * 3).zip(self.mid.chunks_exact_mut(to.0 * 3)) {
            for (i, m) in mid.chunks_exact_mut(3).enumerate() {
                let (first, ws) = self.x.of(i);
                let mut acc = [0f32; 3];
                for (px, &wt) in row[first * 3..].chunks_exact(3).zip(ws) {
                    for c in 0..3 {
                        acc[c] += wt * f32::from(px[c]);
                    }
                }
                m.copy_from_slice(&acc);
            }
        }
        let line = to.0 * 3;
        for (i, dst) in out.as_bytes_mut().chunks_exact_mut(line).enumerate() {
            let (first, ws) = self.y.of(i);
            for (k, d) in dst.iter_mut().enumerate() {
                let mut acc = 0f32;
                for (j, &wt) in ws.iter().enumerate() {
                    acc += wt * self.mid[(first + j) * line + k];
                }
                *d = acc.round().clamp(0.0, 255.0) as u8;
            }
        }
        Ok(())
    }
}

/// Frames brought to one camera's size where they can be: another size of its aspect
/// ratio is rescaled (into a buffer kept between frames), anything else passed through
/// for the caller to refuse or run as it is (`marsupial detect` without a lens model).
#[derive(Debug, Clone, Default)]
pub struct ToCamera {
    size: (usize, usize),
    rescaler: Rescaler,
    scaled: RgbImage,
}

impl ToCamera {
    /// For a camera of `size` (the profile's `width_px`, `height_px`).
    pub fn new(size: (usize, usize)) -> Self {
        Self {
            size,
            ..Self::default()
        }
    }

    /// `im` at the camera's size when it has the camera's aspect ratio, else `im`.
    pub fn fit<'a>(&'a mut self, im: &'a RgbImage) -> &'a RgbImage {
        let size = (im.width(), im.height());
        if size == self.size || !same_aspect(size, self.size) {
            return im;
        }
        self.scaled.resize(self.size.0, self.size.1);
        match self.rescaler.fill(&im.view(), &mut self.scaled) {
            Ok(()) => &self.scaled,
            Err(_) => im,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The footprint mean by its definition: every source pixel weighted by its overlap
    /// with the output pixel's footprint, in f64.
    fn reference(src: &RgbImage, to: (usize, usize)) -> Vec<u8> {
        let (fw, fh) = (src.width(), src.height());
        let (sx, sy) = (fw as f64 / to.0 as f64, fh as f64 / to.1 as f64);
        let overlap = |a: f64, b: f64, j: usize| (b.min(j as f64 + 1.0) - a.max(j as f64)).max(0.0);
        let mut out = Vec::new();
        for oy in 0..to.1 {
            for ox in 0..to.0 {
                let mut acc = [0f64; 3];
                for y in 0..fh {
                    let wy = overlap(oy as f64 * sy, (oy + 1) as f64 * sy, y);
                    for x in 0..fw {
                        let wt = wy * overlap(ox as f64 * sx, (ox + 1) as f64 * sx, x) / (sx * sy);
                        for (c, a) in acc.iter_mut().enumerate() {
                            *a += wt * f64::from(src.as_bytes()[(y * fw + x) * 3 + c]);
                        }
                    }
                }
                out.extend(acc.map(|v| v.round().clamp(0.0, 255.0) as u8));
            }
        }
        out
    }

    #[test]
    fn aspect_within_half_a_pixel() {
        assert!(same_aspect((1280, 720), (640, 360)));
        assert!(same_aspect((320, 240), (640, 480)));
        assert!(!same_aspect((1920, 1088), (640, 360))); // 362.7 px against 360
        assert!(!same_aspect((640, 480), (640, 360)));
        assert!(!same_aspect((0, 480), (640, 480)));
    }

    proptest::proptest! {
        /// Down and up by any same-aspect factor: within 1 of the footprint mean.
        #[test]
        fn area_matches_the_footprint_mean(bw in 1usize..5, bh in 1usize..5, from_k in 1usize..7, to_k in 1usize..7, seed: u64) {
            let (from, to) = ((bw * from_k, bh * from_k), (bw * to_k, bh * to_k));
            let mut x = seed | 1;
            let data: Vec<u8> = (0..from.0 * from.1 * 3).map(|_| { x ^= x << 13; x ^= x >> 7; x ^= x << 17; x as u8 }).collect();
            let src = RgbImage::from_raw(from.0, from.1, data).unwrap();
            let mut out = RgbImage::new(to.0, to.1);
            let mut r = Rescaler::new();
            r.fill(&src.view(), &mut out).unwrap();
            let want = reference(&src, to);
            proptest::prop_assert!(out.as_bytes().iter().zip(&want).all(|(a, b)| a.abs_diff(*b) <= 1));
            // And again with the weights kept: the same bytes.
            let first = out.as_bytes().to_vec();
            r.fill(&src.view(), &mut out).unwrap();
            proptest::prop_assert_eq!(out.as_bytes(), &first[..]);
        }
    }
}
