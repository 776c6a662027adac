//! The `krawler` kind's leaves driven with scripted estimates and commands (no camera,
//! no simulator): the slip monitor against agreeing, stalled, over-spinning and
//! unmeasured wheels and against the encoders; the traverse's commands and timing; the
//! halt; each leaf's bad params named by field.

use marsupial::behaviors::catalog::memory;
use marsupial::behaviors::krawler::slip::{Reference, SlipMonitor, SlipParams};
use marsupial::behaviors::krawler::traverse::{Halt, Traverse, TraverseParams};
use marsupial::behaviors::krawler::{Krawler, KrawlerMemory};
use marsupial::geometry::{Pose2, Twist};
use marsupial::perception::krawler::Dof;
use marsupial::profile::Profile;
use marsupial::schemas::{
    Behavior, DriveCommand, FailureReason, Inputs, MotorOutput, OdometryReading, Outcome, Stamped, Status, Step,
};
use std::path::Path;

/// The shipped AutoKrawler's memory, its estimate to be scripted.
fn memory_of_the_shipped_krawler() -> KrawlerMemory {
    let p = Profile::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/autokrawler.toml")).unwrap();
    memory(&Krawler, &p).unwrap()
}

/// A fresh frame at which every wheel has turned `theta`, measured or not.
fn frame(m: &mut KrawlerMemory, t: f64, theta: f64, valid: bool) {
    m.percept.fresh = true;
    m.percept.stamp = t;
    m.percept.estimate.wheel = [Dof { value: theta, valid }; 4];
}

/// Runs the monitor 10 ticks a second for `seconds`, the wheels turning `optical`
/// rad/s with `commanded` rad/s commanded; the first tick that reports, if any.
fn run(
    mon: &mut SlipMonitor,
    m: &mut KrawlerMemory,
    seconds: f64,
    optical: f64,
    commanded: f64,
) -> Option<(f64, Step)> {
    for i in 0..(seconds * 10.0) as usize {
        let t = i as f64 / 10.0;
        frame(m, t, optical * t, true);
        m.commanded_rate = commanded;
        if let Some(s) = mon.tick(m, &Inputs::empty(t)) {
            return Some((t, s));
        }
    }
    None
}

fn monitor(reference: Reference) -> SlipMonitor {
    let params = SlipParams {
        threshold_rad: 0.3,
        window_s: 1.0,
        reference,
        min_measured: 0.5,
    };
    SlipMonitor::new(params).unwrap()
}

#[test]
fn agreeing_rotations_are_no_slip_and_their_figures_are_kept() {
    let mut m = memory_of_the_shipped_krawler();
    let mut mon = monitor(Reference::Command);
    assert!(run(&mut mon, &mut m, 5.0, 0.8, 0.8).is_none());
    assert!(!m.slip.slip && m.slip.t > 3.0, "{:?}", m.slip);
    assert!((m.slip.optical_rad - m.slip.reference_rad).abs() < 1e-9, "{:?}", m.slip);
    assert!((m.slip.optical_rad - 0.8).abs() < 1e-9);
}

#[test]
fn wheels_that_stall_under_a_command_are_a_slip_within_two_windows() {
    let mut m = memory_of_the_shipped_krawler();
    let mut mon = monitor(Reference::Command);
    let (t, step) = run(&mut mon, &mut m, 5.0, 0.0, 0.8).expect("a slip");
    assert!(t <= 2.0, "{t}");
    assert_eq!(step.status, Status::Event("slip"));
    assert_eq!(step.output, MotorOutput::stop());
    assert!(m.slip.slip && m.slip.optical_rad.abs() < 1e-9 && m.slip.reference_rad > 0.7);
    // Wheels that spin faster than told (a wheel lifted, the estimator confused) too.
    let mut mon = monitor(Reference::Command);
    assert!(run(&mut mon, &mut m, 5.0, 2.0, 0.8).is_some());
}

#[test]
fn unmeasured_windows_are_not_judged() {
    let mut m = memory_of_the_shipped_krawler();
    let mut mon = monitor(Reference::Command);
    for i in 0..50 {
        let t = i as f64 / 10.0;
        frame(&mut m, t, 0.0, false);
        m.commanded_rate = 1.0;
        assert!(mon.tick(&mut m, &Inputs::empty(t)).is_none());
    }
    assert!(!m.slip.slip && m.slip.measured == 0.0, "{:?}", m.slip);
}

