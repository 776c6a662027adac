//! # Composing your robot's behavior in its profile
//!
//! The behavior of a robot is a tree its profile declares: leaves name schemas, inner
//! nodes are the crate's arbiters (priority, vector sum, sequencer). This example is a
//! user's crate doing what yours would, without editing marsupial:
//!
//! 1. **Its own schemas, registered by name.** `toy.search`, `toy.steer` (find the red
//!    beacon and steer at it, as a motion vector), `toy.bumper` and `toy.docked`, each a
//!    [`Behavior`] built from its node's `params` by a factory in a [`Registry`]. The
//!    perception runs once per tick into the robot's [`SharedMemory`], which every leaf
//!    gets for the tick as `&mut` (a `Behavior<ToyMemory>`); a leaf that reads none is a
//!    `Behavior<M>` for every `M`.
//! 2. **Its own sensor kind.** A contact-strip `bumper`, declared in the profile's
//!    `[[sensors]]` and registered with the check of its params, so `marsupial check`-style
//!    errors name a bad `segments`. Its driver is a [`marsupial::robot::Sensor`].
//! 3. **The crate's schemas beside them.** `avoid_obstacles` (Arkin's avoid-static-obstacle
//!    on the crate's `range` sensor kind) is summed with `toy.steer` by a `vector_sum`
//!    node, so the robot slides round a post standing between it and the beacon.
//! 4. **The tree in TOML** ([`PROFILE`]): change an arbiter, a gain or a transition there
//!    and the robot changes, with no Rust rebuilt.
//!
//! [`Composed::build`] turns the profile and the registry into the robot's behavior;
//! the threaded runtime runs the docking mission on the toy hardware of
//! `examples/common/toy_world.rs` (stand-ins for your drivers).
//!
//! Run it with `cargo run --example compose` (about 15 s of real time). Give a start pose
//! as `x y heading_deg` (default `0 0 -115`: facing away, the post on the way):
//! `cargo run --example compose -- 0.4 -0.6 90`. It exits with status 0 only when the robot
//! docked without touching the post.

#[path = "common/red_beacon.rs"]
mod red_beacon;
#[path = "common/toy_world.rs"]
mod toy_world;

use marsupial::arbiter::ReactiveLoop;
use marsupial::arbiter::runtime::{RuntimeConfig, StopHandle, run_missions};
use marsupial::behaviors::registry::{LeafArgs, Registry};
use marsupial::behaviors::{Composed, SharedMemory, common};
use marsupial::geometry::Pose2;
use marsupial::profile::Profile;
use marsupial::robot::Robot;
use marsupial::schemas::{
    Behavior, DriveCommand, FailureReason, Feedback, Inputs, Mission, MissionError, MotionVector, MotorOutput, Outcome,
    Step,
};
use red_beacon::RedBeacon;
use serde::Deserialize;
use std::path::Path;
use std::time::Duration;
use toy_world::{Post, ToyBumper, ToyCamera, ToyDockSwitch, ToyDrive, ToyEncoders, ToyRange, World};

