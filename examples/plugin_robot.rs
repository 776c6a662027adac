//! # A robot kind of your own, served by your own `marsupial` command
//!
//! A user's crate adds a robot none of the papers describes without editing marsupial,
//! and builds its own `marsupial` command that serves it: `check`, `dock`, `trials`,
//! `replay` and the ROS 2 node then know its robot as they know the shipped ones. This
//! example registers:
//!
//! 1. **A fiducial kind**, `red_beacon` ([`BeaconSpec`]): a red panel above the dock's
//!    pouch. Its table is typed (a misspelt field is an error naming its line), and the
//!    simulator learns how to draw its dock ([`paint_beacon_dock`]).
//! 2. **A robot kind**, `beacon_rover` ([`BeaconRover`]): its typed `[robot]` tuning
//!    ([`RoverTuning`]), its shared memory ([`RoverMemory`], the red-beacon finder run once
//!    per tick) and its leaves (`rover.search`, `rover.back_in`, `rover.docked`).
//! 3. **Its own command**: [`marsupial::cli::run_with`] with the shipped catalog plus
//!    these kinds.
//!
//! The profile is `examples/plugin/rover.toml`, the campaign `examples/plugin/docking.toml`:
//!
//! ```sh
//! cargo run --release --example plugin_robot -- check examples/plugin/rover.toml
//! cargo run --release --example plugin_robot -- trials examples/plugin/docking.toml
//! cargo run --release --example plugin_robot -- dock --scenario examples/plugin/docking.toml --start 5
//! ```
//!
//! The rover pursues the beacon's bearing, which cannot tell it where the dock's axis is:
//! it docks from on the axis (the campaign: 0.8–2 m, ±5 cm and ±10° of jitter, 16 of 16
//! docked), and from 10° off the axis it arrives skewed past what the pouch admits and is
//! blocked at the face. It shows how a robot plugs in, not a docking method of its own (the
//! papers' robots are those). CI runs the campaign and fails unless every run docks.

#[path = "common/red_beacon.rs"]
mod red_beacon;

use marsupial::behaviors::catalog::{LeafRegistry, RobotKind};
use marsupial::behaviors::registry::LeafArgs;
use marsupial::behaviors::{Catalog, SharedMemory};
use marsupial::config::{Validate, Validator};
use marsupial::geometry::Twist;
use marsupial::profile::{FiducialKind, Profile};
use marsupial::schemas::{Behavior, DriveCommand, Feedback, Inputs, Mission, MissionError, MotorOutput, Outcome, Step};
use marsupial::sim::SimError;
use marsupial::sim::kinds::SimKinds;
use marsupial::sim::scene::{Material, Tag, albedo, boxed, face_rect};
use marsupial::sim::world::DockCanvas;
use nalgebra::Point3;
use red_beacon::RedBeacon;
use serde::{Deserialize, Serialize};

// ---------------------------------------------------------------------------------------
// The fiducial kind: `[fiducial] kind = "red_beacon"`.
// ---------------------------------------------------------------------------------------

/// A red panel centred above the dock's entrance, facing out along the dock axis.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BeaconSpec {
    /// Width of the panel, m.
    pub width_m: f64,
    /// Height of the panel, m.
    pub height_m: f64,
    /// Height of its centre above the ground, m.
    pub center_height_m: f64,
}

impl FiducialKind for BeaconSpec {
    const KIND: &'static str = "red_beacon";

    fn validate(&self, v: &mut Validator<'_>) {
        v.positive("fiducial.width_m", self.width_m);
        v.positive("fiducial.height_m", self.height_m);
        v.positive("fiducial.center_height_m", self.center_height_m);
    }
}

