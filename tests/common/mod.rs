//! Helpers shared by integration tests: drawing synthetic fiducials, loading shipped
//! profiles, a noiseless sensor, placing a camera and rendering what it sees, temporary
//! folders, and a scripted driver that only backs in.
#![allow(dead_code)]

#[cfg(feature = "sim")]
pub mod axel;
#[cfg(feature = "sim")]
pub mod krawler;

use marsupial::geometry::Pose2;
use marsupial::perception::{RgbImage, SctRange};
use marsupial::profile::Profile;
#[cfg(feature = "sim")]
use marsupial::sim::render::{Renderer, SensorParams};
use std::path::{Path, PathBuf};

/// The real photographs (`../shared/data/photos`), or `None` (saying so) on a checkout
/// without them, so a test that needs them skips.
pub fn photos() -> Option<PathBuf> {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/photos");
    if p.is_dir() {
        Some(p)
    } else {
        eprintln!("skipping: {} not found", p.display());
        None
    }
}

/// A profile shipped in `profiles/`, by name.
pub fn shipped_profile(name: &str) -> Profile {
    Profile::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("profiles/{name}.toml"))).unwrap()
}

/// A sensor without noise or auto-exposure (fixed exposure 1), for renders whose pixel
/// values a test reads.
#[cfg(feature = "sim")]
pub fn quiet_sensor() -> SensorParams {
    SensorParams::noiseless()
}

/// The robot pose that puts camera 0 of `p` `d` m from the dock's origin, `alpha_deg`
/// off the dock axis (+x), with the body's +x pointing away from the origin turned by
/// `turn_deg` (0: a camera mounted on the body axis looking backwards sees the origin
/// straight ahead, as Bujold's and RAPOSA's do).
pub fn pose_seeing_origin(p: &Profile, d: f64, alpha_deg: f64, turn_deg: f64) -> Pose2 {
    let a = alpha_deg.to_radians();
    let theta = a + turn_deg.to_radians();
    let x = p.cameras[0].mount.x_m;
    Pose2::new(d * a.cos() - x * theta.cos(), d * a.sin() - x * theta.sin(), theta)
}

/// A renderer for camera 0 of `p`, its noise table seeded by `seed`.
#[cfg(feature = "sim")]
pub fn renderer(p: &Profile, seed: u64) -> Renderer {
    let cam = &p.cameras[0];
    Renderer::new(
        marsupial::perception::camera_model::CameraModel::from_spec(cam),
        cam.width_px,
        cam.height_px,
        seed,
    )
}

/// What camera 0 of `p` sees from `pose` in `world` under the default (lab) light with
/// the default sensor: the last of `frames` renders (auto-exposure settles over the first
/// few), light seeded by `seed` and frame k's noise by `seed + k`.
#[cfg(feature = "sim")]
pub fn render_lab(
    p: &Profile,
    world: &marsupial::sim::world::World,
    r: &mut Renderer,
    pose: &Pose2,
    seed: u64,
    frames: u64,
) -> RgbImage {
    use marsupial::sim::lighting::{LightingRun, LightingSpec};
    let cam = &p.cameras[0];
    let light = LightingRun::new(
        LightingSpec::default().resolve(),
        &mut marsupial::sim::rng::Rng::new(seed),
        10.0,
    );
    let mut out = RgbImage::default();
    for k in 0..frames.max(1) {
        r.render(
            &world.scene,
            &marsupial::sim::camera::camera_pose(pose, &cam.mount),
            &light.at(0.0),
            &SensorParams::default(),
            seed + k,
            &mut out,
        );
    }
    out
}

pub const CYAN: [u8; 3] = [20, 190, 210];
pub const MAGENTA: [u8; 3] = [200, 30, 190];
pub const GREY: [u8; 3] = [110, 105, 100];

/// Wide SCT ranges for the two test colours.
pub fn ranges() -> [SctRange; 2] {
    let d = |x: f64| x.to_radians();
    [
        SctRange {
            a: [d(30.0), d(60.0)],
            b: [d(70.0), d(90.0)],
            min_l: 30.0,
            min_chroma: 0.0,
        },
        SctRange {
            a: [d(30.0), d(60.0)],
            b: [d(0.0), d(20.0)],
            min_l: 30.0,
            min_chroma: 0.0,
        },
    ]
}

/// Fills the axis-aligned rectangle [x0, x1) × [y0, y1).
pub fn rect(im: &mut RgbImage, x0: usize, y0: usize, x1: usize, y1: usize, c: [u8; 3]) {
    for y in y0..y1 {
        for x in x0..x1 {
            im.put(x, y, c);
        }
    }
}

/// Two adjacent blocks, `left` then `right`, each `bw × bh`, top-left at (x, y).
pub fn fiducial(im: &mut RgbImage, x: usize, y: usize, bw: usize, bh: usize, left: [u8; 3], right: [u8; 3]) {
    rect(im, x, y, x + bw, y + bh, left);
    rect(im, x + bw, y, x + 2 * bw, y + bh, right);
}

