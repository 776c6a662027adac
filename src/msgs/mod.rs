//! ROS 2 messages in CDR and camera pixels, for the places that read cameras: the bridge
//! (`ros2`, feature `ros2`), the replay of logs (`replay`, feature `sim`) and `marsupial
//! detect` (feature `cli`). Compiled with `image-io`, which each of those brings; it
//! needs neither the simulator nor the command-line tool.
//!
//! * [`cdr`]: plain CDR (XCDR1) reading and writing, and the decoders of
//!   `sensor_msgs/msg/Image`, `sensor_msgs/msg/CompressedImage` and
//!   `nav_msgs/msg/Odometry`;
//! * [`ros`]: those messages, their bytes borrowed, and their conversion to what
//!   perception and odometry take;
//! * [`pixels`]: what cameras deliver to packed RGB frames: raw `rgb8`, `bgr8`, `rgba8`,
//!   `bgra8`, `mono8`, YUV ([`yuv`]: `yuyv`, `uyvy`, `nv12`, `nv21`) and Bayer
//!   ([`bayer`]) buffers, and compressed ones (JPEG, so MJPEG, and PNG);
//! * [`camera_frame`]: one camera message to a frame of the profile camera's size;
//! * [`rescale`]: a frame of another size than the profile camera's to its size (same
//!   aspect ratio only), which keeps the profile's intrinsics valid.
//!
//! Every decoder is a pure function over `&[u8]` that never panics, for fuzzing.

pub mod bayer;
pub mod camera_frame;
pub mod cdr;
pub mod pixels;
pub mod raw;
pub mod rescale;
pub mod ros;
pub mod yuv;
