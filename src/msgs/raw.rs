//! The raw encodings read (by their ROS `sensor_msgs/image_encodings` names), how much
//! buffer each needs, and the conversion of a checked buffer into a frame.
//!
//! | encoding | layout | conversion |
//! |---|---|---|
//! | `rgb8`, `bgr8`, `rgba8`, `bgra8` | interleaved 8-bit channels | channels reordered, alpha dropped |
//! | `mono8`, `8UC1` | one 8-bit grey channel | copied to the three channels |
//! | `yuyv` (`yuv422_yuy2`), `uyvy` (`yuv422`) | packed 4:2:2, 2 bytes per pixel, width even | [`super::yuv`], BT.601 limited range |
//! | `nv12`, `nv21` | Y′ plane then interleaved chroma plane, 4:2:0, width and height even | [`super::yuv`], BT.601 limited range |
//! | `bayer_rggb8`, `bayer_bggr8`, `bayer_grbg8`, `bayer_gbrg8` | one 8-bit mosaic sample per pixel, at least 2×2 | [`super::bayer`], bilinear |
//!
//! ROS names `yuv422` for UYVY and `yuv422_yuy2` for YUYV (both deprecated there for
//! `uyvy` and `yuyv`, and both still what many drivers send). Everything else (16-bit
//! and float images, 16-bit mosaics, `nv24`) is refused with the encoding named.

use super::bayer::{self, Pattern};
use super::pixels::PixelError;
use super::yuv::{self, ChromaOrder, Packing};
use crate::perception::RgbImage;

/// Largest side accepted, as for profile cameras.
pub(crate) const MAX_SIDE: u32 = 16384;

/// A raw encoding this module reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Encoding {
    /// Interleaved channels: bytes per pixel and the index of R, G and B in a pixel.
    Interleaved { bpp: usize, rgb: [usize; 3] },
    /// Packed 4:2:2.
    Yuv422(Packing),
    /// Semi-planar 4:2:0.
    Nv(ChromaOrder),
    /// An 8-bit Bayer mosaic.
    Bayer(Pattern),
}

impl Encoding {
    fn from_name(name: &str) -> Option<Self> {
        let il = |bpp, rgb| Some(Encoding::Interleaved { bpp, rgb });
        match name {
            "rgb8" | "RGB8" => il(3, [0, 1, 2]),
            "bgr8" | "BGR8" => il(3, [2, 1, 0]),
            "rgba8" | "RGBA8" => il(4, [0, 1, 2]),
            "bgra8" | "BGRA8" => il(4, [2, 1, 0]),
            "mono8" | "MONO8" | "8UC1" => il(1, [0, 0, 0]),
            "yuyv" | "yuv422_yuy2" => Some(Encoding::Yuv422(Packing::Yuyv)),
            "uyvy" | "yuv422" => Some(Encoding::Yuv422(Packing::Uyvy)),
            "nv12" => Some(Encoding::Nv(ChromaOrder::CbCr)),
            "nv21" => Some(Encoding::Nv(ChromaOrder::CrCb)),
            "bayer_rggb8" => Some(Encoding::Bayer(Pattern::Rggb)),
            "bayer_bggr8" => Some(Encoding::Bayer(Pattern::Bggr)),
            "bayer_grbg8" => Some(Encoding::Bayer(Pattern::Grbg)),
            "bayer_gbrg8" => Some(Encoding::Bayer(Pattern::Gbrg)),
            _ => None,
        }
    }

    /// Bytes in one row of pixels, and the rows of `step` bytes the buffer holds.
    fn extent(self, w: usize, h: usize) -> (usize, usize) {
        match self {
            Encoding::Interleaved { bpp, .. } => (w * bpp, h),
            Encoding::Yuv422(_) => (w * 2, h),
            Encoding::Nv(_) => (w, h + h / 2),
            Encoding::Bayer(_) => (w, h),
        }
    }

