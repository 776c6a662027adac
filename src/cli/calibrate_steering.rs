//! `marsupial calibrate-steering`: fits each axle's steering polynomial λ = f(x) (seed 003
//! §V-B, Fig. 6) from a sweep of belly-camera frames with known steering angles, and
//! optionally writes it into the profile.
//!
//! The sweep is either recorded (`--sweep SWEEP.csv`: one line per frame,
//! `image,steer_front_deg,steer_rear_deg`, image paths relative to the CSV, the angles
//! from the rover's potentiometers or a protractor, as the paper tabulated them) or
//! simulated (the profile's gear rendered by `sim::krawler` with sensor noise, both axles
//! swept from straight to +max, then to −max, in `--step-deg` steps; `--save-sweep DIR`
//! writes it in the recorded format, so the two paths can be compared).
//!
//! Both go through the same steps a running estimator takes: the markers are found in
//! each frame ([`MarkerFinder`]), predicted for the first frame from the profile's
//! nominal gear and then from the previous frame's markers (so the sweep must start near
//! straight and move in small steps, as a hand sweep does), each axle's roll pose from its
//! plate markers and its ratio from its tie-rod markers ([`AxleGeometry`]). An axle with
//! a marker missing in a frame gives no sample there. The fit is [`fit_steering`].

