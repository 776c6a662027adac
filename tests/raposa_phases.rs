//! RAPOSA's phase schemas driven one by one with scripted percepts in memory, without the
//! renderer: each commands what its state's law says and ends with the event its profile
//! transition expects, and only then; the seven-state selector maps percepts to the
//! servo's states, with the look special case.

use crate::common;

use marsupial::arbiter::Selector;
use marsupial::behaviors::SharedMemory;
use marsupial::behaviors::catalog;
use marsupial::behaviors::common::docking::{DockSwitch, Imprint, ImprintEnd};
use marsupial::behaviors::raposa::Raposa;
use marsupial::behaviors::raposa::memory::Memory;
use marsupial::behaviors::raposa::params::*;
use marsupial::behaviors::raposa::region2::{plan, robot_in_ball_frame};
use marsupial::behaviors::raposa::selector::SevenState;
use marsupial::behaviors::raposa::{ServoState, align, departure, final_approach, rotate7, servo};
use marsupial::behaviors::registry::{Registry, SelectorArgs};
use marsupial::geometry::{Pose2, Twist};
use marsupial::perception::{BlueRegion, Ellipse, PyramidDetection, PyramidPercept, PyramidView};
use marsupial::profile::tree::NodeSpec;
use marsupial::profile::{Profile, SegmentationMode};
use marsupial::schemas::{
    ArmPosition, Behavior, DOCK_CONTACT_KIND, DriveCommand, FailureReason, Guides, Inputs, Lights, Mission,
    MissionError, Outcome, SensorInput, Status, Step,
};

fn profile() -> Profile {
    common::shipped_profile("raposa")
}

fn memory() -> Memory {
    catalog::memory(&Raposa, &profile()).unwrap()
}

/// The shipped profile's leaf `name` as the robot builds it, with `params` replaced and
/// a 60 s search timeout.
fn node(name: &str, params: &[(&str, toml::Value)]) -> Box<dyn Behavior<Memory>> {
    let mut p = profile();
    p.behavior.search_timeout_s = 60.0;
    let tree = p.behavior.tree.as_mut().unwrap();
    if let Some(NodeSpec::Leaf { params: table, .. }) = tree.nodes.get_mut(name) {
        for (k, v) in params {
            table.insert((*k).into(), v.clone());
        }
    }
    let mut registry = Registry::new();
    marsupial::behaviors::raposa::register(&mut registry);
    registry
        .build_node(&p, name, &catalog::memory(&Raposa, &p).unwrap())
        .unwrap()
}

/// What the pyramid schema would report: an ellipse `d` m away (with a pair when
/// `alpha_deg` is given) `dev` px off the image centre, and/or the blue edges.
fn seen(d: f64, alpha_deg: Option<f64>, dev: [f64; 2], blue: bool) -> PyramidPercept {
    let mut p = nothing();
    p.detection.ellipse = Some(Ellipse {
        centre: [80.0 + dev[0], 60.0 + dev[1]],
        semi_major: 5.0,
        semi_minor: 5.0,
        angle: 0.0,
        count: 80,
        bbox: [75, 55, 85, 65],
    });
    p.detection.blue = blue.then(|| blue_at(80));
    p.view = Some(PyramidView {
        blue_distance_m: alpha_deg.map(|_| d + 0.16),
        ball_distance_m: d,
        alpha: alpha_deg.map(f64::to_radians),
        alpha_saturated: false,
        bearing: 0.0,
        dev_px: dev,
        // The ball's area at `d` (7 cm at f ≈ 361 px).
        area_px: (std::f64::consts::PI * (361.0 * 0.035 / d).powi(2)) as u64,
    });
    p
}

/// Blue edges alone, centred at column `x` (pixel centre `x + 0.5`).
fn blue_at(x: u32) -> BlueRegion {
    BlueRegion {
        bbox: [x - 10, 50, x + 9, 70],
        count: 100,
    }
}

fn nothing() -> PyramidPercept {
    let mut p = PyramidPercept::not_found(0.0, (160, 120));
    p.detection = PyramidDetection {
        pair: None,
        ellipse: None,
        blue: None,
        candidates: 0,
    };
    p
}

fn inputs(now: f64, odo: Pose2) -> Inputs<'static> {
    common::odometry_inputs(now, odo)
}

