//! Bujold's perceptual schema (SCT segmentation of both colours, labelling, pairing,
//! adaptation) on 640×480 and 256×240 frames, with the per-stage split and the colour
//! space conversions for reference, and the search's frame-change cue. Targets (issue: colour perception): whole schema under
//! 1 ms at 640×480 and under 0.25 ms at 256×240, one core.
//!
//! RAPOSA's pyramid schema (HSV segmentation of both bands, ellipses, blue regions, pair
//! filters, geometry) on a rendered frame of the pyramid, at the profile's 160×120 and at
//! 640×480.
//!
//! Axel's circle fiducials (issue 16): detection, correspondence, the module's pose
//! (stereo triangulation and rigid fit; the monocular fallback), and the whole stereo
//! pipeline (detect, correspond and pose both frames), on rendered 640×480 frames of the
//! central module 1.5 m away, 15° off its axis, with the detection's stages apart (grey and
//! threshold, labelling, the Euler index). Target (issue 16): detection,
//! correspondence and pose for a stereo pair under 5 ms on one core.
//!
//! The AutoKrawler's stages so far (issue 17), on rendered 640×480 belly-fisheye frames:
//! the eight markers, roll/drop and steering from them (geometry), grey pyramids of two
//! frames (whole, and only around one tread window as the wheel stage builds them),
//! Shi–Tomasi corners in an 80×80 window on a tread, pyramidal Lucas–Kanade of those
//! corners to the next frame (wheels turned 3°) and of one wheel's corners with the wheel
//! stage's settings (LK per wheel), RANSAC over forty steps, the wheel stage, and the
//! whole estimate. Target (issue 17): the whole ten-DOF estimate under 5 ms.
//!
//! Run: `cargo bench --bench perception` (add `-- --quick` for a fast pass; `-- axel`
//! for the circle cases only).

use criterion::{Criterion, criterion_group, criterion_main};
use marsupial::geometry::Pose2;
use marsupial::perception::camera_model::CameraModel;
use marsupial::perception::{
    ColorRange, HsvPlanes, Labeler, Mask, SctPlanes, Segmenter, TwoBlockDetector, hsv_from_rgb, sct_from_rgb,
};
use marsupial::profile::Profile;
use marsupial::schemas::{PyramidSchema, TwoBlockSchema};
use marsupial::sim::camera::camera_pose;
use marsupial::sim::lighting::{LightState, LightingRun, LightingSpec};
use marsupial::sim::render::{Renderer, SensorParams};
use marsupial::sim::rng::Rng;
use marsupial::sim::world;
use std::hint::black_box;
use std::path::Path;

#[path = "../tests/common/mod.rs"]
mod common;

fn profile_at(w: usize, h: usize) -> Profile {
    let mut p = Profile::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/bujold.toml")).expect("profile");
    p.cameras[0].width_px = w;
    p.cameras[0].height_px = h;
    p
}

