//! Reading and writing image files (PNG and JPEG; grey and RGBA are converted), for the
//! simulator's backdrops and recorded frames and the CLI's `detect`. Behind the `image-io`
//! feature so the core does not build an image codec.

use crate::perception::RgbImage;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// An image file could not be used.
#[derive(Debug, Error)]
pub enum ImageFileError {
    /// Not readable.
    #[error("{}: cannot read image: {source}", file.display())]
    Read {
        /// The file.
        file: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// Not a PNG or JPEG, or corrupt.
    #[error("{}: cannot decode image ({reason}); expected a PNG or JPEG file", file.display())]
    Decode {
        /// The file.
        file: PathBuf,
        /// Decoder message.
        reason: String,
    },
    /// Zero width or height.
    #[error("{}: image is empty ({width}×{height})", file.display())]
    Empty {
        /// The file.
        file: PathBuf,
        /// Width.
        width: u32,
        /// Height.
        height: u32,
    },
    /// Larger than the decoder accepts (a decompression bomb: a few kilobytes of PNG or
    /// JPEG can declare gigapixels); nothing was decoded.
    #[error(
        "{}: image is too large to decode ({width}×{height} = {} pixels; at most {max_pixels})",
        file.display(),
        u64::from(*width) * u64::from(*height)
    )]
    TooLarge {
        /// The file.
        file: PathBuf,
        /// Width its header declares.
        width: u32,
        /// Height its header declares.
        height: u32,
        /// The bound it exceeds, pixels.
        max_pixels: u64,
    },
    /// Could not be written.
    #[error("{}: cannot write image: {reason}", file.display())]
    Write {
        /// The file.
        file: PathBuf,
        /// Why.
        reason: String,
    },
}

/// The most pixels [`load_rgb`] decodes: 8192 × 8192 (64 Mpx, 512 MiB as 16-bit RGBA
/// while decoding). Larger images are refused with [`ImageFileError::TooLarge`] before any
/// pixel is decoded; [`decode_rgb`] takes another bound.
pub const DEFAULT_MAX_PIXELS: u64 = 8192 * 8192;

/// Loads a PNG or JPEG as packed RGB8, converting grey, grey+alpha and RGBA (alpha dropped)
/// and 16-bit images; at most [`DEFAULT_MAX_PIXELS`] pixels.
///
/// # Errors
/// [`ImageFileError`] naming the file.
pub fn load_rgb(path: &Path) -> Result<RgbImage, ImageFileError> {
    let bytes = std::fs::read(path).map_err(|source| ImageFileError::Read {
        file: path.to_path_buf(),
        source,
    })?;
    decode_rgb(&bytes, path, DEFAULT_MAX_PIXELS)
}

/// Decodes the bytes of a PNG or JPEG file (`file` is used in messages) as [`load_rgb`]
/// does, refusing an image whose header declares more than `max_pixels` pixels: the guard
/// against a decompression bomb. The decoder's own allocations are bounded to match
/// (8 bytes per pixel, 16-bit RGBA).
///
/// # Errors
/// [`ImageFileError::TooLarge`] over the bound, [`ImageFileError::Decode`] for anything
/// but a valid PNG or JPEG, [`ImageFileError::Empty`] for zero width or height.
pub fn decode_rgb(bytes: &[u8], file: &Path, max_pixels: u64) -> Result<RgbImage, ImageFileError> {
    let decode = |reason: String| ImageFileError::Decode {
        file: file.to_path_buf(),
        reason,
    };
    let img = decode_bounded(bytes, |w, h| u64::from(w) * u64::from(h) <= max_pixels).map_err(|e| match e {
        Refusal::Size { width, height } => ImageFileError::TooLarge {
            file: file.to_path_buf(),
            width,
            height,
            max_pixels,
        },
        Refusal::Format(format) => decode(format!("format {format:?} is not supported")),
        Refusal::Decode(why) => decode(why),
    })?;
    let rgb = img.to_rgb8();
    let (w, h) = rgb.dimensions();
    if w == 0 || h == 0 {
        return Err(ImageFileError::Empty {
            file: file.to_path_buf(),
            width: w,
            height: h,
        });
    }
    RgbImage::from_raw(w as usize, h as usize, rgb.into_raw()).map_err(|e| decode(e.to_string()))
}