/// Sets this tick's time, pose and percept in memory (what the root's perception does),
/// then ticks `leaf`.
fn tick(leaf: &mut dyn Behavior<Memory>, mem: &mut Memory, now: f64, odo: Pose2, p: PyramidPercept) -> Step {
    mem.now = now;
    mem.odo = odo;
    mem.percept = p;
    leaf.tick(mem, &inputs(now, odo)).expect("a phase is always active")
}

/// Enters `leaf` at `now`, `odo`, with percept `p` in memory.
fn enter(leaf: &mut dyn Behavior<Memory>, mem: &mut Memory, now: f64, odo: Pose2, p: PyramidPercept) {
    mem.now = now;
    mem.odo = odo;
    mem.percept = p;
    leaf.enter(mem, &inputs(now, odo));
}

fn twist(s: &Step) -> Twist {
    match s.output.drive {
        DriveCommand::Twist(t) => t,
        DriveCommand::Stop => Twist::new(0.0, 0.0),
        other => panic!("expected a twist, got {other:?}"),
    }
}

fn turn_rate(s: &Step) -> f64 {
    match s.output.drive {
        DriveCommand::Turn { omega } => omega,
        DriveCommand::Twist(t) if t.v == 0.0 => t.omega,
        other => panic!("expected a turn, got {other:?}"),
    }
}

fn at(x: f64) -> Pose2 {
    Pose2::new(x, 0.0, 0.0)
}

#[test]
fn servo_states_steer_on_what_they_see() {
    let mut mem = memory();
    let g = marsupial::behaviors::catalog::tuning::<marsupial::behaviors::raposa::Raposa>(&profile())
        .unwrap()
        .seven_state;
    // State 1 near the pyramid: slower than the far speed, turning against x_dev; the
    // camera looks back, so "toward the pyramid" is body-backward.
    let mut s1 = servo::Approach;
    let step = tick(&mut s1, &mut mem, 0.1, at(1.0), seen(0.6, Some(5.0), [20.0, 0.0], true));
    assert_eq!(step.status, Status::Running);
    let t = twist(&step);
    assert!(t.v < 0.0 && -t.v < g.far_speed_mps, "{t:?}");
    assert!((t.omega - -g.k_ang * 20.0).abs() < 1e-12, "{t:?}");
    // State 3: a lone ellipse far away, at the far speed.
    let mut s3 = servo::FarEllipse;
    let t = twist(&tick(
        &mut s3,
        &mut mem,
        0.2,
        at(1.0),
        seen(2.0, None, [0.0, 0.0], false),
    ));
    assert_eq!(t.v, -g.far_speed_mps);
    // Without an ellipse both stand still.
    assert_eq!(
        tick(&mut s1, &mut mem, 0.3, at(1.0), nothing()).output.drive,
        DriveCommand::Stop
    );
    // State 4: turn toward the blue edges; creep only within `centred_px` of the centre.
    let mut s4 = servo::BlueOnly::new(BlueOnlyParams::default());
    let mut blue = nothing();
    blue.detection.blue = Some(blue_at(80));
    let t = twist(&tick(&mut s4, &mut mem, 0.4, at(1.0), blue));
    assert_eq!((t.v, t.omega), (-g.final_speed_mps, 0.0), "centred: creep straight");
    blue.detection.blue = Some(blue_at(100));
    let t = twist(&tick(&mut s4, &mut mem, 0.5, at(1.0), blue));
    assert_eq!(t.v, 0.0, "20 px off: turn only");
    assert!((t.omega - -g.k_ang * 20.0).abs() < 1e-12);
    let wide = BlueOnlyParams { centred_px: 30.0 };
    let mut s4 = servo::BlueOnly::new(wide);
    assert_eq!(
        twist(&tick(&mut s4, &mut mem, 0.6, at(1.0), blue)).v,
        -g.final_speed_mps
    );
}

