//! Nothing allocates per frame or per tick in steady state:
//! * the perceptual schemas in every segmentation mode, imprinted first, with the clock
//!   running through the fallback chain (adapted → imprinted → table): segmentation,
//!   labelling, pairing, adaptation and the colour-cast compensation (Bujold); HSV
//!   segmentation, ellipses, blue regions, pair filters and tracking (RAPOSA);
//! * the per-tick camera list, and the simulator's whole lockstep tick (device reads
//!   through the hardware traits, rendering, the composed behavior, the command, the
//!   physics step);
//! * the composed Bujold and RAPOSA behaviors through their phases;
//! * Axel's circle marks: detection, correspondence and the module's pose (stereo, mono
//!   and the fallback choice);
//! * the AutoKrawler's marker step: segmentation, opening, labelling, identity; and its
//!   whole ten-DOF estimate (markers, roll, drop, steering, and the wheels' pyramids,
//!   corners, Lucas–Kanade, RANSAC and correction);
//! * the AprilTag detector: threshold, labelling, quads, decoding, pose and its check.
//!
//! A counting global allocator, gated to the test's own thread, proves it. (The threaded
//! runtime builds the same per-tick lists as the lockstep; its threads are not counted.)

use crate::common;

use marsupial::perception::{ColorMode, RgbImage};
use marsupial::profile::{Profile, SegmentationMode};
use marsupial::schemas::{CameraInput, CameraInputs};
use marsupial::schemas::{PyramidSchema, TwoBlockSchema};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::path::Path;

struct Counting;
// Both the switch and the count are per thread, so tests running in parallel neither
// count nor reset each other's allocations.
thread_local!(static COUNTING: Cell<bool> = const { Cell::new(false) });
thread_local!(static ALLOCS: Cell<usize> = const { Cell::new(0) });

fn count() {
    if COUNTING.with(|c| c.get()) {
        ALLOCS.with(|a| a.set(a.get() + 1));
    }
}

fn allocs() -> usize {
    ALLOCS.with(|a| a.get())
}

fn reset() {
    ALLOCS.with(|a| a.set(0));
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(p, l, n) }
    }
}

#[global_allocator]
static A: Counting = Counting;

/// The colour modes a segmentation mode must have passed through while allocations were
/// counted: the adaptive model's whole fallback chain, a static model's imprint, a fixed
/// one's table.
fn assert_fallbacks_counted(mode: SegmentationMode, seen: &[Option<ColorMode>; 3], label: &str) {
    let expected: &[ColorMode] = match mode {
        SegmentationMode::Adaptive => &[ColorMode::Adapted, ColorMode::Imprinted, ColorMode::Table],
        SegmentationMode::Static => &[ColorMode::Imprinted],
        SegmentationMode::Fixed => &[ColorMode::Table],
    };
    for m in expected {
        assert!(
            seen.contains(&Some(*m)),
            "{label} {mode:?}: {m:?} not counted: {seen:?}"
        );
    }
}

#[test]
fn steady_state_schema_does_not_allocate() {
    // Every segmentation mode, after imprinting on departure as the robot does: frames
    // with the fiducial at several sizes, then long spells without it, so the adaptive
    // model falls back adapted → imprinted → table and recovers while counted.
    let modes = [
        SegmentationMode::Adaptive,
        SegmentationMode::Static,
        SegmentationMode::Fixed,
    ];
    for ((w, h), mode) in [(640, 480), (256, 240)].into_iter().flat_map(|s| modes.map(|m| (s, m))) {
        let mut p = Profile::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/bujold.toml")).unwrap();
        p.cameras[0].width_px = w;
        p.cameras[0].height_px = h;
        p.perception.mode = mode;
        p.perception.cast_tau_s = 2.0; // the colour-cast compensation is counted too
        let mut schema = TwoBlockSchema::from_profile(&p, 0).unwrap();
        let frames: Vec<_> = (0..6).map(|k| common::scene(w, h, 0.1 + 0.08 * k as f64, k)).collect();
        // The same scene with the fiducial out of view (a cast compensation would take a
        // cut to a different scene for a change of light).
        let empty = common::scene(w, h, 0.0, 6);
        // A frame under a coloured flash (blue at 70 %), so the cast compensation runs.
        let mut flash = frames[3].clone();
        for px in flash.as_bytes_mut().chunks_exact_mut(3) {
            px[2] = (px[2] as f64 * 0.7) as u8;
        }
        let mut corrected = 0;
        for _ in 0..schema.imprint_frames_wanted() {
            schema.imprint_frame(&frames[2].view());
        }
        let imprinted = schema.finish_imprint(0.0);
        assert_eq!(imprinted, mode != SegmentationMode::Fixed, "{mode:?}: imprint");
        let mut t = 0.0;
        for f in &frames {
            t += 0.1;
            schema.process(&f.view(), t).unwrap(); // warm-up
        }
        reset();
        COUNTING.with(|c| c.set(true));
        let mut found = 0;
        // Fixed storage: the test itself must not allocate while counting.
        let mut modes_seen = [None; 3];
        for round in 0..20 {
            for f in &frames {
                t += 0.1;
                found += schema.process(&f.view(), t).unwrap().found as usize;
            }
            t += 0.1;
            schema.process(&flash.view(), t).unwrap();
            corrected += (schema.cast().gains() != [1.0; 3]) as usize;
            if round % 5 == 4 {
                // Ten seconds without the fiducial: past both fallback timeouts.
                for _ in 0..100 {
                    t += 0.1;
                    schema.process(&empty.view(), t).unwrap();
                    let m = schema.model().mode();
                    modes_seen[m as usize] = Some(m);
                }
            }
        }
        COUNTING.with(|c| c.set(false));
        assert_eq!(allocs(), 0, "{w}×{h} {mode:?}: allocations in steady state");
        assert_eq!(found, 120, "{w}×{h} {mode:?}: every fiducial frame detected");
        assert!(corrected > 0, "{w}×{h} {mode:?}: the flash was never corrected");
        assert_fallbacks_counted(mode, &modes_seen, &format!("{w}×{h}"));
    }
    // Control: the counter does see allocations.
    COUNTING.with(|c| c.set(true));
    let v: Vec<u8> = Vec::with_capacity(std::hint::black_box(64));
    COUNTING.with(|c| c.set(false));
    drop(v);
    assert!(allocs() >= 1);
}

