//! The lockstep driver: every device read through the hardware traits, the command sent
//! back through them, on the caller's clock; devices with nothing new keep their last
//! reading and turn stale; `[[sensors]]` are checked like every other required input.

use marsupial::arbiter::{InputKind, Lockstep, LoopConfig, LoopStatus, ReactiveLoop, Staleness, StopReason};
use marsupial::kinematics::{Differential, DriveLimits, DriveModel};
use marsupial::perception::RgbImage;
use marsupial::robot::{Camera, Drive, Exposure, HardwareError, Robot, Sensor, WheelEncoders, WheelTravel};
use marsupial::schemas::{
    Behavior, DOCK_CONTACT_KIND, DeviceReading, DockContact, DriveCommand, Feedback, Inputs, MotorOutput, Step,
};
use std::sync::{Arc, Mutex};

/// A camera that delivers frames until `silent_from` captures, then nothing.
struct Silent {
    captures: u32,
    silent_from: u32,
}

impl Camera for Silent {
    fn resolution(&self) -> (usize, usize) {
        (4, 3)
    }
    fn capture(&mut self, frame: &mut RgbImage) -> Result<Exposure, HardwareError> {
        self.captures += 1;
        if self.captures > self.silent_from {
            return Err(HardwareError::NotReady);
        }
        frame.fill([self.captures as u8, 0, 0]);
        Ok(Exposure::NOW)
    }
}

#[derive(Clone, Default)]
struct Log(Arc<Mutex<Vec<DriveCommand>>>);
impl Drive for Log {
    fn apply(&mut self, c: &DriveCommand) -> Result<(), HardwareError> {
        self.0.lock().unwrap().push(*c);
        Ok(())
    }
}

/// Both wheels roll 1 cm per read.
struct Rolling(f64);
impl WheelEncoders for Rolling {
    fn read(&mut self) -> Result<WheelTravel, HardwareError> {
        self.0 += 0.01;
        Ok(WheelTravel {
            left: self.0,
            right: self.0,
        })
    }
}

/// A sensor whose third reading is NaN.
struct Flaky(u32);
impl Sensor for Flaky {
    fn read(&mut self, values: &mut Vec<f64>) -> Result<(), HardwareError> {
        self.0 += 1;
        values.push(if self.0 == 3 { f64::NAN } else { 1.0 });
        Ok(())
    }
}

/// Records what it saw: the odometry x and the first byte of the frame.
#[derive(Clone, Default)]
struct Watch(Arc<Mutex<Vec<(f64, u8)>>>);
impl Behavior for Watch {
    fn name(&self) -> &str {
        "watch"
    }
    fn tick(&mut self, _mem: &mut (), inputs: &Inputs<'_>) -> Option<Step> {
        let x = inputs.odometry.map_or(f64::NAN, |o| o.value.pose.x);
        let b = inputs.camera(0).map_or(0, |c| c.image.as_bytes()[0]);
        self.0.lock().unwrap().push((x, b));
        Some(Step::running(
            MotorOutput::twist(0.1, 0.0),
            Feedback::new("watch", inputs.now),
        ))
    }
}

fn config(sensor_stale: Option<f64>) -> LoopConfig {
    LoopConfig {
        rate_hz: 10.0,
        staleness: Staleness {
            camera: Some(0.25),
            odometry: Some(0.25),
            sensors: vec![sensor_stale],
            camera_repeats_stale: true,
        },
        frame_sizes: vec![(4, 3)],
        drive: DriveModel::Differential(Differential { track: 0.3 }),
        limits: DriveLimits {
            max_speed: 0.5,
            max_turn_rate: 1.0,
        },
        devices: Default::default(),
    }
}

#[test]
fn devices_are_read_and_commanded_through_the_traits_and_silence_turns_stale() {
    let drive = Log::default();
    let mut robot = Robot::new(
        vec![Box::new(Silent {
            captures: 0,
            silent_from: 4,
        })],
        Box::new(drive.clone()),
    );
    robot.encoders = Some(Box::new(Rolling(0.0)));
    robot.sensors.push(Box::new(Flaky(0)));
    let watch = Watch::default();
    let mut lp = ReactiveLoop::new(Box::new(watch.clone()), config(None));
    let mut step = Lockstep::new(&robot, lp.config());
    let statuses: Vec<LoopStatus> = (0..8)
        .map(|k| step.tick(&mut robot, &mut lp, k as f64 * 0.1).status)
        .collect();
    // Ticks 0..1 run (the first odometry read has no travel yet); tick 2's sensor reads
    // NaN: a safe stop; 3 runs; from tick 4 the camera is silent: its frame of tick 3
    // ages past 0.25 s at tick 6.
    assert!(matches!(statuses[0], LoopStatus::Running { .. }), "{statuses:?}");
    assert!(
        matches!(
            statuses[2],
            LoopStatus::SafeStop {
                reason: StopReason::NonFinite {
                    input: InputKind::Sensor(0)
                }
            }
        ),
        "{statuses:?}"
    );
    assert!(matches!(statuses[3], LoopStatus::Running { .. }), "{statuses:?}");
    assert!(matches!(statuses[5], LoopStatus::Running { .. }), "{statuses:?}");
    assert!(
        matches!(
            statuses[6],
            LoopStatus::SafeStop {
                reason: StopReason::Stale {
                    input: InputKind::Camera(0),
                    ..
                }
            }
        ),
        "{statuses:?}"
    );
    // The behavior ran at ticks 0, 1, 3, 4 and 5, seeing the encoders integrated (1 cm
    // per tick after the first read).
    let seen = watch.0.lock().unwrap().clone();
    let xs: Vec<i64> = seen.iter().map(|s| (s.0 * 1000.0).round() as i64).collect();
    assert_eq!(xs, [0, 10, 30, 40, 50], "{seen:?}");
    // The silent camera's last frame (its 4th) is what the loop kept seeing.
    assert_eq!(seen.last().unwrap().1, 4);
    // Every tick's command reached the drive, the safe stops as stops.
    let cmds = drive.0.lock().unwrap().clone();
    assert_eq!(cmds.len(), 8);
    assert_eq!(cmds[2], DriveCommand::Stop);
    assert!(matches!(cmds[3], DriveCommand::Twist(_)));
}