/// A fiducial rotated by `roll` radians about its centre `c`, `size` = (w, h) overall.
pub fn rolled_fiducial(im: &mut RgbImage, c: (f64, f64), size: (f64, f64), roll: f64, left: [u8; 3], right: [u8; 3]) {
    let ((cx, cy), (w, h)) = (c, size);
    let (s, co) = roll.sin_cos();
    for y in 0..im.height() {
        for x in 0..im.width() {
            let (dx, dy) = (x as f64 + 0.5 - cx, y as f64 + 0.5 - cy);
            let (u, v) = (co * dx + s * dy, -s * dx + co * dy);
            if u.abs() <= w / 2.0 && v.abs() <= h / 2.0 {
                im.put(x, y, if u < 0.0 { left } else { right });
            }
        }
    }
}

pub fn background(w: usize, h: usize) -> RgbImage {
    let mut im = RgbImage::new(w, h);
    im.fill(GREY);
    im
}

/// A deterministic, textured and noisy scene of `w × h` with a magenta|cyan fiducial as
/// Bujold's upside-down camera sees it (magenta on the image's left), about `fid_frac` of
/// the image wide, plus same-coloured clutter. `seed` varies the noise.
pub fn scene(w: usize, h: usize, fid_frac: f64, seed: u64) -> RgbImage {
    let mut im = RgbImage::new(w, h);
    let mut s = seed.wrapping_mul(0x9E3779B97F4A7C15) | 1;
    let mut noise = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s % 13) as i32 - 6
    };
    for y in 0..h {
        for x in 0..w {
            let t = ((x as f64 * 0.07).sin() * 25.0 + (y as f64 * 0.045).cos() * 20.0) as i32;
            let base = [120 + t, 110 + t / 2, 95 - t / 3];
            let px = base.map(|c| (c + noise()).clamp(0, 255) as u8);
            im.put(x, y, px);
        }
    }
    let bw = (w as f64 * fid_frac / 2.0) as usize;
    let bh = bw * 11 / 9;
    let (x0, y0) = (w / 2 - bw, h / 2 - bh / 2);
    for y in y0..y0 + bh {
        for x in x0..x0 + 2 * bw {
            let c: [i32; 3] = if x < x0 + bw { [215, 35, 200] } else { [25, 200, 215] };
            im.put(x, y, c.map(|v| (v + noise()).clamp(0, 255) as u8));
        }
    }
    // Clutter: isolated blobs of both colours, too far apart to pair.
    for k in 0..6 {
        let (cx, cy) = (
            (k * 97 + 13) % (w - 20),
            if k % 2 == 0 { h / 8 } else { h * 7 / 8 - 10 },
        );
        let c = if k % 2 == 0 { [215, 35, 200] } else { [25, 200, 215] };
        rect(&mut im, cx, cy, cx + 8 + k, cy + 9, c);
    }
    im
}

/// Centroid (pixel centres at +0.5) of the pixels within `reach` px of `around`, each
/// weighted by `weight` of its RGB (0 leaves it out); `None` when nothing weighs.
pub fn weighted_centroid(
    im: &RgbImage,
    around: [f64; 2],
    reach: f64,
    weight: impl Fn([u8; 3]) -> f64,
) -> Option<[f64; 2]> {
    let (mut sx, mut sy, mut n) = (0.0, 0.0, 0.0);
    let v = im.view();
    let lo = |c: f64| (c - reach).max(0.0) as usize;
    for y in lo(around[1])..=((around[1] + reach) as usize).min(im.height() - 1) {
        for x in lo(around[0])..=((around[0] + reach) as usize).min(im.width() - 1) {
            let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
            if (px - around[0]).powi(2) + (py - around[1]).powi(2) > reach * reach {
                continue;
            }
            let w = weight(v.get(x, y).unwrap());
            sx += px * w;
            sy += py * w;
            n += w;
        }
    }
    (n > 0.0).then(|| [sx / n, sy / n])
}

/// Writes a scenario named `name` on the shipped profile `profile` (a file name in
/// `profiles/`, referenced by absolute path) into `dir`, its text after the `profile` line
/// being `rest`; returns its path.
pub fn scenario_file(dir: &Path, name: &str, profile: &str, rest: &str) -> PathBuf {
    std::fs::create_dir_all(dir).unwrap();
    let profile = Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles").join(profile);
    let path = dir.join(format!("{name}.toml"));
    std::fs::write(
        &path,
        format!("name = \"{name}\"\nprofile = \"{}\"\n{rest}", profile.display()),
    )
    .unwrap();
    path
}

