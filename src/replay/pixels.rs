//! Logged pixels to the packed RGB8 frames perception takes: raw buffers by their ROS /
//! Foxglove encoding name, compressed ones (JPEG, PNG) through the `image` crate.
//!
//! Colour segmentation needs three 8-bit channels, so only encodings that give them
//! without guessing are read: `rgb8`, `bgr8`, `rgba8`, `bgra8` and `mono8` (grey, copied
//! to the three channels). Bayer mosaics would need a demosaicing choice, and 16-bit or
//! float images are depth, not colour: both are refused with the encoding named.

use crate::perception::RgbImage;
use thiserror::Error;

/// Why logged pixels cannot become an RGB frame.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum PixelError {
    /// An encoding perception cannot use.
    #[error("encoding `{encoding}` is not supported ({why}); supported: rgb8, bgr8, rgba8, bgra8, mono8, JPEG, PNG")]
    Unsupported {
        /// The encoding or format.
        encoding: String,
        /// What kind of data it is.
        why: &'static str,
    },
    /// Width or height 0, a side larger than 16384, or (compressed) more pixels than
    /// [`crate::image_io::DEFAULT_MAX_PIXELS`] (the decompression-bomb guard).
    #[error(
        "image size {width}×{height} is empty or too large (sides up to 16384; compressed frames up to 8192×8192 pixels)"
    )]
    Size {
        /// Columns.
        width: u32,
        /// Rows.
        height: u32,
    },
    /// The row stride is shorter than a row, or the buffer shorter than the rows.
    #[error("{width}×{height} {encoding} needs step ≥ {row} and {need} bytes, got step {step} and {got} bytes")]
    Buffer {
        /// Columns.
        width: u32,
        /// Rows.
        height: u32,
        /// Encoding.
        encoding: String,
        /// Bytes in one row of pixels.
        row: usize,
        /// The declared step.
        step: u32,
        /// Bytes needed (`step · (height − 1) + row`).
        need: usize,
        /// Bytes given.
        got: usize,
    },
    /// Compressed bytes that do not decode.
    #[error("`{format}` data does not decode: {why}")]
    Decode {
        /// The declared format.
        format: String,
        /// The decoder's message.
        why: String,
    },
}

/// Largest side accepted, as for profile cameras.
const MAX_SIDE: u32 = 16384;

/// Why an encoding is refused, or `None` when it is one we do not know at all.
fn refusal(encoding: &str) -> &'static str {
    let e = encoding.to_ascii_lowercase();
    if e.starts_with("bayer_") {
        "a Bayer mosaic: demosaic it before logging, or log a colour image"
    } else if e.contains("16") || e == "mono16" {
        "16-bit data, depth or high-dynamic-range: not a colour image"
    } else if e.contains("32") || e.contains("64") {
        "floating-point or 32-bit data: depth, not a colour image"
    } else if e.starts_with("yuv") || e.starts_with("uyvy") || e.starts_with("yuyv") || e.starts_with("nv") {
        "packed YUV: convert it to rgb8 or bgr8 before logging"
    } else {
        "unknown encoding"
    }
}

/// Packed RGB8 from a raw buffer in `encoding` with `step` bytes per row (ROS's
/// `sensor_msgs/Image` and Foxglove's `RawImage` fields).
///
/// # Errors
/// [`PixelError`] for an unsupported encoding or sizes that do not add up.
///
/// # Example
///
/// ```
/// use marsupial::replay::pixels::rgb_from_raw;
///
/// // 2×1 bgr8 with a 2-byte row pad: blue then red.
/// let im = rgb_from_raw(2, 1, "bgr8", 8, &[255, 0, 0, 0, 0, 255, 9, 9]).unwrap();
/// assert_eq!(im.as_bytes(), &[0, 0, 255, 255, 0, 0]);
/// assert!(rgb_from_raw(2, 1, "bayer_rggb8", 2, &[0, 0]).is_err());
/// ```
pub fn rgb_from_raw(width: u32, height: u32, encoding: &str, step: u32, data: &[u8]) -> Result<RgbImage, PixelError> {
    // (bytes per pixel, index of R, G, B within the pixel)
    let (bpp, [r, g, b]) = match encoding {
        "rgb8" | "RGB8" => (3, [0, 1, 2]),
        "bgr8" | "BGR8" => (3, [2, 1, 0]),
        "rgba8" | "RGBA8" => (4, [0, 1, 2]),
        "bgra8" | "BGRA8" => (4, [2, 1, 0]),
        "mono8" | "MONO8" | "8UC1" => (1, [0, 0, 0]),
        other => {
            return Err(PixelError::Unsupported {
                encoding: other.to_string(),
                why: refusal(other),
            });
        }
    };
    if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE {
        return Err(PixelError::Size { width, height });
    }
    let (w, h) = (width as usize, height as usize);
    let row = w * bpp;
    let need = (step as usize) * (h - 1) + row;
    if (step as usize) < row || data.len() < need {
        return Err(PixelError::Buffer {
            width,
            height,
            encoding: encoding.to_string(),
            row,
            step,
            need,
            got: data.len(),
        });
    }
    let mut out = Vec::with_capacity(w * h * 3);
    for y in 0..h {
        let src = &data[y * step as usize..y * step as usize + row];
        for px in src.chunks_exact(bpp) {
            out.extend_from_slice(&[px[r], px[g], px[b]]);
        }
    }
    RgbImage::from_raw(w, h, out).map_err(|e| PixelError::Decode {
        format: encoding.to_string(),
        why: e.to_string(),
    })
}

