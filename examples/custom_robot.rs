//! # Plugging your own robot into marsupial
//!
//! This is the starting point for a new platform. It shows the three things you write:
//!
//! 1. **A profile** (here `examples/common/toy_robot.toml` plus a few lines inline;
//!    normally `profiles/<robot>.toml`) describing the drive, cameras, body, dock and loop
//!    timing. `marsupial check` validates it.
//! 2. **The hardware traits** from [`marsupial::robot`]: a [`Camera`], a [`Drive`], and
//!    optionally [`WheelEncoders`], and a [`Sensor`] or an [`Actuator`] for each device
//!    the profile declares by kind (here the `dock_contact` switch; a tether reel, arm,
//!    lights … are kinds too, read and commanded typed: [`marsupial::schemas::devices`])
//!    Here they talk to a tiny toy world (a red beacon on a floor,
//!    `examples/common/toy_world.rs`); on your robot they talk to your drivers.
//! 3. **Behaviors**: a perceptual schema (find the red beacon with the crate's perception:
//!    HSV segmentation and connected components, from plain parameters,
//!    `examples/common/red_beacon.rs`), a motor schema (steer at it), paired with an activation condition, under a priority arbiter with a
//!    "docked" check on top.
//!
//! Then [`run`] drives the reactive loop on threads: one per camera, one for the slow
//! sensors, one for the actuators, the loop itself at the profile's rate. It stops the
//! robot if the camera goes stale and exits when the behavior reports an outcome.
//!
//! Run it with `cargo run --example custom_robot`.

#[path = "common/red_beacon.rs"]
mod red_beacon;
#[path = "common/toy_world.rs"]
#[allow(dead_code)] // the post, range finder and bumper are the compose example's
mod toy_world;

use marsupial::arbiter::runtime::{RuntimeConfig, StopHandle, run};
use marsupial::arbiter::{Priority, ReactiveLoop};
use marsupial::geometry::Pose2;
use marsupial::profile::Profile;
use marsupial::robot::Robot;
use marsupial::schemas::{
    Behavior, DriveCommand, Feedback, Inputs, MotorOutput, MotorSchema, Outcome, Percept, PerceptualSchema,
    SchemaBehavior, Step,
};
use red_beacon::RedBeacon;
use std::path::Path;
use std::time::Duration;
use toy_world::{ToyCamera, ToyDockSwitch, ToyDrive, ToyEncoders, World};

/// Step 1, the profile: the toy robot's hardware (`examples/common/toy_robot.toml`,
/// shared with the `compose` example), then this example's name, behavior settings and
/// success criteria. Every field is checked; try misspelling one.
const PROFILE: &str = concat!(
    r#"
name = "toy"
description = "A differential-drive toy that docks at a red beacon"
"#,
    include_str!("common/toy_robot.toml"),
    r#"
[behavior]
max_retries = 0
search_timeout_s = 20.0
phase_timeout_s = 20.0

[success]
lateral_tolerance_m = 0.1
heading_tolerance_deg = 20.0
timeout_s = 30.0
"#
);

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

/// Perceptual schema: the crate's perception with plain parameters
/// (`examples/common/red_beacon.rs`), wrapped as this loop's percept.
struct FindRed(RedBeacon);

impl PerceptualSchema for FindRed {
    type Percept = Beacon;
    fn perceive(&mut self, inputs: &Inputs<'_>) -> Beacon {
        let Some(cam) = inputs.camera(0) else {
            return Beacon {
                stamp: inputs.now,
                found: false,
                offset_px: 0.0,
                pixels: 0,
            };
        };
        let seen = self.0.find(&cam.image);
        Beacon {
            stamp: cam.stamp,
            found: seen.is_some(),
            offset_px: seen.map_or(0.0, |s| s.offset_px),
            pixels: seen.map_or(0, |s| s.pixels as usize),
        }
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
    fn tick(&mut self, _mem: &mut (), inputs: &Inputs<'_>) -> Option<Step> {
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
    fn tick(&mut self, _mem: &mut (), inputs: &Inputs<'_>) -> Option<Step> {
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
    // In the profile's [[sensors]] order: the dock switch is its only one.
    robot.sensors.push(Box::new(ToyDockSwitch(world.clone())));

    let approach = SchemaBehavior::new(
        "approach",
        FindRed(RedBeacon::new(160, 120)),
        SteerAtBeacon,
        |b: &Beacon| b.found,
    );
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
