//! Axel's central module in the simulator: the eight circle fiducials appear where both
//! cameras of the stereo pair (fish-eye lenses) project them, with their pattern (black
//! core, white ring, black rim) and their bars turned as the profile places them; the
//! module stands outdoors.

use crate::common;

use marsupial::geometry::Pose2;
use marsupial::perception::RgbImage;
use marsupial::perception::camera_model::CameraModel;
use marsupial::profile::Profile;
use marsupial::sim::camera::camera_pose;
use marsupial::sim::lighting::LightState;
use marsupial::sim::render::Renderer;
use marsupial::sim::scene::Tag;
use marsupial::sim::world;
use nalgebra::Point3;

fn axel() -> Profile {
    common::shipped_profile("axel")
}

/// Grey level (green channel) at the pixel containing `px`.
fn level(im: &RgbImage, px: [f64; 2]) -> u8 {
    im.view().get(px[0] as usize, px[1] as usize).expect("in view")[1]
}

#[test]
fn both_cameras_see_every_circle_where_their_models_project_it() {
    let p = axel();
    let circles = p
        .fiducial
        .get::<marsupial::profile::CirclesSpec>()
        .cloned()
        .expect("axel has circles");
    let w = world::build(&p, &[], &[]).expect("axel world");
    assert_eq!(w.target_prims.len(), 1, "the marked face is the target");
    let radius = circles.diameter_m / 2.0;
    // 1.6 m out on the axis, a little to one side, facing the module.
    let robot = Pose2::new(1.6, 0.1, std::f64::consts::PI - 0.05);
    let mut centres_x = Vec::new();
    for cam in &p.cameras {
        let model = CameraModel::from_spec(cam);
        let mut r = Renderer::new(model.clone(), cam.width_px, cam.height_px, 1);
        let pose = camera_pose(&robot, &cam.mount);
        let mut im = RgbImage::default();
        r.render(
            &w.scene,
            &pose,
            &LightState::uniform(1.0),
            &common::quiet_sensor(),
            0,
            &mut im,
        );
        let project = |q: Point3<f64>| {
            let c = pose.rotation.transpose() * (q - pose.position);
            model.project(&c).expect("in front of the camera")
        };
        let mut xs = Vec::new();
        for (i, pl) in circles.placements.iter().enumerate() {
            let at = |along: f64, across: f64| {
                // Offsets in the face's (u = +y, v = +z) along and across the bar.
                let rot = pl.rotation_deg.to_radians();
                let (c, s) = (rot.cos(), rot.sin());
                Point3::new(0.0, pl.y_m + along * c - across * s, pl.z_m + along * s + across * c)
            };
            let centre = project(at(0.0, 0.0));
            // The pattern, read across and along the bar.
            let core = level(&im, project(at(0.0, 0.4 * radius)));
            let ring = level(&im, project(at(0.0, 0.7 * radius)));
            let rim = level(&im, project(at(0.0, -0.9 * radius)));
            let bar = level(&im, project(at(0.4 * radius, 0.0)));
            let margin = level(&im, project(at(0.0, 1.15 * radius)));
            assert!(core < 90 && rim < 90, "{} circle {i}: core {core}, rim {rim}", cam.name);
            assert!(
                ring > 170 && bar > 170 && margin > 170,
                "{} circle {i}: ring {ring}, bar {bar}, margin {margin}",
                cam.name
            );
            // The dark pixels' centroid is the projected centre (the pattern is symmetric
            // under a half turn), to within a pixel: through the fish-eye a mark is
            // imaged unevenly (measured worst 0.76 px at 1.6 m); the detector's ellipse fit,
            // not a centroid, finds the centre (0.38 px, `tests/circles_render.rs`).
            let reach = (project(at(0.0, 1.0 * radius))[1] - centre[1])
                .abs()
                .max((project(at(1.0 * radius, 0.0))[0] - centre[0]).abs())
                + 3.0;
            let dark = |p: [u8; 3]| {
                let d = 255.0 - p[1] as f64;
                if d > 60.0 { d } else { 0.0 }
            };
            let [cx, cy] = common::weighted_centroid(&im, centre, reach, dark).expect("dark pixels");
            assert!(
                (cx - centre[0]).abs() < 1.0 && (cy - centre[1]).abs() < 1.0,
                "{} circle {i}: centroid ({cx:.2}, {cy:.2}) vs projected ({:.2}, {:.2})",
                cam.name,
                centre[0],
                centre[1]
            );
            xs.push(centre[0]);
        }
        centres_x.push(xs);
    }
    // The pair's disparity: the left camera (+y) sees every circle further right.
    for (l, r) in centres_x[0].iter().zip(&centres_x[1]) {
        assert!(l - r > 50.0, "disparity {}", l - r);
    }
}

