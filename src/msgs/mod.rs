//! ROS 2 messages in CDR, for the two places that speak them: the bridge
//! (`ros2`, feature `ros2`) and the replay of logs (`replay`, feature `sim`).
//! Compiled with either; it needs neither the simulator nor the command-line tool.
//!
//! * [`cdr`]: plain CDR (XCDR1) reading and writing, and the decoders of
//!   `sensor_msgs/msg/Image`, `sensor_msgs/msg/CompressedImage` and
//!   `nav_msgs/msg/Odometry`;
//! * [`ros`]: those messages, their bytes borrowed, and their conversion to what
//!   perception and odometry take;
//! * [`pixels`]: raw (`rgb8`, `bgr8`, `rgba8`, `bgra8`, `mono8`) and compressed (JPEG,
//!   PNG) pixels to packed RGB frames.
//!
//! Every decoder is a pure function over `&[u8]` that never panics, for fuzzing.

pub mod cdr;
pub mod pixels;
pub mod ros;