/// How the simulator draws a `red_beacon` dock: a grey box body behind the entrance
/// plane x = 0 with the pouch's opening in it, and the red panel above the opening.
fn paint_beacon_dock(c: &mut DockCanvas<'_>) -> Result<(), SimError> {
    let beacon = *c
        .profile
        .fiducial
        .require::<BeaconSpec>()
        .map_err(SimError::Unsupported)?;
    let (length, w2, half) = (c.dock.body_length, c.dock.body_half_width, c.dock.entrance_half);
    let grey = Material::Solid(albedo([90, 92, 95], 1.0));
    let height = beacon.center_height_m + beacon.height_m;
    // The body's sides, back and top; its front is built round the opening.
    let mut body = boxed(
        Point3::new(-length, -w2, 0.0),
        Point3::new(0.0, w2, height),
        grey.clone(),
        Tag::Body,
    );
    body.remove(0);
    c.prims.extend(body);
    let front = |y0: f64, y1: f64, z0: f64, z1: f64, material: Material| {
        face_rect(0.0, [y0, y1], [z0, z1], material, Tag::Body)
    };
    // The front is built of pieces round the opening and the panel: the renderer orders
    // primitives by their centres' distance, so a panel laid over a wider face could be
    // drawn behind it.
    let opening_top = 0.25;
    let (pw, z0, z1) = (
        beacon.width_m / 2.0,
        beacon.center_height_m - beacon.height_m / 2.0,
        beacon.center_height_m + beacon.height_m / 2.0,
    );
    for (y0, y1, za, zb) in [
        (-w2, -half, 0.0, height),
        (half, w2, 0.0, height),
        (-half, half, opening_top, z0),
        (-half, half, z1, height),
        (-half, -pw, z0, z1),
        (pw, half, z0, z1),
    ] {
        c.prims.push(front(y0, y1, za, zb, grey.clone()));
    }
    // The dark pouch behind the opening.
    let dark = Material::Solid(albedo([20, 20, 22], 1.0));
    c.prims
        .push(face_rect(-0.01, [-half, half], [0.0, opening_top], dark, Tag::Body));
    // The beacon, in its gap in the face.
    c.target_prims.push(c.prims.len());
    let red = Material::Solid(albedo([220, 30, 25], 1.0));
    c.prims.push(face_rect(0.0, [-pw, pw], [z0, z1], red, Tag::Target));
    Ok(())
}

// ---------------------------------------------------------------------------------------
// The robot kind: `[robot] kind = "beacon_rover"`.
// ---------------------------------------------------------------------------------------

/// The rover's `[robot]` tuning.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RoverTuning {
    /// Red blobs this small or smaller are noise, px.
    pub min_blob_px: u64,
}

impl Validate for RoverTuning {
    fn validate(&self, v: &mut Validator<'_>) {
        v.require(self.min_blob_px >= 1, "robot.min_blob_px", || {
            "expected at least 1 px".into()
        });
    }
}

/// What the beacon looked like this tick.
#[derive(Debug, Clone, Copy, Default)]
pub struct Beacon {
    /// Seen this tick.
    pub found: bool,
    /// Bearing from the camera's axis, rad (positive to the camera's left).
    pub bearing: f64,
    /// Pixels of the red blob (grows as the rover closes in).
    pub pixels: f64,
}

/// The rover's shared memory: the red-beacon finder and what it last saw.
pub struct RoverMemory {
    finder: RedBeacon,
    focal_px: f64,
    /// This tick's sighting.
    pub beacon: Beacon,
    /// When the beacon was last seen, s.
    pub last_seen: f64,
    /// The side it was last seen on (+1 the camera's left).
    pub last_side: f64,
    /// The most pixels it has filled this docking: close in, it leaves the top of the
    /// view a row at a time, so the last sighting is small.
    pub peak_pixels: f64,
}

impl SharedMemory for RoverMemory {
    fn perceive(&mut self, inputs: &Inputs<'_>) {
        self.beacon = Beacon::default();
        let Some(cam) = inputs.camera(0) else { return };
        if let Some(seen) = self.finder.find(&cam.image) {
            let bearing = (-seen.offset_px / self.focal_px).atan();
            self.beacon = Beacon {
                found: true,
                bearing,
                pixels: seen.pixels as f64,
            };
            self.last_seen = inputs.now;
            self.last_side = bearing.signum();
            self.peak_pixels = self.peak_pixels.max(seen.pixels as f64);
        }
    }

    fn begin(&mut self, _mission: &Mission) -> Result<(), MissionError> {
        self.last_seen = f64::NEG_INFINITY;
        self.peak_pixels = 0.0;
        Ok(())
    }
}

/// The robot kind (see the module docs).
pub struct BeaconRover;

impl RobotKind for BeaconRover {
    const NAME: &'static str = "beacon_rover";
    type Tuning = RoverTuning;
    type Memory = RoverMemory;