#[test]
fn search_waits_its_grace_frames_turns_away_from_the_last_turn_and_times_out() {
    let mut mem = memory();
    let mut s = node("search", &[]);
    let s = &mut *s;
    mem.last_turn = 1.0;
    enter(s, &mut mem, 0.0, at(1.0), nothing());
    for k in 1..=3 {
        let step = tick(s, &mut mem, k as f64 * 0.1, at(1.0), nothing());
        assert_eq!(step.output.drive, DriveCommand::Stop, "grace frame {k}");
    }
    let step = tick(s, &mut mem, 0.4, at(1.0), nothing());
    assert!(turn_rate(&step) < 0.0, "away from the last (left) turn: {step:?}");
    assert_eq!(mem.search_start, Some(0.4));
    assert_eq!(tick(s, &mut mem, 60.4, at(1.0), nothing()).status, Status::Running);
    assert_eq!(
        tick(s, &mut mem, 60.5, at(1.0), nothing()).status,
        Status::Done(Outcome::Failed(FailureReason::TargetLost))
    );
    // Five grace frames: still standing on the fourth.
    let mut mem = memory();
    let mut s = node("search", &[("grace_frames", 5.into())]);
    for k in 1..=4 {
        tick(&mut *s, &mut mem, k as f64 * 0.1, at(1.0), nothing());
    }
    assert_eq!(mem.unseen, 4);
    assert_eq!(mem.search_start, None);
}

#[test]
fn align_plans_counts_and_hands_over_already_turning() {
    let mut mem = memory();
    mem.settling = true;
    let mut a = align::Align;
    // No pair, no plan.
    let step = tick(&mut a, &mut mem, 0.1, at(1.0), seen(1.5, None, [0.0, 0.0], false));
    assert_eq!(step.status, Status::Running);
    assert_eq!(mem.manoeuvres, 0);
    let p = seen(1.5, Some(40.0), [0.0, 0.0], true);
    let step = tick(&mut a, &mut mem, 0.2, at(1.0), p);
    assert_eq!(step.status, Status::Event("planned"));
    let m = &mem;
    let pl = m.plan.expect("the plan is in memory for region II");
    let expected = plan(
        robot_in_ball_frame(&p.view.unwrap(), 40f64.to_radians(), m.camera_x),
        m.gains.region2_distance_m,
        m.half_length,
    );
    assert_eq!(pl, expected);
    assert_eq!((m.manoeuvres, m.settling), (1, false));
    let omega = twist(&step).omega;
    assert_eq!(omega, m.vision_turn * pl.rotation.signum());
    assert_eq!(m.last_turn, pl.rotation.signum());
}

/// A memory holding a plan that turns `rotation_deg` first.
fn planned(rotation_deg: f64) -> Memory {
    let mut mem = memory();
    let mut pl = plan(Pose2::new(1.5, 0.5, 0.0), 0.9, 0.4);
    pl.rotation = rotation_deg.to_radians();
    mem.plan = Some(pl);
    mem
}

fn at_bearing(bearing: f64, dev_x: f64) -> PyramidPercept {
    let mut p = seen(1.5, Some(30.0), [dev_x, 0.0], true);
    p.view.as_mut().unwrap().bearing = bearing;
    p
}

#[test]
fn rotate_7_measures_the_rotation_by_vision_and_resets_the_odometry_frame() {
    let mut mem = planned(17.0);
    let mut r = rotate7::Rotate7::default();
    enter(&mut r, &mut mem, 0.0, at(1.0), at_bearing(0.0, 0.0));
    // 0.05 rad per frame toward a 17° (0.297 rad) goal, tolerance 2°: the predictor stops
    // at 0.25 rad turned (next frame would reach 0.30).
    let mut events = Vec::new();
    for k in 1..=6 {
        let step = tick(
            &mut r,
            &mut mem,
            k as f64 * 0.1,
            at(1.0),
            at_bearing(-0.05 * k as f64, 0.0),
        );
        events.push(step.status);
        if step.status != Status::Running {
            assert_eq!(step.output.drive, DriveCommand::Stop);
            break;
        }
        assert!(turn_rate(&step) > 0.0);
    }
    assert_eq!(events.len(), 5, "{events:?}");
    assert_eq!(*events.last().unwrap(), Status::Event("rotated"));
    // The manoeuvre's frame: the robot's planned start, turned by what vision measured,
    // sits at this tick's odometry pose.
    let m = &mem;
    let pl = m.plan.unwrap();
    let start = Pose2::new(pl.start.x, pl.start.y, pl.start.theta + 0.25);
    let here = m.map.compose(&start);
    assert!(
        (here.x - 1.0).abs() < 1e-9 && here.y.abs() < 1e-9 && here.theta.abs() < 1e-9,
        "{here:?}"
    );
}