/// A pyramid as the back camera sees it: blue square frame, orange ball in front.
fn pyramid_frame(w: usize, h: usize, side: usize) -> RgbImage {
    let mut im = common::background(w, h);
    let (x0, y0) = (w / 2 - side / 2, h / 2 - side / 2);
    let bar = (side / 7).max(1);
    for y in y0..y0 + side {
        for x in x0..x0 + side {
            if x < x0 + bar || x >= x0 + side - bar || y < y0 + bar || y >= y0 + side - bar {
                im.put(x, y, [20, 60, 220]);
            }
        }
    }
    let r = side as f64 * 0.35;
    let (cx, cy) = (w as f64 / 2.0, h as f64 / 2.0);
    for y in 0..h {
        for x in 0..w {
            if (x as f64 + 0.5 - cx).hypot(y as f64 + 0.5 - cy) <= r {
                im.put(x, y, [235, 120, 20]);
            }
        }
    }
    im
}

#[test]
fn steady_state_pyramid_schema_does_not_allocate() {
    // Every segmentation mode, imprinted first: adaptive also samples each pair and moves
    // its bands, and the clock runs, so spells without the pyramid drop the tracking ball
    // and walk the fallback chain while counted.
    let modes = [
        SegmentationMode::Fixed,
        SegmentationMode::Static,
        SegmentationMode::Adaptive,
    ];
    for ((w, h), mode) in [(160, 120), (640, 480)].into_iter().flat_map(|s| modes.map(|m| (s, m))) {
        let mut p = Profile::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/raposa.toml")).unwrap();
        p.cameras[0].width_px = w;
        p.cameras[0].height_px = h;
        p.perception.mode = mode;
        let mut schema = PyramidSchema::from_profile(&p, 0).unwrap();
        let frames: Vec<_> = (0..4).map(|k| pyramid_frame(w, h, h / 6 + k * h / 10)).collect();
        let empty = common::background(w, h);
        // The imprint samples only a pyramid at the imprint distance: the first size that
        // agrees, then as many frames as the profile wants.
        let at_distance = (h / 10..h)
            .map(|side| pyramid_frame(w, h, side))
            .find(|f| schema.imprint_frame(&f.view()).unwrap())
            .expect("some size is at the imprint distance");
        for _ in 1..schema.imprint_frames_wanted() {
            assert!(schema.imprint_frame(&at_distance.view()).unwrap());
        }
        assert_eq!(
            schema.finish_imprint(0.0),
            mode != SegmentationMode::Fixed,
            "{mode:?}: imprint"
        );
        let mut t = 0.0;
        for f in &frames {
            t += 0.1;
            schema.process(&f.view(), t).unwrap(); // warm-up
        }
        reset();
        COUNTING.with(|c| c.set(true));
        let mut pairs = 0;
        // Fixed storage: the test itself must not allocate while counting.
        let mut modes_seen = [None; 3];
        for round in 0..10 {
            for f in &frames {
                t += 0.1;
                pairs += schema.process(&f.view(), t).unwrap().detection.pair.is_some() as usize;
            }
            if round % 3 == 2 {
                // Lost for ten seconds: past both fallback timeouts.
                for _ in 0..100 {
                    t += 0.1;
                    schema.process(&empty.view(), t).unwrap();
                    let m = schema.model().mode();
                    modes_seen[m as usize] = Some(m);
                }
            }
        }
        COUNTING.with(|c| c.set(false));
        assert_eq!(allocs(), 0, "{w}×{h} {mode:?}: allocations in steady state");
        assert_eq!(pairs, 40, "{w}×{h} {mode:?}: every pyramid frame paired");
        assert_fallbacks_counted(mode, &modes_seen, &format!("{w}×{h}"));
    }
}