    /// What the sides must be beyond 1..=16384, or `None` when they are fine.
    fn side_rule(self, w: u32, h: u32) -> Option<&'static str> {
        match self {
            Encoding::Yuv422(_) if !w.is_multiple_of(2) => Some("4:2:2 pairs pixels: the width must be even"),
            Encoding::Nv(_) if !w.is_multiple_of(2) || !h.is_multiple_of(2) => {
                Some("4:2:0 shares chroma in 2×2 blocks: width and height must be even")
            }
            Encoding::Bayer(_) if w < 2 || h < 2 => Some("a Bayer mosaic needs at least one 2×2 tile"),
            _ => None,
        }
    }
}

/// Why an encoding is refused (one we do not read, or do not know).
fn refusal(encoding: &str) -> &'static str {
    let e = encoding.to_ascii_lowercase();
    if e.starts_with("bayer_") && e.ends_with("16") {
        "a 16-bit Bayer mosaic: only 8-bit mosaics are read"
    } else if e.contains("16") {
        "16-bit data, depth or high-dynamic-range: not a colour image"
    } else if e.contains("32") || e.contains("64") {
        "floating-point or 32-bit data: depth, not a colour image"
    } else if e.starts_with("yuv") || e.starts_with("uyvy") || e.starts_with("yuyv") || e.starts_with("nv") {
        "a YUV layout other than uyvy (yuv422), yuyv (yuv422_yuy2), nv12 and nv21"
    } else {
        "unknown encoding"
    }
}

/// A raw buffer checked against its encoding: safe to convert.
pub(crate) struct Checked {
    encoding: Encoding,
    step: usize,
}

/// Checks the encoding, the sides and the buffer, in that order, so a bad message never
/// sizes an allocation.
pub(crate) fn check(width: u32, height: u32, name: &str, step: u32, data: &[u8]) -> Result<Checked, PixelError> {
    let Some(encoding) = Encoding::from_name(name) else {
        return Err(PixelError::Unsupported {
            encoding: name.to_string(),
            why: refusal(name),
        });
    };
    if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE {
        return Err(PixelError::Size { width, height });
    }
    if let Some(why) = encoding.side_rule(width, height) {
        return Err(PixelError::Sides {
            encoding: name.to_string(),
            width,
            height,
            why,
        });
    }
    let (row, rows) = encoding.extent(width as usize, height as usize);
    // `step` is a u32 and rows ≤ 24576: the product fits a u64 (and a 64-bit usize).
    let need = u64::from(step) * (rows as u64 - 1) + row as u64;
    let need = usize::try_from(need).unwrap_or(usize::MAX);
    if (step as usize) < row || data.len() < need {
        return Err(PixelError::Buffer {
            width,
            height,
            encoding: name.to_string(),
            row,
            step,
            need,
            got: data.len(),
        });
    }
    Ok(Checked {
        encoding,
        step: step as usize,
    })
}

/// Converts a checked buffer into `out`, which is its size.
pub(crate) fn convert(checked: &Checked, data: &[u8], out: &mut RgbImage) {
    let step = checked.step;
    match checked.encoding {
        Encoding::Interleaved { bpp, rgb: [r, g, b] } => {
            let (w, row) = (out.width(), out.width() * bpp);
            for (y, dst) in out.as_bytes_mut().chunks_exact_mut(w * 3).enumerate() {
                let Some(src) = data.get(y * step..y * step + row) else {
                    return;
                };
                for (d, px) in dst.chunks_exact_mut(3).zip(src.chunks_exact(bpp)) {
                    d.copy_from_slice(&[px[r], px[g], px[b]]);
                }
            }
        }
        Encoding::Yuv422(packing) => yuv::fill_from_yuv422(packing, step, data, out),
        Encoding::Nv(order) => yuv::fill_from_nv(order, step, data, out),
        Encoding::Bayer(pattern) => bayer::fill_from_bayer(pattern, step, data, out),
    }
}