/// The profile: the toy robot's hardware (`examples/common/toy_robot.toml`, shared with
/// `custom_robot`), its two extra sensors, and its behavior as a tree.
const PROFILE: &str = concat!(
    r#"
name = "toy-composed"
description = "A differential-drive toy that docks at a red beacon, round a post"
"#,
    include_str!("common/toy_robot.toml"),
    r#"
[[sensors]]
name = "front_ranges"
kind = "range"                 # the crate's kind: avoid_obstacles reads it
params = { beams = 13, fov_deg = 180.0, max_range_m = 1.0, x_m = 0.175, yaw_deg = 0.0, noise_m = 0.0 }

[[sensors]]
name = "bumper"
kind = "bumper"                # this crate's kind, registered in main()
params = { segments = 4 }

[behavior]
max_retries = 0
search_timeout_s = 20.0
phase_timeout_s = 30.0

[behavior.tree]
root = "toy"
docking = "search"             # Mission::Docking starts here

[behavior.tree.nodes.toy]
kind = "priority"              # subsumption: the first child that proposes wins
children = ["docked", "bumper", "seek"]

[behavior.tree.nodes.docked]
kind = "leaf"
schema = "toy.docked"          # the dock switch closed: done

[behavior.tree.nodes.bumper]
kind = "leaf"
schema = "toy.bumper"          # touched something: stop, a typed failure

[behavior.tree.nodes.seek]
kind = "sequencer"
states = ["search", "approach"]

[behavior.tree.nodes.search]
kind = "leaf"
schema = "toy.search"
on = { seen = "approach" }
params = { turn_rate_dps = 35.0 }

[behavior.tree.nodes.approach]
kind = "vector_sum"            # Arkin's coordination: steer + avoid, summed
children = ["steer", "avoid"]
gains = [1.0, 1.0]
max_speed_mps = 0.2
k_theta = 2.0
on = { lost = "search" }

[behavior.tree.nodes.steer]
kind = "leaf"
schema = "toy.steer"
params = { speed_mps = 0.2, slow_pixels = 4000.0, lost_after_s = 6.0 }

[behavior.tree.nodes.avoid]
kind = "leaf"
schema = "avoid_obstacles"     # the crate's schema, on the range finder
params = { sphere_m = 0.6, safety_m = 0.25, gain_mps = 0.2, cap = 2.0, swirl = 0.7 }

[success]
lateral_tolerance_m = 0.1
heading_tolerance_deg = 20.0
timeout_s = 40.0
"#
);

// ---------------------------------------------------------------------------------------
// The robot's shared memory: its perception, run once per tick.
// ---------------------------------------------------------------------------------------

/// What the perception saw of the beacon this tick.
#[derive(Debug, Clone, Copy, Default)]
struct Beacon {
    /// Seen this tick.
    found: bool,
    /// Bearing from the camera axis, rad (positive left).
    bearing: f64,
    /// Pixels of the largest red blob (grows as the robot closes in).
    pixels: f64,
}

/// The memory every leaf shares: the red-beacon finder (`examples/common/red_beacon.rs`)
/// and what it last saw.
struct ToyMemory {
    finder: RedBeacon,
    focal_px: f64,
    beacon: Beacon,
    /// When the beacon was last seen, s.
    last_seen: f64,
    /// Where it was last seen: its direction in the odometry frame, rad.
    last_direction: f64,
    /// The robot's heading in the odometry frame this tick, rad.
    heading: f64,
}

impl ToyMemory {
    /// Buffers for `profile`'s first camera, allocated once.
    fn new(profile: &Profile) -> Self {
        let cam = &profile.cameras[0];
        let (w, hfov) = (cam.width_px, cam.hfov_deg.unwrap_or(60.0));
        Self {
            finder: RedBeacon::new(w, cam.height_px),
            focal_px: w as f64 / 2.0 / (hfov / 2.0).to_radians().tan(),
            beacon: Beacon::default(),
            last_seen: f64::NEG_INFINITY,
            last_direction: 0.0,
            heading: 0.0,
        }
    }
}

impl SharedMemory for ToyMemory {
    fn perceive(&mut self, inputs: &Inputs<'_>) {
        self.beacon = Beacon::default();
        if let Some(odo) = &inputs.odometry {
            self.heading = odo.value.pose.theta;
        }
        let Some(cam) = inputs.camera(0) else { return };
        if let Some(seen) = self.finder.find(&cam.image) {
            self.beacon = Beacon {
                found: true,
                bearing: (-seen.offset_px / self.focal_px).atan(),
                pixels: seen.pixels as f64,
            };
            self.last_seen = inputs.now;
            self.last_direction = self.heading + self.beacon.bearing;
        }
    }

