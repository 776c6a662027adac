//! Axel's sense-plan-act cycle as the shipped profile declares it (a sequence of
//! `axel.settle` → the phase's look → `axel.step` → `axel.settle`), driven tick by tick
//! with scripted sightings and odometry, without the renderer: the rover stands still
//! while it settles and looks, perception runs only while it looks, one look drives one
//! motion, and the phase's counts and clock span its cycles.

use crate::common;

use marsupial::behaviors::axel::Axel;
use marsupial::behaviors::axel::memory::{Memory, Sighting};
use marsupial::behaviors::catalog;
use marsupial::behaviors::registry::Registry;
use marsupial::geometry::Pose2;
use marsupial::perception::circles::PoseSource;
use marsupial::profile::Profile;
use marsupial::schemas::{Behavior, DriveCommand, FailureReason, Inputs, Outcome, Status, Step};
use std::f64::consts::PI;

const DT: f64 = 0.2;

fn profile(search_timeout_s: f64) -> Profile {
    let mut p = common::shipped_profile("axel");
    p.behavior.search_timeout_s = search_timeout_s;
    p
}

/// The shipped profile's node `name` (a phase: the whole cycle) and a memory for it.
fn phase(p: &Profile, name: &str) -> (Box<dyn Behavior<Memory>>, Memory) {
    let mut registry = Registry::new();
    marsupial::behaviors::axel::register(&mut registry);
    let m = catalog::memory(&Axel, p).unwrap();
    (registry.build_node(p, name, &m).unwrap(), m)
}

fn inputs(now: f64, odo: Pose2) -> Inputs<'static> {
    common::odometry_inputs(now, odo)
}

/// Sets this tick's time and pose in memory (what the root's perception does), then
/// ticks `node`.
fn tick(node: &mut dyn Behavior<Memory>, m: &mut Memory, now: f64, odo: Pose2) -> Step {
    m.now = now;
    m.odo = odo;
    node.tick(m, &inputs(now, odo)).expect("a phase is always active")
}

fn stopped(s: &Step) -> bool {
    matches!(s.output.drive, DriveCommand::Stop)
}

/// Ticks `node` standing at `odo` from t = 0 until it ends the docking (stopped), before
/// `deadline` s: the outcome and when.
fn until_done(node: &mut dyn Behavior<Memory>, m: &mut Memory, odo: Pose2, deadline: f64) -> (Outcome, f64) {
    let mut t = 0.0;
    loop {
        t += DT;
        let s = tick(node, m, t, odo);
        if let Status::Done(o) = s.status {
            assert!(stopped(&s), "{s:?}");
            return (o, t);
        }
        assert!(t < deadline, "{s:?} at {t}");
    }
}

/// A trusted stereo sighting at `t` of the rover at module-frame `pose`.
fn sighting(t: f64, pose: Pose2) -> Sighting {
    Sighting {
        t,
        pose,
        source: PoseSource::Stereo,
        marks: 8,
        reprojection_px: 0.1,
        residual_m: 0.001,
    }
}

