//! Sparse optical flow: Shi–Tomasi corners ([`corners`]) tracked by pyramidal
//! Lucas–Kanade with a forward–backward check ([`lk`]) over float grey pyramids
//! ([`grey`]). The AutoKrawler's wheel-rotation estimate (seed 003 §V-C) is built on them;
//! they work on any grey frames.

pub mod corners;
pub mod grey;
pub mod lk;

pub use corners::{CornerParams, Roi, ShiTomasi};
pub use grey::{GreyImage, GreyPyramid};
pub use lk::{LkParams, LucasKanade};
