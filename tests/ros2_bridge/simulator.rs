//! The simulator's side of the wire: it publishes a simulated robot's rendered frames,
//! odometry and dock switch in `rmw_zenoh`'s keys and CDR, runs its physics on the wall
//! clock, and applies the `cmd_vel` and `posture` the node sends.

use marsupial::arbiter::runtime::StopHandle;
use marsupial::msgs::cdr::CdrReader;
use marsupial::perception::RgbImage;
use marsupial::robot::Camera;
use marsupial::ros2::devices::command_of;
use marsupial::ros2::interfaces;
use marsupial::ros2::keys::{Attachment, NodeName, gid, now_ns};
use marsupial::ros2::messages::{Twist, encode_image, encode_odometry, stamp};
use marsupial::ros2::node::encode_bool;
use marsupial::schemas::{DOCK_CONTACT_KIND, DeviceCommand, DeviceReading, DockContact, POSTURE_KIND, Posture};
use marsupial::sim::robot::{SimCamera, SimDevices, SimRobot};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};
use zenoh::Wait;

/// Index of the profile's device of kind `kind` (the sim robot's devices are in profile order).
fn device(kinds: &[String], kind: &str) -> usize {
    kinds.iter().position(|k| k == kind).expect("the profile declares it")
}
/// What the simulator does with a payload the node sent.
type OnPayload = Box<dyn Fn(&[u8]) + Send + Sync>;

/// The simulator's side of the wire.
pub struct Simulator {
    stop: StopHandle,
    threads: Vec<JoinHandle<()>>,
    _subs: Vec<zenoh::pubsub::Subscriber<()>>,
    /// Frames published.
    pub frames: Arc<Mutex<u64>>,
}

impl Simulator {
    /// Publishes `sim`'s camera at the loop's rate and its odometry and dock switch at
    /// 50 Hz, runs its physics in real time, and applies what the node commands. With
    /// `camera_stops_after`, the camera falls silent after that many frames.
    pub fn start(session: &zenoh::Session, node: &NodeName, sim: &SimRobot, camera_stops_after: Option<u64>) -> Self {
        let stop = StopHandle::new();
        let mut threads = Vec::new();
        let frames = Arc::new(Mutex::new(0));
        let mut robot = sim.robot(&SimDevices::default()).unwrap();
        let kinds = sim.with(|s| s.profile().loop_config().devices);
        let rate = sim.with(|s| s.profile().loop_.rate_hz);
        let publisher = |name: &str, ty: &interfaces::Interface| {
            let key = node.key(name, ty);
            (session.declare_publisher(key.clone()).wait().unwrap(), gid(&key))
        };
        let put = |p: &zenoh::pubsub::Publisher<'static>, g: [u8; 16], seq: i64, buf: &[u8]| {
            let att = Attachment {
                sequence_number: seq,
                source_timestamp: now_ns(),
                gid: g,
            };
            // A put after the test closed the session fails, and does not matter.
            let _ = p.put(buf.to_vec()).attachment(att.encode()).wait();
        };

        // Physics on the wall clock.
        {
            let (sim, stop) = (sim.clone(), stop.clone());
            threads.push(std::thread::spawn(move || {
                while !stop.is_stopped() {
                    if sim.run_physics(|| stop.is_stopped()).is_some() {
                        // Docked or caught: hold until the test places the robot again.
                        std::thread::sleep(Duration::from_millis(20));
                    }
                }
            }));
        }
        // The camera, rendered at the loop's rate.
        {
            let (image, g) = publisher("camera/image_raw", &interfaces::image());
            let mut camera = SimCamera::new(sim.clone(), 0);
            let (stop, frames) = (stop.clone(), frames.clone());
            threads.push(std::thread::spawn(move || {
                let (w, h) = camera.resolution();
                let mut frame = RgbImage::new(w, h);
                let mut buf = Vec::new();
                let period = Duration::from_secs_f64(1.0 / rate);
                let mut next = Instant::now();
                let mut n = 0;
                while !stop.is_stopped() {
                    if camera_stops_after.is_none_or(|k| n < k) && camera.capture(&mut frame).is_ok() {
                        encode_image(
                            &mut buf,
                            stamp(now_ns()),
                            "camera",
                            w as u32,
                            h as u32,
                            frame.as_bytes(),
                        );
                        n += 1;
                        put(&image, g, n as i64, &buf);
                        *frames.lock().unwrap() = n;
                    }
                    next += period;
                    if let Some(d) = next.checked_duration_since(Instant::now()) {
                        std::thread::sleep(d);
                    }
                }
            }));
        }
        // Odometry and the dock switch.
        {
            let (odom, go) = publisher("odom", &interfaces::odometry());
            let (switch, gs) = publisher("dock_contact", &interfaces::message("std_msgs/msg/Bool"));
            let mut odometer = robot.odometer.take().unwrap();
            let mut plates = robot.sensors.swap_remove(device(&kinds.sensors, DOCK_CONTACT_KIND));
            let stop = stop.clone();
            threads.push(std::thread::spawn(move || {
                let mut buf = Vec::new();
                let mut seq = 0;
                while !stop.is_stopped() {
                    seq += 1;
                    if let Ok(o) = odometer.read() {
                        encode_odometry(&mut buf, stamp(now_ns()), o.pose, o.twist.v, o.twist.omega);
                        put(&odom, go, seq, &buf);
                    }
                    let mut v = Vec::new();
                    if let Some(c) = plates.read(&mut v).ok().and_then(|()| DockContact::decode(&v)) {
                        put(&switch, gs, seq, &encode_bool(c.0));
                    }
                    std::thread::sleep(Duration::from_millis(20));
                }
            }));
        }
        // What the node commands.
        let drive = Arc::new(Mutex::new(robot.drive));
        // Bujold's actuators: her posture (she has no guides: the node publishes none).
        let posture = robot.actuators.swap_remove(device(&kinds.actuators, POSTURE_KIND));
        let posture = Arc::new(Mutex::new(posture));
        let subscribe = |name: &str, ty: &interfaces::Interface, f: OnPayload| {
            session
                .declare_subscriber(node.key(name, ty))
                .callback(move |s| f(&s.payload().to_bytes()))
                .wait()
                .unwrap()
        };
        let string = interfaces::message("std_msgs/msg/String");
        let text = |b: &[u8]| CdrReader::new(b).and_then(|mut r| r.string("data").map(str::to_owned));
        let subs = vec![
            subscribe(
                "cmd_vel",
                &interfaces::twist(),
                Box::new(move |b| {
                    let t = Twist::decode(b).expect("cmd_vel decodes");
                    drive.lock().unwrap().apply(&command_of(t)).unwrap();
                }),
            ),
            subscribe(
                "posture",
                &string,
                Box::new(move |b| {
                    let p = match text(b).unwrap().as_str() {
                        "lowered" => Posture::Lowered,
                        _ => Posture::Raised,
                    };
                    posture.lock().unwrap().apply(p.encode().values()).unwrap();
                }),
            ),
        ];
        Self {
            stop,
            threads,
            _subs: subs,
            frames,
        }
    }

    pub fn end(self) {
        self.stop.stop();
        for t in self.threads {
            t.join().unwrap();
        }
    }
}