#[test]
fn rotate_7_stops_before_the_image_edge_and_gives_up_when_lost() {
    let mut mem = planned(40.0);
    let mut r = rotate7::Rotate7::default();
    enter(&mut r, &mut mem, 0.0, at(1.0), at_bearing(0.0, 50.0));
    // 0.05 rad is 18 px at f = 361 px: 50 + 18 passes 80 − 10 px.
    assert_eq!(
        tick(&mut r, &mut mem, 0.1, at(1.0), at_bearing(-0.05, 55.0)).status,
        Status::Event("edge")
    );
    // Lost: stand still; the event comes on the `lost_frames`-th frame without it.
    let lost_frames = mem.gains.lost_frames;
    enter(&mut r, &mut mem, 1.0, at(1.0), at_bearing(0.0, 0.0));
    for k in 1..lost_frames {
        let step = tick(&mut r, &mut mem, 1.0 + k as f64 * 0.1, at(1.0), nothing());
        assert_eq!((step.status, step.output.drive), (Status::Running, DriveCommand::Stop));
    }
    assert_eq!(
        tick(&mut r, &mut mem, 2.0, at(1.0), nothing()).status,
        Status::Event("lost")
    );
}

#[test]
fn the_blind_manoeuvre_turns_travels_and_faces_the_ball_by_odometry() {
    let mut mem = memory();
    let pl = plan(Pose2::new(1.5, 0.8, 0.0), 0.9, 0.4);
    mem.plan = Some(pl);
    mem.map = Pose2::default();
    let mut rot = node("rotate_odo", &[]);
    let rot = &mut *rot;
    enter(rot, &mut mem, 0.0, Pose2::new(1.5, 0.8, 0.0), nothing());
    assert!(mem.blind, "entering the blind part tells the perception");
    let step = tick(rot, &mut mem, 0.1, Pose2::new(1.5, 0.8, 0.0), nothing());
    assert_eq!(step.status, Status::Running);
    assert_eq!(turn_rate(&step).signum(), pl.rotation.signum());
    let facing = Pose2::new(1.5, 0.8, pl.travel_heading);
    assert_eq!(
        tick(rot, &mut mem, 0.2, facing, nothing()).status,
        Status::Event("rotated")
    );
    let mut travel = node("travel", &[]);
    let travel = &mut *travel;
    enter(travel, &mut mem, 0.2, facing, nothing());
    let step = tick(travel, &mut mem, 0.3, facing, nothing());
    assert!(twist(&step).v != 0.0, "{step:?}");
    let arrived = Pose2::new(pl.target.0, pl.target.1, pl.travel_heading);
    assert_eq!(
        tick(travel, &mut mem, 0.4, arrived, nothing()).status,
        Status::Event("arrived")
    );
    // φ: the ball is at the frame's origin; the camera looks back, so the body faces +x.
    let mut phi = node("rotate_phi", &[]);
    let phi = &mut *phi;
    enter(phi, &mut mem, 0.4, arrived, nothing());
    assert!(turn_rate(&tick(phi, &mut mem, 0.5, arrived, nothing())) != 0.0);
    let done = tick(phi, &mut mem, 0.6, Pose2::new(pl.target.0, 0.0, 0.01), nothing());
    assert_eq!(done.status, Status::Event("facing"));
    assert_eq!(done.output.drive, DriveCommand::Stop);
}

#[test]
fn look_clears_blind_settles_then_searches_away_from_the_last_turn() {
    let mut mem = memory();
    mem.blind = true;
    mem.last_turn = 1.0;
    let mut look = node("look", &[]);
    let look = &mut *look;
    enter(look, &mut mem, 10.0, at(1.0), nothing());
    assert!(!mem.blind);
    mem.last_turn = -1.0; // later turns do not change the first direction
    assert_eq!(
        tick(look, &mut mem, 10.4, at(1.0), nothing()).output.drive,
        DriveCommand::Stop
    );
    assert!(turn_rate(&tick(look, &mut mem, 10.6, at(1.0), nothing())) < 0.0);
    assert_eq!(
        tick(look, &mut mem, 70.1, at(1.0), nothing()).status,
        Status::Done(Outcome::Failed(FailureReason::TargetLost))
    );
    let mut slow = node("look", &[("settle_s", 2.0.into())]);
    let slow = &mut *slow;
    enter(slow, &mut mem, 0.0, at(1.0), nothing());
    assert_eq!(
        tick(slow, &mut mem, 1.9, at(1.0), nothing()).output.drive,
        DriveCommand::Stop
    );
}

