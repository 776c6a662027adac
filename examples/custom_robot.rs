//! # Plugging your own robot into marsupial
//!
//! This is the starting point for a new platform. It shows the three things you write:
//!
//! 1. **A profile** (here inline; normally `profiles/<robot>.toml`) describing the drive,
//!    cameras, body, dock and loop timing. `marsupial check` validates it.
//! 2. **The hardware traits** from [`marsupial::robot`]: a [`Camera`], a [`Drive`], and
//!    optionally [`WheelEncoders`], a [`DockSensor`], a tether reel, arm, lights …
//!    Here they talk to a tiny toy world (a red beacon on a floor,
//!    `examples/common/toy_world.rs`); on your robot they talk to your drivers.
//! 3. **Behaviors**: a perceptual schema (find the red beacon with the crate's perception:
//!    HSV segmentation and connected components, from plain parameters), a motor schema (steer at
//!    it), paired with an activation condition, under a priority arbiter with a
//!    "docked" check on top.
//!
//! Then [`run`] drives the reactive loop on threads: one per camera, one for the slow
//! sensors, one for the actuators, the loop itself at the profile's rate. It stops the
//! robot if the camera goes stale and exits when the behavior reports an outcome.
//!
//! Run it with `cargo run --example custom_robot`.

#[path = "common/toy_world.rs"]
#[allow(dead_code)] // the post, range finder and bumper are the compose example's
mod toy_world;

use marsupial::arbiter::runtime::{RuntimeConfig, StopHandle, run};
use marsupial::arbiter::{Priority, ReactiveLoop};
use marsupial::geometry::Pose2;
use marsupial::perception::{ColorRange, HsvRange, Labeler, Mask, Segmenter};
use marsupial::profile::Profile;
use marsupial::robot::Robot;
use marsupial::schemas::{
    Behavior, DriveCommand, Feedback, Inputs, MotorOutput, MotorSchema, Outcome, Percept, PerceptualSchema,
    SchemaBehavior, Step,
};
use std::path::Path;
use std::time::Duration;
use toy_world::{ToyCamera, ToyDockSwitch, ToyDrive, ToyEncoders, World};

/// 1. The profile. Every field is checked; try misspelling one.
const PROFILE: &str = r#"
name = "toy"
description = "A differential-drive toy that docks at a red beacon"

[drive]
kind = "differential"
track_m = 0.30
max_speed_mps = 0.25
max_turn_rate_dps = 60.0

[body]
length_m = 0.35
width_m = 0.30
height_m = 0.20

[[cameras]]
name = "front"
model = "pinhole"
width_px = 160
height_px = 120
hfov_deg = 60.0
fps = 30.0

[dock]
entrance_width_m = 0.40
depth_m = 0.10
approach_radius_m = 3.0
approach_half_angle_deg = 90.0

[fiducial.markers]
count = 1
side_m = 0.10
color = "red"

[behavior]
approach = "none"
max_retries = 0
search_timeout_s = 20.0
phase_timeout_s = 20.0

[loop]
rate_hz = 20.0
camera_stale_s = 0.3

[success]
lateral_tolerance_m = 0.1
heading_tolerance_deg = 20.0
timeout_s = 30.0
"#;

// ---------------------------------------------------------------------------------------
// 2. Hardware: the toy world's devices (examples/common/toy_world.rs) stand in for your
//    drivers: a camera, a drive, wheel encoders and a dock switch.
// ---------------------------------------------------------------------------------------

// ---------------------------------------------------------------------------------------
// 3. Behaviors.
// ---------------------------------------------------------------------------------------

/// Percept: where the red beacon is in the image.
#[derive(Debug, Clone, Copy)]
struct Beacon {
    stamp: f64,
    found: bool,
    /// Column offset from the image centre, px (positive right).
    offset_px: f64,
    /// Pixels of the largest red blob (grows as we approach).
    pixels: usize,
}

impl Percept for Beacon {
    fn stamp(&self) -> f64 {
        self.stamp
    }
    fn found(&self) -> bool {
        self.found
    }
}

/// Perceptual schema: the crate's perception with plain parameters, no profile needed.
/// Red is a box in HSV (hue wrapping through 0°); the [`Segmenter`] writes the red pixels
/// into a [`Mask`], the [`Labeler`] finds its 8-connected blobs, and the largest blob is
/// the beacon. Every buffer is allocated once, for the camera's resolution.
struct FindRed {
    red: [ColorRange; 1],
    segmenter: Segmenter,
    mask: [Mask; 1],
    labeler: Labeler,
}

impl FindRed {
    /// Blobs smaller than this are noise, px.
    const MIN_PIXELS: u64 = 10;

