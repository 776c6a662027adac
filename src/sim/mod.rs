//! The embedded simulator: rendered cameras, lighting, motion with slip, contact, tether,
//! scenarios and trial campaigns.

pub mod camera;
pub mod krawler;
pub mod krawler_sequence;
pub mod lighting;
pub mod lighting_random;
pub mod render;
pub mod rng;
pub mod scene;
pub mod world;

use thiserror::Error;

/// Simulator errors.
#[derive(Debug, Error)]
pub enum SimError {
    /// The simulator cannot (yet) build what the profile describes.
    #[error("not supported by the simulator: {0}")]
    Unsupported(String),
    /// A command-line argument that cannot be used (e.g. an unknown `--bin` parameter).
    #[error("{0}")]
    InvalidArgument(String),
    /// A start pose the robot cannot be placed at.
    #[error("{0}")]
    InvalidStart(String),
    /// A scenario file problem.
    #[error(transparent)]
    Config(#[from] crate::config::ConfigError),
    /// An image (backdrop) could not be loaded.
    #[error(transparent)]
    Image(#[from] crate::image_io::ImageFileError),
    /// A run's MCAP recording could not be written.
    #[error(transparent)]
    Record(#[from] record::RecordError),
    /// Output could not be written.
    #[error("{path}: {source}")]
    Io {
        /// The path.
        path: String,
        /// Why.
        source: std::io::Error,
    },
}
pub mod campaign;
pub mod devices;
pub mod dock;
pub mod endurance;
pub mod engine;
pub mod faults;
pub mod kinds;
pub mod motion;
pub mod obstacles;
pub mod range;
pub mod record;
pub mod robot;
pub mod run;
pub mod scenario;
pub mod shard;
pub mod tether;