/// Packed RGB8 from a compressed image (`format` as logged: `jpeg`, `png`, or
/// image_transport's `bgr8; jpeg compressed bgr8`). The bytes decide the codec; the
/// format only rules out depth (`compressedDepth`, 16-bit PNG).
///
/// # Errors
/// [`PixelError::Unsupported`] for depth or 16-bit images and codecs other than JPEG and
/// PNG, [`PixelError::Decode`] for bytes that do not decode.
pub fn rgb_from_compressed(format: &str, data: &[u8]) -> Result<RgbImage, PixelError> {
    use crate::image_io::Refusal;
    let unsupported = |why| PixelError::Unsupported {
        encoding: format.to_string(),
        why,
    };
    if format.contains("compressedDepth") {
        return Err(unsupported("compressed 16-bit depth: not a colour image"));
    }
    let decode = |why: String| PixelError::Decode {
        format: format.to_string(),
        why,
    };
    // The header's size first, so a small message declaring a huge image (a
    // decompression bomb) is refused before anything is allocated.
    let accept = |w: u32, h: u32| {
        w > 0
            && h > 0
            && w <= MAX_SIDE
            && h <= MAX_SIDE
            && u64::from(w) * u64::from(h) <= crate::image_io::DEFAULT_MAX_PIXELS
    };
    let img = crate::image_io::decode_bounded(data, accept).map_err(|e| match e {
        Refusal::Format(_) => unsupported("a codec other than JPEG or PNG"),
        Refusal::Size { width, height } => PixelError::Size { width, height },
        Refusal::Decode(why) => decode(why),
    })?;
    use image::ColorType as C;
    if matches!(
        img.color(),
        C::L16 | C::La16 | C::Rgb16 | C::Rgba16 | C::Rgb32F | C::Rgba32F
    ) {
        return Err(unsupported("16-bit or float pixels: depth, not a colour image"));
    }
    let rgb = img.to_rgb8();
    let (w, h) = rgb.dimensions();
    if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
        return Err(PixelError::Size { width: w, height: h });
    }
    RgbImage::from_raw(w as usize, h as usize, rgb.into_raw()).map_err(|e| decode(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encodings_map_to_rgb() {
        let px = |enc, bytes: &[u8], bpp| rgb_from_raw(1, 1, enc, bpp, bytes).unwrap().as_bytes().to_vec();
        assert_eq!(px("rgb8", &[1, 2, 3], 3), [1, 2, 3]);
        assert_eq!(px("bgr8", &[1, 2, 3], 3), [3, 2, 1]);
        assert_eq!(px("rgba8", &[1, 2, 3, 4], 4), [1, 2, 3]);
        assert_eq!(px("bgra8", &[1, 2, 3, 4], 4), [3, 2, 1]);
        assert_eq!(px("mono8", &[7], 1), [7, 7, 7]);
    }

    #[test]
    fn refusals_name_the_encoding() {
        for enc in ["bayer_rggb8", "16UC1", "mono16", "32FC1", "yuv422"] {
            let e = rgb_from_raw(2, 2, enc, 4, &[0; 16]).unwrap_err();
            assert!(e.to_string().contains(enc), "{e}");
        }
        assert!(matches!(
            rgb_from_raw(2, 2, "rgb8", 5, &[0; 12]),
            Err(PixelError::Buffer { row: 6, .. })
        ));
        assert!(matches!(
            rgb_from_raw(2, 2, "rgb8", 6, &[0; 11]),
            Err(PixelError::Buffer { need: 12, .. })
        ));
        assert!(matches!(
            rgb_from_raw(0, 2, "rgb8", 0, &[]),
            Err(PixelError::Size { .. })
        ));
        assert!(matches!(
            rgb_from_compressed("16UC1; compressedDepth png", &[0; 8]),
            Err(PixelError::Unsupported { .. })
        ));
        assert!(matches!(
            rgb_from_compressed("jpeg", b"not a jpeg"),
            Err(PixelError::Decode { .. })
        ));
    }
}