#[test]
fn final_runs_the_state_1_law_once_then_creeps_and_retries() {
    let mut mem = memory();
    let g = marsupial::behaviors::catalog::tuning::<marsupial::behaviors::raposa::Raposa>(&profile())
        .unwrap()
        .seven_state;
    mem.retries = common::retries(3, 0);
    let mut f = final_approach::FinalApproach::new(Default::default());
    let near = seen(0.28, Some(3.0), [4.0, 10.0], true);
    enter(&mut f, &mut mem, 5.0, at(0.5), near);
    let aux = mem.aux;
    assert_eq!(aux.get::<ArmPosition>(), Some(ArmPosition(-g.k_arm * 10.0)));
    assert_eq!(aux.get::<Lights>(), Some(Lights(true)));
    let first = tick(&mut f, &mut mem, 5.0, at(0.5), near);
    let mut approach = servo::Approach;
    assert_eq!(first.output, tick(&mut approach, &mut mem, 5.0, at(0.5), near).output);
    assert_eq!(first.output.aux.get::<Lights>(), Some(Lights(true)));
    let t = twist(&tick(&mut f, &mut mem, 5.1, at(0.5), near));
    assert_eq!(t.v, -g.final_speed_mps);
    assert_eq!(tick(&mut f, &mut mem, 14.9, at(0.5), near).status, Status::Running);
    let end = tick(&mut f, &mut mem, 15.1, at(0.5), near);
    assert_eq!(end.status, Status::Event("retry"));
    assert_eq!(end.output.drive, DriveCommand::Stop);
    assert_eq!(end.output.aux.get::<Lights>(), Some(Lights(false)));
    assert_eq!(mem.retries.used(), 1);
    // The last retry used: retries exhausted.
    mem.retries = common::retries(3, 3);
    enter(&mut f, &mut mem, 20.0, at(0.5), near);
    tick(&mut f, &mut mem, 20.0, at(0.5), near);
    assert_eq!(
        tick(&mut f, &mut mem, 30.1, at(0.5), near).status,
        Status::Done(Outcome::Failed(FailureReason::RetriesExhausted))
    );
}

#[test]
fn back_aways_leave_by_their_distance_then_clear() {
    let mut mem = memory();
    let g = marsupial::behaviors::catalog::tuning::<marsupial::behaviors::raposa::Raposa>(&profile())
        .unwrap()
        .seven_state;
    let mut retreat = node("retreat", &[]);
    let retreat = &mut *retreat;
    enter(retreat, &mut mem, 0.0, at(0.5), nothing());
    let step = tick(retreat, &mut mem, 0.1, at(0.6), nothing());
    assert_eq!(twist(&step).v, g.far_speed_mps, "body forward, away from the pyramid");
    assert_eq!(
        tick(retreat, &mut mem, 0.2, at(0.89), nothing()).status,
        Status::Running
    );
    assert_eq!(
        tick(retreat, &mut mem, 0.3, at(0.91), nothing()).status,
        Status::Event("cleared")
    );
    // The dead zone: the socket is 0.43 − 0.1 = 0.33 m from the ball; out to 0.6 m.
    let mut dz = node("leave_dead_zone", &[]);
    let close = seen(0.43, Some(60.0), [0.0, 0.0], true);
    enter(&mut *dz, &mut mem, 0.0, at(0.5), close);
    assert_eq!(tick(&mut *dz, &mut mem, 0.1, at(0.76), close).status, Status::Running);
    assert_eq!(
        tick(&mut *dz, &mut mem, 0.2, at(0.78), close).status,
        Status::Event("cleared")
    );
    // Already past the exit distance: the shortest back-away still runs.
    let out = seen(1.0, Some(60.0), [0.0, 0.0], true);
    let mut dz = node("leave_dead_zone", &[("min_distance_m", 0.2.into())]);
    enter(&mut *dz, &mut mem, 0.0, at(0.5), out);
    assert_eq!(tick(&mut *dz, &mut mem, 0.1, at(0.69), out).status, Status::Running);
    assert_eq!(
        tick(&mut *dz, &mut mem, 0.2, at(0.71), out).status,
        Status::Event("cleared")
    );
}