#[test]
fn a_ticks_camera_list_does_not_allocate() {
    let frames: Vec<RgbImage> = (0..4).map(|_| RgbImage::new(8, 6)).collect();
    reset();
    COUNTING.with(|c| c.set(true));
    let cams: CameraInputs<'_> = frames
        .iter()
        .map(|f| {
            Some(CameraInput {
                stamp: 0.0,
                image: f.view(),
            })
        })
        .collect();
    COUNTING.with(|c| c.set(false));
    assert_eq!(cams.len(), 4);
    assert_eq!(allocs(), 0, "four cameras fit inline");
}

/// The composed Bujold behavior (perception, shared memory, arbiters, phase schemas)
/// allocates nothing per tick once warmed up: through search, approach, the at-dock
/// decision, repositioning and back, with frames that come and go.
#[test]
fn composed_bujold_ticks_do_not_allocate() {
    use marsupial::behaviors::agent_for;
    use marsupial::geometry::Pose2;
    use marsupial::schemas::{Inputs, OdometryReading, Stamped};
    let p = Profile::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/bujold.toml")).unwrap();
    let mut agent = agent_for(&p).unwrap();
    // Far (small), near (at the dock's pixel count) and no fiducial.
    let frames = [
        common::scene(256, 240, 0.25, 1),
        common::scene(256, 240, 0.9, 2),
        common::background(256, 240),
    ];
    let run = |agent: &mut Box<dyn marsupial::schemas::Agent>, from: u64, to: u64| {
        let mut phases = 0u64;
        for k in from..to {
            let t = k as f64 * 0.1;
            let f = &frames[(k / 40 % 3) as usize];
            let cams: CameraInputs<'_> = smallvec::smallvec![Some(CameraInput {
                stamp: t,
                image: f.view()
            })];
            let mut inputs = Inputs::empty(t);
            inputs.cameras = &cams;
            let pose = Pose2::new(1.0 + 0.001 * (k % 50) as f64, 0.0, 0.01 * (k % 7) as f64);
            inputs.odometry = Some(Stamped::new(
                t,
                OdometryReading {
                    pose,
                    ..Default::default()
                },
            ));
            if let Some(s) = agent.tick(&mut (), &inputs) {
                phases = phases.wrapping_add(s.feedback.phase.len() as u64);
            }
        }
        phases
    };
    agent.begin(&marsupial::schemas::Mission::docking()).unwrap();
    run(&mut agent, 0, 240); // warm-up: every phase's buffers sized once
    reset();
    COUNTING.with(|c| c.set(true));
    let ran = run(&mut agent, 240, 600);
    COUNTING.with(|c| c.set(false));
    assert!(ran > 0);
    assert_eq!(allocs(), 0, "allocations in the composed behavior's ticks");
}

/// A synthetic back-camera view: the blue frame (`side` px, none when 0) centred
/// `dx` px right of the image centre, the orange ball (radius `r` px) `ball_dx` px right
/// of the frame's centre (off the axis: α ≠ 0).
fn pyramid_view(side: usize, dx: f64, ball_dx: f64, r: f64) -> RgbImage {
    let (w, h) = (160, 120);
    let mut im = common::background(w, h);
    let cx = w as f64 / 2.0 + dx;
    if side > 0 {
        let (x0, y0) = (cx as usize - side / 2, h / 2 - side / 2);
        let bar = (side / 7).max(1);
        for y in y0..y0 + side {
            for x in x0..x0 + side {
                if x < x0 + bar || x >= x0 + side - bar || y < y0 + bar || y >= y0 + side - bar {
                    im.put(x, y, [20, 60, 220]);
                }
            }
        }
    }
    let (bx, by) = (cx + ball_dx, h as f64 / 2.0);
    for y in 0..h {
        for x in 0..w {
            if (x as f64 + 0.5 - bx).hypot(y as f64 + 0.5 - by) <= r {
                im.put(x, y, [235, 120, 20]);
            }
        }
    }
    im
}

