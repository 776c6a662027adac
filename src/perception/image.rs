//! Owned RGB frames and borrowed views: the currency between cameras and perception.
//!
//! Pixels are packed `R, G, B` bytes in row-major order. Cameras write into an
//! [`RgbImage`] the caller owns (so steady-state capture does not allocate); perception
//! functions read an [`RgbView`].

use thiserror::Error;

/// Errors from constructing images or views with inconsistent sizes.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum ImageError {
    /// Width or height is zero.
    #[error("image is empty ({width}×{height}): expected width and height ≥ 1")]
    Empty {
        /// Width in pixels.
        width: usize,
        /// Height in pixels.
        height: usize,
    },
    /// The byte buffer does not match `width × height × 3`.
    #[error("RGB buffer holds {got} bytes but {width}×{height}×3 = {expected} were expected")]
    BufferSize {
        /// Width in pixels.
        width: usize,
        /// Height in pixels.
        height: usize,
        /// Bytes expected.
        expected: usize,
        /// Bytes found.
        got: usize,
    },
}

/// An owned, packed RGB8 image.
///
/// # Example
///
/// A 4×3 frame filled by hand: one colour everywhere, one red pixel, then read back
/// through a view and as packed bytes.
///
/// ```
/// use marsupial::perception::RgbImage;
///
/// let mut im = RgbImage::new(4, 3);
/// im.fill([10, 20, 30]);
/// im.put(3, 2, [255, 0, 0]);
/// im.put(9, 9, [1, 1, 1]); // outside the image: ignored
/// let v = im.view();
/// assert_eq!((v.width(), v.height()), (4, 3));
/// assert_eq!(v.get(0, 0), Some([10, 20, 30]));
/// assert_eq!(v.get(3, 2), Some([255, 0, 0]));
/// assert_eq!(v.get(4, 0), None);
/// // Row-major R, G, B: pixel (3, 2) starts at byte (2·4 + 3)·3 = 33.
/// assert_eq!(&im.as_bytes()[33..36], &[255, 0, 0]);
/// // Resizing keeps the buffer consistent with the new size.
/// im.resize(2, 2);
/// assert_eq!(im.as_bytes().len(), 2 * 2 * 3);
/// ```
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct RgbImage {
    width: usize,
    height: usize,
    data: Vec<u8>,
}

impl RgbImage {
    /// A black image of the given size. Zero sizes are allowed (an unfilled buffer).
    pub fn new(width: usize, height: usize) -> Self {
        Self {
            width,
            height,
            data: vec![0; width * height * 3],
        }
    }

    /// Wraps an existing packed RGB buffer.
    ///
    /// # Errors
    /// [`ImageError::BufferSize`] when `data.len() != width*height*3`.
    ///
    /// # Example
    ///
    /// ```
    /// use marsupial::perception::{ImageError, RgbImage};
    ///
    /// // 2×1: a black pixel, then a white one.
    /// let im = RgbImage::from_raw(2, 1, vec![0, 0, 0, 255, 255, 255]).unwrap();
    /// assert_eq!(im.view().get(1, 0), Some([255, 255, 255]));
    /// // One byte short of 2×2×3.
    /// assert_eq!(
    ///     RgbImage::from_raw(2, 2, vec![0; 11]),
    ///     Err(ImageError::BufferSize { width: 2, height: 2, expected: 12, got: 11 })
    /// );
    /// ```
    pub fn from_raw(width: usize, height: usize, data: Vec<u8>) -> Result<Self, ImageError> {
        let expected = width * height * 3;
        if data.len() != expected {
            return Err(ImageError::BufferSize {
                width,
                height,
                expected,
                got: data.len(),
            });
        }
        Ok(Self { width, height, data })
    }