#[test]
fn departure_drives_out_to_the_imprint_distance_then_imprints() {
    let mut mem = memory();
    let mut d = departure::Depart::new(&mem);
    // Docked, the camera is 0.1 m from the ball; it imprints from 0.6 m.
    let step = tick(&mut d, &mut mem, 0.1, at(0.0), nothing());
    assert!(twist(&step).v > 0.0, "body forward: {step:?}");
    assert_eq!(tick(&mut d, &mut mem, 0.2, at(0.45), nothing()).status, Status::Running);
    assert_eq!(
        tick(&mut d, &mut mem, 0.3, at(0.5), nothing()).status,
        Status::Event("stopped")
    );
    // Imprint: the first frame skipped, then `imprint_frames` (5); nothing sampled here
    // (no camera), so the departure fails.
    // As `raposa.imprint` is registered.
    let frames = mem.source.imprint_frames_wanted();
    let mut im = Imprint::new(1, frames, ImprintEnd::Outcome);
    enter(&mut im, &mut mem, 0.3, at(0.5), nothing());
    for k in 1..=5 {
        assert_eq!(
            tick(&mut im, &mut mem, 0.3 + k as f64 * 0.1, at(0.5), nothing()).status,
            Status::Running
        );
    }
    assert_eq!(
        tick(&mut im, &mut mem, 0.9, at(0.5), nothing()).status,
        Status::Done(Outcome::Failed(FailureReason::TargetNeverDetected))
    );
    assert!(!mem.imprinted);
}

#[test]
fn the_dock_switch_closes_the_guides_and_docks() {
    let mut mem = memory();
    let mut s = DockSwitch;
    assert!(s.tick(&mut mem, &Inputs::empty(0.0)).is_none());
    let mut i = Inputs::empty(0.1);
    let sensors = [Some(SensorInput {
        kind: DOCK_CONTACT_KIND,
        stamp: 0.1,
        values: &[1.0],
    })];
    i.sensors = &sensors;
    let step = s.tick(&mut mem, &i).unwrap();
    assert_eq!(step.status, Status::Done(Outcome::Docked));
    assert_eq!(step.output.drive, DriveCommand::Stop);
    assert_eq!(step.output.aux.get::<Guides>(), Some(Guides::Closed));
}

#[test]
fn the_memory_perceives_only_outside_the_departure() {
    let mut m = catalog::memory(&Raposa, &profile()).unwrap();
    // Fixed bands: nothing to imprint, no departure.
    assert!(matches!(
        m.begin(&Mission::Departure),
        Err(MissionError::Unavailable { .. })
    ));
    let mut p = profile();
    p.perception.mode = SegmentationMode::Static;
    let mut m = catalog::memory(&Raposa, &p).unwrap();
    m.begin(&Mission::Departure).unwrap();
    m.percept = seen(1.0, None, [0.0, 0.0], false);
    SharedMemory::perceive(&mut m, &inputs(0.5, at(0.2)));
    assert_eq!((m.now, m.odo), (0.5, at(0.2)), "time and odometry still follow");
    assert!(m.percept.view.is_some(), "the perception did not run");
    m.begin(&Mission::docking()).unwrap();
    assert_eq!(m.aux.get::<Guides>(), Some(Guides::Open));
    m.unseen = 2;
    SharedMemory::perceive(&mut m, &inputs(0.6, at(0.2)));
    assert!(m.percept.view.is_none(), "no camera: nothing seen");
    assert_eq!(m.unseen, 2, "only a sighting resets the unseen count");
}

/// The servo's states as the shipped profile lists them.
fn servo_states(p: &Profile) -> Vec<String> {
    match &p.behavior.tree.as_ref().unwrap().nodes["servo"] {
        NodeSpec::Sequencer { states, .. } => states.clone(),
        other => panic!("servo is a sequencer, got {other:?}"),
    }
}