/// The composed RAPOSA behavior (pyramid perception, shared memory, the seven-state
/// selector, the nested region-II sequence, the phase schemas) allocates nothing per tick
/// once warmed up. The views cycle through nothing, a pair 18° off the axis (region II,
/// its ellipse then swept toward either image edge), a near ball (state 6, then the
/// retreat), a far pair, blue edges alone and a far ball alone, while odometry follows the
/// commands; a first docking warms up, a second is counted.
#[test]
fn composed_raposa_ticks_do_not_allocate() {
    use marsupial::behaviors::agent_for;
    use marsupial::geometry::{Pose2, integrate_twist};
    use marsupial::schemas::{Agent, Inputs, Mission, OdometryReading, Stamped};
    let mut p = Profile::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/raposa.toml")).unwrap();
    p.behavior.max_retries = 1000; // the final approach never meets a dock here
    let mut agent = agent_for(&p).unwrap();
    let frames = [
        common::background(160, 120),
        pyramid_view(30, 0.0, 14.0, 6.5),
        pyramid_view(30, 45.0, 14.0, 6.5),
        pyramid_view(30, -45.0, 14.0, 6.5),
        pyramid_view(0, 0.0, 0.0, 44.0),
        pyramid_view(24, 0.0, 0.0, 8.4),
        pyramid_view(30, 0.0, 0.0, 0.0),
        pyramid_view(0, 0.0, 0.0, 6.0),
    ];
    let run = |agent: &mut Box<dyn Agent>, phases: &mut Vec<&'static str>| {
        let mut pose = Pose2::new(1.0, 0.0, 0.0);
        let mut n = 0u64;
        for k in 0..1500u64 {
            let t = k as f64 * 0.1;
            let f = &frames[(k / 37 % frames.len() as u64) as usize];
            let cams: CameraInputs<'_> = smallvec::smallvec![Some(CameraInput {
                stamp: t,
                image: f.view()
            })];
            let mut inputs = Inputs::empty(t);
            inputs.cameras = &cams;
            inputs.odometry = Some(Stamped::new(
                t,
                OdometryReading {
                    pose,
                    ..Default::default()
                },
            ));
            if let Some(s) = agent.tick(&mut (), &inputs) {
                n = n.wrapping_add(s.feedback.phase.len() as u64);
                pose = integrate_twist(&pose, &s.output.drive.to_twist(), 0.1);
                if phases.len() < phases.capacity() && !phases.contains(&s.feedback.phase) {
                    phases.push(s.feedback.phase);
                }
            }
        }
        n
    };
    let mut phases: Vec<&'static str> = Vec::with_capacity(64);
    agent.begin(&Mission::docking()).unwrap();
    run(&mut agent, &mut phases); // warm-up: every phase's buffers sized once
    phases.clear();
    agent.begin(&Mission::docking()).unwrap();
    reset();
    COUNTING.with(|c| c.set(true));
    let ran = run(&mut agent, &mut phases);
    COUNTING.with(|c| c.set(false));
    assert!(ran > 0);
    assert_eq!(allocs(), 0, "allocations in the composed behavior's ticks");
    for phase in [
        "state_5",
        "state_7",
        "state_2_rotate",
        "state_2_travel",
        "state_2_rotate_phi",
        "state_1",
        "state_6",
        "retreat",
    ] {
        assert!(phases.contains(&phase), "{phase} did not run: {phases:?}");
    }
}

/// The simulator's path: the per-tick camera and sensor lists, the device reads through
/// the hardware traits (rendering into the lockstep's frames), the composed behavior, the
/// command and the physics step allocate nothing per tick once warmed up, through Bujold's
/// departure (undock, drive out, imprint).
#[cfg(feature = "sim")]
#[test]
fn a_simulated_robots_lockstep_ticks_do_not_allocate() {
    simulated_lockstep_ticks(false);
}

/// The same with every camera imperfection on (motion blur, rolling shutter, vignetting,
/// defocus, JPEG): their buffers are sized by the first frames and reused.
#[cfg(feature = "sim")]
#[test]
fn a_simulated_robots_lockstep_ticks_do_not_allocate_with_every_camera_imperfection() {
    simulated_lockstep_ticks(true);
}

