//! `marsupial detect`: run the two-block perceptual schema over image files, as a stream.

use crate::config::ConfigError;
use crate::image_io::{ImageFileError, load_rgb, save_png};
use crate::perception::overlay::paint_overlay;
use crate::perception::{RgbImage, TwoBlockPercept, VisionError};
use crate::profile::Profile;
use crate::schemas::TwoBlockSchema;
use serde::Serialize;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;
use thiserror::Error;

/// Options of `marsupial detect` (also its command-line arguments).
#[derive(Debug, Clone, PartialEq, clap::Args)]
pub struct DetectOptions {
    /// Profile with a [fiducial.two_block] (e.g. profiles/bujold.toml).
    #[arg(long, value_name = "PROFILE")]
    pub profile: PathBuf,
    /// Imprint on this image first (repeatable; several frames are averaged).
    #[arg(long, value_name = "IMAGE")]
    pub imprint: Vec<PathBuf>,
    /// Static segmentation: keep the imprint, never adapt.
    #[arg(long = "static")]
    pub static_mode: bool,
    /// One JSON object per image.
    #[arg(long)]
    pub json: bool,
    /// Write the frame with segmented pixels painted in (PNG); with several images an
    /// index is added: OUT-000.png, OUT-001.png …
    #[arg(long, value_name = "OUT.png")]
    pub overlay: Option<PathBuf>,
    /// Time the whole schema this many times per image and report the median.
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub repeat: usize,
    /// Seconds between images (default: one frame period of the profile's camera).
    #[arg(long, value_name = "S")]
    pub interval: Option<f64>,
    /// Images, in stream order.
    #[arg(required = true, value_name = "IMAGE")]
    pub images: Vec<PathBuf>,
}

/// Why `detect` failed.
#[derive(Debug, Error)]
pub enum DetectError {
    /// Bad profile.
    #[error(transparent)]
    Profile(#[from] ConfigError),
    /// Bad image file.
    #[error(transparent)]
    Image(#[from] ImageFileError),
    /// The profile does not describe a two-block fiducial.
    #[error("{0}")]
    Vision(#[from] VisionError),
    /// Imprinting found too few bright pixels.
    #[error(
        "imprinting failed: the imprint images have fewer than 10 bright pixels in a profile imprint rectangle ([perception.imprint])"
    )]
    Imprint,
    /// Bad option value.
    #[error("{0}")]
    Usage(String),
    /// Writing the output failed.
    #[error("cannot write output: {0}")]
    Output(#[from] std::io::Error),
}

/// One line of `--json` output.
#[derive(Debug, Clone, Serialize)]
pub struct DetectRecord<'a> {
    /// The image path as given.
    pub image: &'a str,
    /// Width, px.
    pub width: usize,
    /// Height, px.
    pub height: usize,
    /// Fiducial found.
    pub found: bool,
    /// Pixels of the image-left block.
    pub left_px: u64,
    /// Pixels of the image-right block.
    pub right_px: u64,
    /// Sum of both.
    pub total_px: u64,
    /// min/max pixel-count ratio.
    pub ratio: f64,
    /// Image-left block centroid (x, y), or null.
    pub left_centroid: Option<[f64; 2]>,
    /// Image-right block centroid (x, y), or null.
    pub right_centroid: Option<[f64; 2]>,
    /// Pair midpoint minus image centre, px, or null.
    pub offset_px: Option<f64>,
    /// Statistics that segmented this image: `adapted`, `imprinted` or `table`.
    pub mode: String,
    /// Median wall time of the whole schema on this image, µs.
    pub us_per_frame: f64,
}

fn overlay_path(base: &Path, index: usize, count: usize) -> PathBuf {
    if count <= 1 {
        return base.to_path_buf();
    }
    let stem = base
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "overlay".into());
    let ext = base
        .extension()
        .map(|e| e.to_string_lossy().into_owned())
        .unwrap_or_else(|| "png".into());
    base.with_file_name(format!("{stem}-{index:03}.{ext}"))
}

