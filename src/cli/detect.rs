//! `marsupial detect`: run a profile's fiducial detection over image files. A
//! `two_block`-fiducial profile runs the two-block perceptual schema as a stream
//! (adaptation carries from image to image); a `circles`-fiducial profile runs Axel's
//! circle-mark detection, correspondence and monocular pose on each image independently,
//! and with `--stereo` the stereo pose of each pair of images from cameras 0 and 1
//! ([`run`] dispatches on the profile).

use super::json_line;
use crate::config::ConfigError;
use crate::image_io::{ImageFileError, load_rgb, save_png};
use crate::msgs::pixels::{PixelError, rgb_from_raw};
use crate::msgs::rescale::ToCamera;
use crate::perception::circles::{
    CircleDetector, CircleModel, CircleParams, CorrespondenceError, CorrespondenceParams, DetectedMark, LensPlane,
    MarkObservations, ModelFit, ModulePose, PoseBuffers, PoseError, PoseParams, RigCamera, correspond,
    correspond_through, mono_pose, stereo_pose,
};
use crate::perception::overlay::{CirclesDrawing, paint_circles_overlay, paint_overlay};
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
    /// Profile with a `two_block` fiducial (e.g. profiles/bujold.toml) or a
    /// `circles` fiducial (profiles/axel.toml).
    #[arg(long, value_name = "PROFILE")]
    pub profile: PathBuf,
    /// The profile camera the images come from (its colour order for two-block; its lens
    /// model and mount for the circles' pose).
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub camera: usize,
    /// Imprint on this image first (repeatable; several frames are averaged; two-block only).
    #[arg(long, value_name = "IMAGE")]
    pub imprint: Vec<PathBuf>,
    /// Static segmentation: keep the imprint, never adapt (two-block only).
    #[arg(long = "static")]
    pub static_mode: bool,
    /// One JSON object per image.
    #[arg(long)]
    pub json: bool,
    /// Write the frame with what was found drawn in (PNG): two-block, the segmented
    /// pixels; circles, the marks, their ids and the reprojected model. With several
    /// images an index is added: OUT-000.png, OUT-001.png …
    #[arg(long, value_name = "OUT.png")]
    pub overlay: Option<PathBuf>,
    /// Time the whole schema (circles: detection, correspondence and pose) this many
    /// times per image and report the median.
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub repeat: usize,
    /// Seconds between images (default: one frame period of the profile's camera;
    /// two-block only).
    #[arg(long, value_name = "S")]
    pub interval: Option<f64>,
    /// Circles with two cameras: take the images in pairs (camera 0's, then camera 1's,
    /// taken together) and after each pair's two records print a third with the stereo
    /// pose (the marks labelled in both images triangulated, then the model fitted to
    /// them). Not with `--camera`.
    #[arg(long)]
    pub stereo: bool,
    /// The images (and imprint images) are raw camera frames, as `v4l2-ctl --stream-to`
    /// or a driver dumps them: ENCODING (a ROS name: `yuyv`, `uyvy`, `nv12`, `nv21`,
    /// `bayer_rggb8` …, `rgb8`, `mono8` …), WIDTH×HEIGHT, rows packed without padding.
    /// Without it, PNG and JPEG files.
    #[arg(long, value_name = "ENCODING:WxH", value_parser = parse_raw)]
    pub raw: Option<RawFormat>,
    /// Images, in stream order.
    #[arg(required = true, value_name = "IMAGE")]
    pub images: Vec<PathBuf>,
}

/// `--raw`: the encoding and size of raw frame files.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RawFormat {
    /// ROS encoding name.
    pub encoding: String,
    /// Columns.
    pub width: u32,
    /// Rows.
    pub height: u32,
}

fn parse_raw(s: &str) -> Result<RawFormat, String> {
    let bad = || format!("`{s}`: expected ENCODING:WIDTHxHEIGHT, e.g. yuyv:640x480");
    let (encoding, size) = s.split_once(':').ok_or_else(bad)?;
    let (w, h) = size.split_once(['x', '×']).ok_or_else(bad)?;
    let (width, height) = (w.parse().map_err(|_| bad())?, h.parse().map_err(|_| bad())?);
    Ok(RawFormat {
        encoding: encoding.to_string(),
        width,
        height,
    })
}

