//! The threaded runtime: latest-frame-wins delivery, stale-input safe stop and resume,
//! clean shutdown with a final stop command.

use marsupial::arbiter::runtime::{RuntimeConfig, RuntimeEvent, StopHandle, run, run_missions};
use marsupial::arbiter::{InputKind, LoopConfig, ReactiveLoop, Staleness, StopReason};
use marsupial::kinematics::{Differential, DriveLimits, DriveModel};
use marsupial::perception::RgbImage;
use marsupial::robot::{Actuator, Camera, Drive, Exposure, HardwareError, Robot, Sensor};
use marsupial::schemas::{
    Agent, Behavior, Command, DriveCommand, Feedback, Inputs, Mission, MissionError, MotorOutput, Outcome, Step,
};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// A camera at `fps` that goes silent between `gap.0` and `gap.1` seconds after start.
/// Each frame's first byte is a frame counter.
struct GappyCamera {
    start: Option<Instant>,
    fps: f64,
    gap: (f64, f64),
    count: u8,
}

impl Camera for GappyCamera {
    fn resolution(&self) -> (usize, usize) {
        (8, 6)
    }
    fn capture(&mut self, frame: &mut RgbImage) -> Result<Exposure, HardwareError> {
        let start = *self.start.get_or_insert_with(Instant::now);
        std::thread::sleep(Duration::from_secs_f64(1.0 / self.fps));
        let t = start.elapsed().as_secs_f64();
        if t >= self.gap.0 && t < self.gap.1 {
            return Err(HardwareError::NotReady);
        }
        self.count = self.count.wrapping_add(1);
        frame.as_bytes_mut()[0] = self.count;
        Ok(Exposure::NOW)
    }
}

#[derive(Clone, Default)]
struct LogDrive(Arc<Mutex<Vec<DriveCommand>>>);
impl Drive for LogDrive {
    fn apply(&mut self, c: &DriveCommand) -> Result<(), HardwareError> {
        self.0.lock().unwrap().push(*c);
        Ok(())
    }
}

/// Drives forward and records the age of each frame it sees.
#[derive(Clone, Default)]
struct Creep(Arc<Mutex<Vec<(f64, u8)>>>);
impl Behavior for Creep {
    fn name(&self) -> &str {
        "creep"
    }
    fn tick(&mut self, _mem: &mut (), inputs: &Inputs<'_>) -> Option<Step> {
        if let Some(c) = inputs.camera(0) {
            self.0
                .lock()
                .unwrap()
                .push((inputs.now - c.stamp, c.image.as_bytes()[0]));
        }
        Some(Step::running(
            MotorOutput::twist(0.1, 0.0),
            Feedback::new("creep", inputs.now),
        ))
    }
}