fn bench_size(c: &mut Criterion, w: usize, h: usize) {
    let frame = common::scene(w, h, 0.3, 1);
    let view = frame.view();
    let profile = profile_at(w, h);
    let mut schema = TwoBlockSchema::from_profile(&profile, 0).expect("schema");
    // Warm up into the adapted state, as on a real approach.
    for k in 0..5 {
        assert!(
            schema.process(&view, k as f64 * 0.1).expect("frame").found,
            "bench scene must contain the fiducial"
        );
    }
    let mut t = 1.0;
    let mut g = c.benchmark_group(format!("bujold_schema_{w}x{h}"));
    g.bench_function("whole_schema", |b| {
        b.iter(|| {
            t += 0.1;
            black_box(schema.process(black_box(&view), t).expect("frame"))
        })
    });
    // The search's frame-change cue (Bujold's jam detection), alternating two frames.
    let other = common::scene(w, h, 0.3, 2);
    let mut cue = marsupial::perception::frame_change::FrameChange::new();
    let mut flip = false;
    g.bench_function("frame_change_cue", |b| {
        b.iter(|| {
            flip = !flip;
            let v = if flip { other.view() } else { frame.view() };
            black_box(cue.observe(black_box(&v)))
        })
    });
    let ranges = schema.model().ranges();
    let cr = [ColorRange::Sct(ranges[0]), ColorRange::Sct(ranges[1])];
    let mut seg = Segmenter::new();
    let mut masks = [Mask::new(w, h), Mask::new(w, h)];
    g.bench_function("stage_1_segment_both_colours", |b| {
        b.iter(|| seg.segment(black_box(&view), &cr, &mut masks).expect("segment"))
    });
    let mut lab = [Labeler::new(w, h), Labeler::new(w, h)];
    g.bench_function("stage_2_label_both_masks", |b| {
        b.iter(|| {
            for (l, m) in lab.iter_mut().zip(&masks) {
                black_box(l.label(m).expect("label").len());
            }
        })
    });
    let mut det = TwoBlockDetector::new(w, h, *schema.detector().limits());
    g.bench_function("stages_1_to_3_detect", |b| {
        b.iter(|| black_box(det.detect(&view, &ranges).expect("detect")))
    });
    let pair = det.detect(&view, &ranges).expect("detect").expect("found");
    g.bench_function("stage_4_adaptation_statistics", |b| {
        b.iter(|| black_box(det.measure(&view, &pair)))
    });
    let mut sct = SctPlanes::new(w, h);
    g.bench_function("reference_sct_frame_fast_atan", |b| {
        b.iter(|| sct_from_rgb(&view, &mut sct).expect("sct"))
    });
    let mut hsv = HsvPlanes::new(w, h);
    g.bench_function("reference_hsv_frame", |b| {
        b.iter(|| hsv_from_rgb(&view, &mut hsv).expect("hsv"))
    });
    g.finish();
}

fn bench_pyramid(c: &mut Criterion, w: usize, h: usize) {
    let mut p = Profile::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/raposa.toml")).expect("profile");
    p.cameras[0].width_px = w;
    p.cameras[0].height_px = h;
    let world = world::build(&p, &[], &[]).expect("world");
    let cam = &p.cameras[0];
    // Camera 1.2 m from the ball, 20° off the pyramid axis, looking at it.
    let a = 20f64.to_radians();
    let robot = Pose2::new(
        1.2 * a.cos() - cam.mount.x_m * a.cos(),
        1.2 * a.sin() - cam.mount.x_m * a.sin(),
        a,
    );
    let mut r = Renderer::new(CameraModel::from_spec(cam), w, h, 1);
    let light = LightingRun::new(LightingSpec::default().resolve(), &mut Rng::new(1), 10.0);
    let mut frame = marsupial::perception::RgbImage::default();
    r.render(
        &world.scene,
        &camera_pose(&robot, &cam.mount),
        &light.at(0.0),
        &SensorParams::default(),
        1,
        &mut frame,
    );
    let view = frame.view();
    let mut schema = PyramidSchema::from_profile(&p, 0).expect("schema");
    assert!(
        schema.process(&view, 0.0).expect("frame").detection.pair.is_some(),
        "bench frame must show the pyramid"
    );
    let mut g = c.benchmark_group(format!("raposa_schema_{w}x{h}"));
    g.bench_function("whole_schema", |b| {
        b.iter(|| black_box(schema.process(black_box(&view), 0.0).expect("frame")))
    });
    // Adaptive mode also samples the pair's pixels and moves the bands every frame.
    let mut adaptive_profile = p.clone();
    adaptive_profile.perception.mode = marsupial::profile::SegmentationMode::Adaptive;
    let mut adaptive = PyramidSchema::from_profile(&adaptive_profile, 0).expect("schema");
    g.bench_function("whole_schema_adaptive", |b| {
        b.iter(|| black_box(adaptive.process(black_box(&view), 0.0).expect("frame")))
    });
    let bands = schema.detector().bands();
    let cr = [ColorRange::Hsv(bands[0]), ColorRange::Hsv(bands[1])];
    let mut seg = Segmenter::new();
    let mut masks = [Mask::new(w, h), Mask::new(w, h)];
    g.bench_function("stage_1_segment_both_bands", |b| {
        b.iter(|| seg.segment(black_box(&view), &cr, &mut masks).expect("segment"))
    });
    g.finish();
}

