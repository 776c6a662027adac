//! A toy world standing in for a real robot's drivers, shared by the examples
//! `custom_robot` and `compose`: a differential-drive robot on a grey floor, a red beacon
//! to dock at and, optionally, a round post in the way. Each hardware trait of
//! [`marsupial::robot`] is implemented here the way a driver would: it reads or commands
//! the world, which advances the robot along its last twist up to the present on every
//! call. On your robot these structs talk to your drivers instead.

use marsupial::geometry::{Pose2, Twist, integrate_twist};
use marsupial::perception::RgbImage;
use marsupial::robot::{Camera, Drive, Exposure, HardwareError, Sensor, WheelEncoders, WheelTravel};
use marsupial::schemas::DriveCommand;
use marsupial::schemas::{DeviceReading, DockContact};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

/// Where the beacon stands, m.
pub const BEACON: (f64, f64) = (2.0, 0.6);
/// Distance between the wheels, m.
pub const TRACK_M: f64 = 0.30;
/// Half the body's length, m (the front bumper and the range finder sit there).
pub const HALF_LENGTH_M: f64 = 0.175;
/// Camera image size, px.
pub const IMAGE: (usize, usize) = (160, 120);
/// Horizontal field of view of the pin-hole camera, degrees.
pub const HFOV_DEG: f64 = 60.0;

/// Height of a post, m.
pub const POST_HEIGHT_M: f64 = 0.1;

/// A round post on the floor, [`POST_HEIGHT_M`] tall.
#[derive(Debug, Clone, Copy)]
pub struct Post {
    /// Centre, m.
    pub x: f64,
    /// Centre, m.
    pub y: f64,
    /// Radius, m.
    pub radius: f64,
}

/// The robot on the floor.
pub struct World {
    /// The robot's pose.
    pub pose: Pose2,
    twist: Twist,
    travel: WheelTravel,
    last: Instant,
    /// An obstacle, if any.
    pub post: Option<Post>,
}

impl World {
    /// A world with the robot at `pose`, shared by the hardware that talks to it.
    pub fn shared(pose: Pose2, post: Option<Post>) -> Shared {
        Arc::new(Mutex::new(World {
            pose,
            twist: Twist::ZERO,
            travel: WheelTravel::default(),
            last: Instant::now(),
            post,
        }))
    }

    /// Moves the robot along its current twist up to the present.
    fn advance(&mut self) {
        let now = Instant::now();
        let dt = (now - self.last).as_secs_f64();
        self.last = now;
        self.pose = integrate_twist(&self.pose, &self.twist, dt);
        let half = self.twist.omega * TRACK_M / 2.0;
        self.travel.left += (self.twist.v - half) * dt;
        self.travel.right += (self.twist.v + half) * dt;
    }

    /// Distance from the robot's centre to the post's surface (infinite without a post).
    pub fn clearance(&self) -> f64 {
        self.post.map_or(f64::INFINITY, |p| {
            (self.pose.x - p.x).hypot(self.pose.y - p.y) - p.radius
        })
    }
}

/// The world, as every device sees it.
pub type Shared = Arc<Mutex<World>>;

/// Locks the world for a device, advanced to the present.
fn world(shared: &Shared) -> Result<MutexGuard<'_, World>, HardwareError> {
    let mut w = shared.lock().map_err(|_| HardwareError::Fault {
        device: "world".into(),
        detail: "poisoned".into(),
    })?;
    w.advance();
    Ok(w)
}

/// Focal length of the toy camera, px.
fn focal_px() -> f64 {
    IMAGE.0 as f64 / 2.0 / (HFOV_DEG / 2.0).to_radians().tan()
}

/// A 30 fps pin-hole camera 0.2 m above the floor: the beacon a red bar, the post a dark
/// one, nearest in front.
pub struct ToyCamera(pub Shared);

impl ToyCamera {
    /// Height of the camera above the floor, m.
    const HEIGHT_M: f64 = 0.2;

    /// Paints an upright bar of half-width `half_w_m` from `bottom_m` to `top_m` above the
    /// floor at `(x, y)` in the robot's frame.
    fn bar(frame: &mut RgbImage, (lx, ly): (f64, f64), half_w_m: f64, (bottom_m, top_m): (f64, f64), rgb: [u8; 3]) {
        if lx <= 0.05 {
            return;
        }
        let (w, h) = (IMAGE.0 as f64, IMAGE.1 as f64);
        let f = focal_px();
        let u = w / 2.0 - f * ly / lx;
        let half_w = (f * half_w_m / lx).max(1.0);
        let row = |z: f64| (h / 2.0 - f * (z - Self::HEIGHT_M) / lx).clamp(0.0, h);
        for x in (u - half_w).max(0.0) as usize..(u + half_w).clamp(0.0, w) as usize {
            for y in row(top_m) as usize..row(bottom_m) as usize {
                frame.put(x, y, rgb);
            }
        }
    }
}

impl Camera for ToyCamera {
    fn resolution(&self) -> (usize, usize) {
        IMAGE
    }