    fn memory(&self, profile: &Profile, tuning: &RoverTuning) -> Result<RoverMemory, String> {
        profile.fiducial.require::<BeaconSpec>()?;
        let cam = profile.cameras.first().ok_or("needs a camera")?;
        let hfov = cam.hfov_deg.ok_or("needs a camera with hfov_deg")?;
        Ok(RoverMemory {
            finder: RedBeacon::new(cam.width_px, cam.height_px).with_min_pixels(tuning.min_blob_px),
            focal_px: cam.width_px as f64 / 2.0 / (hfov / 2.0).to_radians().tan(),
            beacon: Beacon::default(),
            last_seen: f64::NEG_INFINITY,
            last_side: 1.0,
            peak_pixels: 0.0,
        })
    }

    fn leaves(&self, registry: &mut LeafRegistry<RoverMemory>) {
        registry
            .register("rover.search", |_: &RoverMemory, a: &LeafArgs<'_>| {
                Ok(Box::new(Search { params: a.params()? }))
            })
            .register("rover.back_in", |_: &RoverMemory, a: &LeafArgs<'_>| {
                Ok(Box::new(BackIn { params: a.params()? }))
            })
            .register("rover.docked", |_: &RoverMemory, a: &LeafArgs<'_>| {
                a.no_params()?;
                Ok(Box::new(Docked))
            });
    }
}

/// `rover.search`: turn toward the side the beacon was last seen on until it is seen
/// (event `seen`).
struct Search {
    params: SearchParams,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SearchParams {
    /// Turn rate, degrees/s.
    turn_rate_dps: f64,
}

impl Behavior<RoverMemory> for Search {
    fn tick(&mut self, m: &mut RoverMemory, inputs: &Inputs<'_>) -> Option<Step> {
        let feedback = Feedback::new("search", inputs.now);
        if m.beacon.found {
            return Some(Step::event("seen", MotorOutput::stop(), feedback));
        }
        let omega = m.last_side * self.params.turn_rate_dps.to_radians();
        Some(Step::running(
            MotorOutput::drive(DriveCommand::Turn { omega }),
            feedback,
        ))
    }
}

/// `rover.back_in`: back toward the beacon, turning the camera's axis onto it and
/// slowing as it fills the view. Close in, the beacon leaves the top of the view: once it
/// has filled `close_pixels` or more, the rover backs on straight, blind, for `blind_s`;
/// otherwise event `lost` once it has been out of sight for `lost_after_s`.
struct BackIn {
    params: BackInParams,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct BackInParams {
    /// Speed far from the beacon, m/s.
    speed_mps: f64,
    /// Blob size at which the speed has halved, px.
    slow_pixels: f64,
    /// Turn rate per radian of bearing, 1/s.
    k_bearing: f64,
    /// Out of sight this long: `lost`, s.
    lost_after_s: f64,
    /// Seen this big last, the rover is at the entrance and backs on blind, px.
    close_pixels: f64,
    /// Longest blind backing, s.
    blind_s: f64,
}

impl Behavior<RoverMemory> for BackIn {
    fn tick(&mut self, m: &mut RoverMemory, inputs: &Inputs<'_>) -> Option<Step> {
        let feedback = Feedback::new("back_in", inputs.now);
        let p = &self.params;
        let unseen = inputs.now - m.last_seen;
        let blind = m.peak_pixels >= p.close_pixels;
        if (blind && unseen > p.blind_s) || (!blind && unseen > p.lost_after_s) {
            return Some(Step::event("lost", MotorOutput::stop(), feedback));
        }
        // The camera looks back: backing moves it toward the beacon, and turning the body
        // counter-clockwise turns the camera's axis counter-clockwise too.
        let b = m.beacon;
        let pixels = if b.found { b.pixels } else { m.peak_pixels };
        let v = -p.speed_mps / (1.0 + pixels / p.slow_pixels);
        let omega = if b.found { p.k_bearing * b.bearing } else { 0.0 };
        Some(Step::running(
            MotorOutput::drive(DriveCommand::Twist(Twist { v, omega })),
            feedback,
        ))
    }
}

/// `rover.docked`: the pouch's contact plate closed. It reads no memory, so it fits in
/// any robot's tree.
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

// ---------------------------------------------------------------------------------------
// The command: marsupial's, serving these kinds too.
// ---------------------------------------------------------------------------------------

fn main() -> std::process::ExitCode {
    let mut catalog = Catalog::shipped();
    catalog.register_fiducial::<BeaconSpec>().register_robot(BeaconRover);
    let mut sim = SimKinds::default();
    sim.painters.register(BeaconSpec::KIND, paint_beacon_dock);
    marsupial::cli::run_with(marsupial::cli::Plugins { catalog, sim })
}
