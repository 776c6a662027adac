//! One camera message to a frame of the profile camera's size: decoded from whatever the
//! camera delivers ([`super::pixels`]) and rescaled when its size is another
//! ([`super::rescale`]). The ROS 2 node's cameras use it (`ros2::devices::TopicCamera`),
//! and a hand-written [`crate::robot::Camera`] driver can too.
//!
//! It owns the buffers that take: the native-size frame a rescale reads and the
//! rescaler's weights, so a stream of raw frames of one size converts without allocating
//! (the JPEG and PNG decoders allocate their own output).

use super::pixels::{PixelError, rgb_from_compressed, rgb_into_raw};
use super::rescale::Rescaler;
use crate::perception::RgbImage;

/// A camera's message, bytes borrowed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CameraBytes<'a> {
    /// Raw pixels, as `sensor_msgs/msg/Image` has them.
    Raw {
        /// Columns.
        width: u32,
        /// Rows.
        height: u32,
        /// The ROS encoding name (`rgb8`, `yuyv`, `nv12`, `bayer_rggb8` …).
        encoding: &'a str,
        /// Bytes per row.
        step: u32,
        /// The pixels.
        data: &'a [u8],
    },
    /// A compressed image (an MJPEG camera's JPEG frame, or PNG), as
    /// `sensor_msgs/msg/CompressedImage` has it.
    Compressed {
        /// `jpeg`, `png`, or image_transport's `bgr8; jpeg compressed bgr8`.
        format: &'a str,
        /// The compressed bytes.
        data: &'a [u8],
    },
}

/// Decodes camera messages into frames of a fixed size, keeping its buffers.
#[derive(Debug, Clone, Default)]
pub struct FrameDecoder {
    native: RgbImage,
    rescaler: Rescaler,
}

impl FrameDecoder {
    /// A decoder; its buffers grow to the first frames' sizes.
    pub fn new() -> Self {
        Self::default()
    }

    /// Decodes `bytes` into `frame`, rescaled to `frame`'s size when the message is of
    /// another size with the same aspect ratio (the profile's intrinsics then hold, see
    /// [`super::rescale`]). Returns the message's own size.
    ///
    /// # Errors
    /// [`PixelError`]: an encoding not read, sizes that do not add up, bytes that do not
    /// decode (a truncated or corrupt JPEG), or [`PixelError::Aspect`]. `frame` is then
    /// left as it was: every check comes before the first write.
    ///
    /// # Example
    ///
    /// ```
    /// use marsupial::msgs::camera_frame::{CameraBytes, FrameDecoder};
    /// use marsupial::perception::RgbImage;
    ///
    /// let mut frame = RgbImage::new(1, 1);
    /// let mut dec = FrameDecoder::new();
    /// // A 2×2 Bayer tile rescaled to the 1×1 camera.
    /// let tile = CameraBytes::Raw { width: 2, height: 2, encoding: "bayer_rggb8", step: 2, data: &[200, 100, 100, 0] };
    /// assert_eq!(dec.decode_into(tile, &mut frame).unwrap(), (2, 2));
    /// assert_eq!(frame.as_bytes(), &[200, 100, 0]);
    /// ```
    pub fn decode_into(&mut self, bytes: CameraBytes<'_>, frame: &mut RgbImage) -> Result<(usize, usize), PixelError> {
        let camera = (frame.width(), frame.height());
        match bytes {
            CameraBytes::Raw {
                width,
                height,
                encoding,
                step,
                data,
            } => {
                let size = (width as usize, height as usize);
                if size == camera {
                    rgb_into_raw(width, height, encoding, step, data, frame)?;
                    return Ok(size);
                }
                // Sizes are checked before the native buffer grows to them.
                if !super::rescale::same_aspect(size, camera) {
                    return Err(aspect(size, camera));
                }
                super::raw::check(width, height, encoding, step, data)?;
                self.native.resize(size.0, size.1);
                rgb_into_raw(width, height, encoding, step, data, &mut self.native)?;
                self.rescaler.fill(&self.native.view(), frame)?;
                Ok(size)
            }
            CameraBytes::Compressed { format, data } => {
                let rgb = rgb_from_compressed(format, data)?;
                let size = (rgb.width(), rgb.height());
                self.rescaler.fill(&rgb.view(), frame)?;
                Ok(size)
            }
        }
    }
}

fn aspect(size: (usize, usize), camera: (usize, usize)) -> PixelError {
    PixelError::Aspect {
        width: size.0,
        height: size.1,
        camera_width: camera.0,
        camera_height: camera.1,
    }
}