    fn capture(&mut self, frame: &mut RgbImage) -> Result<Exposure, HardwareError> {
        std::thread::sleep(Duration::from_millis(33));
        let (pose, post) = {
            let w = world(&self.0)?;
            (w.pose, w.post)
        };
        frame.fill([90, 90, 90]);
        // The beacon: 10 cm wide, from the floor to 0.5 m, above the camera. The post:
        // 10 cm tall, below the camera's line of sight, so it hides only the beacon's foot.
        let beacon = pose.to_local(BEACON.0, BEACON.1);
        let post = post.map(|p| (pose.to_local(p.x, p.y), p.radius));
        // Painter's order: the farther object first.
        let post_nearer = post.is_some_and(|(l, _)| l.0 < beacon.0);
        let paint_post = |frame: &mut RgbImage| {
            if let Some((l, r)) = post {
                Self::bar(frame, l, r, (0.0, POST_HEIGHT_M), [40, 40, 40]);
            }
        };
        if !post_nearer {
            paint_post(frame);
        }
        Self::bar(frame, beacon, 0.05, (0.0, 0.5), [220, 30, 30]);
        if post_nearer {
            paint_post(frame);
        }
        Ok(Exposure::NOW)
    }
}

/// The motor controller: applies twists.
pub struct ToyDrive(pub Shared);

impl Drive for ToyDrive {
    fn apply(&mut self, command: &DriveCommand) -> Result<(), HardwareError> {
        world(&self.0)?.twist = command.to_twist();
        Ok(())
    }
}

/// Wheel encoders: each wheel's travel.
pub struct ToyEncoders(pub Shared);

impl WheelEncoders for ToyEncoders {
    fn read(&mut self) -> Result<WheelTravel, HardwareError> {
        Ok(world(&self.0)?.travel)
    }
}

/// The dock's contact switch (the crate's `dock_contact` kind): closes when the robot's
/// centre is within 35 cm of the beacon.
pub struct ToyDockSwitch(pub Shared);

impl Sensor for ToyDockSwitch {
    fn read(&mut self, values: &mut Vec<f64>) -> Result<(), HardwareError> {
        let w = world(&self.0)?;
        DockContact((w.pose.x - BEACON.0).hypot(w.pose.y - BEACON.1) < 0.35).encode(values);
        Ok(())
    }
}

/// A forward range finder: `beams` beams over `fov_deg`, from the robot's front centre,
/// each reading the distance to the post's surface or `max_range_m` (the crate's `range`
/// sensor kind, [`marsupial::profile::RangeParams`]).
pub struct ToyRange {
    /// The world.
    pub world: Shared,
    /// Number of beams.
    pub beams: usize,
    /// Fan width, degrees.
    pub fov_deg: f64,
    /// Longest range, m.
    pub max_range_m: f64,
}

impl Sensor for ToyRange {
    fn read(&mut self, values: &mut Vec<f64>) -> Result<(), HardwareError> {
        let (pose, post) = {
            let w = world(&self.world)?;
            (w.pose, w.post)
        };
        let (s, c) = pose.theta.sin_cos();
        let origin = (pose.x + HALF_LENGTH_M * c, pose.y + HALF_LENGTH_M * s);
        for i in 0..self.beams {
            let step = if self.beams > 1 {
                self.fov_deg / (self.beams - 1) as f64
            } else {
                0.0
            };
            let a = pose.theta + (-self.fov_deg / 2.0 + step * i as f64).to_radians();
            let r = post.and_then(|p| ray_circle(origin, a, p)).unwrap_or(f64::INFINITY);
            values.push(r.min(self.max_range_m));
        }
        Ok(())
    }
}

/// Distance along the ray from `o` at angle `a` to circle `p`, if it hits.
fn ray_circle(o: (f64, f64), a: f64, p: Post) -> Option<f64> {
    let (dx, dy) = (a.cos(), a.sin());
    let (ox, oy) = (o.0 - p.x, o.1 - p.y);
    let b = ox * dx + oy * dy;
    let disc = b * b - (ox * ox + oy * oy - p.radius * p.radius);
    if disc < 0.0 {
        return None;
    }
    let t = -b - disc.sqrt();
    (t >= 0.0).then_some(t)
}

/// A contact-strip bumper round the body, in `segments` equal arcs: one value per
/// segment, 1 when pressed. The world presses the segment facing the post when the body
/// (a circle of [`HALF_LENGTH_M`]) touches it.
pub struct ToyBumper {
    /// The world.
    pub world: Shared,
    /// Number of segments.
    pub segments: usize,
}

impl Sensor for ToyBumper {
    fn read(&mut self, values: &mut Vec<f64>) -> Result<(), HardwareError> {
        let w = world(&self.world)?;
        values.resize(self.segments, 0.0);
        if let Some(p) = w.post
            && w.clearance() < HALF_LENGTH_M
        {
            let (lx, ly) = w.pose.to_local(p.x, p.y);
            let bearing = ly.atan2(lx).rem_euclid(std::f64::consts::TAU);
            let i = (bearing / std::f64::consts::TAU * self.segments as f64) as usize;
            values[i.min(self.segments - 1)] = 1.0;
        }
        Ok(())
    }
}