#[cfg(feature = "sim")]
fn simulated_lockstep_ticks(imperfect: bool) {
    use marsupial::arbiter::{Lockstep, LoopStatus, ReactiveLoop};
    use marsupial::behaviors::agent_for;
    use marsupial::schemas::Mission;
    use marsupial::sim::campaign;
    use marsupial::sim::robot::SimDevices;
    use marsupial::sim::run::docked_robot;
    use marsupial::sim::scenario::Scenario;

    let scenario = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/bujold-table1.toml");
    let mut scenario = Scenario::load(&scenario).unwrap();
    if imperfect {
        let s = &mut scenario.scenario.sensor;
        s.motion_blur = true;
        s.rolling_shutter_readout_s = 0.03;
        s.vignetting_corner = 0.65;
        s.focus_m = Some(1.0);
        s.jpeg_quality = 80;
    }
    let prepared = campaign::prepare(scenario).unwrap();
    let profile = &prepared.loaded.profile;
    let sim = docked_robot(&prepared, &prepared.runs[0]);
    let mut robot = sim.robot(&SimDevices::default()).unwrap();
    let config = profile.loop_config();
    let mut step = Lockstep::new(&robot, &config);
    let mut lp = ReactiveLoop::new(agent_for(profile).unwrap(), config);
    lp.begin(&Mission::Departure).unwrap();
    let mut tick = |n: usize| {
        let mut running = 0;
        for _ in 0..n {
            let now = sim.with(|s| s.time());
            let out = step.tick(&mut robot, &mut lp, now);
            running += matches!(out.status, LoopStatus::Running { .. }) as usize;
            assert!(sim.advance().is_none(), "the departure runs on");
        }
        running
    };
    tick(20); // warm-up: buffers sized, the first phase entered
    reset();
    COUNTING.with(|c| c.set(true));
    let running = tick(60);
    COUNTING.with(|c| c.set(false));
    assert_eq!(allocs(), 0, "allocations in the simulator's lockstep ticks");
    assert_eq!(running, 60, "every counted tick ran the behavior");
}

#[test]
fn circle_detection_and_correspondence_do_not_allocate() {
    use marsupial::perception::circles::{
        CircleDetector, CircleModel, CircleParams, CorrespondenceParams, LensPlane, RigCamera, correspond,
        correspond_through,
    };
    let p = common::shipped_profile("axel");
    let model = CircleModel::from_profile(&p).unwrap();
    // The robot labels through its fish-eye: the same frames through camera 0's lens.
    let mut lens = LensPlane::new(RigCamera::from_profile(&p, 0).unwrap().model);
    let (w, h) = (640, 480);
    let frames: Vec<RgbImage> = [
        (300.0, [320.0, 240.0]),
        (220.0, [300.0, 260.0]),
        (380.0, [330.0, 230.0]),
    ]
    .into_iter()
    .map(|(s, c)| common::axel_marks_frame(w, h, s, c))
    .collect();
    let empty = common::background(w, h);
    let mut det = CircleDetector::new(w, h, CircleParams::for_image(w));
    let params = CorrespondenceParams::default();
    for f in &frames {
        let marks = det.detect(&f.view()).unwrap();
        assert_eq!(correspond(&model, marks, &params).unwrap().inliers, 8); // warm-up
        assert_eq!(
            correspond_through(&model, marks, &mut lens, &params).unwrap().inliers,
            8
        );
    }
    reset();
    COUNTING.with(|c| c.set(true));
    let mut fits = 0;
    for _ in 0..5 {
        for f in &frames {
            let marks = det.detect(&f.view()).unwrap();
            fits += correspond(&model, marks, &params).is_ok() as usize;
            fits += correspond_through(&model, marks, &mut lens, &params).is_ok() as usize;
        }
        let marks = det.detect(&empty.view()).unwrap();
        fits += correspond(&model, marks, &params).is_ok() as usize;
        fits += correspond_through(&model, marks, &mut lens, &params).is_ok() as usize;
    }
    COUNTING.with(|c| c.set(false));
    assert_eq!(allocs(), 0, "allocations in steady state");
    assert_eq!(fits, 30);
}