    /// Resizes the buffer to `width × height`, reusing its allocation when it is big enough.
    /// Contents are unspecified afterwards.
    pub fn resize(&mut self, width: usize, height: usize) {
        self.width = width;
        self.height = height;
        self.data.resize(width * height * 3, 0);
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The packed bytes.
    pub fn as_bytes(&self) -> &[u8] {
        &self.data
    }

    /// The packed bytes, mutable.
    pub fn as_bytes_mut(&mut self) -> &mut [u8] {
        &mut self.data
    }

    /// Sets pixel (x, y); out-of-range coordinates are ignored.
    pub fn put(&mut self, x: usize, y: usize, rgb: [u8; 3]) {
        if x < self.width && y < self.height {
            let i = (y * self.width + x) * 3;
            self.data[i..i + 3].copy_from_slice(&rgb);
        }
    }

    /// Fills every pixel with one colour.
    pub fn fill(&mut self, rgb: [u8; 3]) {
        for px in self.data.chunks_exact_mut(3) {
            px.copy_from_slice(&rgb);
        }
    }

    /// A borrowed view of the whole image.
    pub fn view(&self) -> RgbView<'_> {
        RgbView {
            width: self.width,
            height: self.height,
            data: &self.data,
        }
    }
}

/// A borrowed, packed RGB8 image.
///
/// # Example
///
/// A view over bytes the caller owns (a camera driver's buffer, say), without copying.
///
/// ```
/// use marsupial::perception::{ImageError, RgbView};
///
/// let bytes = [0, 0, 0, 9, 8, 7, 1, 2, 3]; // 3×1
/// let v = RgbView::new(3, 1, &bytes).unwrap();
/// assert_eq!(v.get(1, 0), Some([9, 8, 7]));
/// assert_eq!(v.get(0, 1), None);
/// assert!(!v.is_empty());
/// assert!(matches!(
///     RgbView::new(2, 2, &bytes),
///     Err(ImageError::BufferSize { expected: 12, got: 9, .. })
/// ));
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RgbView<'a> {
    width: usize,
    height: usize,
    data: &'a [u8],
}

impl<'a> RgbView<'a> {
    /// Wraps a packed RGB buffer.
    ///
    /// # Errors
    /// [`ImageError::BufferSize`] when the length is not `width*height*3`.
    pub fn new(width: usize, height: usize, data: &'a [u8]) -> Result<Self, ImageError> {
        let expected = width * height * 3;
        if data.len() != expected {
            return Err(ImageError::BufferSize {
                width,
                height,
                expected,
                got: data.len(),
            });
        }
        Ok(Self { width, height, data })
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// True when the view holds no pixel.
    pub fn is_empty(&self) -> bool {
        self.width == 0 || self.height == 0
    }

    /// The packed bytes.
    pub fn as_bytes(&self) -> &'a [u8] {
        self.data
    }

    /// Pixel (x, y), or `None` outside the image.
    pub fn get(&self, x: usize, y: usize) -> Option<[u8; 3]> {
        if x < self.width && y < self.height {
            let i = (y * self.width + x) * 3;
            Some([self.data[i], self.data[i + 1], self.data[i + 2]])
        } else {
            None
        }
    }
}

/// Every one of the 2²⁴ RGB colours, as 256 slabs of 256 × 256 pixels (slab `r` holds
/// red `r`, green along x, blue along y), each handed to `f` with its red value. The
/// slabs are split across the machine's cores, so exhaustive tests against per-pixel
/// references take seconds in the optimised test profile.
#[cfg(test)]
pub(crate) fn for_each_cube_slab(f: impl Fn(u8, &RgbImage) + Sync) {
    let threads = std::thread::available_parallelism().map_or(2, |n| n.get()).min(8);
    std::thread::scope(|scope| {
        for t in 0..threads {
            let f = &f;
            scope.spawn(move || {
                let mut slab = RgbImage::new(256, 256);
                for r in (t..256).step_by(threads) {
                    for b in 0..256 {
                        for g in 0..256 {
                            slab.put(g, b, [r as u8, g as u8, b as u8]);
                        }
                    }
                    f(r as u8, &slab);
                }
            });
        }
    });
}

/// The sRGB transfer function's inverse: an 8-bit-scaled code value in [0, 1] to linear
/// light.
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_are_checked() {
        assert!(matches!(
            RgbImage::from_raw(2, 2, vec![0; 11]),
            Err(ImageError::BufferSize {
                expected: 12,
                got: 11,
                ..
            })
        ));
        assert!(RgbView::new(1, 1, &[1, 2, 3]).is_ok());
    }

    #[test]
    fn put_and_get() {
        let mut im = RgbImage::new(3, 2);
        im.put(2, 1, [9, 8, 7]);
        im.put(5, 5, [1, 1, 1]); // ignored
        assert_eq!(im.view().get(2, 1), Some([9, 8, 7]));
        assert_eq!(im.view().get(3, 1), None);
    }
}
