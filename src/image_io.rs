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
    /// Could not be written.
    #[error("{}: cannot write image: {reason}", file.display())]
    Write {
        /// The file.
        file: PathBuf,
        /// Why.
        reason: String,
    },
}

/// Loads a PNG or JPEG as packed RGB8, converting grey, grey+alpha and RGBA (alpha dropped)
/// and 16-bit images.
///
/// # Errors
/// [`ImageFileError`] naming the file.
pub fn load_rgb(path: &Path) -> Result<RgbImage, ImageFileError> {
    let bytes = std::fs::read(path).map_err(|source| ImageFileError::Read {
        file: path.to_path_buf(),
        source,
    })?;
    let decode = |reason: String| ImageFileError::Decode {
        file: path.to_path_buf(),
        reason,
    };
    let format = image::guess_format(&bytes).map_err(|e| decode(e.to_string()))?;
    if !matches!(format, image::ImageFormat::Png | image::ImageFormat::Jpeg) {
        return Err(decode(format!("format {format:?} is not supported")));
    }
    let img = image::load_from_memory_with_format(&bytes, format).map_err(|e| decode(e.to_string()))?;
    let rgb = img.to_rgb8();
    let (w, h) = rgb.dimensions();
    if w == 0 || h == 0 {
        return Err(ImageFileError::Empty {
            file: path.to_path_buf(),
            width: w,
            height: h,
        });
    }
    RgbImage::from_raw(w as usize, h as usize, rgb.into_raw()).map_err(|e| decode(e.to_string()))
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