/// Draws a circle mark of the simulator's pattern (`sim::scene::CircleMark`), 4×4
/// supersampled: centre (cx, cy) px, outer radius `r` px, bar at `rot_deg`
/// counter-clockwise (y up), on white paper out to 1.3 r.
pub fn circle_mark(im: &mut RgbImage, cx: f64, cy: f64, r: f64, rot_deg: f64) {
    let (s, c) = rot_deg.to_radians().sin_cos();
    let reach = 1.3 * r;
    let (w, h) = (im.width() as f64, im.height() as f64);
    for y in ((cy - reach).floor().max(0.0) as usize)..((cy + reach).ceil().min(h) as usize) {
        for x in ((cx - reach).floor().max(0.0) as usize)..((cx + reach).ceil().min(w) as usize) {
            let (mut acc, mut n) = (0.0, 0.0);
            let old = im.view().get(x, y).map_or(0.0, |p| p[1] as f64);
            for sy in 0..4 {
                for sx in 0..4 {
                    let a = x as f64 + (sx as f64 + 0.5) / 4.0 - cx;
                    let b = -(y as f64 + (sy as f64 + 0.5) / 4.0 - cy);
                    let rr = a.hypot(b);
                    let bar = rr < 0.6 * r && (b * c - a * s).abs() < 0.12 * r;
                    let black = rr < r && !(0.6 * r..0.8 * r).contains(&rr) && !bar;
                    acc += if rr >= reach {
                        old
                    } else if black {
                        12.0
                    } else {
                        220.0
                    };
                    n += 1.0;
                }
            }
            let v = (acc / n).round() as u8;
            im.put(x, y, [v, v, v]);
        }
    }
}

/// Axel's eight marks (`profiles/axel.toml`) seen face-on at `px_per_m`, the face's
/// (0, 0.6) m at `centre`: a frame for detection and correspondence without the
/// simulator.
pub fn axel_marks_frame(w: usize, h: usize, px_per_m: f64, centre: [f64; 2]) -> RgbImage {
    let mut im = background(w, h);
    let p = shipped_profile("axel");
    let c = p
        .fiducial
        .get::<marsupial::profile::CirclesSpec>()
        .expect("axel has circles");
    for pl in &c.placements {
        let x = centre[0] + px_per_m * pl.y_m;
        let y = centre[1] - px_per_m * (pl.z_m - 0.6);
        circle_mark(&mut im, x, y, px_per_m * c.diameter_m / 2.0, pl.rotation_deg);
    }
    im
}

/// A temporary folder, `marsupial-{tag}-{pid}-{nanos}` under the system's, emptied when
/// created and removed when dropped.
pub struct TempDir(pub PathBuf);

impl TempDir {
    /// A fresh folder for `tag`.
    pub fn new(tag: &str) -> Self {
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.subsec_nanos());
        let dir = std::env::temp_dir().join(format!("marsupial-{tag}-{}-{nanos}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Self(dir)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A scripted driver with no perception: lowers, then backs straight at 5 cm/s until
/// the dock switch closes. It refuses the departure mission (it only backs in).
pub struct Backer {
    started: Option<f64>,
}

impl marsupial::schemas::Behavior for Backer {
    fn name(&self) -> &str {
        "scripted_backer"
    }
    fn tick(&mut self, _mem: &mut (), inputs: &marsupial::schemas::Inputs<'_>) -> Option<marsupial::schemas::Step> {
        use marsupial::schemas::{Auxiliary, DriveCommand, Feedback, MotorOutput, Outcome, Posture, Step};
        let t0 = *self.started.get_or_insert(inputs.now);
        let fb = Feedback::new("back_in", inputs.now - t0);
        let aux = Auxiliary::with(Posture::Lowered);
        if inputs.docked_contact() {
            return Some(Step::done(Outcome::Docked, MotorOutput::stop().with_aux(aux), fb));
        }
        Some(Step::running(
            MotorOutput {
                drive: DriveCommand::Straight { v: -0.05 },
                aux,
            },
            fb,
        ))
    }
}

impl marsupial::schemas::Agent for Backer {
    fn begin(&mut self, mission: &marsupial::schemas::Mission) -> Result<(), marsupial::schemas::MissionError> {
        use marsupial::schemas::{Mission, MissionError};
        match mission {
            Mission::Departure => Err(MissionError::Unavailable {
                robot: "scripted_backer".into(),
                mission: "departure",
                why: "it only backs in".into(),
            }),
            Mission::Docking { .. } => {
                self.started = None;
                Ok(())
            }
        }
    }
}

/// A campaign's agent factory for [`Backer`].
pub fn backer(_: &Profile) -> Result<Box<dyn marsupial::schemas::Agent>, marsupial::behaviors::BuildError> {
    Ok(Box::new(Backer { started: None }))
}

/// A docking's retries: `used` of `max` spent.
pub fn retries(max: u32, used: u32) -> marsupial::behaviors::common::retries::Retries {
    let mut r = marsupial::behaviors::common::retries::Retries::new(max);
    for _ in 0..used {
        r.spend();
    }
    r
}

/// A tick's inputs at `now` holding only an odometry reading of `odo` (the phase tests
/// that drive leaves without the renderer).
pub fn odometry_inputs(now: f64, odo: marsupial::geometry::Pose2) -> marsupial::schemas::Inputs<'static> {
    let mut i = marsupial::schemas::Inputs::empty(now);
    i.odometry = Some(marsupial::schemas::Stamped::new(
        now,
        marsupial::schemas::OdometryReading {
            pose: odo,
            ..Default::default()
        },
    ));
    i
}
