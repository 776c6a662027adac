//! Bujold's phase schemas driven one by one with scripted memory and inputs, without the
//! renderer: each ends with the event its profile transition expects, and only then.

use crate::common;

use marsupial::behaviors::bujold::Bujold;
use marsupial::behaviors::bujold::memory::{Memory, RepositionPlan};
use marsupial::behaviors::bujold::params::*;
use marsupial::behaviors::bujold::{approach, back_in, decide, departure};
use marsupial::behaviors::catalog;
use marsupial::behaviors::common::docking::{DockSwitch, Imprint, ImprintEnd};
use marsupial::behaviors::registry::Registry;
use marsupial::geometry::Pose2;
use marsupial::perception::RgbImage;
use marsupial::perception::two_block_pose::FiducialView;
use marsupial::schemas::{
    Agent, Behavior, CameraInput, DOCK_CONTACT_KIND, DriveCommand, FailureReason, Inputs, Mission, OdometryReading,
    Outcome, Posture, SensorInput, Stamped, Status, Step,
};

fn memory() -> Memory {
    catalog::memory(&Bujold, &common::shipped_profile("bujold")).unwrap()
}

/// The shipped profile's node `name` (a leaf or a whole phase), as the robot builds it.
fn node(name: &str) -> Box<dyn Behavior<Memory>> {
    let profile = common::shipped_profile("bujold");
    let mut registry = Registry::new();
    marsupial::behaviors::bujold::register(&mut registry);
    registry.build_node(&profile, name, &memory_of(&profile)).unwrap()
}

fn memory_of(profile: &marsupial::profile::Profile) -> Memory {
    catalog::memory(&Bujold, profile).unwrap()
}

/// The shipped search, turning at 0.4 rad/s and giving up after 40 s.
fn search() -> Box<dyn Behavior<Memory>> {
    let mut profile = common::shipped_profile("bujold");
    profile.behavior.search_timeout_s = 40.0;
    let mut m = memory_of(&profile);
    m.approach.steering.turn_rate = 0.4;
    let mut registry = Registry::new();
    marsupial::behaviors::bujold::register(&mut registry);
    registry.build_node(&profile, "search", &m).unwrap()
}

/// A view `d` m out, `alpha_deg` off the axis, with `px` pixels in both blocks.
fn view(d: f64, alpha_deg: f64, px: u64) -> FiducialView {
    FiducialView {
        distance: d,
        alpha: alpha_deg.to_radians(),
        asym: 0.0,
        offset_px: 0.0,
        bearing: 0.0,
        heading: 0.0,
        total_px: px,
        height_px: 50.0,
    }
}

/// Sets this tick's time, pose and view in memory (what the root's perception does), then
/// ticks `leaf`.
fn tick(leaf: &mut dyn Behavior<Memory>, mem: &mut Memory, now: f64, odo: Pose2, v: Option<FiducialView>) -> Step {
    mem.now = now;
    mem.odo = odo;
    mem.view = v;
    mem.planning = v;
    if v.is_some() {
        mem.last_seen = Some(now);
        mem.ever_seen = true;
    }
    let mut inputs = Inputs::empty(now);
    inputs.odometry = Some(Stamped::new(
        now,
        OdometryReading {
            pose: odo,
            ..Default::default()
        },
    ));
    leaf.tick(mem, &inputs).expect("a phase is always active")
}

fn enter(leaf: &mut dyn Behavior<Memory>, mem: &mut Memory, now: f64, odo: Pose2) {
    mem.now = now;
    mem.odo = odo;
    leaf.enter(mem, &Inputs::empty(now));
}

fn at(x: f64) -> Pose2 {
    Pose2::new(x, 0.0, 0.0)
}

