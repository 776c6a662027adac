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
    /// The image's size is not that of the frame it is to fill.
    #[error("image is {width}×{height}, the frame to fill is {frame_width}×{frame_height}")]
    Frame {
        /// The image's columns.
        width: u32,
        /// The image's rows.
        height: u32,
        /// The frame's columns.
        frame_width: usize,
        /// The frame's rows.
        frame_height: usize,
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
/// use marsupial::msgs::pixels::rgb_from_raw;
///
/// // 2×1 bgr8 with a 2-byte row pad: blue then red.
/// let im = rgb_from_raw(2, 1, "bgr8", 8, &[255, 0, 0, 0, 0, 255, 9, 9]).unwrap();
/// assert_eq!(im.as_bytes(), &[0, 0, 255, 255, 0, 0]);
/// assert!(rgb_from_raw(2, 1, "bayer_rggb8", 2, &[0, 0]).is_err());
/// ```
pub fn rgb_from_raw(width: u32, height: u32, encoding: &str, step: u32, data: &[u8]) -> Result<RgbImage, PixelError> {
    let layout = raw_layout(width, height, encoding, step, data)?;
    // Validated first, so a bad message never sizes an allocation.
    let mut out = RgbImage::new(width as usize, height as usize);
    convert_raw(&layout, step, data, &mut out);
    Ok(out)
}

/// [`rgb_from_raw`] into a caller's frame of the same size, so that a camera loop
/// converts each message without allocating (`ros2::devices::TopicCamera`).
///
/// # Errors
/// As [`rgb_from_raw`], and [`PixelError::Frame`] when `out` is not `width × height`
/// (`out` is then left as it was).
///
/// # Example
///
/// ```
/// use marsupial::perception::RgbImage;
/// use marsupial::msgs::pixels::rgb_into_raw;
///
/// let mut frame = RgbImage::new(1, 1);
/// rgb_into_raw(1, 1, "mono8", 1, &[7], &mut frame).unwrap();
/// assert_eq!(frame.as_bytes(), &[7, 7, 7]);
/// assert!(rgb_into_raw(2, 1, "mono8", 2, &[7, 7], &mut frame).is_err());
/// ```
pub fn rgb_into_raw(
    width: u32,
    height: u32,
    encoding: &str,
    step: u32,
    data: &[u8],
    out: &mut RgbImage,
) -> Result<(), PixelError> {
    let layout = raw_layout(width, height, encoding, step, data)?;
    if (out.width(), out.height()) != (width as usize, height as usize) {
        return Err(PixelError::Frame {
            width,
            height,
            frame_width: out.width(),
            frame_height: out.height(),
        });
    }
    convert_raw(&layout, step, data, out);
    Ok(())
}

/// A raw buffer's validated layout: bytes per pixel, the index of R, G and B within a
/// pixel, and the bytes in one row of pixels.
struct RawLayout {
    bpp: usize,
    rgb: [usize; 3],
    row: usize,
}

/// Checks the encoding, the sides and the buffer, in that order.
fn raw_layout(width: u32, height: u32, encoding: &str, step: u32, data: &[u8]) -> Result<RawLayout, PixelError> {
    let (bpp, rgb) = match encoding {
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
    Ok(RawLayout { bpp, rgb, row })
}

/// Copies a validated buffer into `out`, which is its size.
fn convert_raw(layout: &RawLayout, step: u32, data: &[u8], out: &mut RgbImage) {
    let [r, g, b] = layout.rgb;
    let dst_row = out.width() * 3;
    for (y, dst) in out.as_bytes_mut().chunks_exact_mut(dst_row).enumerate() {
        let src = &data[y * step as usize..y * step as usize + layout.row];
        for (d, px) in dst.chunks_exact_mut(3).zip(src.chunks_exact(layout.bpp)) {
            d.copy_from_slice(&[px[r], px[g], px[b]]);
        }
    }
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

    proptest::proptest! {
        /// Filling a frame gives what allocating one gives, for every encoding, pad and
        /// size, and refuses a frame of another size without touching it.
        #[test]
        fn into_a_frame_matches_a_new_one(
            w in 1u32..9, h in 1u32..9, enc in 0usize..7, pad in 0u32..5, seed in proptest::prelude::any::<u64>()
        ) {
            let (name, bpp) = [("rgb8", 3), ("bgr8", 3), ("rgba8", 4), ("bgra8", 4), ("mono8", 1), ("8UC1", 1), ("BGR8", 3)][enc];
            let step = w * bpp + pad;
            let mut x = seed | 1;
            let data: Vec<u8> = (0..step * h).map(|_| { x ^= x << 13; x ^= x >> 7; x ^= x << 17; x as u8 }).collect();
            let want = rgb_from_raw(w, h, name, step, &data).unwrap();
            let mut frame = RgbImage::new(w as usize, h as usize);
            rgb_into_raw(w, h, name, step, &data, &mut frame).unwrap();
            proptest::prop_assert_eq!(frame.as_bytes(), want.as_bytes());
            let mut other = RgbImage::new(w as usize + 1, h as usize);
            let before = other.as_bytes().to_vec();
            let is_frame_error = matches!(rgb_into_raw(w, h, name, step, &data, &mut other), Err(PixelError::Frame { .. }));
            proptest::prop_assert!(is_frame_error);
            proptest::prop_assert_eq!(other.as_bytes(), &before[..]);
        }
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