#[test]
fn circle_pose_does_not_allocate() {
    use marsupial::perception::circles::{
        CircleDetector, CircleModel, CircleParams, CorrespondenceParams, MarkObservations, PoseBuffers, PoseParams,
        RigCamera, correspond, module_pose, mono_pose, stereo_pose,
    };
    use nalgebra::{Rotation3, Vector3};
    let p = common::shipped_profile("axel");
    let model = CircleModel::from_profile(&p).unwrap();
    let cams = [
        RigCamera::from_profile(&p, 0).unwrap(),
        RigCamera::from_profile(&p, 1).unwrap(),
    ];
    // Stereo: the model projected through both cameras with the module 2 m ahead.
    let r = *Rotation3::from_axis_angle(&Vector3::z_axis(), std::f64::consts::PI + 0.1).matrix();
    let t = Vector3::new(2.0, 0.1, 0.0);
    let mut obs = [MarkObservations::new(model.len()); 2];
    for (k, o) in obs.iter_mut().enumerate() {
        for (j, c) in model.centres().iter().enumerate() {
            o.set(j, cams[k].project(&(r * Vector3::new(0.0, c[0], c[1]) + t)));
        }
    }
    // Mono: a detected frame, labelled (the synthetic frame's scale is not a camera's,
    // but the pose still runs through every step).
    let (w, h) = (640, 480);
    let frame = common::axel_marks_frame(w, h, 300.0, [320.0, 240.0]);
    let mut det = CircleDetector::new(w, h, CircleParams::for_image(w));
    let cparams = CorrespondenceParams::default();
    let params = PoseParams::default();
    let mut buf = PoseBuffers::new();
    let empty = MarkObservations::new(model.len());
    let mut run = |buf: &mut PoseBuffers| {
        let mut ok = 0;
        ok += stereo_pose(&model, [&cams[0], &cams[1]], [&obs[0], &obs[1]], &params, buf).is_ok() as usize;
        ok += module_pose(&model, [&cams[0], &cams[1]], [&empty, &obs[1]], &params, buf).is_ok() as usize;
        let marks = det.detect(&frame.view()).unwrap();
        let fit = correspond(&model, marks, &cparams).unwrap();
        let seen = MarkObservations::from_fit(&fit, marks);
        ok += mono_pose(&model, &cams[0], 0, &seen, &params, buf).is_ok() as usize;
        ok
    };
    assert_eq!(run(&mut buf), 3); // warm-up
    reset();
    COUNTING.with(|c| c.set(true));
    let mut ok = 0;
    for _ in 0..5 {
        ok += run(&mut buf);
    }
    COUNTING.with(|c| c.set(false));
    assert_eq!(allocs(), 0, "allocations in steady state");
    assert_eq!(ok, 15);
}

/// Eight 10×10 magenta squares on grey at `at` (shifted by `dx`), plus a stray magenta
/// speck and a stray blob (clutter).
fn krawler_markers_frame(at: &[[usize; 2]; 8], dx: usize) -> RgbImage {
    let (w, h) = (640, 480);
    let mut data = vec![110u8; w * h * 3];
    let mut paint = |x0: usize, y0: usize, side: usize| {
        for y in y0..y0 + side {
            for x in x0..x0 + side {
                data[(y * w + x) * 3..(y * w + x) * 3 + 3].copy_from_slice(&[220, 40, 210]);
            }
        }
    };
    for a in at {
        paint(a[0] + dx - 5, a[1] - 5, 10);
    }
    paint(600, 20, 2);
    paint(40, 400, 12);
    RgbImage::from_raw(w, h, data).unwrap()
}

#[test]
fn krawler_marker_finding_does_not_allocate() {
    use marsupial::perception::krawler::{ExpectedMarker, MarkerFinder, MarkerParams};
    let at = [
        [280, 100],
        [360, 100],
        [270, 140],
        [370, 140],
        [280, 380],
        [360, 380],
        [270, 340],
        [370, 340],
    ];
    let expected = at.map(|a| ExpectedMarker {
        at: [a[0] as f64, a[1] as f64],
        area: 100.0,
    });
    let frames: Vec<RgbImage> = (0..4).map(|dx| krawler_markers_frame(&at, dx * 2)).collect();
    let mut finder = MarkerFinder::new(640, 480, MarkerParams::default());
    for f in &frames {
        assert_eq!(finder.find(&f.view(), &expected).unwrap().found(), 8); // warm-up
    }
    reset();
    COUNTING.with(|c| c.set(true));
    let mut found = 0;
    for _ in 0..3 {
        for f in &frames {
            found += finder.find(&f.view(), &expected).unwrap().found();
        }
    }
    COUNTING.with(|c| c.set(false));
    assert_eq!(allocs(), 0, "allocations in steady state");
    assert_eq!(found, 96);
}