    fn new(width: usize, height: usize) -> Self {
        Self {
            red: [ColorRange::Hsv(HsvRange {
                h: [340.0, 20.0],
                s: [0.5, 1.0],
                v: [0.4, 1.0],
            })],
            segmenter: Segmenter::new(),
            mask: [Mask::new(width, height)],
            labeler: Labeler::new(width, height),
        }
    }
}

impl PerceptualSchema for FindRed {
    type Percept = Beacon;
    fn perceive(&mut self, inputs: &Inputs<'_>) -> Beacon {
        let mut beacon = Beacon {
            stamp: inputs.now,
            found: false,
            offset_px: 0.0,
            pixels: 0,
        };
        let Some(cam) = inputs.camera(0) else {
            return beacon;
        };
        beacon.stamp = cam.stamp;
        // A frame of the wrong size is an error, not a beacon: report nothing seen.
        if self.segmenter.segment(&cam.image, &self.red, &mut self.mask).is_err() {
            return beacon;
        }
        let Ok(blobs) = self.labeler.label(&self.mask[0]) else {
            return beacon;
        };
        if let Some(blob) = blobs.iter().max_by_key(|b| b.count) {
            beacon.found = blob.count > Self::MIN_PIXELS;
            beacon.offset_px = blob.centroid().0 - cam.image.width() as f64 / 2.0;
            beacon.pixels = blob.count as usize;
        }
        beacon
    }
}

/// Motor schema: turn toward the beacon, slow down as it grows.
struct SteerAtBeacon;
impl MotorSchema for SteerAtBeacon {
    type Percept = Beacon;
    fn act(&self, b: &Beacon) -> MotorOutput {
        let v = (0.2 - b.pixels as f64 * 2e-5).clamp(0.05, 0.2);
        MotorOutput::twist(v, -0.012 * b.offset_px)
    }
}

/// Turns in place while nothing is seen.
struct Search;
impl Behavior for Search {
    fn name(&self) -> &str {
        "search"
    }
    fn tick(&mut self, inputs: &Inputs<'_>) -> Option<Step> {
        Some(Step::running(
            MotorOutput::drive(DriveCommand::Turn { omega: 0.6 }),
            Feedback::new("search", inputs.now),
        ))
    }
}

/// Top priority: report `Docked` once the dock switch closes.
struct DockedCheck;
impl Behavior for DockedCheck {
    fn name(&self) -> &str {
        "docked"
    }
    fn tick(&mut self, inputs: &Inputs<'_>) -> Option<Step> {
        inputs.docked_contact().then(|| {
            Step::done(
                Outcome::Docked,
                MotorOutput::stop(),
                Feedback::new("docked", inputs.now),
            )
        })
    }
}

fn main() {
    let profile = match Profile::parse(PROFILE, Path::new("custom_robot.toml")) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(1);
        }
    };

    // Start facing away from the beacon so the search behavior has work to do.
    let world = World::shared(Pose2::new(0.0, 0.0, -2.0), None);
    let mut robot = Robot::new(
        vec![Box::new(ToyCamera(world.clone()))],
        Box::new(ToyDrive(world.clone())),
    );
    robot.encoders = Some(Box::new(ToyEncoders(world.clone())));
    robot.dock_sensor = Some(Box::new(ToyDockSwitch(world.clone())));

    let approach = SchemaBehavior::new("approach", FindRed::new(160, 120), SteerAtBeacon, |b: &Beacon| b.found);
    let root = Priority::new(
        "root",
        vec![Box::new(DockedCheck), Box::new(approach), Box::new(Search)],
    );
    let mut lp = ReactiveLoop::new(Box::new(root), profile.loop_config());

    let config = RuntimeConfig {
        max_duration: Some(Duration::from_secs_f64(profile.success.timeout_s)),
        ..RuntimeConfig::default()
    };
    println!(
        "running the toy robot at {} Hz (up to {} s)…",
        profile.loop_.rate_hz, profile.success.timeout_s
    );
    let report = run(&mut robot, &mut lp, &config, &StopHandle::new());

    for e in &report.events {
        println!("{e}");
    }
    let pose = world.lock().map(|w| w.pose).unwrap_or_default();
    println!(
        "{} ticks in {:.1} s ({} overruns, slowest tick {:.3} ms); final pose ({:.2}, {:.2}, {:.0}°); outcome {:?}",
        report.ticks,
        report.elapsed_s,
        report.overruns,
        report.max_tick_s * 1e3,
        pose.x,
        pose.y,
        pose.theta.to_degrees(),
        report.outcome
    );
    if report.outcome != Some(Outcome::Docked) {
        std::process::exit(2);
    }
}