#[test]
fn the_module_body_blocks_starts_and_the_cone_is_its_dock() {
    let p = axel();
    let w = world::build(&p, &[], &[]).expect("axel world");
    let dock = w.dock;
    assert!(!dock.open && !dock.needs_lowered);
    assert_eq!(dock.entrance_half, p.dock.unwrap().entrance_width_m / 2.0);
    assert!(dock.body_half_width >= dock.entrance_half, "the mouth fits the face");
    let widest = p
        .fiducial
        .get::<marsupial::profile::CirclesSpec>()
        .unwrap()
        .placements
        .iter()
        .map(|q| q.y_m.abs())
        .fold(0.0, f64::max);
    assert!(dock.body_half_width > widest + 0.05, "every mark is on the face");
    // The module lies behind its face (x ≤ 0), within its footprint.
    for prim in w
        .scene
        .prims
        .iter()
        .filter(|q| matches!(q.tag, Tag::Body | Tag::Target))
    {
        for q in prim.bounds().as_slice() {
            assert!(q.x <= 1e-9 && q.x >= -dock.body_length - 1e-9, "{q:?}");
            assert!(q.y.abs() <= dock.body_half_width + 1e-9, "{q:?}");
        }
    }
}

#[test]
fn axel_stands_outdoors_with_seven_metre_starts_inside_the_world() {
    let p = axel();
    let w = world::build(&p, &[], &[]).expect("axel world");
    assert!(w.dock.cone.is_some(), "Axel's dock is the cone");
    // No backdrop (the room's walls) within 10 m: a 7 m start at 40° is well inside.
    for prim in w.scene.prims.iter().filter(|q| matches!(q.tag, Tag::Backdrop)) {
        for q in prim.bounds().as_slice() {
            assert!(q.x.abs().max(q.y.abs()) > 10.0, "{q:?}");
        }
    }
    let start = (7.0 * 40f64.to_radians().cos(), 7.0 * 40f64.to_radians().sin());
    assert!(start.0.abs().max(start.1.abs()) < 10.0);
}

/// The circle marks' detection range on the profile's cameras, measured: facing the
/// module on its axis and 20° off it, the marks each camera detects and labels at 3 to
/// 7 m (printed with `--nocapture`). The 10 cm marks span 2·651.9·0.05/d px across, 16 px
/// at 4 m, 12 px at 5.5 m and 9 px at 7 m; their rim is a fifth of the radius and the bar
/// a quarter. A far mark's rim is lost when the threshold window reaches past the mark's
/// bright ring and margin to the dark core and module face, which pull a blurred rim
/// pixel's local mean down to its own grey: the rim breaks (Euler number 1) and the mark
/// is dropped at the Euler filter. With one window of width/64 (17 px) no mark was found
/// from 4.5 m, with a 7-px window none from 5 m on the left camera; the 5-px window
/// (`CircleParams::for_image`) keeps the rims whole to 5.5 m (8/8 on the axis, 6/6 at
/// 20°). At 6 m the rim (1.1 px) breaks at its blurred top and bottom even so. Asserted:
/// every camera labels at least 5 marks (enough for a pose) to 5.5 m, on the axis and
/// at 20°.
#[test]
fn the_marks_are_detected_to_the_range_the_behavior_plans_within() {
    use marsupial::perception::circles::{
        CircleDetector, CircleModel, CircleParams, CorrespondenceParams, LensPlane, RigCamera, correspond_through,
    };
    let p = axel();
    let w = world::build(&p, &[], &[]).expect("axel world");
    let model = CircleModel::from_profile(&p).expect("model");
    let mut dets: Vec<CircleDetector> = p
        .cameras
        .iter()
        .map(|c| CircleDetector::new(c.width_px, c.height_px, CircleParams::for_image(c.width_px)))
        .collect();
    // Labelled through each camera's lens, as the robot does.
    let mut lenses: Vec<LensPlane> = (0..p.cameras.len())
        .map(|c| LensPlane::new(RigCamera::from_profile(&p, c).expect("camera").model))
        .collect();
    for alpha in [0.0, 20.0] {
        for d in [3.0, 4.0, 4.5, 5.0, 5.5, 6.0, 7.0] {
            let robot = common::axel::facing(d, alpha, 0.0);
            let mut labelled = [0usize; 2];
            for (cam, det) in dets.iter_mut().enumerate() {
                let im = common::axel::render(&p, &w, cam, &robot, 7 + cam as u64);
                let marks = det.detect(&im.view()).expect("detect");
                labelled[cam] = correspond_through(&model, marks, &mut lenses[cam], &CorrespondenceParams::default())
                    .map_or(0, |f| f.inliers);
            }
            eprintln!(
                "{d} m, α {alpha}°: marks labelled left {}, right {}",
                labelled[0], labelled[1]
            );
            if d <= 5.5 {
                assert!(
                    labelled.iter().all(|&n| n >= 5),
                    "{d} m, α {alpha}°: {labelled:?} marks labelled"
                );
            }
        }
    }
}

