//! Camera pixels to the packed RGB8 frames perception takes: raw buffers by their ROS /
//! Foxglove encoding name, compressed ones (JPEG, so MJPEG cameras' frames, and PNG)
//! through the `image` crate.
//!
//! Raw encodings read ([`super::raw`] has the table): `rgb8`, `bgr8`, `rgba8`, `bgra8`,
//! `mono8` (grey, copied to the three channels), packed 4:2:2 `yuyv` / `yuv422_yuy2` and
//! `uyvy` / `yuv422`, 4:2:0 `nv12` and `nv21` (BT.601 limited range, [`super::yuv`]),
//! and 8-bit Bayer mosaics `bayer_rggb8`, `bayer_bggr8`, `bayer_grbg8`, `bayer_gbrg8`
//! (bilinear demosaic, [`super::bayer`]). 16-bit or float images are depth, not colour:
//! they are refused with the encoding named, as is any encoding not listed.

use super::raw;
use crate::perception::RgbImage;
use thiserror::Error;

/// Why logged pixels cannot become an RGB frame.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum PixelError {
    /// An encoding perception cannot use.
    #[error(
        "encoding `{encoding}` is not supported ({why}); supported: rgb8, bgr8, rgba8, bgra8, mono8, yuyv (yuv422_yuy2), uyvy (yuv422), nv12, nv21, bayer_rggb8, bayer_bggr8, bayer_grbg8, bayer_gbrg8, JPEG, PNG"
    )]
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
    /// Sides the encoding cannot have: an odd width for 4:2:2, an odd side for 4:2:0, less
    /// than 2×2 for a Bayer mosaic.
    #[error("a {width}×{height} {encoding} image cannot be: {why}")]
    Sides {
        /// Encoding.
        encoding: String,
        /// Columns.
        width: u32,
        /// Rows.
        height: u32,
        /// The rule broken.
        why: &'static str,
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
    /// A frame whose aspect ratio is not the camera's, so it cannot be rescaled to the
    /// camera's size without distorting it ([`super::rescale`]).
    #[error(
        "a {width}×{height} frame has another aspect ratio than the {camera_width}×{camera_height} camera: it is rescaled only when the ratios agree (set the camera to a mode of that ratio, or give the profile this camera's size)"
    )]
    Aspect {
        /// The frame's columns.
        width: usize,
        /// The frame's rows.
        height: usize,
        /// The camera's columns.
        camera_width: usize,
        /// The camera's rows.
        camera_height: usize,
    },
    /// Compressed bytes that do not decode (a truncated or corrupt JPEG frame among them).
    #[error("`{format}` data does not decode: {why}")]
    Decode {
        /// The declared format.
        format: String,
        /// The decoder's message.
        why: String,
    },
}

const MAX_SIDE: u32 = raw::MAX_SIDE;