fn fit(schema: &mut TwoBlockSchema, im: &RgbImage) {
    schema.detector_mut().resize(im.width(), im.height());
}

/// Runs `detect`, writing one line per image to `out`.
///
/// # Errors
/// [`DetectError`] for a bad profile, image, or option; nothing is printed for images
/// after the first bad one.
pub fn run(opts: &DetectOptions, out: &mut dyn Write) -> Result<(), DetectError> {
    if opts.images.is_empty() {
        return Err(DetectError::Usage("no IMAGE given".into()));
    }
    if opts.repeat == 0 {
        return Err(DetectError::Usage("--repeat must be at least 1".into()));
    }
    let profile = Profile::load(&opts.profile)?;
    let mut schema = TwoBlockSchema::from_profile(&profile, 0)?;
    let interval = match opts.interval {
        Some(i) if i.is_finite() && i >= 0.0 => i,
        Some(i) => return Err(DetectError::Usage(format!("--interval must be a number ≥ 0, got {i}"))),
        None => 1.0 / profile.cameras[0].fps,
    };
    // Load everything first so a bad file fails before any output.
    let imprint: Vec<RgbImage> = opts.imprint.iter().map(|p| load_rgb(p)).collect::<Result<_, _>>()?;
    let images: Vec<RgbImage> = opts.images.iter().map(|p| load_rgb(p)).collect::<Result<_, _>>()?;
    if !imprint.is_empty() {
        for im in &imprint {
            schema.imprint_frame(&im.view());
        }
        if !schema.finish_imprint(0.0) {
            return Err(DetectError::Imprint);
        }
    }
    schema.model_mut().set_adaptive(!opts.static_mode);
    let mut scratch = schema.clone();
    let mut overlay = RgbImage::default();
    let mut times = Vec::with_capacity(opts.repeat);
    for (k, (path, im)) in opts.images.iter().zip(&images).enumerate() {
        fit(&mut schema, im);
        let t = (k + 1) as f64 * interval;
        // Timing on a copy of the schema's state, so repeats do not adapt the stream.
        times.clear();
        for _ in 0..opts.repeat {
            scratch.clone_from(&schema);
            let start = Instant::now();
            let p = scratch.process(&im.view(), t)?;
            times.push(start.elapsed().as_secs_f64() * 1e6);
            std::hint::black_box(p);
        }
        times.sort_by(f64::total_cmp);
        let us = times[times.len() / 2];
        let p = schema.process(&im.view(), t)?;
        write_record(out, &path.display().to_string(), &p, us, opts.json)?;
        if let Some(base) = &opts.overlay {
            paint_overlay(&im.view(), schema.detector(), schema.last_pair(), &mut overlay);
            save_png(&overlay_path(base, k, opts.images.len()), &overlay)?;
        }
    }
    Ok(())
}

fn write_record(out: &mut dyn Write, image: &str, p: &TwoBlockPercept, us: f64, json: bool) -> Result<(), DetectError> {
    let found = |v: [f64; 2]| p.found.then_some(v);
    let rec = DetectRecord {
        image,
        width: p.image_size.0,
        height: p.image_size.1,
        found: p.found,
        left_px: p.left_px,
        right_px: p.right_px,
        total_px: p.total_px,
        ratio: p.ratio,
        left_centroid: found(p.left_centroid),
        right_centroid: found(p.right_centroid),
        offset_px: p.found.then_some(p.offset_px),
        mode: p.mode.to_string(),
        us_per_frame: (us * 10.0).round() / 10.0,
    };
    if json {
        writeln!(out, "{}", serde_json::to_string(&rec).map_err(std::io::Error::other)?)?;
    } else if p.found {
        writeln!(
            out,
            "{image}: found  left {} px  right {} px  ratio {:.3}  offset {:+.1} px  [{}]  {:.1} µs",
            p.left_px, p.right_px, p.ratio, p.offset_px, p.mode, rec.us_per_frame
        )?;
    } else {
        writeln!(out, "{image}: not found  [{}]  {:.1} µs", p.mode, rec.us_per_frame)?;
    }
    Ok(())
}
