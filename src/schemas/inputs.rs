//! The timestamped sensor snapshot one loop tick consumes.

use super::devices::{DeviceReading, DockContact};
use super::percept::Stamped;
use crate::geometry::{Pose2, Twist};
use crate::perception::RgbView;
use serde::{Deserialize, Serialize};

/// One camera frame handed to a tick.
#[derive(Debug, Clone, Copy)]
pub struct CameraInput<'a> {
    /// Capture time, seconds on the loop clock.
    pub stamp: f64,
    /// The pixels.
    pub image: RgbView<'a>,
}

/// Most cameras a tick holds without allocating: the cameras of one tick are built fresh
/// each tick (the frames they borrow change), inline up to this many, so building them
/// allocates nothing for any robot this crate models (Axel's stereo pair is the most;
/// `tests/no_alloc.rs`); more spill to the heap.
pub const INLINE_CAMERAS: usize = 4;

/// The cameras of one tick (inline up to [`INLINE_CAMERAS`]).
pub type CameraInputs<'a> = smallvec::SmallVec<[Option<CameraInput<'a>>; INLINE_CAMERAS]>;

/// One reading of a `[[sensors]]` entry (see [`crate::profile::devices`]): what the
/// values mean is the sensor's kind's business (a range finder: one distance per beam;
/// the tether: its [`TetherReading`]), read typed with
/// [`DeviceReading`].
#[derive(Debug, Clone, Copy)]
pub struct SensorInput<'a> {
    /// The sensor's kind (its `[[sensors]]` entry's `kind`).
    pub kind: &'a str,
    /// Capture time, seconds on the loop clock.
    pub stamp: f64,
    /// The values.
    pub values: &'a [f64],
}

/// The `[[sensors]]` readings of one tick, inline for up to
/// [`INLINE_DEVICES`](super::INLINE_DEVICES) sensors (building it allocates nothing for
/// such robots; more spill to the heap).
pub type SensorInputs<'a> = smallvec::SmallVec<[Option<SensorInput<'a>>; super::devices::INLINE_DEVICES]>;

/// An odometry estimate: pose in the odometry frame plus the current body twist.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct OdometryReading {
    /// Pose in the odometry frame (origin where odometry was last reset).
    pub pose: Pose2,
    /// Body twist estimated from the wheels.
    pub twist: Twist,
}

/// A tether reading: what a reel reports. Tension is not among it: Axel had no tension
/// sensor and inferred the pull from the reel motor's current (seed 000 §IV-A), so a
/// behavior may read the current (noisier, and idle current flows while the reel turns
/// with no load), never the tension.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct TetherReading {
    /// Tether paid out, metres.
    pub length: f64,
    /// The reel motor's current, amperes (0 when the reel is idle and the tether slack).
    pub motor_current_a: f64,
}

/// Everything one tick of the reactive loop sees.
///
/// `now` is the loop clock, supplied by the caller (the threaded runtime's monotonic
/// clock, or the simulator's step counter); nothing downstream reads a clock itself.
/// `cameras` is indexed like the profile's `[[cameras]]` list and `sensors` like its
/// `[[sensors]]`, the tether reel and the dock switch among them; a `None` entry means
/// nothing has arrived from that device yet.
#[derive(Debug, Clone, Copy)]
pub struct Inputs<'a> {
    /// Loop time, seconds.
    pub now: f64,
    /// Latest frame per camera.
    pub cameras: &'a [Option<CameraInput<'a>>],
    /// Latest odometry estimate.
    pub odometry: Option<Stamped<OdometryReading>>,
    /// Latest reading per `[[sensors]]` entry, in profile order (`None`: none yet).
    pub sensors: &'a [Option<SensorInput<'a>>],
}

impl<'a> Inputs<'a> {
    /// A snapshot with no sensor data at time `now`.
    pub fn empty(now: f64) -> Self {
        Self {
            now,
            cameras: &[],
            odometry: None,
            sensors: &[],
        }
    }

    /// Camera `i`'s latest frame, if any.
    pub fn camera(&self, i: usize) -> Option<&CameraInput<'a>> {
        self.cameras.get(i).and_then(Option::as_ref)
    }

    /// Sensor `i`'s (profile `[[sensors]]` order) latest reading, if any.
    pub fn sensor(&self, i: usize) -> Option<&SensorInput<'a>> {
        self.sensors.get(i).and_then(Option::as_ref)
    }

    /// The latest reading of the first sensor of `R`'s kind that has one, typed; `None`
    /// when the profile declares no such sensor, it has not reported yet, or its values
    /// do not make a reading.
    pub fn reading<R: DeviceReading>(&self) -> Option<Stamped<R>> {
        let s = self.sensors.iter().flatten().find(|s| s.kind == R::KIND)?;
        R::decode(s.values).map(|r| Stamped::new(s.stamp, r))
    }

    /// The tether reel's latest reading (a [`TETHER_KIND`](super::TETHER_KIND) sensor).
    pub fn tether(&self) -> Option<Stamped<TetherReading>> {
        self.reading()
    }

    /// The dock contact switch's latest reading (a
    /// [`DOCK_CONTACT_KIND`](super::DOCK_CONTACT_KIND) sensor): true when closed.
    pub fn dock_contact(&self) -> Option<Stamped<bool>> {
        self.reading::<DockContact>().map(|c| Stamped::new(c.stamp, c.value.0))
    }

    /// True when the dock contact switch reads closed.
    pub fn docked_contact(&self) -> bool {
        self.dock_contact().is_some_and(|c| c.value)
    }
}