fn bench_circles(c: &mut Criterion) {
    use marsupial::perception::circles::{
        CircleDetector, CircleModel, CircleParams, CorrespondenceParams, LensPlane, MarkObservations, PoseBuffers,
        PoseParams, RigCamera, correspond, correspond_through, mono_pose, stereo_pose,
    };
    let (w, h) = (640, 480);
    let mut p = Profile::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/axel.toml")).expect("profile");
    for cam in &mut p.cameras {
        // The same lens on a smaller sensor: a fish-eye's polynomial and centre are in
        // pixels, so they scale with the width (ρ' = kρ: a_i' = a_i k^(1−i)).
        let k = w as f64 / cam.width_px as f64;
        if let Some(fe) = &mut cam.fisheye {
            for (i, a) in fe.poly.iter_mut().enumerate() {
                *a *= k.powi(1 - i as i32);
            }
            fe.center_px = fe.center_px.map(|c| c * k);
        }
        cam.width_px = w;
        cam.height_px = h;
    }
    let world = world::build(&p, &[], &[]).expect("world");
    let model = CircleModel::from_profile(&p).expect("model");
    let a = 15f64.to_radians();
    let robot = Pose2::new(1.5 * a.cos(), 1.5 * a.sin(), a + std::f64::consts::PI);
    let light = LightingRun::new(LightingSpec::default().resolve(), &mut Rng::new(1), 10.0);
    let frames: Vec<_> = p
        .cameras
        .iter()
        .map(|cam| {
            let mut r = Renderer::new(CameraModel::from_spec(cam), w, h, 1);
            let mut frame = marsupial::perception::RgbImage::default();
            for k in 0..4 {
                r.render(
                    &world.scene,
                    &camera_pose(&robot, &cam.mount),
                    &light.at(0.0),
                    &SensorParams::default(),
                    1 + k,
                    &mut frame,
                );
            }
            frame
        })
        .collect();
    let mut det = CircleDetector::new(w, h, CircleParams::for_image(w));
    let params = CorrespondenceParams::default();
    let cams = [
        RigCamera::from_profile(&p, 0).expect("left"),
        RigCamera::from_profile(&p, 1).expect("right"),
    ];
    // The robot labels through each camera's lens (`correspond_through`).
    let mut lenses = [
        LensPlane::new(cams[0].model.clone()),
        LensPlane::new(cams[1].model.clone()),
    ];
    for (f, lens) in frames.iter().zip(&mut lenses) {
        let marks = det.detect(&f.view()).expect("detect");
        assert_eq!(marks.len(), 8, "bench frames must show all eight marks");
        assert_eq!(
            correspond_through(&model, marks, lens, &params).expect("fit").inliers,
            8
        );
    }
    let marks = det.detect(&frames[0].view()).expect("detect").to_vec();
    let pose_params = PoseParams::default();
    let mut buf = PoseBuffers::new();
    let obs: Vec<MarkObservations> = frames
        .iter()
        .zip(&mut lenses)
        .map(|(f, lens)| {
            let m = det.detect(&f.view()).expect("detect");
            MarkObservations::from_fit(&correspond_through(&model, m, lens, &params).expect("fit"), m)
        })
        .collect();
    let stereo = stereo_pose(&model, [&cams[0], &cams[1]], [&obs[0], &obs[1]], &pose_params, &mut buf).expect("pose");
    assert_eq!(stereo.marks_used, 8, "bench frames must give an 8-mark stereo pose");
    let mut g = c.benchmark_group(format!("axel_circles_{w}x{h}"));
    g.bench_function("detect_one_frame", |b| {
        b.iter(|| black_box(det.detect(black_box(&frames[0].view())).expect("detect").len()))
    });
    // The detection's stages, each on the same frame with its own reusable buffers: the
    // grey image and both masks, labelling the black mask, the black blobs' Euler index.
    // What `detect_one_frame` spends beyond their sum is the blob filters, labelling the
    // white mask inside the black candidates' boxes, pairing and refinement. Labelling
    // the whole white mask too (as the detector did before it labelled only those boxes)
    // is read for comparison.
    {
        use marsupial::perception::circles::{RunIndex, Thresholder};
        let det_params = *det.params();
        det.detect(&frames[0].view()).expect("detect");
        let [black, white] = det.masks().clone();
        let mut thr = Thresholder::new(w, h);
        let (mut grey, mut bm, mut wm) = (Vec::with_capacity(w * h), Mask::new(w, h), Mask::new(w, h));
        g.bench_function("stage_grey_and_threshold", |b| {
            b.iter(|| {
                thr.apply_rgb_with(
                    black_box(&frames[0].view()),
                    &mut grey,
                    &det_params.threshold,
                    &mut bm,
                    &mut wm,
                );
                black_box(bm.data()[w * h / 2])
            })
        });
        let (mut lb, mut lw) = (Labeler::new(w, h), Labeler::new_four_connected(w, h));
        g.bench_function("stage_label_black_mask", |b| {
            b.iter(|| black_box(lb.label(black_box(&black)).expect("label").len()))
        });
        g.bench_function("label_both_whole_masks", |b| {
            b.iter(|| {
                let nb = lb.label(black_box(&black)).expect("label").len();
                black_box(nb + lw.label(black_box(&white)).expect("label").len())
            })
        });
        let mut index = RunIndex::new(w, h);
        lb.label(&black).expect("label");
        g.bench_function("stage_euler_index_black", |b| {
            b.iter(|| {
                index.build(black_box(&lb));
                black_box(index.euler(0))
            })
        });
    }
    g.bench_function("correspond_eight_marks", |b| {
        b.iter(|| black_box(correspond(&model, black_box(&marks), &params).expect("fit").inliers))
    });
    g.bench_function("correspond_eight_marks_through_lens", |b| {
        b.iter(|| {
            black_box(
                correspond_through(&model, black_box(&marks), &mut lenses[0], &params)
                    .expect("fit")
                    .inliers,
            )
        })
    });
    g.bench_function("pose_stereo", |b| {
        b.iter(|| {
            let p = stereo_pose(&model, [&cams[0], &cams[1]], [&obs[0], &obs[1]], &pose_params, &mut buf);
            black_box(p.expect("pose").marks_used)
        })
    });
    g.bench_function("pose_mono", |b| {
        b.iter(|| {
            black_box(
                mono_pose(&model, &cams[0], 0, &obs[0], &pose_params, &mut buf)
                    .expect("pose")
                    .marks_used,
            )
        })
    });
    g.bench_function("detect_and_correspond_stereo_pair", |b| {
        b.iter(|| {
            for (f, lens) in frames.iter().zip(&mut lenses) {
                let m = det.detect(black_box(&f.view())).expect("detect");
                black_box(correspond_through(&model, m, lens, &params).expect("fit").inliers);
            }
        })
    });
    g.bench_function("detect_correspond_and_pose_stereo_pair", |b| {
        let mut seen = [MarkObservations::new(model.len()); 2];
        b.iter(|| {
            for (k, f) in frames.iter().enumerate() {
                let m = det.detect(black_box(&f.view())).expect("detect");
                seen[k] = MarkObservations::from_fit(
                    &correspond_through(&model, m, &mut lenses[k], &params).expect("fit"),
                    m,
                );
            }
            let p = stereo_pose(
                &model,
                [&cams[0], &cams[1]],
                [&seen[0], &seen[1]],
                &pose_params,
                &mut buf,
            );
            black_box(p.expect("pose").translation)
        })
    });
    g.finish();
}