#[test]
fn search_turns_toward_the_last_side_acquires_and_times_out_by_what_it_saw() {
    let mut mem = memory();
    let mut s = search();
    mem.last_side = -1.0; // the side is chosen as the search is entered
    enter(&mut *s, &mut mem, 0.0, at(1.0));
    let step = tick(&mut *s, &mut mem, 0.1, at(1.0), None);
    assert_eq!(step.status, Status::Running);
    assert_eq!(step.output.drive, DriveCommand::Turn { omega: -0.4 });
    // Acquisition hands over with the approach motor schema's command this very tick.
    let step = tick(&mut *s, &mut mem, 0.2, at(1.0), Some(view(1.0, 0.0, 800)));
    assert_eq!(step.status, Status::Event("acquired"));
    assert!(
        matches!(step.output.drive, DriveCommand::Straight { v } if v != 0.0),
        "{step:?}"
    );
    // Never seen: the timeout says so; seen before: the target was lost.
    let mut fresh = memory();
    let mut s = search();
    enter(&mut *s, &mut fresh, 0.0, at(1.0));
    assert_eq!(tick(&mut *s, &mut fresh, 39.9, at(1.0), None).status, Status::Running);
    let end = tick(&mut *s, &mut fresh, 40.1, at(1.0), None).status;
    assert_eq!(end, Status::Done(Outcome::Failed(FailureReason::TargetNeverDetected)));
    let mut s = search();
    enter(&mut *s, &mut mem, 50.0, at(1.0));
    let end = tick(&mut *s, &mut mem, 90.1, at(1.0), None).status;
    assert_eq!(end, Status::Done(Outcome::Failed(FailureReason::TargetLost)));
}

#[test]
fn search_is_jammed_when_turning_does_not_change_the_view() {
    let mut mem = memory();
    let mut s = search();
    enter(&mut *s, &mut mem, 0.0, at(1.0));
    let still = RgbImage::new(256, 240);
    let mut events = Vec::new();
    for k in 1..=30 {
        let now = k as f64 * 0.1;
        mem.now = now;
        let cams = [Some(CameraInput {
            stamp: now,
            image: still.view(),
        })];
        let mut inputs = Inputs::empty(now);
        inputs.cameras = &cams;
        events.push((now, s.tick(&mut mem, &inputs).unwrap().status));
    }
    // Still frames from the second on: jammed 1.5 s later; each jam turns the search the
    // other way, and after `max_unjams` (3) the search keeps turning.
    let jammed: Vec<f64> = events
        .iter()
        .filter(|e| e.1 == Status::Event("jammed"))
        .map(|e| e.0)
        .collect();
    assert_eq!(jammed.len(), 3, "{events:?}");
    assert!((jammed[0] - 1.7).abs() < 1e-9, "{jammed:?}");
    assert_eq!(events.last().unwrap().1, Status::Running);
    assert_eq!(mem.unjams, 3);
    assert_eq!(mem.last_side, -1.0);
}

#[test]
fn approach_signals_the_dock_a_lost_target_and_an_off_axis_view() {
    let mut mem = memory();
    let total = mem.approach.steering.dock_total_px;
    let mut a = approach::Approach::new(&mem, ApproachParams::default(), total).unwrap();
    enter(&mut a, &mut mem, 0.0, at(1.0));
    assert_eq!(
        tick(&mut a, &mut mem, 0.1, at(1.0), Some(view(1.0, 0.0, 900))).status,
        Status::Running
    );
    let step = tick(&mut a, &mut mem, 0.2, at(0.4), Some(view(0.38, 0.0, total as u64)));
    assert_eq!(step.status, Status::Event("at_dock"));
    // Out of sight: hold for 1.5 s, then back to search.
    assert_eq!(tick(&mut a, &mut mem, 1.0, at(0.4), None).status, Status::Running);
    assert_eq!(tick(&mut a, &mut mem, 1.8, at(0.4), None).status, Status::Event("lost"));
    // A full window of reliable frames 12° off the axis at 0.8 m is 17 cm off it.
    for _ in 0..16 {
        mem.alpha_window.push(12f64.to_radians());
    }
    let step = tick(&mut a, &mut mem, 2.0, at(0.8), Some(view(0.8, 12.0, 1500)));
    assert_eq!(step.status, Status::Event("off_axis"));
    assert_eq!(mem.retries.used(), 1);
    assert!(mem.plan.is_some());
}