#[test]
fn one_look_drives_one_arc_then_the_rover_settles_and_looks_again() {
    let p = profile(60.0);
    let (mut node, mut m) = phase(&p, "approach");
    let mut odo = Pose2::default();
    node.enter(&mut m, &inputs(0.0, odo));
    // Settling: stopped, not looking, for settle_s (0.6 s).
    let mut t = 0.0;
    while !m.looking {
        t += DT;
        let s = tick(node.as_mut(), &mut m, t, odo);
        assert!(stopped(&s) && s.feedback.phase == "approach", "{s:?}");
        assert!(t < 0.7 + 1e-9, "still settling at {t}");
    }
    assert!(t >= 0.6 - 1e-9, "looked after {t} s");
    // Looking, stopped, until a trusted pose arrives: 3.6 m out, 0.4 m aside.
    t += DT;
    assert!(stopped(&tick(node.as_mut(), &mut m, t, odo)));
    m.sighting = Some(sighting(t, Pose2::new(3.6, 0.4, PI)));
    t += DT;
    let first = tick(node.as_mut(), &mut m, t, odo);
    let DriveCommand::Twist(twist) = first.output.drive else {
        panic!("the look starts the arc at once: {first:?}");
    };
    assert!(twist.v > 0.0, "{twist:?}");
    assert_eq!(m.arcs, 1);
    assert!(!m.looking, "no perception while driving");
    assert!(m.step.is_none(), "the step leg took the motion");
    // The step leg drives that arc (odometry following the command exactly), then stops.
    let mut driven = 0;
    loop {
        odo = odo.compose(&Pose2::new(twist.v * DT, 0.0, twist.omega * DT));
        t += DT;
        let s = tick(node.as_mut(), &mut m, t, odo);
        assert!(!m.looking);
        if stopped(&s) {
            break;
        }
        assert_eq!(s.output.drive, DriveCommand::Twist(twist));
        driven += 1;
        assert!(driven < 200, "the arc never ended");
    }
    // One arc step is at most step_m (1.5 m) of path.
    let path = twist.v * DT * (driven + 1) as f64;
    assert!(path <= 1.5 + twist.v * DT + 1e-9, "drove {path} m");
    // Settle again, then look again: one motion per look.
    let stop_at = t;
    while !m.looking {
        t += DT;
        assert!(stopped(&tick(node.as_mut(), &mut m, t, odo)));
    }
    assert!((t - stop_at - 0.6).abs() < DT + 1e-9, "settled {} s", t - stop_at);
    assert_eq!(m.arcs, 1);
}

#[test]
fn looks_without_a_trusted_pose_are_counted_across_cycles_until_lost() {
    let p = profile(600.0);
    let (mut node, mut m) = phase(&p, "approach");
    let odo = Pose2::default();
    node.enter(&mut m, &inputs(0.0, odo));
    let mut t = 0.0;
    let lost = loop {
        t += DT;
        let s = tick(node.as_mut(), &mut m, t, odo);
        if let Status::Event(e) = s.status {
            break (e, t);
        }
        assert!(s.status == Status::Running && t < 30.0, "{s:?} at {t}");
    };
    // `lost_looks = 3` looks of up to look_s (1.2 s), each after a settle (0.6 s).
    assert_eq!(lost.0, "lost");
    assert!(
        lost.1 > 3.0 * 1.8 - 1e-9 && lost.1 < 3.0 * 1.8 + 4.0 * DT,
        "lost at {}",
        lost.1
    );
    assert_eq!(m.looks.unseen, 3);
    assert_eq!(m.arcs, 0);
}

#[test]
fn the_search_gives_up_on_its_clock_in_whichever_leg_is_running() {
    for limit in [2.0, 2.5, 3.1, 4.0] {
        let p = profile(limit);
        let (mut node, mut m) = phase(&p, "acquire");
        let odo = Pose2::default();
        node.enter(&mut m, &inputs(0.0, odo));
        let end = until_done(node.as_mut(), &mut m, odo, limit + 1.0);
        assert_eq!(end.0, Outcome::Failed(FailureReason::TargetNeverDetected));
        assert!(
            end.1 > limit && end.1 <= limit + DT + 1e-9,
            "limit {limit}: failed at {}",
            end.1
        );
    }
}

#[test]
fn a_fix_seen_before_makes_the_searchs_failure_target_lost() {
    let p = profile(2.0);
    let (mut node, mut m) = phase(&p, "acquire");
    let odo = Pose2::default();
    node.enter(&mut m, &inputs(0.0, odo));
    m.fix(&sighting(0.0, Pose2::new(3.0, 0.0, PI)));
    let (outcome, _) = until_done(node.as_mut(), &mut m, odo, 5.0);
    assert_eq!(outcome, Outcome::Failed(FailureReason::TargetLost));
}