/// Packed RGB8 from a raw buffer in `encoding` with `step` bytes per row (ROS's
/// `sensor_msgs/Image` and Foxglove's `RawImage` fields; for `nv12` and `nv21` the
/// chroma plane's rows follow the `height` luma rows, `step` bytes apart as ROS has it).
///
/// # Errors
/// [`PixelError`] for an unsupported encoding, sides it cannot have
/// ([`PixelError::Sides`]), or sizes that do not add up.
///
/// # Example
///
/// ```
/// use marsupial::msgs::pixels::rgb_from_raw;
///
/// // 2×1 bgr8 with a 2-byte row pad: blue then red.
/// let im = rgb_from_raw(2, 1, "bgr8", 8, &[255, 0, 0, 0, 0, 255, 9, 9]).unwrap();
/// assert_eq!(im.as_bytes(), &[0, 0, 255, 255, 0, 0]);
/// assert!(rgb_from_raw(2, 1, "16UC1", 4, &[0; 4]).is_err());
/// ```
pub fn rgb_from_raw(width: u32, height: u32, encoding: &str, step: u32, data: &[u8]) -> Result<RgbImage, PixelError> {
    let checked = raw::check(width, height, encoding, step, data)?;
    // Checked first, so a bad message never sizes an allocation.
    let mut out = RgbImage::new(width as usize, height as usize);
    raw::convert(&checked, data, &mut out);
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
    let checked = raw::check(width, height, encoding, step, data)?;
    if (out.width(), out.height()) != (width as usize, height as usize) {
        return Err(PixelError::Frame {
            width,
            height,
            frame_width: out.width(),
            frame_height: out.height(),
        });
    }
    raw::convert(&checked, data, out);
    Ok(())
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

    proptest::proptest! {
        /// The camera encodings too: filling a frame gives what allocating one gives, for
        /// any even size, pad and content.
        #[test]
        fn camera_encodings_into_a_frame(hw in 1u32..5, hh in 1u32..5, enc in 0usize..10, pad in 0u32..5, seed in proptest::prelude::any::<u64>()) {
            let (name, row_bytes_per_px, rows_x2) = [
                ("yuyv", 2, 2), ("yuv422_yuy2", 2, 2), ("uyvy", 2, 2), ("yuv422", 2, 2), ("nv12", 1, 3), ("nv21", 1, 3),
                ("bayer_rggb8", 1, 2), ("bayer_bggr8", 1, 2), ("bayer_grbg8", 1, 2), ("bayer_gbrg8", 1, 2),
            ][enc];
            let (w, h) = (hw * 2, hh * 2);
            let step = w * row_bytes_per_px + pad;
            let mut x = seed | 1;
            let data: Vec<u8> = (0..step * h * rows_x2 / 2).map(|_| { x ^= x << 13; x ^= x >> 7; x ^= x << 17; x as u8 }).collect();
            let want = rgb_from_raw(w, h, name, step, &data).unwrap();
            let mut frame = RgbImage::new(w as usize, h as usize);
            rgb_into_raw(w, h, name, step, &data, &mut frame).unwrap();
            proptest::prop_assert_eq!(frame.as_bytes(), want.as_bytes());
            // One byte short is refused, never read past.
            let short = rgb_from_raw(w, h, name, step, &data[..data.len() - 1 - pad as usize]);
            proptest::prop_assert!(matches!(short, Err(PixelError::Buffer { .. })), "{short:?}");
        }
    }

    #[test]
    fn camera_encodings_refuse_sides_they_cannot_have() {
        for (enc, w, h) in [
            ("yuyv", 3, 2),
            ("uyvy", 1, 1),
            ("nv12", 4, 3),
            ("nv21", 3, 4),
            ("bayer_rggb8", 1, 4),
            ("bayer_gbrg8", 4, 1),
        ] {
            let e = rgb_from_raw(w, h, enc, 64, &[0; 4096]).unwrap_err();
            assert!(matches!(e, PixelError::Sides { .. }), "{enc}: {e:?}");
            assert!(e.to_string().contains(enc), "{e}");
        }
        // A step shorter than a row, zero sides and an empty buffer.
        assert!(matches!(
            rgb_from_raw(4, 2, "yuyv", 7, &[0; 64]),
            Err(PixelError::Buffer { row: 8, .. })
        ));
        assert!(matches!(
            rgb_from_raw(0, 2, "nv12", 0, &[]),
            Err(PixelError::Size { .. })
        ));
        assert!(matches!(
            rgb_from_raw(4, 2, "nv12", 4, &[0; 11]),
            Err(PixelError::Buffer { need: 12, .. })
        ));
        assert!(matches!(
            rgb_from_raw(2, 2, "bayer_bggr8", 2, &[]),
            Err(PixelError::Buffer { .. })
        ));
        // A step near u32::MAX does not overflow the size arithmetic.
        assert!(matches!(
            rgb_from_raw(2, 16384, "nv12", u32::MAX, &[0; 8]),
            Err(PixelError::Buffer { .. })
        ));
    }

    #[test]
    fn a_truncated_or_corrupt_jpeg_is_a_decode_error() {
        let mut im = image::RgbImage::new(32, 24);
        im.pixels_mut()
            .enumerate()
            .for_each(|(i, p)| *p = image::Rgb([i as u8, 80, 200]));
        let mut jpeg = Vec::new();
        image::codecs::jpeg::JpegEncoder::new_with_quality(&mut jpeg, 90)
            .encode_image(&im)
            .unwrap();
        assert!(rgb_from_compressed("jpeg", &jpeg).is_ok());
        for cut in [2, 20, jpeg.len() / 2, jpeg.len() - 2] {
            match rgb_from_compressed("jpeg", &jpeg[..cut]) {
                Err(PixelError::Decode { format, .. }) => assert_eq!(format, "jpeg"),
                // A cut in the entropy-coded data may decode, grey below the cut; it must not panic.
                Ok(rgb) => assert_eq!((rgb.width(), rgb.height()), (32, 24)),
                Err(e) => panic!("cut at {cut}: {e:?}"),
            }
        }
        let mut corrupt = jpeg.clone();
        corrupt[2..40].fill(0xFF);
        assert!(matches!(
            rgb_from_compressed("jpeg", &corrupt),
            Err(PixelError::Decode { .. })
        ));
    }

    #[test]
    fn refusals_name_the_encoding() {
        for enc in ["bayer_rggb16", "16UC1", "mono16", "32FC1", "nv24", "yuv420", "hsv8"] {
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