/// Reads one image: a PNG or JPEG file, or with `--raw` a raw frame of that encoding.
fn load(opts: &DetectOptions, path: &Path) -> Result<RgbImage, DetectError> {
    let Some(raw) = &opts.raw else {
        return Ok(load_rgb(path)?);
    };
    let bytes = std::fs::read(path).map_err(|source| ImageFileError::Read {
        file: path.to_path_buf(),
        source,
    })?;
    // Rows packed: a row is the frame's size over its rows (4:2:0's chroma rows included).
    let rows = if matches!(raw.encoding.as_str(), "nv12" | "nv21") {
        u64::from(raw.height) * 3 / 2
    } else {
        u64::from(raw.height)
    };
    let step = u32::try_from(bytes.len() as u64 / rows.max(1)).unwrap_or(u32::MAX);
    rgb_from_raw(raw.width, raw.height, &raw.encoding, step, &bytes).map_err(|why| DetectError::Raw {
        file: path.to_path_buf(),
        why,
    })
}

fn load_all(opts: &DetectOptions, paths: &[PathBuf]) -> Result<Vec<RgbImage>, DetectError> {
    paths.iter().map(|p| load(opts, p)).collect()
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
    /// A `--raw` frame file that is not a frame of that encoding and size.
    #[error("{}: {why}", file.display())]
    Raw {
        /// The file.
        file: PathBuf,
        /// Why, naming the encoding.
        why: PixelError,
    },
    /// Bad option value.
    #[error("{0}")]
    Usage(String),
    /// The profile has no fiducial `detect` handles.
    #[error("profile `{0}` has no `two_block` fiducial or `circles` fiducial: detect handles those two fiducials")]
    NoFiducial(String),
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
    if opts.camera >= profile.cameras.len() {
        return Err(DetectError::Usage(format!(
            "--camera {}: profile `{}` has {} camera(s), numbered from 0",
            opts.camera,
            profile.name,
            profile.cameras.len()
        )));
    }
    if profile.fiducial.get::<crate::profile::CirclesSpec>().is_some() {
        return run_circles(opts, &profile, out);
    }
    if profile
        .fiducial
        .get::<crate::profile::TwoBlockSpec>()
        .copied()
        .is_none()
    {
        return Err(DetectError::NoFiducial(profile.name.clone()));
    }
    if opts.stereo {
        return Err(DetectError::Usage(format!(
            "--stereo applies to `circles` fiducials only; `{}` has `two_block` fiducial",
            profile.name
        )));
    }
    let mut schema = TwoBlockSchema::from_profile(&profile, opts.camera)?;
    let interval = match opts.interval {
        Some(i) if i.is_finite() && i >= 0.0 => i,
        Some(i) => return Err(DetectError::Usage(format!("--interval must be a number ≥ 0, got {i}"))),
        None => 1.0 / profile.cameras[opts.camera].fps,
    };
    // Load everything first so a bad file fails before any output.
    let imprint = load_all(opts, &opts.imprint)?;
    let images = load_all(opts, &opts.images)?;
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
        let us = median(&mut times);
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
        json_line(out, &rec)?;
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

/// One labelled mark of a circles record: a model mark, detected or filled in.
#[derive(Debug, Clone, Serialize)]
pub struct CircleMarkRecord {
    /// Index of the mark in the profile's ``circles` fiducial.placements`.
    pub id: usize,
    /// The bar's rotation, degrees: as the detector read it for a detected mark, the
    /// model's for a filled-in one.
    pub rotation_deg: f64,
    /// Centre, px: the fitted ellipse's for a detected mark, the homography's
    /// reprojection for a filled-in one.
    pub centroid: [f64; 2],
    /// True when detected; false when filled in from the reprojection.
    pub detected: bool,
}

/// A detected mark the correspondence did not label (a false positive, or any mark when
/// no labelling was accepted).
#[derive(Debug, Clone, Serialize)]
pub struct UnlabelledMarkRecord {
    /// The bar's rotation as read, degrees (null when the bar was not resolved).
    pub rotation_deg: Option<f64>,
    /// Centre of the fitted ellipse, px.
    pub centroid: [f64; 2],
}

/// The module's pose in a circles record: the monocular pose through the camera's lens
/// model, or the stereo pose of a pair, in the rover frame (+x forward, +y left, +z up,
/// origin on the ground under the rover's reference point).
#[derive(Debug, Clone, Serialize)]
pub struct CirclePoseRecord {
    /// `mono` (one image, one camera) or `stereo` (a pair, cameras 0 and 1).
    pub source: &'static str,
    /// The camera it was measured through (for `stereo`, 0: the pair's first).
    pub camera: usize,
    /// The module frame's origin (its face centre on the ground) in the rover frame, m.
    pub position_m: [f64; 3],
    /// Direction the module's face looks, degrees counter-clockwise from rover +x
    /// (about ±180 when the rover faces the face squarely).
    pub heading_deg: f64,
    /// The rover's planar pose about the module, (x m, y m, heading °) in the module
    /// frame: what the polar planner uses.
    pub rover_in_module: [f64; 3],
    /// Quality figure: RMS distance between the detected centres and the posed model's
    /// marks projected through the camera (for `stereo`, through both), px.
    pub reprojection_px: f64,
    /// Quality figure: RMS distance between the posed model's marks and the rays
    /// through their detections, m.
    pub rms_residual_m: f64,
    /// Detected marks the pose was computed from.
    pub marks_used: usize,
}

/// One line of `--json` output for a `circles`-fiducial profile.
#[derive(Debug, Clone, Serialize)]
pub struct CirclesRecord<'a> {
    /// The image path as given.
    pub image: &'a str,
    /// Width, px.
    pub width: usize,
    /// Height, px.
    pub height: usize,
    /// A labelling of at least 5 marks was accepted.
    pub found: bool,
    /// Why not found (null when found).
    pub reason: Option<String>,
    /// The profile camera the image is taken as.
    pub camera: usize,
    /// Marks the detector reported.
    pub detected: usize,
    /// Every model mark, by id, when found (empty otherwise).
    pub marks: Vec<CircleMarkRecord>,
    /// Detections left unlabelled.
    pub unlabelled: Vec<UnlabelledMarkRecord>,
    /// The correspondence hypothesis kept, 0–15 (bit c: rotation class c's marks taken in
    /// reverse), or null.
    pub hypothesis: Option<u8>,
    /// Distinct hypotheses tried (at most 16), or null.
    pub hypotheses_tried: Option<u8>,
    /// RMS distance between the inliers and the homography's reprojection, px, or null.
    pub reprojection_px: Option<f64>,
    /// Detected marks the labelling matched, or null.
    pub inliers: Option<usize>,
    /// The module's pose, or null.
    pub pose: Option<CirclePoseRecord>,
    /// Why there is no pose although marks were labelled (null otherwise).
    pub pose_error: Option<String>,
    /// Median wall time of detection, correspondence and pose on this image, µs.
    pub us_per_frame: f64,
}

