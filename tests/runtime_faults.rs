//! The threaded runtime when the robot's own parts fail: a camera driver that panics or
//! blocks, a drive that rejects commands for a moment or for good, a drive that blocks, an
//! odometer that blocks, a tick that overruns, and a behavior that panics. Each is
//! detected, the base is commanded to stop, the reason is reported, and the run returns.

use marsupial::arbiter::runtime::{AbortReason, RuntimeConfig, RuntimeEvent, RuntimeReport, StopHandle, run};
use marsupial::arbiter::{InputKind, LoopConfig, ReactiveLoop, Staleness, StopReason};
use marsupial::kinematics::{Differential, DriveLimits, DriveModel};
use marsupial::perception::RgbImage;
use marsupial::robot::{Camera, DeviceId, Drive, Exposure, HardwareError, Odometer, Robot};
use marsupial::schemas::{Behavior, DriveCommand, Feedback, Inputs, MotorOutput, OdometryReading, Step};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// When, after the device was made, a fake device misbehaves.
#[derive(Clone, Copy)]
enum Trouble {
    None,
    /// Panics on every call from this time.
    Panic(f64),
    /// Blocks from this time until the test releases it; works again after.
    Block(f64),
    /// Fails every call in [from, to).
    Fail(f64, f64),
    /// Fails every call that is not a stop, from this time.
    RejectMotion(f64),
}

/// A fake device's clock and misbehaviour; `release` unblocks a blocked call (dropping
/// the sender does too).
struct Fault {
    born: Instant,
    trouble: Trouble,
    release: Mutex<mpsc::Receiver<()>>,
    released: AtomicBool,
}

impl Fault {
    fn new(trouble: Trouble) -> (Self, mpsc::Sender<()>) {
        let (tx, rx) = mpsc::channel();
        let f = Fault {
            born: Instant::now(),
            trouble,
            release: Mutex::new(rx),
            released: AtomicBool::new(false),
        };
        (f, tx)
    }

    /// Misbehaves as told; `Err` for a failed call.
    fn strike(&self, is_stop: bool) -> Result<(), HardwareError> {
        let t = self.born.elapsed().as_secs_f64();
        match self.trouble {
            Trouble::Panic(from) if t >= from => panic!("driver bug at {t:.2} s"),
            Trouble::Block(from) if t >= from && !self.released.load(Ordering::SeqCst) => {
                let _ = self.release.lock().unwrap().recv();
                self.released.store(true, Ordering::SeqCst);
                Err(HardwareError::NotReady)
            }
            Trouble::Fail(from, to) if t >= from && t < to => Err(HardwareError::Fault {
                device: "fake".into(),
                detail: "bus error".into(),
            }),
            Trouble::RejectMotion(from) if t >= from && !is_stop => Err(HardwareError::Fault {
                device: "fake".into(),
                detail: "motion refused".into(),
            }),
            _ => Ok(()),
        }
    }
}

/// A 100 fps camera.
struct FakeCamera(Fault);
impl Camera for FakeCamera {
    fn resolution(&self) -> (usize, usize) {
        (8, 6)
    }
    fn capture(&mut self, _: &mut RgbImage) -> Result<Exposure, HardwareError> {
        std::thread::sleep(Duration::from_millis(10));
        self.0.strike(false)?;
        Ok(Exposure::NOW)
    }
}

/// A drive that logs each command it accepted, with the time.
struct FakeDrive(Fault, Arc<Mutex<Vec<(f64, DriveCommand)>>>);
impl Drive for FakeDrive {
    fn apply(&mut self, c: &DriveCommand) -> Result<(), HardwareError> {
        self.0.strike(*c == DriveCommand::Stop)?;
        self.1.lock().unwrap().push((self.0.born.elapsed().as_secs_f64(), *c));
        Ok(())
    }
}

/// An odometer standing still.
struct FakeOdometer(Fault);
impl Odometer for FakeOdometer {
    fn read(&mut self) -> Result<OdometryReading, HardwareError> {
        self.0.strike(false)?;
        Ok(OdometryReading::default())
    }
}

/// Creeps forward at 0.1 m/s; on ticks in `slow` it sleeps `nap` first and asks for
/// 0.2 m/s, so a command from a slow tick can be told apart.
#[derive(Clone)]
struct Creep {
    ticks: u32,
    slow: (u32, u32),
    nap: Duration,
    panic_at: Option<u32>,
}