#[test]
fn a_required_sensor_that_never_reads_stops_the_robot() {
    struct Never;
    impl Sensor for Never {
        fn read(&mut self, _: &mut Vec<f64>) -> Result<(), HardwareError> {
            Err(HardwareError::NotReady)
        }
    }
    let mut robot = Robot::new(
        vec![Box::new(Silent {
            captures: 0,
            silent_from: 100,
        })],
        Box::new(Log::default()),
    );
    robot.encoders = Some(Box::new(Rolling(0.0)));
    robot.sensors.push(Box::new(Never));
    let mut lp = ReactiveLoop::new(Box::new(Watch::default()), config(Some(0.3)));
    let mut step = Lockstep::new(&robot, lp.config());
    let out = step.tick(&mut robot, &mut lp, 0.0);
    assert_eq!(
        out.status,
        LoopStatus::SafeStop {
            reason: StopReason::Missing {
                input: InputKind::Sensor(0)
            }
        }
    );
    assert_eq!(out.command.drive, DriveCommand::Stop);
    assert_eq!(step.take_errors().count(), 0, "NotReady is not a fault");
}

/// A dock switch that answers `false` for `answers` reads, then never again.
struct FadingSwitch {
    answers: u32,
}
impl Sensor for FadingSwitch {
    fn read(&mut self, values: &mut Vec<f64>) -> Result<(), HardwareError> {
        if self.answers == 0 {
            return Err(HardwareError::NotReady);
        }
        self.answers -= 1;
        DockContact(false).encode(values);
        Ok(())
    }
}

/// A camera whose frames come from a one-second driver buffer, and which says so.
struct Buffered;
impl Camera for Buffered {
    fn resolution(&self) -> (usize, usize) {
        (4, 3)
    }
    fn capture(&mut self, frame: &mut RgbImage) -> Result<Exposure, HardwareError> {
        frame.fill([7, 0, 0]);
        Ok(Exposure::ago(std::time::Duration::from_secs(1)))
    }
}

#[test]
fn the_dock_switch_and_buffered_frames_are_checked_for_age() {
    let statuses = |camera: Box<dyn Camera>, dock_switch: Option<f64>| {
        let mut robot = Robot::new(vec![camera], Box::new(Log::default()));
        robot.encoders = Some(Box::new(Rolling(0.0)));
        robot.sensors.push(Box::new(FadingSwitch { answers: 3 }));
        let mut cfg = config(dock_switch);
        cfg.devices.sensors = vec![DOCK_CONTACT_KIND.into()];
        let mut lp = ReactiveLoop::new(Box::new(Watch::default()), cfg);
        let mut step = Lockstep::new(&robot, lp.config());
        (0..8)
            .map(|k| step.tick(&mut robot, &mut lp, k as f64 * 0.1).status)
            .collect::<Vec<_>>()
    };
    let fresh = || -> Box<dyn Camera> {
        Box::new(Silent {
            captures: 0,
            silent_from: u32::MAX,
        })
    };
    // The switch answers at 0.0, 0.1, 0.2 s; against 0.25 s its reading is stale at 0.5 s.
    let s = statuses(fresh(), Some(0.25));
    assert!(matches!(s[4], LoopStatus::Running { .. }), "{s:?}");
    let stale_switch = |st: &LoopStatus| {
        matches!(
            st,
            LoopStatus::SafeStop {
                reason: StopReason::Stale {
                    input: InputKind::Sensor(0),
                    ..
                }
            }
        )
    };
    assert!(s[5..].iter().all(stale_switch), "{s:?}");
    // Not required: the same silence goes unchecked.
    let s = statuses(fresh(), None);
    assert!(s.iter().all(|st| matches!(st, LoopStatus::Running { .. })), "{s:?}");
    // A frame exposed a second before it was read is stale from the first tick.
    let s = statuses(Box::new(Buffered), None);
    assert!(
        s.iter().all(|st| matches!(
            st,
            LoopStatus::SafeStop {
                reason: StopReason::Stale {
                    input: InputKind::Camera(0),
                    ..
                }
            }
        )),
        "{s:?}"
    );
}
