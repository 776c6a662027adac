//! The threaded runtime allocates nothing per tick in steady state, on any of its threads:
//! the camera thread recycles its frame buffers, the slow-sensor thread its value buffers,
//! and the loop builds each tick's camera and sensor lists inline. A counting global
//! allocator that counts on every thread proves it (this file holds one test, so no other
//! test's allocations are counted).

use marsupial::arbiter::runtime::{RuntimeConfig, StopHandle, run};
use marsupial::arbiter::{LoopConfig, ReactiveLoop, Staleness};
use marsupial::kinematics::{Differential, DriveLimits, DriveModel};
use marsupial::perception::RgbImage;
use marsupial::robot::{Camera, Drive, Exposure, HardwareError, Robot, Sensor, WheelEncoders, WheelTravel};
use marsupial::schemas::{Behavior, DriveCommand, Feedback, Inputs, MotorOutput, Step};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Duration;

static COUNTING: AtomicBool = AtomicBool::new(false);
static ALLOCS: AtomicUsize = AtomicUsize::new(0);

struct Counting;

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        if COUNTING.load(Ordering::Relaxed) {
            ALLOCS.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        if COUNTING.load(Ordering::Relaxed) {
            ALLOCS.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.realloc(p, l, n) }
    }
}

#[global_allocator]
static A: Counting = Counting;

/// 100 fps; each frame's first byte counts frames.
struct Cam(u8);
impl Camera for Cam {
    fn resolution(&self) -> (usize, usize) {
        (32, 24)
    }
    fn capture(&mut self, frame: &mut RgbImage) -> Result<Exposure, HardwareError> {
        std::thread::sleep(Duration::from_millis(10));
        self.0 = self.0.wrapping_add(1);
        frame.as_bytes_mut()[0] = self.0;
        Ok(Exposure::NOW)
    }
}

struct NullDrive;
impl Drive for NullDrive {
    fn apply(&mut self, _: &DriveCommand) -> Result<(), HardwareError> {
        Ok(())
    }
}

struct Wheels(f64);
impl WheelEncoders for Wheels {
    fn read(&mut self) -> Result<WheelTravel, HardwareError> {
        self.0 += 0.001;
        Ok(WheelTravel {
            left: self.0,
            right: self.0,
        })
    }
}

/// Five ranges.
struct Ranges;
impl Sensor for Ranges {
    fn read(&mut self, values: &mut Vec<f64>) -> Result<(), HardwareError> {
        values.extend_from_slice(&[1.0, 1.1, 1.2, 1.3, 1.4]);
        Ok(())
    }
}

/// Creeps forward while it sees frames and ranges.
struct Creep;
impl Behavior for Creep {
    fn name(&self) -> &str {
        "creep"
    }
    fn tick(&mut self, _mem: &mut (), inputs: &Inputs<'_>) -> Option<Step> {
        let seen = inputs.camera(0).is_some() && inputs.sensor(0).is_some();
        Some(Step::running(
            MotorOutput::twist(if seen { 0.1 } else { 0.0 }, 0.0),
            Feedback::new("creep", inputs.now),
        ))
    }
}

#[test]
fn the_threaded_runtime_does_not_allocate_per_tick() {
    let mut robot = Robot::new(vec![Box::new(Cam(0))], Box::new(NullDrive));
    robot.encoders = Some(Box::new(Wheels(0.0)));
    robot.sensors.push(Box::new(Ranges));
    let config = LoopConfig {
        rate_hz: 50.0,
        staleness: Staleness {
            camera: Some(0.2),
            odometry: Some(0.2),
            sensors: vec![Some(0.2)],
            camera_repeats_stale: true,
        },
        frame_sizes: vec![(32, 24)],
        drive: DriveModel::Differential(Differential { track: 0.3 }),
        limits: DriveLimits {
            max_speed: 0.5,
            max_turn_rate: 1.0,
        },
        devices: Default::default(),
    };
    let mut lp = ReactiveLoop::new(Box::new(Creep), config);
    let cfg = RuntimeConfig {
        max_duration: Some(Duration::from_millis(1500)),
        ..RuntimeConfig::default()
    };
    // Count from 0.5 s (threads started, buffers sized) to 1.3 s.
    let window = std::thread::spawn(|| {
        std::thread::sleep(Duration::from_millis(500));
        ALLOCS.store(0, Ordering::SeqCst);
        COUNTING.store(true, Ordering::SeqCst);
        std::thread::sleep(Duration::from_millis(800));
        COUNTING.store(false, Ordering::SeqCst);
    });
    let report = run(&mut robot, &mut lp, &cfg, &StopHandle::new());
    window.join().unwrap();
    let allocs = ALLOCS.load(Ordering::SeqCst);
    assert!(report.ticks >= 60, "{report:?}");
    assert!(
        report.last_command.is_some_and(|c| c.drive != DriveCommand::Stop),
        "it ran on fresh inputs: {report:?}"
    );
    assert_eq!(allocs, 0, "allocations on the runtime's threads in steady state");
    // Control: the counter sees an allocation on any thread.
    COUNTING.store(true, Ordering::SeqCst);
    let v = std::thread::spawn(|| Vec::<u8>::with_capacity(std::hint::black_box(64)))
        .join()
        .unwrap();
    COUNTING.store(false, Ordering::SeqCst);
    drop(v);
    assert!(ALLOCS.load(Ordering::SeqCst) >= 1);
}