/// Shi–Tomasi corners and pyramidal Lucas–Kanade (with the forward–backward check) on
/// 640×480 frames: pyramids, corner buffers and windows are reused, nothing allocates.
#[test]
fn corners_and_lucas_kanade_do_not_allocate() {
    use marsupial::perception::flow::{CornerParams, GreyPyramid, LkParams, LucasKanade, Roi, ShiTomasi};
    let frame = |shift: f64| {
        let mut im = RgbImage::new(640, 480);
        for y in 0..480 {
            for x in 0..640 {
                let (u, v) = (x as f64 - shift, y as f64 + 0.5 * shift);
                let g = 128.0 + 60.0 * (u * 0.11).sin() * (v * 0.07).cos() + 40.0 * ((u + v) * 0.05).sin();
                let g = g.clamp(0.0, 255.0) as u8;
                im.put(x, y, [g, g, g]);
            }
        }
        im
    };
    let frames = [frame(0.0), frame(1.3), frame(2.6)];
    let (mut a, mut b) = (GreyPyramid::new(3), GreyPyramid::new(3));
    let params = CornerParams {
        min_eigen: 5.0,
        ..CornerParams::default()
    };
    let mut corners = ShiTomasi::new(640, 480, params);
    let mut lk = LucasKanade::new(LkParams::default(), 100);
    let mut pts = [[0.0f64; 2]; 100];
    let mut out = [None; 100];
    let mut run = |a: &mut GreyPyramid, b: &mut GreyPyramid| {
        let mut tracked = 0;
        for pair in frames.windows(2) {
            a.build_from_rgb(&pair[0].view());
            b.build_from_rgb(&pair[1].view());
            let c = corners.detect(a.level(0), Roi::around(320.0, 240.0, 100.0, 640, 480));
            let n = c.len();
            pts[..n].copy_from_slice(c);
            lk.track_checked(a, b, &pts[..n], &mut out[..n]);
            tracked += out[..n].iter().filter(|o| o.is_some()).count();
        }
        tracked
    };
    let warm = run(&mut a, &mut b); // warm-up
    assert!(warm > 20, "{warm}");
    reset();
    COUNTING.with(|c| c.set(true));
    let tracked = run(&mut a, &mut b);
    COUNTING.with(|c| c.set(false));
    assert_eq!(allocs(), 0, "allocations in steady state");
    assert_eq!(tracked, warm);
}

/// The AutoKrawler's whole ten-DOF estimate (`KrawlerStateSchema`) on rendered frames:
/// pyramids, corner and track buffers and RANSAC's steps are reused, nothing allocates.
#[cfg(feature = "sim")]
#[test]
fn krawler_state_estimation_does_not_allocate() {
    use common::krawler::{Rig, axles, draw};
    use marsupial::perception::krawler::{KrawlerParams, KrawlerStateSchema, SteeringPoly};
    use marsupial::sim::krawler::{KrawlerState, expected_markers};
    use marsupial::sim::render::SensorParams;
    use marsupial::sim::rng::Rng;
    let mut rig = Rig::new(SensorParams::default(), 1);
    let frames: Vec<RgbImage> = (0..4)
        .map(|k| {
            let state = KrawlerState {
                steer: [0.2, -0.1],
                wheel: [0.08 * k as f64 + 1.0; 4],
                ..rig.rest
            };
            let mut im = RgbImage::default();
            rig.render(&state, &mut im);
            im
        })
        .collect();
    let mut schema = KrawlerStateSchema::new(
        (640, 480),
        rig.geometry.clone(),
        rig.layout,
        SteeringPoly::from_profile(&rig.profile).unwrap(),
        KrawlerParams::default(),
        expected_markers(&rig.profile, &rig.rest).unwrap(),
        axles(&rig.rest),
    );
    let mut rng = Rng::new(2);
    let mut valid = 0;
    let mut run = |schema: &mut KrawlerStateSchema| {
        for f in &frames {
            let e = schema.estimate(&f.view(), draw(&mut rng)).unwrap();
            valid += e.wheel.iter().filter(|w| w.valid).count() + e.markers.found();
        }
    };
    run(&mut schema); // warm-up
    reset();
    COUNTING.with(|c| c.set(true));
    run(&mut schema);
    COUNTING.with(|c| c.set(false));
    assert_eq!(allocs(), 0, "allocations in steady state");
    assert!(valid > 60, "{valid}");
}

/// The AutoKrawler robot's composed ticks (`krawler` kind): its memory's perceptual
/// schema (the whole estimate, each frame once) and its tree (slip monitor, traverse)
/// allocate nothing.
#[cfg(feature = "sim")]
#[test]
fn composed_krawler_ticks_do_not_allocate() {
    use common::krawler::Rig;
    use marsupial::schemas::{Agent, Behavior, Inputs, Mission};
    use marsupial::sim::krawler::KrawlerState;
    use marsupial::sim::render::SensorParams;
    let mut rig = Rig::new(SensorParams::default(), 4);
    let frames: Vec<RgbImage> = (0..6)
        .map(|k| {
            let state = KrawlerState {
                wheel: [0.02 * k as f64 + 0.5; 4],
                ..rig.rest
            };
            let mut im = RgbImage::default();
            rig.render(&state, &mut im);
            im
        })
        .collect();
    let mut robot = marsupial::behaviors::catalog::shipped()
        .compose(&marsupial::behaviors::krawler::Krawler, &rig.profile)
        .unwrap();
    robot.begin(&Mission::docking()).unwrap();
    let mut k = 0u32;
    let mut run = |robot: &mut marsupial::behaviors::Composed<marsupial::behaviors::krawler::KrawlerMemory>| {
        for f in &frames {
            let t = f64::from(k) / 30.0;
            k += 1;
            let cameras = [Some(CameraInput {
                stamp: t,
                image: f.view(),
            })];
            let inputs = Inputs {
                cameras: &cameras,
                ..Inputs::empty(t)
            };
            assert!(robot.tick(&mut (), &inputs).is_some());
        }
    };
    run(&mut robot); // warm-up
    reset();
    COUNTING.with(|c| c.set(true));
    run(&mut robot);
    COUNTING.with(|c| c.set(false));
    assert_eq!(allocs(), 0, "allocations in steady state");
    assert_eq!(robot.memory().percept.frames, 12);
}