    fn begin(&mut self, _mission: &Mission) -> Result<(), MissionError> {
        self.last_seen = f64::NEG_INFINITY;
        Ok(())
    }
}

type Mem = ToyMemory;

// ---------------------------------------------------------------------------------------
// The robot's schemas: leaves the tree names.
// ---------------------------------------------------------------------------------------

/// `toy.search`: turn in place until the beacon is seen (event `seen`).
struct Search {
    params: SearchParams,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SearchParams {
    /// Turn rate, degrees/s.
    turn_rate_dps: f64,
}

impl Behavior<Mem> for Search {
    fn tick(&mut self, m: &mut Mem, inputs: &Inputs<'_>) -> Option<Step> {
        let feedback = Feedback::new("search", inputs.now);
        if m.beacon.found {
            return Some(Step::event("seen", MotorOutput::stop(), feedback));
        }
        let omega = self.params.turn_rate_dps.to_radians();
        Some(Step::running(
            MotorOutput::drive(DriveCommand::Turn { omega }),
            feedback,
        ))
    }
}

/// `toy.steer`: a motion vector at the beacon, slowing as it fills the view. Out of view
/// (avoid turned the robot aside, or the post hides it), it steers toward where the
/// beacon was last seen, by odometry; event `lost` when unseen for `lost_after_s`.
struct Steer {
    params: SteerParams,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SteerParams {
    /// Speed far from the beacon, m/s.
    speed_mps: f64,
    /// Blob size at which the speed has halved, px.
    slow_pixels: f64,
    /// Unseen this long: `lost`, s.
    lost_after_s: f64,
}

impl Behavior<Mem> for Steer {
    fn tick(&mut self, m: &mut Mem, inputs: &Inputs<'_>) -> Option<Step> {
        let feedback = Feedback::new("steer", inputs.now);
        let p = &self.params;
        if inputs.now - m.last_seen > p.lost_after_s {
            return Some(Step::event("lost", MotorOutput::stop(), feedback));
        }
        let b = m.beacon;
        let speed = p.speed_mps / (1.0 + b.pixels / p.slow_pixels);
        let bearing = if b.found {
            b.bearing
        } else {
            let d = m.last_direction - m.heading;
            d.sin().atan2(d.cos())
        };
        let v = MotionVector::from_polar(speed, bearing);
        Some(Step::running(MotorOutput::drive(DriveCommand::Vector(v)), feedback))
    }
}

/// `toy.bumper`: any bumper segment pressed stops the robot and ends the mission with a
/// typed failure (`stuck_contact`); silent otherwise, so the priority passes on. It reads
/// no memory, so it fits in any robot's tree.
struct Bumper {
    sensor: usize,
}

impl<M: ?Sized> Behavior<M> for Bumper {
    fn tick(&mut self, _mem: &mut M, inputs: &Inputs<'_>) -> Option<Step> {
        let pressed = inputs.sensor(self.sensor)?.values.iter().any(|&v| v > 0.5);
        pressed.then(|| {
            Step::done(
                Outcome::Failed(FailureReason::StuckContact),
                MotorOutput::stop(),
                Feedback::new("bumper", inputs.now),
            )
        })
    }
}

/// `toy.docked`: the dock switch closed.
struct Docked;

impl<M: ?Sized> Behavior<M> for Docked {
    fn tick(&mut self, _mem: &mut M, inputs: &Inputs<'_>) -> Option<Step> {
        inputs.docked_contact().then(|| {
            Step::done(
                Outcome::Docked,
                MotorOutput::stop(),
                Feedback::new("docked", inputs.now),
            )
        })
    }
}

/// Checks a `bumper` sensor's params: `segments`, 1 to 16.
fn check_bumper(params: &toml::Table) -> Result<(), String> {
    if let Some(key) = params.keys().find(|k| *k != "segments") {
        return Err(format!("params: unknown field `{key}`, expected `segments`"));
    }
    match params.get("segments").and_then(toml::Value::as_integer) {
        Some(1..=16) => Ok(()),
        Some(n) => Err(format!("params.segments: expected 1 to 16, got {n}")),
        None => Err("params.segments: expected an integer".into()),
    }
}

/// Everything this crate adds to marsupial's registry.
fn registry() -> Registry<Mem> {
    let mut r = Registry::new();
    common::register(&mut r); // avoid_obstacles
    r.register_sensor_kind("bumper", check_bumper)
        .register("toy.search", |_: &Mem, a: &LeafArgs<'_>| {
            Ok(Box::new(Search { params: a.params()? }))
        })
        .register("toy.steer", |_: &Mem, a: &LeafArgs<'_>| {
            Ok(Box::new(Steer { params: a.params()? }))
        })
        .register("toy.bumper", |_: &Mem, a: &LeafArgs<'_>| {
            a.no_params()?;
            Ok(Box::new(Bumper {
                sensor: a.sensor("bumper")?,
            }))
        })
        .register("toy.docked", |_: &Mem, a: &LeafArgs<'_>| {
            a.no_params()?;
            Ok(Box::new(Docked))
        });
    r
}