/// One `--stereo` line of `--json` output: the stereo pose of a pair of images.
#[derive(Debug, Clone, Serialize)]
pub struct StereoRecord<'a> {
    /// The pair's images as given: camera 0's, camera 1's.
    pub stereo: [&'a str; 2],
    /// The module's pose from both images (`source` = `stereo`), or null.
    pub pose: Option<CirclePoseRecord>,
    /// Why there is no stereo pose (null when there is one): a camera found no
    /// labelling, or too few marks were labelled in both.
    pub pose_error: Option<String>,
    /// Median wall time of both images' detection and correspondence and the stereo
    /// pose, µs.
    pub us_per_pair: f64,
}

/// The circles pipeline for one camera, every buffer owned and reused.
struct CirclesRun {
    detector: CircleDetector,
    model: CircleModel,
    cam: RigCamera,
    /// The camera's lens, for labelling through its distortion.
    lens: LensPlane,
    camera: usize,
    cam_size: (usize, usize),
    corr: CorrespondenceParams,
    pose_params: PoseParams,
    buf: PoseBuffers,
}

/// What the pipeline made of one image (the marks stay in the detector).
struct CirclesOutcome {
    fit: Result<ModelFit, CorrespondenceError>,
    pose: Option<Result<ModulePose, String>>,
}

impl CirclesRun {
    fn new(profile: &Profile, camera: usize) -> Result<Self, DetectError> {
        let spec = &profile.cameras[camera];
        let cam = RigCamera::from_profile(profile, camera)?;
        Ok(Self {
            detector: CircleDetector::new(
                spec.width_px,
                spec.height_px,
                CircleParams::from_profile(profile, spec.width_px),
            ),
            model: CircleModel::from_profile(profile)?,
            lens: LensPlane::new(cam.model.clone()),
            cam,
            camera,
            cam_size: (spec.width_px, spec.height_px),
            corr: CorrespondenceParams::default(),
            pose_params: PoseParams::default(),
            buf: PoseBuffers::new(),
        })
    }