#[test]
fn decide_backs_in_aligned_retries_misaligned_and_gives_up_when_out_of_retries() {
    let mut mem = memory();
    let new = || decide::Decide::new(DecideParams::default(), 0.02, 5f64.to_radians());
    let mut d = new();
    enter(&mut d, &mut mem, 0.0, at(0.4));
    for k in 1..5 {
        let s = tick(&mut d, &mut mem, k as f64 * 0.1, at(0.4), Some(view(0.38, 0.2, 4600)));
        assert_eq!(s.status, Status::Running);
    }
    let s = tick(&mut d, &mut mem, 0.5, at(0.4), Some(view(0.38, 0.2, 4600)));
    assert_eq!(s.status, Status::Event("aligned"));
    assert_eq!(s.output.aux.get::<Posture>(), Some(Posture::Lowered));
    // 5° off at 0.38 m: reposition (a retry), then out of retries: give up.
    for (retries_before, expected) in [(0, "misaligned"), (1, "retries_exhausted")] {
        mem.retries = common::retries(1, retries_before);
        enter(&mut d, &mut mem, 1.0, at(0.4));
        let mut last = None;
        for k in 1..=5 {
            last = Some(tick(
                &mut d,
                &mut mem,
                1.0 + k as f64 * 0.1,
                at(0.4),
                Some(view(0.38, 5.0, 4600)),
            ));
        }
        assert_eq!(last.unwrap().status, Status::Event(expected));
    }
    assert_eq!(mem.failing, Some(FailureReason::RetriesExhausted));
    // Too few views within 3 s: lost at the gate.
    enter(&mut d, &mut mem, 10.0, at(0.4));
    assert_eq!(tick(&mut d, &mut mem, 12.9, at(0.4), None).status, Status::Running);
    assert_eq!(
        tick(&mut d, &mut mem, 13.1, at(0.4), None).status,
        Status::Event("lost")
    );
}

#[test]
fn back_in_drives_blind_and_lowered_then_reports_the_miss() {
    let mut mem = memory();
    mem.samples_distance = 0.38;
    let mut b = back_in::BackIn::new(BackInParams::default(), 0.30);
    enter(&mut b, &mut mem, 0.0, at(0.4));
    let s = tick(&mut b, &mut mem, 0.1, at(0.35), None);
    assert_eq!(s.output.aux.get::<Posture>(), Some(Posture::Lowered));
    assert!(matches!(s.output.drive, DriveCommand::Straight { .. }));
    let s = tick(&mut b, &mut mem, 20.0, at(-0.5), None);
    assert_eq!(s.status, Status::Event("missed"));
    assert_eq!(mem.failing, Some(FailureReason::FailedToControl));
}

#[test]
fn reposition_turns_drives_and_turns_to_the_staging_pose() {
    let mut mem = memory();
    let target = Pose2::new(0.75, 0.0, 0.0);
    mem.plan = Some(RepositionPlan {
        target,
        clear_first: false,
    });
    mem.alpha_window.push(0.3);
    let mut r = node("reposition");
    let r = &mut *r;
    let start = Pose2::new(0.75, 0.4, 0.0);
    enter(r, &mut mem, 0.0, start);
    // Facing along x with the target to the right: turn first.
    let s = tick(r, &mut mem, 0.1, start, None);
    assert!(
        matches!(s.output.drive, DriveCommand::Turn { omega } if omega < 0.0),
        "{s:?}"
    );
    // Facing it: the stage changes, then it drives.
    let facing = Pose2::new(0.75, 0.4, -std::f64::consts::FRAC_PI_2);
    assert_eq!(tick(r, &mut mem, 0.2, facing, None).status, Status::Running);
    let s = tick(r, &mut mem, 0.3, facing, None);
    assert!(
        matches!(s.output.drive, DriveCommand::Straight { v } if v > 0.0),
        "{s:?}"
    );
    // Arrived, facing the wrong way: turn to the staging heading, then done.
    let there = Pose2::new(0.75, 0.0, -std::f64::consts::FRAC_PI_2);
    tick(r, &mut mem, 0.4, there, None);
    let s = tick(r, &mut mem, 0.5, there, None);
    assert!(
        matches!(s.output.drive, DriveCommand::Turn { omega } if omega > 0.0),
        "{s:?}"
    );
    let s = tick(r, &mut mem, 0.6, target, None);
    assert_eq!(
        s.status,
        Status::Event("aligned"),
        "the sequence hands `aligned` to the close dock"
    );
    assert!(!mem.alpha_window.is_full() && mem.alpha_window.median().is_none());
}

#[test]
fn move_away_retries_and_give_up_fails_with_the_reason_left_in_memory() {
    let mut mem = memory();
    for (give_up, failing, expected) in [
        (false, None, Status::Event("done")),
        (true, None, Status::Done(Outcome::Failed(FailureReason::Timeout))),
        (
            true,
            Some(FailureReason::FailedToControl),
            Status::Done(Outcome::Failed(FailureReason::FailedToControl)),
        ),
    ] {
        mem.failing = failing;
        let mut m = node(if give_up { "give_up" } else { "move_away" });
        enter(&mut *m, &mut mem, 0.0, at(0.4));
        assert_eq!(tick(&mut *m, &mut mem, 0.1, at(0.5), None).status, Status::Running);
        assert_eq!(tick(&mut *m, &mut mem, 6.0, at(0.76), None).status, expected);
    }
}