/// The start pose from the command line (`x y heading_deg`), or the default.
fn start_pose() -> Result<Pose2, String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.as_slice() {
        [] => Ok(Pose2::new(0.0, 0.0, (-115f64).to_radians())),
        [x, y, h] => {
            let num = |s: &String| s.parse::<f64>().map_err(|e| format!("`{s}`: {e}"));
            Ok(Pose2::new(num(x)?, num(y)?, num(h)?.to_radians()))
        }
        _ => Err("expected no arguments or `x y heading_deg`".into()),
    }
}

fn main() {
    if let Err(e) = dock() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn dock() -> Result<(), Box<dyn std::error::Error>> {
    let profile = Profile::parse(PROFILE, Path::new("compose.toml"))?;
    let memory = ToyMemory::new(&profile);
    let behavior = Composed::build(&profile, &registry(), memory)?;

    // The post stands on the line from the default start to the beacon.
    let post = Post {
        x: 1.0,
        y: 0.3,
        radius: 0.1,
    };
    let world = World::shared(start_pose()?, Some(post));
    let mut robot = Robot::new(
        vec![Box::new(ToyCamera(world.clone()))],
        Box::new(ToyDrive(world.clone())),
    );
    robot.encoders = Some(Box::new(ToyEncoders(world.clone())));
    // In the profile's [[sensors]] order (the dock switch is toy_robot.toml's).
    robot.sensors = vec![
        Box::new(ToyDockSwitch(world.clone())),
        Box::new(ToyRange {
            world: world.clone(),
            beams: 13,
            fov_deg: 180.0,
            max_range_m: 1.0,
        }),
        Box::new(ToyBumper {
            world: world.clone(),
            segments: 4,
        }),
    ];

    let mut lp = ReactiveLoop::new(Box::new(behavior), profile.loop_config());
    let config = RuntimeConfig {
        max_duration: Some(Duration::from_secs_f64(profile.success.timeout_s)),
        ..RuntimeConfig::default()
    };
    println!(
        "the composed toy robot docks round a post (real time, up to {} s)…",
        profile.success.timeout_s
    );
    let report = run_missions(&mut robot, &mut lp, &[Mission::docking()], &config, &StopHandle::new());
    for e in &report.events {
        println!("{e}");
    }
    let w = world.lock().map_err(|_| "world poisoned")?;
    println!(
        "{} ticks in {:.1} s; final pose ({:.2}, {:.2}, {:.0}°); outcome {:?}",
        report.ticks,
        report.elapsed_s,
        w.pose.x,
        w.pose.y,
        w.pose.theta.to_degrees(),
        report.outcome
    );
    match report.outcome {
        Some(Outcome::Docked) => Ok(()),
        other => Err(format!("did not dock: outcome {other:?}").into()),
    }
}