    fn process(&mut self, im: &RgbImage) -> Result<CirclesOutcome, VisionError> {
        if self.detector.size() != (im.width(), im.height()) {
            let params = self.detector.params().for_width(im.width());
            self.detector = CircleDetector::new(im.width(), im.height(), params);
        }
        let marks = self.detector.detect(&im.view())?;
        // Through the lens when the image is the camera's; another size has no lens model.
        let fit = if (im.width(), im.height()) == self.cam_size {
            correspond_through(&self.model, marks, &mut self.lens, &self.corr)
        } else {
            correspond(&self.model, marks, &self.corr)
        };
        let pose = fit.as_ref().ok().map(|f| {
            if (im.width(), im.height()) != self.cam_size {
                return Err(format!(
                    "the image is {}×{} px but camera {} is {}×{}: no pose through its model",
                    im.width(),
                    im.height(),
                    self.camera,
                    self.cam_size.0,
                    self.cam_size.1
                ));
            }
            let obs = MarkObservations::from_fit(f, marks);
            mono_pose(
                &self.model,
                &self.cam,
                self.camera,
                &obs,
                &self.pose_params,
                &mut self.buf,
            )
            .map_err(|e: PoseError| e.to_string())
        });
        Ok(CirclesOutcome { fit, pose })
    }
}

fn round(v: f64, decimals: i32) -> f64 {
    let s = 10f64.powi(decimals);
    (v * s).round() / s
}

fn run_circles(opts: &DetectOptions, profile: &Profile, out: &mut dyn Write) -> Result<(), DetectError> {
    for (given, name) in [
        (!opts.imprint.is_empty(), "--imprint"),
        (opts.static_mode, "--static"),
        (opts.interval.is_some(), "--interval"),
    ] {
        if given {
            return Err(DetectError::Usage(format!(
                "{name} applies to `two_block` fiducials only; `{}` has `circles` fiducial",
                profile.name
            )));
        }
    }
    if opts.stereo {
        return run_circles_stereo(opts, profile, out);
    }
    let mut run = CirclesRun::new(profile, opts.camera)?;
    let images = load_all(opts, &opts.images)?;
    let mut overlay = RgbImage::default();
    let mut times = Vec::with_capacity(opts.repeat);
    // Another size of the camera's aspect ratio is rescaled, so its lens model holds.
    let mut to_camera = ToCamera::new(run.cam_size);
    for (k, (path, im)) in opts.images.iter().zip(&images).enumerate() {
        let im = to_camera.fit(im);
        times.clear();
        let mut outcome = None;
        for _ in 0..opts.repeat {
            let start = Instant::now();
            let o = run.process(im)?;
            times.push(start.elapsed().as_secs_f64() * 1e6);
            outcome = Some(o);
        }
        let Some(o) = outcome else { continue };
        let name = path.display().to_string();
        let rec = circles_record(&name, im, &run, &o, median(&mut times));
        write_circles(out, &rec, opts.json)?;
        if let Some(base) = &opts.overlay {
            draw_circles(&run, &o, im, &mut overlay, &overlay_path(base, k, opts.images.len()))?;
        }
    }
    Ok(())
}