#[test]
fn departure_undocks_imprints_once_and_fails_without_an_imprint() {
    let mut mem = memory();
    let mut u = departure::Undock::new(UndockParams::default(), 0.30);
    enter(&mut u, &mut mem, 0.0, at(-0.2));
    let s = tick(&mut u, &mut mem, 0.1, at(-0.1), None);
    assert_eq!(
        (s.status, s.output.aux.get::<Posture>()),
        (Status::Running, Some(Posture::Lowered))
    );
    assert_eq!(tick(&mut u, &mut mem, 5.0, at(0.16), None).status, Status::Event("out"));
    let mut d = departure::DriveOut::new(DriveOutParams::default(), 0.6);
    enter(&mut d, &mut mem, 5.0, at(0.16));
    assert_eq!(tick(&mut d, &mut mem, 6.0, at(0.3), None).status, Status::Running);
    assert_eq!(
        tick(&mut d, &mut mem, 9.0, at(0.41), None).status,
        Status::Event("imprint")
    );
    // The imprint (here on no frames) failed: imprinting is tried again.
    let mut i = Imprint::new(0, 2, ImprintEnd::Event("imprinted"));
    enter(&mut i, &mut mem, 9.0, at(0.41));
    assert_eq!(tick(&mut i, &mut mem, 9.1, at(0.41), None).status, Status::Running);
    assert_eq!(
        tick(&mut i, &mut mem, 9.2, at(0.41), None).status,
        Status::Event("imprinted")
    );
    assert!(!mem.imprinted);
    assert_eq!(
        tick(&mut d, &mut mem, 9.3, at(0.41), None).status,
        Status::Event("imprint")
    );
    // Imprinted: on out, and done at the departure distance.
    mem.imprinted = true;
    assert_eq!(tick(&mut d, &mut mem, 12.0, at(0.6), None).status, Status::Running);
    assert_eq!(
        tick(&mut d, &mut mem, 20.0, at(1.1), None).status,
        Status::Done(Outcome::Completed)
    );
    // An imprint distance beyond the departure's: it ends without imprinting, and says so.
    mem.imprinted = false;
    let mut far = departure::DriveOut::new(DriveOutParams::default(), 2.0);
    let end = tick(&mut far, &mut mem, 20.0, at(1.1), None).status;
    assert_eq!(end, Status::Done(Outcome::Failed(FailureReason::TargetNeverDetected)));
}

#[test]
fn the_dock_switch_is_released_only_by_contact() {
    let mut mem = memory();
    let mut c = DockSwitch;
    assert!(c.tick(&mut mem, &Inputs::empty(0.0)).is_none());
    let mut inputs = Inputs::empty(0.1);
    let sensors = [Some(SensorInput {
        kind: DOCK_CONTACT_KIND,
        stamp: 0.1,
        values: &[1.0],
    })];
    inputs.sensors = &sensors;
    let s = c.tick(&mut mem, &inputs).unwrap();
    assert_eq!(s.status, Status::Done(Outcome::Docked));
    assert_eq!(s.output.aux.get::<Posture>(), Some(Posture::Lowered));
}

/// A dock hint drives to the approach zone first (the ballistic states) unless the
/// mission says the robot is already staged (Nav2's `navigate_to_staging_pose = false`).
#[test]
fn a_staged_docking_skips_the_ballistic_leg() {
    let p = common::shipped_profile("bujold");
    let hint = Pose2::new(-3.0, 0.5, 0.2);
    let first_phase = |mission: Mission| {
        let mut robot = catalog::shipped().compose(&Bujold, &p).unwrap();
        robot.begin(&mission).unwrap();
        let mut inputs = Inputs::empty(0.0);
        inputs.odometry = Some(Stamped::new(0.0, OdometryReading::default()));
        robot
            .tick_perceived(&inputs, |m| m.perceive(&inputs))
            .unwrap()
            .feedback
            .phase
    };
    assert!(first_phase(Mission::docking_at(hint)).starts_with("ballistic"));
    let staged = Mission::Docking {
        dock_hint: Some(hint),
        stage: false,
    };
    assert_eq!(first_phase(staged), "search");
    assert_eq!(first_phase(Mission::docking()), "search");
}