fn loop_config() -> LoopConfig {
    LoopConfig {
        rate_hz: 20.0,
        staleness: Staleness {
            camera: Some(0.25),
            odometry: None,
            sensors: Vec::new(),
            camera_repeats_stale: true,
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

#[test]
fn stale_camera_stops_the_robot_and_fresh_frames_resume_it() {
    let drive = LogDrive::default();
    let creep = Creep::default();
    let cam = GappyCamera {
        start: None,
        fps: 100.0,
        gap: (0.6, 1.4),
        count: 0,
    };
    let mut robot = Robot::new(vec![Box::new(cam)], Box::new(drive.clone()));
    let mut lp = ReactiveLoop::new(Box::new(creep.clone()), loop_config());
    let cfg = RuntimeConfig {
        max_duration: Some(Duration::from_millis(2200)),
        ..Default::default()
    };
    let report = run(&mut robot, &mut lp, &cfg, &StopHandle::new());

    let stops: Vec<_> = report
        .events
        .iter()
        .filter_map(|e| match e {
            RuntimeEvent::SafeStop { t, reason } => Some((*t, *reason)),
            _ => None,
        })
        .collect();
    let resumes: Vec<f64> = report
        .events
        .iter()
        .filter_map(|e| {
            if let RuntimeEvent::Resumed { t } = e {
                Some(*t)
            } else {
                None
            }
        })
        .collect();
    // The first frame may arrive after the first tick: a `Missing` stop at start is fine.
    let stale: Vec<_> = stops
        .iter()
        .filter(|(_, r)| {
            matches!(
                r,
                StopReason::Stale {
                    input: InputKind::Camera(0),
                    ..
                }
            )
        })
        .collect();
    assert_eq!(stale.len(), 1, "events: {:?}", report.events);
    let t_stop = stale[0].0;
    assert!(t_stop > 0.8 && t_stop < 1.2, "stopped at {t_stop}");
    assert!(
        resumes.iter().any(|&t| t > t_stop && t < 1.8),
        "resumes {resumes:?} after stop at {t_stop}"
    );

    let cmds = drive.0.lock().unwrap().clone();
    assert!(cmds.contains(&DriveCommand::Stop), "the stale stop reached the drive");
    assert!(cmds.iter().filter(|c| matches!(c, DriveCommand::Twist(_))).count() > 20);
    assert_eq!(
        cmds.last(),
        Some(&DriveCommand::Stop),
        "the run ends with a stop command"
    );
    assert!(report.ticks >= 30, "{report:?}");
}

#[test]
fn newest_frame_wins() {
    let drive = LogDrive::default();
    let creep = Creep::default();
    let cam = GappyCamera {
        start: None,
        fps: 200.0,
        gap: (1e9, 1e9),
        count: 0,
    };
    let mut robot = Robot::new(vec![Box::new(cam)], Box::new(drive.clone()));
    let mut lp = ReactiveLoop::new(Box::new(creep.clone()), loop_config());
    let cfg = RuntimeConfig {
        max_duration: Some(Duration::from_millis(800)),
        ..Default::default()
    };
    let report = run(&mut robot, &mut lp, &cfg, &StopHandle::new());
    let seen = creep.0.lock().unwrap().clone();
    assert!(seen.len() >= 8, "{report:?}");
    // The loop runs at 20 Hz and the camera at ~200 Hz: frames are skipped, never queued,
    // so every frame the loop sees is recent.
    let max_age = seen.iter().map(|(a, _)| *a).fold(0.0, f64::max);
    assert!(max_age < 0.05, "oldest frame seen was {max_age} s old");
    let skipped = seen.windows(2).filter(|w| w[1].1.wrapping_sub(w[0].1) > 1).count();
    assert!(skipped > seen.len() / 2, "frames were not skipped: {seen:?}");
}

#[test]
fn stop_handle_ends_the_run() {
    let drive = LogDrive::default();
    let cam = GappyCamera {
        start: None,
        fps: 50.0,
        gap: (1e9, 1e9),
        count: 0,
    };
    let mut robot = Robot::new(vec![Box::new(cam)], Box::new(drive.clone()));
    let mut lp = ReactiveLoop::new(Box::new(Creep::default()), loop_config());
    let stop = StopHandle::new();
    let s2 = stop.clone();
    let t = std::thread::spawn(move || {
        std::thread::sleep(Duration::from_millis(300));
        s2.stop();
    });
    let report = run(&mut robot, &mut lp, &RuntimeConfig::default(), &stop);
    t.join().unwrap();
    assert!(report.elapsed_s < 2.0);
    assert_eq!(drive.0.lock().unwrap().last(), Some(&DriveCommand::Stop));
}

/// A robot with two missions: each drives for `ticks` ticks and completes; the second
/// ("docking") also reads sensor 0 and commands actuator 0 with the sum of its values.
struct TwoMissions {
    mission: Option<Mission>,
    ticks: u32,
    started: Vec<&'static str>,
    sums: Arc<Mutex<Vec<f64>>>,
}

impl Behavior for TwoMissions {
    fn name(&self) -> &str {
        "two_missions"
    }
    fn tick(&mut self, _mem: &mut (), inputs: &Inputs<'_>) -> Option<Step> {
        let m = self.mission?;
        self.ticks += 1;
        let mut out = MotorOutput::twist(0.1, 0.0);
        if let (Mission::Docking { .. }, Some(s)) = (m, inputs.sensor(0)) {
            let sum: f64 = s.values.iter().sum();
            self.sums.lock().unwrap().push(sum);
            out.aux.put(Command::of("log", [sum]));
        }
        let fb = Feedback::new(m.name(), inputs.now);
        Some(if self.ticks >= 5 {
            self.mission = None;
            Step::done(Outcome::Completed, out, fb)
        } else {
            Step::running(out, fb)
        })
    }
}

impl Agent for TwoMissions {
    fn begin(&mut self, mission: &Mission) -> Result<(), MissionError> {
        if self.started.len() >= 2 {
            return Err(MissionError::Unavailable {
                robot: "two_missions".into(),
                mission: mission.name(),
                why: "only two missions a day".into(),
            });
        }
        self.started.push(mission.name());
        self.mission = Some(*mission);
        self.ticks = 0;
        Ok(())
    }
}

/// Reads three ones.
struct Ones;
impl Sensor for Ones {
    fn read(&mut self, values: &mut Vec<f64>) -> Result<(), HardwareError> {
        values.extend([1.0, 1.0, 1.0]);
        Ok(())
    }
}

#[derive(Clone, Default)]
struct LogActuator(Arc<Mutex<Vec<f64>>>);
impl Actuator for LogActuator {
    fn apply(&mut self, values: &[f64]) -> Result<(), HardwareError> {
        self.0.lock().unwrap().extend_from_slice(values);
        Ok(())
    }
}

#[test]
fn missions_run_one_after_the_other_and_custom_devices_reach_the_behavior() {
    let cam = GappyCamera {
        start: None,
        fps: 100.0,
        gap: (10.0, 10.0),
        count: 0,
    };
    let drive = LogDrive::default();
    let actuator = LogActuator::default();
    let mut robot = Robot::new(vec![Box::new(cam)], Box::new(drive.clone()));
    robot.sensors.push(Box::new(Ones));
    robot.actuators.push(Box::new(actuator.clone()));
    let sums = Arc::new(Mutex::new(Vec::new()));
    let agent = TwoMissions {
        mission: None,
        ticks: 0,
        started: Vec::new(),
        sums: sums.clone(),
    };
    let mut config = loop_config();
    config.staleness.sensors = vec![Some(0.25)];
    config.devices.sensors = vec!["ones".into()];
    config.devices.actuators = vec!["log".into()];
    let mut lp = ReactiveLoop::new(Box::new(agent), config);
    let cfg = RuntimeConfig {
        max_duration: Some(Duration::from_secs(5)),
        sensor_rate_hz: 100.0,
        ..Default::default()
    };
    let missions = [Mission::Departure, Mission::docking(), Mission::docking()];
    let report = run_missions(&mut robot, &mut lp, &missions, &cfg, &StopHandle::new());
    let kinds: Vec<String> = report
        .events
        .iter()
        .filter(|e| !matches!(e, RuntimeEvent::SafeStop { .. } | RuntimeEvent::Resumed { .. }))
        .map(|e| e.to_string().split("  ").last().unwrap_or_default().to_string())
        .collect();
    assert_eq!(
        kinds,
        [
            "departure started",
            "finished: Completed",
            "docking started",
            "finished: Completed",
            "refused: `two_missions` cannot start a docking: only two missions a day",
        ],
        "{:#?}",
        report.events
    );
    assert_eq!(lp.root().started, ["departure", "docking"]);
    // The sensor's readings reached the docking mission, and its commands the actuator.
    let sums = sums.lock().unwrap().clone();
    assert!(!sums.is_empty() && sums.iter().all(|&s| s == 3.0), "{sums:?}");
    let applied = actuator.0.lock().unwrap().clone();
    assert!(!applied.is_empty() && applied.iter().all(|&v| v == 3.0), "{applied:?}");
}

#[test]
fn a_mission_the_robot_refuses_runs_nothing() {
    let mut robot = Robot::new(
        vec![Box::new(GappyCamera {
            start: None,
            fps: 100.0,
            gap: (10.0, 10.0),
            count: 0,
        })],
        Box::new(LogDrive::default()),
    );
    let agent = TwoMissions {
        mission: None,
        ticks: 0,
        started: vec!["a", "b"],
        sums: Arc::default(),
    };
    let mut lp = ReactiveLoop::new(Box::new(agent), loop_config());
    let report = run_missions(
        &mut robot,
        &mut lp,
        &[Mission::Departure],
        &RuntimeConfig::default(),
        &StopHandle::new(),
    );
    assert_eq!(report.ticks, 0);
    assert!(
        matches!(report.events[..], [RuntimeEvent::MissionRefused { .. }]),
        "{report:?}"
    );
}

/// A driver that hands out frames from a one-second buffer: each is fresh off the queue,
/// but was exposed a second ago, and the driver says so.
struct BufferedCamera {
    inner: GappyCamera,
    delay: Duration,
}

impl Camera for BufferedCamera {
    fn resolution(&self) -> (usize, usize) {
        self.inner.resolution()
    }
    fn capture(&mut self, frame: &mut RgbImage) -> Result<Exposure, HardwareError> {
        self.inner.capture(frame)?;
        Ok(Exposure::ago(self.delay))
    }
}

#[test]
fn a_frame_from_a_one_second_buffer_is_stale() {
    let run_with = |delay: Duration| {
        let drive = LogDrive::default();
        let creep = Creep::default();
        let cam = BufferedCamera {
            inner: GappyCamera {
                start: None,
                fps: 50.0,
                gap: (1e9, 1e9),
                count: 0,
            },
            delay,
        };
        let mut robot = Robot::new(vec![Box::new(cam)], Box::new(drive.clone()));
        let mut lp = ReactiveLoop::new(Box::new(creep.clone()), loop_config());
        let cfg = RuntimeConfig {
            max_duration: Some(Duration::from_millis(600)),
            ..Default::default()
        };
        let report = run(&mut robot, &mut lp, &cfg, &StopHandle::new());
        let cmds = drive.0.lock().unwrap().clone();
        (report, cmds, creep.0.lock().unwrap().len())
    };
    // Frames arrive at 50 Hz, but each was exposed 1 s before: stale against 0.25 s.
    let (report, cmds, ticked) = run_with(Duration::from_secs(1));
    let stale_age = report.events.iter().find_map(|e| match e {
        RuntimeEvent::SafeStop {
            reason:
                StopReason::Stale {
                    input: InputKind::Camera(0),
                    age_s,
                    ..
                },
            ..
        } => Some(*age_s),
        _ => None,
    });
    let age = stale_age.unwrap_or_else(|| panic!("not caught as stale: {:?}", report.events));
    assert!((1.0..1.1).contains(&age), "the frame's age is its exposure's: {age}");
    assert_eq!(ticked, 0, "the behavior never ran on a buffered frame");
    assert!(cmds.iter().all(|c| *c == DriveCommand::Stop), "{cmds:?}");
    // Control: the same camera reporting its frames as just exposed drives.
    let (_, cmds, ticked) = run_with(Duration::ZERO);
    assert!(ticked > 5 && cmds.iter().any(|c| matches!(c, DriveCommand::Twist(_))));
}