#[test]
fn the_selector_maps_percepts_to_states_and_looks_until_the_ellipse_is_seen() {
    let p = profile();
    let states = servo_states(&p);
    let mut mem = memory();
    let args = SelectorArgs {
        node: "servo",
        states: &states,
        profile: &p,
    };
    let mut sel = SevenState::new(&args).unwrap();
    let idx = |name: &str| states.iter().position(|s| s == name).unwrap();
    let mut select = |mem: &mut Memory, current: &str, percept: PyramidPercept| {
        mem.percept = percept;
        sel.select(mem, &Inputs::empty(0.0), idx(current))
            .map(|i| states[i].as_str())
    };
    let from = "search";
    assert_eq!(
        select(&mut mem, from, seen(1.5, Some(5.0), [0.0, 0.0], true)),
        Some("approach")
    );
    assert_eq!(
        select(&mut mem, from, seen(1.5, Some(40.0), [0.0, 0.0], true)),
        Some("align")
    );
    assert_eq!(
        select(&mut mem, from, seen(2.0, None, [0.0, 0.0], false)),
        Some("far_ellipse")
    );
    let mut blue = nothing();
    blue.detection.blue = Some(blue_at(80));
    assert_eq!(select(&mut mem, from, blue), Some("blue_only"));
    assert_eq!(select(&mut mem, "approach", nothing()), Some("search"));
    assert_eq!(
        select(&mut mem, from, seen(0.28, Some(40.0), [0.0, 0.0], true)),
        Some("final")
    );
    assert_eq!(
        select(&mut mem, from, seen(0.43, Some(60.0), [0.0, 0.0], true)),
        Some("leave_dead_zone")
    );
    // Only the ball in the dead zone, no pair yet this docking: probe after
    // `lost_frames` frames (8), at most four times; a pair seen before means the side is
    // known, and the lone ball is approached.
    let lone_ball = || seen(0.43, None, [0.0, 0.0], false);
    mem.lone = 7;
    assert_eq!(select(&mut mem, from, lone_ball()), Some("approach"));
    mem.lone = 8;
    assert_eq!(select(&mut mem, from, lone_ball()), Some("probe"));
    assert_eq!(
        select(&mut mem, from, seen(0.8, None, [0.0, 0.0], false)),
        Some("approach"),
        "outside the dead zone"
    );
    mem.probes = 4;
    assert_eq!(select(&mut mem, from, lone_ball()), Some("approach"));
    mem.probes = 0;
    mem.pair_seen = true;
    assert_eq!(select(&mut mem, from, lone_ball()), Some("approach"));
    mem.pair_seen = false;
    mem.lone = 0;
    // A sighting restarts the search clock.
    mem.search_start = Some(3.0);
    select(&mut mem, from, seen(1.5, Some(5.0), [0.0, 0.0], true));
    assert_eq!(mem.search_start, None);
    // After region II: keep looking without the ellipse (blue alone does not count)...
    assert_eq!(select(&mut mem, "look", nothing()), None);
    assert_eq!(select(&mut mem, "look", blue), None);
    assert!(!mem.settling);
    // ...and select with the threshold widened once it is seen: 18° is not region II.
    assert_eq!(
        select(&mut mem, "look", seen(1.0, Some(18.0), [0.0, 0.0], true)),
        Some("approach")
    );
    assert!(mem.settling);
    assert_eq!(
        select(&mut mem, "approach", seen(1.0, Some(18.0), [0.0, 0.0], true)),
        Some("approach")
    );
    mem.settling = false;
    assert_eq!(
        select(&mut mem, "approach", seen(1.0, Some(18.0), [0.0, 0.0], true)),
        Some("align")
    );
    // Every servo state of `select_state` but state 7 (align hands over to it) has one.
    for s in [
        ServoState::S1Approach,
        ServoState::S2Align,
        ServoState::S3FarEllipse,
        ServoState::S4BlueOnly,
        ServoState::S5Nothing,
        ServoState::S6Final,
        ServoState::LeaveDeadZone,
        ServoState::Probe,
    ] {
        assert!(sel.index(s).is_some(), "{s:?}");
    }
    assert_eq!(sel.index(ServoState::S7Rotate), None);
}

#[test]
fn the_selector_names_a_missing_state() {
    let p = profile();
    let mut states = servo_states(&p);
    states.retain(|s| s != "look");
    let args = SelectorArgs {
        node: "servo",
        states: &states,
        profile: &p,
    };
    let e = SevenState::new(&args).err().unwrap();
    assert!(e.contains("`look`"), "{e}");
}