use crate::geometry::Pose2;
use crate::perception::RgbImage;
use crate::perception::krawler::{
    AxleGeometry, ExpectedMarker, GearGeometry, MarkerFinder, MarkerParams, SteeringFit, SteeringPoly, fit_steering,
};
use crate::profile::Profile;
use crate::sim::camera::camera_pose;
use crate::sim::krawler::{KrawlerState, build};
use crate::sim::lighting::LightState;
use crate::sim::render::{Renderer, SensorParams};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Options of `marsupial calibrate-steering` (also its command-line arguments).
#[derive(Debug, Clone, clap::Args)]
pub struct CalibrateSteeringOptions {
    /// The AutoKrawler-like profile (double-Ackermann drive, fisheye, eight markers).
    #[arg(long, value_name = "PROFILE")]
    pub profile: PathBuf,
    /// A recorded sweep: CSV `image,steer_front_deg,steer_rear_deg` with a header, image
    /// paths relative to the CSV. Without it, the sweep is simulated.
    #[arg(long, value_name = "SWEEP.csv")]
    pub sweep: Option<PathBuf>,
    /// Write the simulated sweep here as frames and sweep.csv (the recorded format).
    #[arg(long, value_name = "DIR", conflicts_with = "sweep")]
    pub save_sweep: Option<PathBuf>,
    /// The polynomial's order: 2 (the paper's) or 3 (for a linkage whose ratio saturates
    /// toward full lock, as the simulated trapezoid's does).
    #[arg(long, value_name = "N", default_value_t = 3)]
    pub order: usize,
    /// The simulated sweep's step, degrees.
    #[arg(long, value_name = "DEG", default_value_t = 1.0)]
    pub step_deg: f64,
    /// Write the fitted coefficients into the profile's ``markers` fiducial
    /// steering_poly_deg`, keeping the file's comments and layout.
    #[arg(long)]
    pub write: bool,
    /// Print JSON instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// One frame of a sweep.
struct SweepFrame {
    image: RgbImage,
    /// Steering (front, rear), degrees.
    steer_deg: [f64; 2],
    /// Where it came from, for errors.
    name: String,
}

/// The fits of both axles and their samples.
#[derive(Debug, Clone)]
pub struct SteeringCalibration {
    /// Front and rear fits.
    pub fits: [SteeringFit; 2],
    /// Samples used per axle: (ratio, λ in degrees).
    pub samples: [Vec<(f64, f64)>; 2],
    /// Frames in the sweep.
    pub frames: usize,
}

fn err(path: &Path, what: impl std::fmt::Display) -> String {
    format!("{}: {what}", path.display())
}

/// The steering angles of a simulated sweep: 0 → +max → −max in `step` steps, degrees.
pub fn simulated_angles(max_deg: f64, step_deg: f64) -> Vec<f64> {
    let n = (max_deg / step_deg).round() as i64;
    let up = (0..=n).map(|i| i as f64 * step_deg);
    let down = (1..=2 * n).map(|i| (n - i) as f64 * step_deg);
    up.chain(down).map(|a| a.clamp(-max_deg, max_deg)).collect()
}

fn render_sweep(profile: &Profile, step_deg: f64) -> Result<Vec<SweepFrame>, String> {
    let rest = KrawlerState::rest(profile).map_err(|e| e.to_string())?;
    let cam = &profile.cameras[0];
    let model = crate::perception::CameraModel::from_spec(cam);
    let mut renderer = Renderer::new(model, cam.width_px, cam.height_px, 17);
    let pose = camera_pose(&Pose2::new(0.0, 0.0, 0.0), &cam.mount);
    let max = profile.drive.max_steer_deg.unwrap_or(30.0);
    simulated_angles(max, step_deg)
        .into_iter()
        .enumerate()
        .map(|(i, deg)| {
            let l = deg.to_radians();
            let gear = build(profile, &KrawlerState { steer: [l, l], ..rest }).map_err(|e| e.to_string())?;
            let mut image = RgbImage::default();
            renderer.render(
                &gear.scene,
                &pose,
                &LightState::uniform(1.0),
                &SensorParams::default(),
                i as u64,
                &mut image,
            );
            Ok(SweepFrame {
                image,
                steer_deg: [deg, deg],
                name: format!("simulated frame {i} ({deg}°)"),
            })
        })
        .collect()
}

fn read_sweep(csv: &Path, profile: &Profile) -> Result<Vec<SweepFrame>, String> {
    let text = std::fs::read_to_string(csv).map_err(|e| err(csv, e))?;
    let base = csv.parent().unwrap_or(Path::new("."));
    let cam = &profile.cameras[0];
    let mut lines = text.lines().enumerate().filter(|(_, l)| !l.trim().is_empty());
    let header = lines.next().map(|(_, l)| l.trim()).unwrap_or_default();
    if header != "image,steer_front_deg,steer_rear_deg" {
        return Err(err(
            csv,
            format!("line 1: expected the header `image,steer_front_deg,steer_rear_deg`, got `{header}`"),
        ));
    }
    lines
        .map(|(i, line)| {
            let at = |what: String| err(csv, format!("line {}: {what}", i + 1));
            let cols: Vec<&str> = line.split(',').map(str::trim).collect();
            let [image, front, rear] = cols[..] else {
                return Err(at(format!("expected 3 columns, got {}", cols.len())));
            };
            let angle = |s: &str| {
                s.parse::<f64>()
                    .ok()
                    .filter(|a| a.is_finite())
                    .ok_or_else(|| at(format!("`{s}` is not a finite angle in degrees")))
            };
            let steer_deg = [angle(front)?, angle(rear)?];
            let path = base.join(image);
            let im = crate::image_io::load_rgb(&path).map_err(|e| at(e.to_string()))?;
            if (im.width(), im.height()) != (cam.width_px, cam.height_px) {
                return Err(at(format!(
                    "{image} is {}×{}, but the profile's camera is {}×{}",
                    im.width(),
                    im.height(),
                    cam.width_px,
                    cam.height_px
                )));
            }
            Ok(SweepFrame {
                image: im,
                steer_deg,
                name: format!("{image} (line {})", i + 1),
            })
        })
        .collect()
}

fn save_sweep(dir: &Path, frames: &[SweepFrame]) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| err(dir, e))?;
    let mut csv = String::from("image,steer_front_deg,steer_rear_deg\n");
    for (i, f) in frames.iter().enumerate() {
        let name = format!("sweep-{i:03}.png");
        crate::image_io::save_png(&dir.join(&name), &f.image).map_err(|e| err(dir, e))?;
        csv.push_str(&format!("{name},{},{}\n", f.steer_deg[0], f.steer_deg[1]));
    }
    let p = dir.join("sweep.csv");
    std::fs::write(&p, csv).map_err(|e| err(&p, e))
}