/// Why [`decode_bounded`] refused bytes.
pub(crate) enum Refusal {
    /// A codec other than PNG or JPEG.
    Format(image::ImageFormat),
    /// The header's size is not accepted; nothing was decoded.
    Size {
        /// Width the header declares.
        width: u32,
        /// Height the header declares.
        height: u32,
    },
    /// Not a decodable image (the decoder's message).
    Decode(String),
}

/// The one way the crate decodes PNG or JPEG bytes, for image files and for a replayed
/// log's compressed frames: the codec from the bytes, then the header's size, which
/// `accept(width, height)` must allow before anything is allocated (the guard against a
/// decompression bomb), then the decode, its allocations bounded to match (8 bytes a
/// pixel: 16-bit RGBA). A PNG whose palette would crash the decoder is refused first
/// ([`png_palette_fault`]); any other panic inside the decoder is a [`Refusal::Decode`].
pub(crate) fn decode_bounded(bytes: &[u8], accept: impl Fn(u32, u32) -> bool) -> Result<image::DynamicImage, Refusal> {
    let format = image::guess_format(bytes).map_err(|e| Refusal::Decode(e.to_string()))?;
    if !matches!(format, image::ImageFormat::Png | image::ImageFormat::Jpeg) {
        return Err(Refusal::Format(format));
    }
    if format == image::ImageFormat::Png
        && let Some(why) = png_palette_fault(bytes)
    {
        return Err(Refusal::Decode(why));
    }
    let reader = || image::ImageReader::with_format(std::io::Cursor::new(bytes), format);
    let (width, height) = reader().into_dimensions().map_err(|e| Refusal::Decode(e.to_string()))?;
    if !accept(width, height) {
        return Err(Refusal::Size { width, height });
    }
    let mut limits = image::Limits::default();
    limits.max_alloc = Some((u64::from(width) * u64::from(height)).saturating_mul(8).max(1 << 20));
    let mut r = reader();
    r.limits(limits);
    crate::panics::contain("no message", || r.decode())
        .map_err(|why| Refusal::Decode(format!("the decoder failed on it ({why})")))?
        .map_err(|e| Refusal::Decode(e.to_string()))
}

/// Why a PNG's palette would crash the decoder, if it would: a `PLTE` chunk whose length
/// is not a multiple of three (the PNG specification, §11.2.3, requires whole RGB
/// entries). The `png` decoder (0.18) checks only that the length is 3–768 bytes and
/// then indexes past the end of a partial entry when it expands indexed pixels: a panic
/// on a 60-byte file, which fuzzing found. Checked here, before decoding, so such a file
/// is a decode error like any other corrupt image.
///
/// Walks the whole chunk list from the signature (a palette after the pixel data is
/// invalid too, but the decoder is not trusted to say so first); a list that ends early or declares a chunk
/// past the end is left to the decoder to report.
fn png_palette_fault(bytes: &[u8]) -> Option<String> {
    let mut at = 8usize;
    while let Some(header) = bytes.get(at..at.checked_add(8)?) {
        let len = u32::from_be_bytes([header[0], header[1], header[2], header[3]]) as usize;
        let kind = &header[4..8];
        if kind == b"PLTE" && !len.is_multiple_of(3) {
            return Some(format!(
                "PLTE chunk is {len} bytes, not a whole number of 3-byte palette entries"
            ));
        }
        if kind == b"IEND" {
            return None;
        }
        at = at.checked_add(12)?.checked_add(len)?;
    }
    None
}

/// Writes an RGB image as PNG.
///
/// # Errors
/// [`ImageFileError::Write`].
pub fn save_png(path: &Path, im: &RgbImage) -> Result<(), ImageFileError> {
    let write = |reason: String| ImageFileError::Write {
        file: path.to_path_buf(),
        reason,
    };
    let buf = image::RgbImage::from_raw(im.width() as u32, im.height() as u32, im.as_bytes().to_vec())
        .ok_or_else(|| write("buffer size does not match".into()))?;
    buf.save_with_format(path, image::ImageFormat::Png)
        .map_err(|e| write(e.to_string()))
}