fn bench_krawler(c: &mut Criterion) {
    use marsupial::perception::flow::{CornerParams, GreyPyramid, LkParams, LucasKanade, Roi, ShiTomasi};
    use marsupial::perception::krawler::{AxleGeometry, ExpectedMarker, MarkerFinder, MarkerParams, SteeringPoly};
    use marsupial::sim::krawler::{KrawlerState, build};
    let p = Profile::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/autokrawler.toml")).expect("profile");
    let (w, h) = (p.cameras[0].width_px, p.cameras[0].height_px);
    let geometry = AxleGeometry::from_profile(&p, 0).expect("geometry");
    let polys = SteeringPoly::from_profile(&p).expect("calibrated");
    let pose = camera_pose(&Pose2::new(0.0, 0.0, 0.0), &p.cameras[0].mount);
    let rest = KrawlerState::rest(&p).expect("rest");
    let state = KrawlerState {
        roll: [0.05, -0.03],
        steer: [0.2, -0.1],
        ..rest
    };
    let mut r = Renderer::new(geometry.model.clone(), w, h, 1);
    let mut frames = [
        marsupial::perception::RgbImage::default(),
        marsupial::perception::RgbImage::default(),
    ];
    for (k, f) in frames.iter_mut().enumerate() {
        let turned = KrawlerState {
            wheel: [0.05 * k as f64; 4],
            ..state
        };
        let gear = build(&p, &turned).expect("gear");
        r.render(
            &gear.scene,
            &pose,
            &LightState::uniform(1.0),
            &SensorParams::default(),
            k as u64,
            f,
        );
    }
    let gear = build(&p, &state).expect("gear");
    let project = |q: [f64; 3]| geometry.model.project(&pose.to_camera(&nalgebra::Point3::from(q)));
    let expected: [ExpectedMarker; 8] = gear.markers.map(|m| {
        ExpectedMarker::from_square(project, m.coords.into(), [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], 0.03).expect("projects")
    });
    let mut finder = MarkerFinder::new(w, h, MarkerParams::default());
    let found = finder.find(&frames[0].view(), &expected).expect("find");
    assert_eq!(found.found(), 8, "bench frame must show all eight markers");
    let at = found.at.map(|a| a.expect("found"));
    // A tread window: around the front-left wheel's correction face at rest, projected.
    let tread = project(gear.correction[0].coords.into()).expect("tread projects");
    let roi = Roi::around(tread[0], tread[1], 40.0, w, h);
    let (mut pa, mut pb) = (GreyPyramid::new(3), GreyPyramid::new(3));
    pa.build_from_rgb(&frames[0].view());
    pb.build_from_rgb(&frames[1].view());
    let mut corners = ShiTomasi::new(w, h, CornerParams::default());
    let pts: Vec<[f64; 2]> = corners.detect(pa.level(0), roi).to_vec();
    let mut lk = LucasKanade::new(LkParams::default(), 100);
    let mut out = vec![None; pts.len()];
    let mut g = c.benchmark_group(format!("autokrawler_{w}x{h}"));
    g.bench_function("markers", |b| {
        b.iter(|| {
            black_box(
                finder
                    .find(black_box(&frames[0].view()), &expected)
                    .expect("find")
                    .found(),
            )
        })
    });
    g.bench_function("roll_drop_and_steering_both_axles", |b| {
        b.iter(|| {
            let mut s = 0.0;
            for (axle, poly) in polys.iter().enumerate() {
                let o = axle * 4;
                let ap = geometry.axle_pose(axle, at[o], at[o + 1]).expect("pose");
                let x = geometry.steering_ratio(&ap, [at[o + 2], at[o + 3]]).expect("ratio");
                s += ap.roll + ap.drop + poly.steer(x);
            }
            black_box(s)
        })
    });
    let mount = marsupial::perception::krawler::MountParams::default();
    let half_spacing = marsupial::perception::krawler::GearSpec::default().plate_marker_y_m;
    g.bench_function("mount_fit_four_plate_markers", |b| {
        b.iter(|| {
            let plate = [at[0], at[1], at[4], at[5]].map(Some);
            black_box(marsupial::perception::krawler::fit_mount(
                &geometry,
                black_box(plate),
                [(0.0, 0.25); 2],
                half_spacing,
                &mount,
            ))
        })
    });
    g.bench_function("grey_pyramids_two_frames", |b| {
        b.iter(|| {
            pa.build_from_rgb(black_box(&frames[0].view()));
            pb.build_from_rgb(black_box(&frames[1].view()));
        })
    });
    g.bench_function("corners_one_tread_window", |b| {
        b.iter(|| black_box(corners.detect(pa.level(0), roi).len()))
    });
    g.bench_function(format!("lk_checked_{}_points_one_wheel", pts.len()), |b| {
        b.iter(|| {
            lk.track_checked(&pa, &pb, black_box(&pts), &mut out);
            black_box(out.iter().filter(|o| o.is_some()).count())
        })
    });
    // The wheel stage's own settings: its corners in a 41×41 window and its tracker,
    // over pyramids built only around the window (grown by the stage's margin).
    let wp = marsupial::perception::krawler::WheelParams::default();
    let margin = wp.pyramid_margin_px.unwrap_or(0);
    let win = Roi::around(tread[0], tread[1], wp.window_half_px, w, h);
    let grown = Roi {
        x0: win.x0.saturating_sub(margin),
        y0: win.y0.saturating_sub(margin),
        x1: (win.x1 + margin).min(w),
        y1: (win.y1 + margin).min(h),
    };
    g.bench_function("grey_pyramids_two_frames_one_tread_window", |b| {
        b.iter(|| {
            pa.build_from_rgb_in(black_box(&frames[0].view()), &[grown]);
            pb.build_from_rgb_in(black_box(&frames[1].view()), &[grown]);
        })
    });
    let mut wheel_corners = ShiTomasi::new(w, h, wp.corners);
    let wheel_pts: Vec<[f64; 2]> = wheel_corners.detect(pa.level(0), win).to_vec();
    let mut wheel_lk = LucasKanade::new(wp.lk, wp.corners.max_corners);
    let mut wheel_out = vec![None; wheel_pts.len()];
    g.bench_function(
        format!("lk_per_wheel_checked_{}_points_wheel_params", wheel_pts.len()),
        |b| {
            b.iter(|| {
                wheel_lk.track_checked(&pa, &pb, black_box(&wheel_pts), &mut wheel_out);
                black_box(wheel_out.iter().filter(|o| o.is_some()).count())
            })
        },
    );
    bench_krawler_state(&mut g, &p, &frames);
    g.finish();
}