/// Fits both axles' polynomials from a sweep (recorded with `opts.sweep`, else
/// simulated).
///
/// # Errors
/// A message for a profile without the gear, an unreadable or malformed sweep (naming
/// the line), or a sweep that cannot be fitted (naming the axle).
pub fn calibrate(profile: &Profile, opts: &CalibrateSteeringOptions) -> Result<SteeringCalibration, String> {
    if profile.fiducial.get::<crate::profile::MarkersSpec>().copied().is_none() || profile.cameras.is_empty() {
        return Err(format!(
            "profile `{}` has no `markers` fiducial or no camera: calibrate-steering is for a belly-camera gear like profiles/autokrawler.toml",
            profile.name
        ));
    }
    if !(opts.step_deg > 0.0 && opts.step_deg <= 5.0) {
        return Err(format!(
            "--step-deg {}: expected a step in (0, 5]° (the markers are tracked from frame to frame)",
            opts.step_deg
        ));
    }
    let frames = match &opts.sweep {
        Some(csv) => read_sweep(csv, profile)?,
        None => render_sweep(profile, opts.step_deg)?,
    };
    if let Some(dir) = &opts.save_sweep {
        save_sweep(dir, &frames)?;
    }
    let geometry = AxleGeometry::from_profile(profile, 0).map_err(|e| e.to_string())?;
    let cam = &profile.cameras[0];
    // The first predictions from the estimator's own model of the gear at rest (a real
    // sweep's frames have no simulator behind them).
    let gear_spec = crate::behaviors::krawler::gear_spec(profile).map_err(|e| e.to_string())?;
    let gear = GearGeometry::from_profile(profile, gear_spec).map_err(|e| e.to_string())?;
    let side = profile
        .fiducial
        .get::<crate::profile::MarkersSpec>()
        .map_or(0.03, |m| m.side_m);
    let (mut predicted, _) = gear
        .start(&geometry, side)
        .ok_or("a marker of the gear at rest does not project into the camera")?;
    let mut finder = MarkerFinder::new(cam.width_px, cam.height_px, MarkerParams::default());
    let mut samples: [Vec<(f64, f64)>; 2] = [Vec::new(), Vec::new()];
    for f in &frames {
        let found = finder
            .find(&f.image.view(), &predicted)
            .map_err(|e| format!("{}: {e}", f.name))?;
        // Track: the next prediction is where each marker was seen, at its seen size.
        for blob in finder.blobs().iter().filter(|b| !b.rejected) {
            if let Some(m) = blob.marker {
                predicted[m] = ExpectedMarker {
                    at: blob.centre,
                    area: blob.area as f64,
                };
            }
        }
        for (axle, s) in samples.iter_mut().enumerate() {
            let o = axle * 4;
            let (Some(a1), Some(a2), Some(b1), Some(b2)) =
                (found.at[o], found.at[o + 1], found.at[o + 2], found.at[o + 3])
            else {
                continue;
            };
            if let Some(x) = geometry
                .axle_pose(axle, a1, a2)
                .and_then(|p| geometry.steering_ratio(&p, [b1, b2]))
            {
                s.push((x, f.steer_deg[axle]));
            }
        }
    }
    let fit = |axle: usize| {
        fit_steering(&samples[axle], opts.order).map_err(|e| {
            format!(
                "{} axle: {e} ({} of {} frames had all four of its markers)",
                ["front", "rear"][axle],
                samples[axle].len(),
                frames.len()
            )
        })
    };
    Ok(SteeringCalibration {
        fits: [fit(0)?, fit(1)?],
        samples,
        frames: frames.len(),
    })
}