impl Creep {
    fn steady() -> Self {
        Creep {
            ticks: 0,
            slow: (0, 0),
            nap: Duration::ZERO,
            panic_at: None,
        }
    }
}

impl Behavior for Creep {
    fn name(&self) -> &str {
        "creep"
    }
    fn tick(&mut self, _mem: &mut (), inputs: &Inputs<'_>) -> Option<Step> {
        self.ticks += 1;
        if self.panic_at == Some(self.ticks) {
            panic!("behavior bug");
        }
        let v = if (self.slow.0..self.slow.1).contains(&self.ticks) {
            std::thread::sleep(self.nap);
            0.2
        } else {
            0.1
        };
        Some(Step::running(
            MotorOutput::twist(v, 0.0),
            Feedback::new("creep", inputs.now),
        ))
    }
}

fn loop_config(odometry: bool) -> LoopConfig {
    LoopConfig {
        rate_hz: 20.0,
        staleness: Staleness {
            camera: Some(0.25),
            odometry: odometry.then_some(0.25),
            sensors: Vec::new(),
            // The fakes deliver blank frames: repeats are not faults here.
            camera_repeats_stale: false,
        },
        frame_sizes: vec![(8, 6)],
        drive: DriveModel::Differential(Differential { track: 0.3 }),
        limits: DriveLimits {
            max_speed: 0.5,
            max_turn_rate: 1.0,
        },
        devices: Default::default(),
    }
}

fn config(max_s: f64) -> RuntimeConfig {
    RuntimeConfig {
        max_duration: Some(Duration::from_secs_f64(max_s)),
        device_timeout: Duration::from_millis(500),
        actuator_hold: Duration::from_millis(300),
        ..Default::default()
    }
}

type Log = Arc<Mutex<Vec<(f64, DriveCommand)>>>;

/// A robot with one fake camera and a fake drive, and the drive's log.
fn robot(camera: Trouble, drive: Trouble) -> (Robot, Log, [mpsc::Sender<()>; 2]) {
    let (cam_fault, cam_release) = Fault::new(camera);
    let (drive_fault, drive_release) = Fault::new(drive);
    let log = Log::default();
    let robot = Robot::new(
        vec![Box::new(FakeCamera(cam_fault))],
        Box::new(FakeDrive(drive_fault, log.clone())),
    );
    (robot, log, [cam_release, drive_release])
}

fn log_of(log: &Log) -> Vec<(f64, DriveCommand)> {
    log.lock().unwrap().clone()
}

fn moving(c: &DriveCommand) -> bool {
    *c != DriveCommand::Stop
}

/// The first time a safe stop for `pred` was reported.
fn stop_time(report: &RuntimeReport, pred: impl Fn(&StopReason) -> bool) -> Option<f64> {
    report.events.iter().find_map(|e| match e {
        RuntimeEvent::SafeStop { t, reason } if pred(reason) => Some(*t),
        _ => None,
    })
}

#[test]
fn a_camera_driver_that_panics_ends_the_run_with_a_stop() {
    let (mut robot, log, _release) = robot(Trouble::Panic(0.5), Trouble::None);
    let mut lp = ReactiveLoop::new(Box::new(Creep::steady()), loop_config(false));
    let report = run(&mut robot, &mut lp, &config(5.0), &StopHandle::new());
    match &report.aborted {
        Some(AbortReason::DevicePanicked { device, message }) => {
            assert_eq!(*device, DeviceId::nth("camera", 0));
            assert!(message.starts_with("driver bug"), "{message}");
        }
        other => panic!("{other:?}: {:#?}", report.events),
    }
    assert!(report.elapsed_s < 1.0, "the run ended at once: {report:?}");
    let cmds = log_of(&log);
    assert!(
        cmds.iter().filter(|(_, c)| moving(c)).count() > 3,
        "it drove before the panic"
    );
    assert_eq!(cmds.last().map(|c| c.1), Some(DriveCommand::Stop));
    assert!(report.abandoned.is_empty());
    assert_eq!(robot.cameras[0].resolution(), (8, 6), "the camera came back");
}