#[test]
fn apriltag_detection_and_pose_do_not_allocate() {
    use marsupial::perception::Pinhole;
    use marsupial::perception::apriltag::{AprilTagDetector, AprilTagParams, TagFamily, TagSprite, draw_tag};
    use nalgebra::{Matrix3, Vector3};
    let cam = Pinhole::ideal(600.0, 640, 480);
    let facing = Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, -1.0));
    let frames: Vec<RgbImage> = [0.8, 1.0, 1.3]
        .iter()
        .map(|&z| {
            let mut im = RgbImage::new(640, 480);
            im.fill([128; 3]);
            let tag = TagSprite {
                family: TagFamily::Tag36h11,
                id: 11,
                size_m: 0.16,
                supersample: 2,
            };
            draw_tag(&mut im, &cam, &tag, &facing, &Vector3::new(0.05, 0.02, z));
            im
        })
        .collect();
    let params = AprilTagParams {
        expected_id: Some(11),
        ..AprilTagParams::default()
    };
    let mut det = AprilTagDetector::new(params);
    for f in &frames {
        det.detect(&f.view(), &cam).unwrap(); // buffers grow to the frame
    }
    reset();
    COUNTING.with(|c| c.set(true));
    let mut accepted = 0;
    for f in &frames {
        for d in det.detect(&f.view(), &cam).unwrap() {
            accepted += params.accept(d).is_ok() as usize;
        }
    }
    COUNTING.with(|c| c.set(false));
    assert_eq!(accepted, 3);
    assert_eq!(allocs(), 0, "apriltag detection allocated");
}

/// A camera's raw frames decode without allocating once the decoder has seen their size:
/// at the camera's size (straight into the loop's frame) and at twice it (decoded into the
/// decoder's own buffer, then area-rescaled), for 4:2:2, 4:2:0 and Bayer. (A JPEG frame
/// is decoded by the `image` crate into a new image each time: not counted here.)
#[cfg(feature = "image-io")]
#[test]
fn camera_frames_decode_without_allocating() {
    use marsupial::msgs::camera_frame::{CameraBytes, FrameDecoder};
    let (w, h) = (64u32, 48u32);
    let mut frame = RgbImage::new(w as usize, h as usize);
    let mut decoder = FrameDecoder::new();
    // (encoding, width, height, bytes) at the camera's size and at twice it.
    let messages: Vec<(&str, u32, u32, Vec<u8>)> = [1u32, 2]
        .into_iter()
        .flat_map(|scale| {
            let (mw, mh) = (w * scale, h * scale);
            let ramp = |n: usize| (0..n).map(|i| (i * 7 % 251) as u8).collect::<Vec<u8>>();
            [
                ("yuyv", mw, mh, ramp((2 * mw * mh) as usize)),
                ("uyvy", mw, mh, ramp((2 * mw * mh) as usize)),
                ("nv12", mw, mh, ramp((mw * mh * 3 / 2) as usize)),
                ("bayer_grbg8", mw, mh, ramp((mw * mh) as usize)),
            ]
        })
        .collect();
    let decode = |decoder: &mut FrameDecoder, frame: &mut RgbImage| {
        for (encoding, mw, mh, data) in &messages {
            let step = match *encoding {
                "yuyv" | "uyvy" => 2 * mw,
                _ => *mw,
            };
            let bytes = CameraBytes::Raw {
                width: *mw,
                height: *mh,
                encoding,
                step,
                data,
            };
            assert_eq!(decoder.decode_into(bytes, frame).unwrap(), (*mw as usize, *mh as usize));
        }
    };
    decode(&mut decoder, &mut frame); // the decoder's buffers grow to the sizes
    reset();
    COUNTING.with(|c| c.set(true));
    for _ in 0..3 {
        decode(&mut decoder, &mut frame);
    }
    COUNTING.with(|c| c.set(false));
    assert_eq!(allocs(), 0, "decoding camera frames allocated");
}