/// `--stereo`: the images in pairs, camera 0's then camera 1's; each image's record as
/// without `--stereo`, then the pair's stereo pose.
fn run_circles_stereo(opts: &DetectOptions, profile: &Profile, out: &mut dyn Write) -> Result<(), DetectError> {
    if profile.cameras.len() < 2 {
        return Err(DetectError::Usage(format!(
            "--stereo needs two cameras; profile `{}` has {}",
            profile.name,
            profile.cameras.len()
        )));
    }
    if opts.camera != 0 {
        return Err(DetectError::Usage(
            "--stereo takes the images as pairs from cameras 0 and 1: leave out --camera".into(),
        ));
    }
    if !opts.images.len().is_multiple_of(2) {
        return Err(DetectError::Usage(format!(
            "--stereo takes the images in pairs (camera 0's, then camera 1's); {} given",
            opts.images.len()
        )));
    }
    let mut runs = [CirclesRun::new(profile, 0)?, CirclesRun::new(profile, 1)?];
    let images = load_all(opts, &opts.images)?;
    let mut overlay = RgbImage::default();
    let (mut times, mut pair_times) = ([Vec::new(), Vec::new()], Vec::new());
    let mut to_camera = [ToCamera::new(runs[0].cam_size), ToCamera::new(runs[1].cam_size)];
    for (pair, (paths, ims)) in opts.images.chunks(2).zip(images.chunks(2)).enumerate() {
        let [fit0, fit1] = &mut to_camera;
        let ims = [fit0.fit(&ims[0]), fit1.fit(&ims[1])];
        let mut last = None;
        times.iter_mut().for_each(Vec::clear);
        pair_times.clear();
        for _ in 0..opts.repeat {
            let started = Instant::now();
            let mut outcomes = Vec::with_capacity(2);
            for (c, run) in runs.iter_mut().enumerate() {
                let t = Instant::now();
                outcomes.push(run.process(ims[c])?);
                times[c].push(t.elapsed().as_secs_f64() * 1e6);
            }
            let stereo = stereo_of(&mut runs, &outcomes, ims);
            pair_times.push(started.elapsed().as_secs_f64() * 1e6);
            last = Some((outcomes, stereo));
        }
        let Some((outcomes, stereo)) = last else { continue };
        let names = [paths[0].display().to_string(), paths[1].display().to_string()];
        for c in 0..2 {
            let rec = circles_record(&names[c], ims[c], &runs[c], &outcomes[c], median(&mut times[c]));
            write_circles(out, &rec, opts.json)?;
            if let Some(base) = &opts.overlay {
                let path = overlay_path(base, 2 * pair + c, opts.images.len());
                draw_circles(&runs[c], &outcomes[c], ims[c], &mut overlay, &path)?;
            }
        }
        let rec = StereoRecord {
            stereo: [&names[0], &names[1]],
            pose: stereo.as_ref().ok().map(|p| pose_record(p, "stereo", 0)),
            pose_error: stereo.err(),
            us_per_pair: round(median(&mut pair_times), 1),
        };
        write_stereo(out, &rec, opts.json)?;
    }
    Ok(())
}

/// The stereo pose from both cameras' labellings, or why there is none.
fn stereo_of(
    runs: &mut [CirclesRun; 2],
    outcomes: &[CirclesOutcome],
    ims: [&RgbImage; 2],
) -> Result<ModulePose, String> {
    let mut obs = [MarkObservations::new(runs[0].model.len()); 2];
    for c in 0..2 {
        let fit = outcomes[c].fit.as_ref().map_err(|e| format!("camera {c}: {e}"))?;
        if (ims[c].width(), ims[c].height()) != runs[c].cam_size {
            return Err(format!(
                "camera {c}'s image is {}×{} px but the camera is {}×{}",
                ims[c].width(),
                ims[c].height(),
                runs[c].cam_size.0,
                runs[c].cam_size.1
            ));
        }
        obs[c] = MarkObservations::from_fit(fit, runs[c].detector.marks());
    }
    let [r0, r1] = runs;
    stereo_pose(
        &r0.model,
        [&r0.cam, &r1.cam],
        [&obs[0], &obs[1]],
        &r0.pose_params,
        &mut r0.buf,
    )
    .map_err(|e: PoseError| e.to_string())
}

/// The median of `times` (sorted in place); 0 when empty.
fn median(times: &mut [f64]) -> f64 {
    times.sort_by(f64::total_cmp);
    times.get(times.len() / 2).copied().unwrap_or(0.0)
}

fn draw_circles(
    run: &CirclesRun,
    o: &CirclesOutcome,
    im: &RgbImage,
    overlay: &mut RgbImage,
    path: &Path,
) -> Result<(), DetectError> {
    let pose = o.pose.as_ref().and_then(|p| p.as_ref().ok()).map(|p| (p, &run.cam));
    let drawing = CirclesDrawing {
        marks: run.detector.marks(),
        model: &run.model,
        fit: o.fit.as_ref().ok(),
        pose,
    };
    paint_circles_overlay(&im.view(), &drawing, overlay);
    save_png(path, overlay)?;
    Ok(())
}