#[test]
fn a_camera_that_blocks_stops_the_base_then_ends_the_run_and_is_abandoned() {
    let (mut robot, log, release) = robot(Trouble::Block(0.5), Trouble::None);
    let mut lp = ReactiveLoop::new(Box::new(Creep::steady()), loop_config(false));
    let started = Instant::now();
    let report = run(&mut robot, &mut lp, &config(10.0), &StopHandle::new());
    let returned = started.elapsed().as_secs_f64();

    let t_stale = stop_time(&report, |r| {
        matches!(
            r,
            StopReason::Stale {
                input: InputKind::Camera(0),
                ..
            }
        )
    })
    .unwrap_or_else(|| panic!("no stale stop: {:#?}", report.events));
    assert!((0.5..1.0).contains(&t_stale), "stale stop at {t_stale}");
    match report.aborted {
        Some(AbortReason::DeviceBlocked { device, for_s }) => {
            assert_eq!(device, DeviceId::nth("camera", 0));
            assert!((0.5..0.7).contains(&for_s), "{for_s}");
        }
        ref other => panic!("{other:?}: {:#?}", report.events),
    }
    // The loop noticed within a tick or two of the timeout, then waited one timeout for
    // the camera thread before leaving it behind.
    assert!(returned < 2.5, "run returned after {returned} s");
    assert_eq!(report.abandoned, [DeviceId::nth("camera", 0)]);
    let mut frame = RgbImage::new(8, 6);
    assert!(matches!(
        robot.cameras[0].capture(&mut frame),
        Err(HardwareError::Disconnected { .. })
    ));
    // Nothing moved from a tick after the last frame went stale.
    let cmds = log_of(&log);
    assert!(
        cmds.iter().all(|(t, c)| !moving(c) || *t < t_stale + 0.06),
        "moved after the stale stop: {cmds:?}"
    );
    assert_eq!(cmds.last().map(|c| c.1), Some(DriveCommand::Stop));
    drop(release);
}

#[test]
fn a_brief_drive_fault_holds_a_safe_stop_then_the_run_goes_on() {
    let (mut robot, log, _release) = robot(Trouble::None, Trouble::Fail(0.5, 0.6));
    let mut lp = ReactiveLoop::new(Box::new(Creep::steady()), loop_config(false));
    let report = run(&mut robot, &mut lp, &config(1.6), &StopHandle::new());
    assert_eq!(report.aborted, None, "{:#?}", report.events);
    let t_fault = stop_time(&report, |r| {
        *r == StopReason::ActuatorFault {
            device: DeviceId::one("drive"),
        }
    })
    .unwrap_or_else(|| panic!("no actuator stop: {:#?}", report.events));
    assert!((0.45..0.7).contains(&t_fault), "{t_fault}");
    let resumed = report
        .events
        .iter()
        .any(|e| matches!(e, RuntimeEvent::Resumed { t } if *t > t_fault));
    assert!(resumed, "{:#?}", report.events);
    assert!(
        report
            .events
            .iter()
            .any(|e| matches!(e, RuntimeEvent::HardwareError { device: "drive", .. }))
    );
    let cmds = log_of(&log);
    // Within the hold after the fault the drive only accepted stops; motion came back after.
    let first_error = 0.5;
    assert!(
        cmds.iter()
            .all(|(t, c)| !moving(c) || *t < first_error || *t >= first_error + 0.3 - 0.02),
        "{cmds:?}"
    );
    assert!(cmds.iter().any(|(t, c)| moving(c) && *t > 1.0), "motion resumed");
}

#[test]
fn a_drive_that_keeps_refusing_motion_ends_the_run() {
    let (mut robot, log, _release) = robot(Trouble::None, Trouble::RejectMotion(0.5));
    let mut lp = ReactiveLoop::new(Box::new(Creep::steady()), loop_config(false));
    let report = run(&mut robot, &mut lp, &config(10.0), &StopHandle::new());
    match report.aborted {
        Some(AbortReason::DeviceFailing { device, for_s }) => {
            assert_eq!(device, DeviceId::one("drive"));
            assert!((0.5..0.7).contains(&for_s), "{for_s}");
        }
        ref other => panic!("{other:?}: {:#?}", report.events),
    }
    assert!(report.elapsed_s < 1.5, "{}", report.elapsed_s);
    let cmds = log_of(&log);
    assert!(cmds.iter().all(|(t, c)| !moving(c) || *t < 0.5), "{cmds:?}");
    assert_eq!(cmds.last().map(|c| c.1), Some(DriveCommand::Stop));
}