/// The wheel stage and the whole ten-DOF estimate on the two bench frames, alternated,
/// and RANSAC over forty steps.
fn bench_krawler_state(
    g: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    p: &Profile,
    frames: &[marsupial::perception::RgbImage; 2],
) {
    use marsupial::perception::krawler::{
        AxleGeometry, AxleState, GearGeometry, KrawlerParams, KrawlerStateSchema, SteeringPoly, WheelParams,
        WheelTracker, ransac_angle,
    };
    use marsupial::sim::krawler::{KrawlerState, expected_markers};
    let (w, h) = (p.cameras[0].width_px, p.cameras[0].height_px);
    let geometry = AxleGeometry::from_profile(p, 0).expect("geometry");
    let gear = marsupial::behaviors::krawler::gear_spec(p).expect("gear");
    let layout = GearGeometry::from_profile(p, gear).expect("layout").layout();
    let rest = KrawlerState::rest(p).expect("rest");
    let axles = [0, 1].map(|a| AxleState {
        roll: [0.05, -0.03][a],
        drop: rest.drop[a],
        steer: [0.2, -0.1][a],
    });
    let mut rng = Rng::new(1);
    let mut draw = move |n: usize| (rng.next_u64() % n as u64) as usize;
    let mut wheels = WheelTracker::new(w, h, layout, WheelParams::default());
    let mut k = 0;
    g.bench_function("wheel_stage_four_wheels_pyramid_corners_lk_ransac", |b| {
        b.iter(|| {
            k ^= 1;
            let s = wheels.update(black_box(&frames[k].view()), &geometry, &axles, &mut draw);
            black_box(s.iter().filter(|s| s.step.is_some()).count())
        })
    });
    let steps: Vec<f64> = (0..40)
        .map(|i| 0.05 + 0.0005 * ((i * 7) % 11) as f64 + if i % 5 == 0 { 0.3 } else { 0.0 })
        .collect();
    g.bench_function("ransac_40_steps", |b| {
        b.iter(|| black_box(ransac_angle(black_box(&steps), 0.01, 40, &mut draw)))
    });
    let mut schema = KrawlerStateSchema::new(
        (w, h),
        geometry.clone(),
        layout,
        SteeringPoly::from_profile(p).expect("calibrated"),
        KrawlerParams::default(),
        expected_markers(p, &rest).expect("markers"),
        [0, 1].map(|a| AxleState {
            roll: 0.0,
            drop: rest.drop[a],
            steer: 0.0,
        }),
    );
    g.bench_function("whole_ten_dof_estimate", |b| {
        b.iter(|| {
            k ^= 1;
            let e = schema
                .estimate(black_box(&frames[k].view()), &mut draw)
                .expect("estimate");
            black_box(e.wheel.iter().filter(|w| w.valid).count())
        })
    });
}

fn benches(c: &mut Criterion) {
    bench_krawler(c);
    bench_circles(c);
    bench_size(c, 640, 480);
    bench_size(c, 256, 240);
    bench_pyramid(c, 160, 120);
    bench_pyramid(c, 640, 480);
}

criterion_group!(perception, benches);
criterion_main!(perception);