fn circles_record<'a>(
    image: &'a str,
    im: &RgbImage,
    run: &CirclesRun,
    o: &CirclesOutcome,
    us: f64,
) -> CirclesRecord<'a> {
    let marks: &[DetectedMark] = run.detector.marks();
    let px = |c: [f64; 2]| [round(c[0], 2), round(c[1], 2)];
    let mut rec = CirclesRecord {
        image,
        width: im.width(),
        height: im.height(),
        found: o.fit.is_ok(),
        reason: o.fit.as_ref().err().map(|e| e.to_string()),
        camera: run.camera,
        detected: marks.len(),
        marks: Vec::new(),
        unlabelled: Vec::new(),
        hypothesis: None,
        hypotheses_tried: None,
        reprojection_px: None,
        inliers: None,
        pose: None,
        pose_error: None,
        us_per_frame: round(us, 1),
    };
    let fit = o.fit.as_ref().ok();
    for (i, m) in marks.iter().enumerate() {
        if !fit.is_some_and(|f| f.is_inlier(i)) {
            rec.unlabelled.push(UnlabelledMarkRecord {
                rotation_deg: m.rotation.map(|r| r.degrees()),
                centroid: px(m.centre),
            });
        }
    }
    let Some(fit) = fit else { return rec };
    for (j, model_rot) in run.model.rotations().iter().enumerate() {
        let det = fit.detection_of(j).and_then(|i| marks.get(i));
        rec.marks.push(CircleMarkRecord {
            id: j,
            rotation_deg: det.and_then(|m| m.rotation).unwrap_or(*model_rot).degrees(),
            centroid: px(fit.centre(marks, j).unwrap_or(fit.projected()[j])),
            detected: det.is_some(),
        });
    }
    rec.hypothesis = Some(fit.hypothesis);
    rec.hypotheses_tried = Some(fit.hypotheses_tried);
    rec.reprojection_px = Some(round(fit.rms_px, 3));
    rec.inliers = Some(fit.inliers);
    match &o.pose {
        Some(Ok(p)) => rec.pose = Some(pose_record(p, "mono", run.camera)),
        Some(Err(e)) => rec.pose_error = Some(e.clone()),
        None => {}
    }
    rec
}

fn pose_record(p: &ModulePose, source: &'static str, camera: usize) -> CirclePoseRecord {
    let t = p.translation;
    let r = p.rover_in_module();
    CirclePoseRecord {
        source,
        camera,
        position_m: [round(t.x, 4), round(t.y, 4), round(t.z, 4)],
        heading_deg: round(p.heading().to_degrees(), 2),
        rover_in_module: [round(r[0], 4), round(r[1], 4), round(r[2].to_degrees(), 2)],
        reprojection_px: round(p.reprojection_px, 3),
        rms_residual_m: round(p.rms_residual_m, 5),
        marks_used: p.marks_used,
    }
}

fn write_circles(out: &mut dyn Write, rec: &CirclesRecord<'_>, json: bool) -> Result<(), DetectError> {
    if json {
        json_line(out, rec)?;
        return Ok(());
    }
    let image = rec.image;
    let Some(reason) = &rec.reason else {
        let filled = rec.marks.iter().filter(|m| !m.detected).count();
        write!(
            out,
            "{image}: found  {} marks ({filled} filled in, {} unlabelled)  hypothesis {} of {}  reprojection {:.2} px",
            rec.marks.len(),
            rec.unlabelled.len(),
            rec.hypothesis.unwrap_or_default(),
            rec.hypotheses_tried.unwrap_or_default(),
            rec.reprojection_px.unwrap_or_default(),
        )?;
        match (&rec.pose, &rec.pose_error) {
            (Some(p), _) => write!(
                out,
                "  module at ({:.3}, {:.3}, {:.3}) m heading {:.1}° [mono, camera {}, {:.2} px, {} marks]",
                p.position_m[0],
                p.position_m[1],
                p.position_m[2],
                p.heading_deg,
                p.camera,
                p.reprojection_px,
                p.marks_used
            )?,
            (None, Some(e)) => write!(out, "  no pose: {e}")?,
            (None, None) => {}
        }
        writeln!(out, "  {:.1} µs", rec.us_per_frame)?;
        return Ok(());
    };
    writeln!(out, "{image}: not found: {reason}  {:.1} µs", rec.us_per_frame)?;
    Ok(())
}

fn write_stereo(out: &mut dyn Write, rec: &StereoRecord<'_>, json: bool) -> Result<(), DetectError> {
    if json {
        json_line(out, rec)?;
        return Ok(());
    }
    let [left, right] = rec.stereo;
    match (&rec.pose, &rec.pose_error) {
        (Some(p), _) => writeln!(
            out,
            "{left} + {right}: stereo module at ({:.3}, {:.3}, {:.3}) m heading {:.1}° [{:.2} px, {:.4} m, {} marks]  {:.1} µs",
            p.position_m[0],
            p.position_m[1],
            p.position_m[2],
            p.heading_deg,
            p.reprojection_px,
            p.rms_residual_m,
            p.marks_used,
            rec.us_per_pair
        )?,
        (None, e) => writeln!(
            out,
            "{left} + {right}: no stereo pose: {}  {:.1} µs",
            e.as_deref().unwrap_or("unknown"),
            rec.us_per_pair
        )?,
    }
    Ok(())
}