/// A false mark painted on the face among the real ones (`world::build_face`), the
/// paper's hard case (seed 000 §V-D): the detector finds it where it is painted, the
/// correspondence leaves it unlabelled beside 5 true marks and refuses 4 true marks with
/// it, from both cameras and two poses.
#[test]
fn a_false_mark_painted_among_the_marks_is_drawn_and_never_labelled() {
    use marsupial::perception::circles::{
        CircleDetector, CircleModel, CircleParams, CorrespondenceError, CorrespondenceParams, LensPlane, RigCamera,
        correspond_through,
    };
    use marsupial::profile::CirclePlacement;
    let p = axel();
    let model = CircleModel::from_profile(&p).expect("model");
    // Among the marks, at least 3 radii from every one of them.
    let false_mark = CirclePlacement {
        y_m: 0.12,
        z_m: 0.62,
        rotation_deg: 90.0,
    };
    for (covered, labelled) in [(&[2usize, 3, 4][..], Some(5)), (&[0, 2, 3, 4][..], None)] {
        let w = world::build_face(&p, &[], &[], covered, &[false_mark]).expect("axel world");
        for (k, robot) in [
            common::axel::facing(2.0, 0.0, 0.0),
            common::axel::facing(2.5, 20.0, 3.0),
        ]
        .iter()
        .enumerate()
        {
            for cam in 0..p.cameras.len() {
                let spec = &p.cameras[cam];
                let rig = RigCamera::from_profile(&p, cam).expect("camera");
                let mut det =
                    CircleDetector::new(spec.width_px, spec.height_px, CircleParams::for_image(spec.width_px));
                let im = common::axel::render(&p, &w, cam, robot, 50 + k as u64);
                let marks = det.detect(&im.view()).expect("detect").to_vec();
                let label = format!("camera {cam}, pose {k}, covered {covered:?}");
                assert_eq!(marks.len(), 8 - covered.len() + 1, "{label}: {marks:?}");
                // The false mark is detected where it is painted.
                let pose = camera_pose(robot, &spec.mount);
                let q = Point3::new(0.0, false_mark.y_m, false_mark.z_m);
                let px = rig
                    .model
                    .project(&(pose.rotation.transpose() * (q - pose.position)))
                    .expect("in view");
                assert!(
                    marks
                        .iter()
                        .any(|m| (m.centre[0] - px[0]).hypot(m.centre[1] - px[1]) < 1.0),
                    "{label}: nothing detected at {px:?}"
                );
                let mut lens = LensPlane::new(rig.model.clone());
                let res = correspond_through(&model, &marks, &mut lens, &CorrespondenceParams::default());
                match labelled {
                    Some(n) => {
                        let fit = res.unwrap_or_else(|e| panic!("{label}: {e}"));
                        assert_eq!(fit.inliers, n, "{label}");
                        assert_eq!((0..marks.len()).filter(|&i| !fit.is_inlier(i)).count(), 1, "{label}");
                    }
                    None => assert!(
                        matches!(res, Err(CorrespondenceError::NoConsistentFit { .. })),
                        "{label}: {res:?}"
                    ),
                }
            }
        }
    }
}
