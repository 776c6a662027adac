//! Perception: pure image functions that write into caller-owned buffers.
//!
//! Everything here is a plain function or a struct that allocates its scratch space once
//! and reuses it every frame; nothing reads a clock or a random source.

pub mod image;

pub use image::{ImageError, RgbImage, RgbView};