#[test]
fn a_drive_that_blocks_is_named_and_abandoned_and_gets_the_stop_when_it_returns() {
    let (mut robot, log, [_cam, drive_release]) = robot(Trouble::None, Trouble::Block(0.5));
    let mut lp = ReactiveLoop::new(Box::new(Creep::steady()), loop_config(false));
    let started = Instant::now();
    let report = run(&mut robot, &mut lp, &config(10.0), &StopHandle::new());
    let returned = started.elapsed().as_secs_f64();
    match report.aborted {
        Some(AbortReason::DeviceBlocked { device, .. }) => assert_eq!(device, DeviceId::one("drive")),
        ref other => panic!("{other:?}: {:#?}", report.events),
    }
    assert!(returned < 2.5, "{returned}");
    assert_eq!(report.abandoned, [DeviceId::one("drive")]);
    assert!(
        robot.drive.apply(&DriveCommand::Stop).is_err(),
        "a stand-in holds its place"
    );
    // When the stuck call returns, the thread applies the final stop before it ends.
    drop(drive_release);
    let deadline = Instant::now() + Duration::from_secs(2);
    while log_of(&log).last().map(|c| c.1) != Some(DriveCommand::Stop) && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(10));
    }
    assert_eq!(log_of(&log).last().map(|c| c.1), Some(DriveCommand::Stop));
}

#[test]
fn an_odometer_that_blocks_is_named() {
    let (mut robot, log, _release) = robot(Trouble::None, Trouble::None);
    let (odo_fault, odo_release) = Fault::new(Trouble::Block(0.5));
    robot.odometer = Some(Box::new(FakeOdometer(odo_fault)));
    let mut lp = ReactiveLoop::new(Box::new(Creep::steady()), loop_config(true));
    let report = run(&mut robot, &mut lp, &config(10.0), &StopHandle::new());
    match report.aborted {
        Some(AbortReason::DeviceBlocked { device, .. }) => assert_eq!(device, DeviceId::one("odometer")),
        ref other => panic!("{other:?}: {:#?}", report.events),
    }
    let t_stale = stop_time(&report, |r| {
        matches!(
            r,
            StopReason::Stale {
                input: InputKind::Odometry,
                ..
            }
        )
    })
    .unwrap_or_else(|| panic!("{:#?}", report.events));
    let cmds = log_of(&log);
    assert!(cmds.iter().all(|(t, c)| !moving(c) || *t < t_stale + 0.06), "{cmds:?}");
    assert_eq!(report.abandoned, [DeviceId::one("odometer")]);
    drop(odo_release);
}

#[test]
fn a_tick_that_overruns_sends_a_stop_instead_of_its_stale_command() {
    let (mut robot, log, _release) = robot(Trouble::None, Trouble::None);
    let creep = Creep {
        slow: (12, 14),
        nap: Duration::from_millis(300),
        ..Creep::steady()
    };
    let mut lp = ReactiveLoop::new(Box::new(creep), loop_config(false));
    let report = run(&mut robot, &mut lp, &config(2.0), &StopHandle::new());
    assert_eq!(report.aborted, None);
    let overrun = report.events.iter().find_map(|e| match e {
        RuntimeEvent::SafeStop {
            reason: StopReason::Overrun { tick_s, limit_s },
            ..
        } => Some((*tick_s, *limit_s)),
        _ => None,
    });
    let (tick_s, limit_s) = overrun.unwrap_or_else(|| panic!("{:#?}", report.events));
    assert!(tick_s >= 0.3 && limit_s == 0.25, "{tick_s} {limit_s}");
    assert!(report.overruns >= 2);
    let cmds = log_of(&log);
    let slow_cmd = |c: &DriveCommand| matches!(c, DriveCommand::Twist(t) if t.v > 0.15);
    assert!(
        !cmds.iter().any(|(_, c)| slow_cmd(c)),
        "a slow tick's command went out: {cmds:?}"
    );
    assert!(cmds.iter().any(|(t, c)| moving(c) && *t > 1.5), "the run went on");
}

#[test]
fn a_behavior_that_panics_still_leaves_the_base_stopped() {
    let (mut robot, log, _release) = robot(Trouble::None, Trouble::None);
    let creep = Creep {
        panic_at: Some(10),
        ..Creep::steady()
    };
    let mut lp = ReactiveLoop::new(Box::new(creep), loop_config(false));
    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        run(&mut robot, &mut lp, &config(5.0), &StopHandle::new())
    }));
    assert!(outcome.is_err(), "the behavior's panic reaches the caller");
    let deadline = Instant::now() + Duration::from_secs(1);
    while log_of(&log).last().map(|c| c.1) != Some(DriveCommand::Stop) && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(10));
    }
    let cmds = log_of(&log);
    assert!(cmds.iter().any(|(_, c)| moving(c)));
    assert_eq!(cmds.last().map(|c| c.1), Some(DriveCommand::Stop));
}