/// Writes `polys` into the profile file at `path` as ``markers` fiducial
/// steering_poly_deg`, rounded to 1e-4°, keeping the rest of the file as it is.
///
/// # Errors
/// A message when the file cannot be read, parsed or written, or has no
/// `markers` fiducial table.
pub fn write_polys(path: &Path, polys: &[SteeringPoly; 2]) -> Result<(), String> {
    let text = std::fs::read_to_string(path).map_err(|e| err(path, e))?;
    let mut doc: toml_edit::DocumentMut = text.parse().map_err(|e| err(path, e))?;
    let markers = doc
        .get_mut("fiducial")
        .and_then(|m| m.as_table_like_mut())
        .filter(|f| f.get("kind").and_then(|k| k.as_str()) == Some("markers"))
        .ok_or_else(|| err(path, "no [fiducial] table of kind `markers`"))?;
    let mut outer = toml_edit::Array::new();
    for p in polys {
        let mut inner = toml_edit::Array::new();
        let order = if p.deg[3] == 0.0 { 2 } else { 3 };
        for c in &p.deg[..=order] {
            inner.push((c * 1e4).round() / 1e4);
        }
        outer.push(inner);
    }
    let mut item = toml_edit::value(outer);
    if let Some(v) = item.as_value_mut() {
        v.decor_mut().set_suffix(
            "  # λ (deg) = c0 + c1·(x−1) + c2·(x−1)² [+ c3·(x−1)³], front then rear; fitted by `marsupial calibrate-steering`",
        );
    }
    markers.insert("steering_poly_deg", item);
    std::fs::write(path, doc.to_string()).map_err(|e| err(path, e))?;
    // What was written must load.
    Profile::load(path).map(|_| ()).map_err(|e| e.to_string())
}

/// Runs the calibration and prints it (JSON with `--json`); with `--write`, updates the
/// profile.
///
/// # Errors
/// As [`calibrate`] and [`write_polys`], and for an unloadable profile.
pub fn run(opts: &CalibrateSteeringOptions, out: &mut dyn Write) -> Result<SteeringCalibration, String> {
    let profile = Profile::load(&opts.profile).map_err(|e| e.to_string())?;
    let cal = calibrate(&profile, opts)?;
    let polys = cal.fits.map(|f| f.poly);
    if opts.write {
        write_polys(&opts.profile, &polys)?;
    }
    let w = |e: std::io::Error| e.to_string();
    if opts.json {
        let axle = |a: usize| {
            let f = &cal.fits[a];
            serde_json::json!({
                "coefficients_deg": f.poly.deg,
                "rms_deg": f.rms_deg,
                "max_deg": f.max_deg,
                "ratio_range": [f.ratio_range.0, f.ratio_range.1],
                "samples": cal.samples[a].len(),
            })
        };
        let v = serde_json::json!({
            "frames": cal.frames,
            "front": axle(0),
            "rear": axle(1),
            "written": opts.write,
        });
        writeln!(out, "{v}").map_err(w)?;
    } else {
        writeln!(
            out,
            "λ (deg) = c0 + c1·(x−1) + c2·(x−1)² + c3·(x−1)³ (order {}), x = d(B1,A1)/d(B2,A2); {} frames",
            opts.order, cal.frames
        )
        .map_err(w)?;
        writeln!(
            out,
            "axle   c0        c1          c2          c3           samples  ratio range      RMS (°)  max (°)"
        )
        .map_err(w)?;
        for (a, f) in cal.fits.iter().enumerate() {
            writeln!(
                out,
                "{:<5}  {:>8.4}  {:>10.4}  {:>10.4}  {:>11.4}  {:>7}  {:.4}–{:.4}  {:>7.3}  {:>7.3}",
                ["front", "rear"][a],
                f.poly.deg[0],
                f.poly.deg[1],
                f.poly.deg[2],
                f.poly.deg[3],
                cal.samples[a].len(),
                f.ratio_range.0,
                f.ratio_range.1,
                f.rms_deg,
                f.max_deg
            )
            .map_err(w)?;
        }
        if opts.write {
            writeln!(out, "written to {}", opts.profile.display()).map_err(w)?;
        }
    }
    Ok(cal)
}