#[test]
fn the_odometry_reference_reads_the_encoders_speed() {
    let mut m = memory_of_the_shipped_krawler();
    let r = m.wheel_radius;
    let mut mon = monitor(Reference::Odometry);
    for i in 0..30 {
        let t = i as f64 / 10.0;
        // Told nothing; the encoders say 0.1 m/s and the camera agrees.
        frame(&mut m, t, 0.1 / r * t, true);
        let odometry = Some(Stamped::new(
            t,
            OdometryReading {
                pose: Pose2::default(),
                twist: Twist::new(0.1, 0.0),
            },
        ));
        let inputs = Inputs {
            odometry,
            ..Inputs::empty(t)
        };
        assert!(mon.tick(&mut m, &inputs).is_none(), "t {t}");
    }
    assert!((m.slip.reference_rad - 0.1 / r).abs() < 1e-9, "{:?}", m.slip);
}

#[test]
fn slip_monitor_bad_params_name_their_field() {
    let p = |threshold_rad, window_s, min_measured| SlipParams {
        threshold_rad,
        window_s,
        reference: Reference::Command,
        min_measured,
    };
    let e = |p| SlipMonitor::new(p).err().unwrap();
    assert!(e(p(0.0, 1.0, 0.5)).starts_with("params.threshold_rad"));
    assert!(e(p(0.3, f64::NAN, 0.5)).starts_with("params.window_s"));
    assert!(e(p(0.3, 1.0, 1.5)).starts_with("params.min_measured"));
}

fn traverse(speed_mps: f64, turn_rate_dps: f64, duration_s: Option<f64>) -> Traverse {
    let params = TraverseParams {
        speed_mps,
        turn_rate_dps,
        duration_s,
    };
    Traverse::new(params).unwrap()
}

#[test]
fn traverse_commands_its_speed_and_says_the_wheel_rate_until_its_time_is_up() {
    let mut m = memory_of_the_shipped_krawler();
    let mut leaf = traverse(0.1, 0.0, Some(2.0));
    let s = leaf.tick(&mut m, &Inputs::empty(5.0)).unwrap();
    assert_eq!(s.output.drive, DriveCommand::Straight { v: 0.1 });
    assert_eq!(s.status, Status::Running);
    assert!((m.commanded_rate - 0.1 / 0.115).abs() < 1e-12);
    let s = leaf.tick(&mut m, &Inputs::empty(6.9)).unwrap();
    assert_eq!(s.status, Status::Running);
    let s = leaf.tick(&mut m, &Inputs::empty(7.0)).unwrap();
    assert_eq!(s.status, Status::Done(Outcome::Completed));
    assert_eq!((s.output, m.commanded_rate), (MotorOutput::stop(), 0.0));
    // Restarted, its clock starts again.
    leaf.reset();
    let s = leaf.tick(&mut m, &Inputs::empty(8.0)).unwrap();
    assert_eq!(s.status, Status::Running);
}

#[test]
fn a_turning_traverse_commands_a_twist() {
    let mut m = memory_of_the_shipped_krawler();
    let s = traverse(0.05, 10.0, None).tick(&mut m, &Inputs::empty(0.0)).unwrap();
    let DriveCommand::Twist(t) = s.output.drive else {
        panic!("{:?}", s.output.drive)
    };
    assert!((t.v - 0.05).abs() < 1e-12 && (t.omega - 10f64.to_radians()).abs() < 1e-12);
}

#[test]
fn halt_stops_and_ends_stuck() {
    let mut m = memory_of_the_shipped_krawler();
    m.commanded_rate = 1.0;
    let s = Halt.tick(&mut m, &Inputs::empty(1.0)).unwrap();
    assert_eq!(s.status, Status::Done(Outcome::Failed(FailureReason::StuckContact)));
    assert_eq!((s.output, m.commanded_rate), (MotorOutput::stop(), 0.0));
}

#[test]
fn traverse_bad_params_name_their_field() {
    let e = |v, w, d| {
        Traverse::new(TraverseParams {
            speed_mps: v,
            turn_rate_dps: w,
            duration_s: d,
        })
        .err()
        .unwrap()
    };
    assert!(e(f64::NAN, 0.0, None).starts_with("params.speed_mps"));
    assert!(e(0.1, f64::INFINITY, None).starts_with("params.turn_rate_dps"));
    assert!(e(0.1, 0.0, Some(-1.0)).starts_with("params.duration_s"));
}
