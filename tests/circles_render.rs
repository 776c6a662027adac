//! Axel's circle fiducials on rendered frames: from several poses, both cameras of the
//! stereo pair find every mark that is wholly in view, read its rotation, and label it
//! by the correspondence search; the centroid error against the camera model's projection
//! of the mark's centre is stated (printed with `--nocapture`) and bounded here.
//!
//! Range: on the profile's 1024-px, 90° cameras the poses here keep every mark's radius
//! at 10 px or more. Below that (about 2.6 m at 30° off the face, 3 m at 25°) the rim,
//! 0.2 of the radius, is under 2 px and foreshortened, anti-aliasing leaves it mid-grey,
//! and some marks are missed: short of the paper's "discernable from 5 m".

use crate::common;
use common::axel::{facing, render as render_frame, render_lit};

use marsupial::geometry::Pose2;
use marsupial::perception::camera_model::CameraModel;
use marsupial::perception::circles::RunIndex;
use marsupial::perception::circles::{
    CircleDetector, CircleModel, CircleParams, CorrespondenceParams, FixedThreshold, LensPlane, MarkRotation,
    Threshold, correspond_through,
};
use marsupial::perception::{Labeler, RgbImage};
use marsupial::profile::Profile;
use marsupial::sim::camera::camera_pose;
use marsupial::sim::lighting::{LightState, ShadowBand};
use marsupial::sim::world;
use nalgebra::Point3;

/// A mark's projected centre and outer radius, px.
type Seen = ([f64; 2], f64);

/// Camera `cam` of `p` at robot pose `robot`: the frame (the default sensor, with noise,
/// after four frames of auto-exposure) and each mark's projected centre and outer radius,
/// px (`None` when the mark with its margin is not wholly in view).
fn render(p: &Profile, w: &world::World, cam: usize, robot: &Pose2, seed: u64) -> (RgbImage, Vec<Option<Seen>>) {
    let im = render_frame(p, w, cam, robot, seed);
    let spec = &p.cameras[cam];
    let model = CameraModel::from_spec(spec);
    let pose = camera_pose(robot, &spec.mount);
    let circles = p.fiducial.get::<marsupial::profile::CirclesSpec>().expect("circles");
    let radius = circles.diameter_m / 2.0;
    let project = |q: Point3<f64>| model.project(&(pose.rotation.transpose() * (q - pose.position)));
    let truth = circles
        .placements
        .iter()
        .map(|pl| {
            let c = project(Point3::new(0.0, pl.y_m, pl.z_m))?;
            // The mark with its margin, sampled round its rim.
            let mut rad: f64 = 0.0;
            for k in 0..16 {
                let t = k as f64 * std::f64::consts::TAU / 16.0;
                let q = project(Point3::new(
                    0.0,
                    pl.y_m + 1.3 * radius * t.cos(),
                    pl.z_m + 1.3 * radius * t.sin(),
                ))?;
                let inside =
                    q[0] > 2.0 && q[1] > 2.0 && q[0] < spec.width_px as f64 - 2.0 && q[1] < spec.height_px as f64 - 2.0;
                if !inside {
                    return None;
                }
                rad = rad.max((q[0] - c[0]).hypot(q[1] - c[1]) / 1.3);
            }
            Some((c, rad))
        })
        .collect();
    (im, truth)
}

#[test]
fn every_visible_mark_is_found_labelled_and_centred_from_several_poses() {
    let p = common::shipped_profile("axel");
    let w = world::build(&p, &[], &[]).expect("axel world");
    let model = CircleModel::from_profile(&p).expect("model");
    let rotations: Vec<MarkRotation> = model.rotations().to_vec();
    let poses = [
        (1.2, 0.0, 0.0),
        (2.0, 15.0, 0.0),
        (2.5, -25.0, 5.0),
        (2.2, 30.0, -8.0),
        (1.6, -35.0, 10.0),
    ];
    let mut worst: f64 = 0.0;
    let mut found_total = 0;
    for (k, &(d, a, t)) in poses.iter().enumerate() {
        let robot = facing(d, a, t);
        for cam in 0..p.cameras.len() {
            let (im, truth) = render(&p, &w, cam, &robot, 100 + k as u64);
            let spec = &p.cameras[cam];
            let mut det = CircleDetector::new(spec.width_px, spec.height_px, CircleParams::for_image(spec.width_px));
            let marks = det.detect(&im.view()).expect("detect").to_vec();
            let label = format!("{} at {d} m, α {a}°, turned {t}°", spec.name);
            let visible = truth.iter().filter(|t| t.is_some()).count();
            assert!(visible >= 5, "{label}: only {visible} marks in view: pick another pose");
            // Every visible mark is detected once, near its projected centre, with its
            // rotation; nothing else is detected.
            let mut err_max: f64 = 0.0;
            let mut bar_max: f64 = 0.0;
            for (j, tr) in truth.iter().enumerate() {
                let Some((c, rad)) = tr else { continue };
                let near: Vec<_> = marks
                    .iter()
                    .filter(|m| (m.centre[0] - c[0]).hypot(m.centre[1] - c[1]) < 0.5 * rad)
                    .collect();
                assert_eq!(
                    near.len(),
                    1,
                    "{label}: mark {j} at {c:?} (radius {rad:.1} px): {near:?}"
                );
                let m = near[0];
                let e = (m.centre[0] - c[0]).hypot(m.centre[1] - c[1]);
                err_max = err_max.max(e);
                let d = (m.bar_angle_deg - rotations[j].degrees() + 90.0).rem_euclid(180.0) - 90.0;
                bar_max = bar_max.max(d.abs());
                assert_eq!(
                    m.rotation,
                    Some(rotations[j]),
                    "{label}: mark {j} (radius {rad:.1} px): {m:?}"
                );
            }
            assert_eq!(marks.len(), visible, "{label}: {marks:?}");
            // The correspondence labels each one, through the camera's lens as the robot does.
            let mut lens = LensPlane::new(CameraModel::from_spec(spec));
            let fit = correspond_through(&model, &marks, &mut lens, &CorrespondenceParams::default()).expect(&label);
            assert_eq!(fit.inliers, visible, "{label}");
            for (j, tr) in truth.iter().enumerate() {
                let Some((c, _)) = tr else { continue };
                let i = fit.detection_of(j).expect("labelled");
                let m = &marks[i];
                assert!(
                    (m.centre[0] - c[0]).hypot(m.centre[1] - c[1]) < 2.0,
                    "{label}: mark {j} labelled {i}"
                );
            }
            eprintln!(
                "{label}: {visible} marks, centroid error ≤ {err_max:.3} px, bar angle error ≤ {bar_max:.1}°, reprojection RMS {:.3} px, hypothesis {} of {}",
                fit.rms_px, fit.hypothesis, fit.hypotheses_tried
            );
            assert!(bar_max < 10.0, "{label}: bar angle error {bar_max:.1}°");
            worst = worst.max(err_max);
            found_total += visible;
        }
    }
    eprintln!("worst centroid error over {found_total} marks: {worst:.3} px");
    assert!(worst < 0.5, "worst centroid error {worst:.3} px");
}

#[test]
fn a_frame_without_the_module_has_no_marks() {
    let p = common::shipped_profile("axel");
    let w = world::build(&p, &[], &[]).expect("axel world");
    // Facing away from the module.
    let robot = Pose2::new(3.0, 0.5, 0.3);
    let (im, _) = render(&p, &w, 0, &robot, 7);
    let spec = &p.cameras[0];
    let mut det = CircleDetector::new(spec.width_px, spec.height_px, CircleParams::for_image(spec.width_px));
    assert!(det.detect(&im.view()).expect("detect").is_empty());
}

/// Full light with the `axel-lighting` campaign's shadow on the module's face: a hard
/// edge through the face's centre whose normal, in face coordinates (a, b) = (y, z − the
/// face's centre), points 30° up from +y, taking 80 % of the light on one side, with a
/// 2 cm penumbra.
fn campaign_shadow() -> LightState {
    let mut light = LightState::uniform(1.0);
    let (s, c) = 150f32.to_radians().sin_cos();
    light.push_target_shadow(ShadowBand {
        cos: c,
        sin: s,
        offset: 0.0,
        softness: 0.02,
        strength: 0.8,
    });
    light
}

/// Seed 000 §V-E: an intense uneven shadow across the module's face defeated the paper's
/// fixed thresholds (8 of 15 docks against 21 of 25 in uniform light). A hard shadow edge
/// across the face, taking 80 % of the light from its lower-left part: the adaptive
/// threshold still finds every mark in view, in the shade and in the light, where fixed
/// levels that find every mark in uniform light lose the shaded ones.
#[test]
fn a_shadow_across_the_face_defeats_fixed_levels_but_not_the_adaptive_threshold() {
    let p = common::shipped_profile("axel");
    let w = world::build(&p, &[], &[]).expect("axel world");
    let shadowed = campaign_shadow();
    let uniform = LightState::uniform(1.0);
    // Fixed levels as the paper chose its own, from frames in even light: black well
    // below the face's grey, white well above it.
    let fixed = Threshold::Fixed(FixedThreshold {
        black_below: 70,
        white_above: 150,
    });
    let (mut adaptive_shade, mut fixed_shade, mut fixed_even, mut visible_total) = (0, 0, 0, 0);
    for (k, &(d, a)) in [(1.8, 0.0), (2.4, 15.0), (2.0, -20.0)].iter().enumerate() {
        let robot = facing(d, a, 0.0);
        for cam in 0..p.cameras.len() {
            let spec = &p.cameras[cam];
            let (_, truth) = render(&p, &w, cam, &robot, 0);
            let visible = truth.iter().filter(|t| t.is_some()).count();
            let adaptive = CircleParams::for_image(spec.width_px);
            let fixed = CircleParams {
                threshold: fixed,
                ..adaptive
            };
            let count = |params: CircleParams, light: &LightState| {
                let im = render_lit(&p, &w, cam, &robot, 300 + k as u64, light);
                let mut det = CircleDetector::new(spec.width_px, spec.height_px, params);
                det.detect(&im.view()).expect("detect").len()
            };
            let label = format!("{} at {d} m, α {a}°", spec.name);
            let (a_shade, f_shade, f_even) = (
                count(adaptive, &shadowed),
                count(fixed, &shadowed),
                count(fixed, &uniform),
            );
            eprintln!(
                "{label}: {visible} marks in view; adaptive under the shadow {a_shade}, fixed under the shadow {f_shade}, fixed in even light {f_even}"
            );
            assert_eq!(a_shade, visible, "{label}: the adaptive threshold under the shadow");
            assert_eq!(f_even, visible, "{label}: fixed levels in even light");
            adaptive_shade += a_shade;
            fixed_shade += f_shade;
            fixed_even += f_even;
            visible_total += visible;
        }
    }
    eprintln!(
        "of {visible_total} marks in view: adaptive under the shadow {adaptive_shade}, fixed {fixed_shade} (in even light {fixed_even})"
    );
    assert!(
        fixed_shade + visible_total / 4 <= visible_total,
        "fixed levels lost only {} of {visible_total} marks under the shadow",
        visible_total - fixed_shade
    );
}

/// The shadow of `a_shadow_across_the_face_…` as the `axel-lighting` campaign casts it,
/// from the docking range in: the shipped detector finds under the shadow every mark it
/// finds in even light. Nearer than 1.4 m the shaded rims are pitted with pinholes (the
/// camera's gamma stretches dark noise), and without filling them
/// ([`CircleParams::max_pinhole_px`] 0) the Euler filter loses marks there: the README's
/// figures (`cargo test --release --test sim circles_render::under_the_shadow -- --nocapture`).
#[test]
fn under_the_shadow_every_mark_is_found_once_pinholes_are_filled() {
    let p = common::shipped_profile("axel");
    let w = world::build(&p, &[], &[]).expect("axel world");
    let shadowed = campaign_shadow();
    let uniform = LightState::uniform(1.0);
    let (mut lost_unfilled, mut visible) = (0, 0);
    let mut holes = RimHoles::default();
    for seed in [300, 301] {
        for d in [1.0, 1.1, 1.2, 1.4, 1.6, 2.0] {
            let robot = facing(d, 0.0, 0.0);
            for cam in 0..p.cameras.len() {
                let spec = &p.cameras[cam];
                let shipped = CircleParams::for_image(spec.width_px);
                let unfilled = CircleParams {
                    max_pinhole_px: 0,
                    ..shipped
                };
                let count = |params: CircleParams, im: &RgbImage| {
                    let mut det = CircleDetector::new(spec.width_px, spec.height_px, params);
                    det.detect(&im.view()).expect("detect").len()
                };
                let even = count(shipped, &render_lit(&p, &w, cam, &robot, seed, &uniform));
                let shaded = render_lit(&p, &w, cam, &robot, seed, &shadowed);
                let (kept, unfilled) = (count(shipped, &shaded), count(unfilled, &shaded));
                if d <= 1.2 {
                    holes.add(&shaded, shipped);
                }
                visible += even;
                let label = format!("{} at {d} m, seed {seed}", spec.name);
                eprintln!(
                    "{label}: {even} marks found in even light; under the shadow {kept}, and {unfilled} without filling pinholes"
                );
                assert!(even >= 4, "{label}: only {even} marks in even light");
                assert_eq!(kept, even, "{label}: the shipped detector under the shadow");
                lost_unfilled += even - unfilled.min(even);
            }
        }
    }
    eprintln!("without filling pinholes, {lost_unfilled} of {visible} marks lost under the shadow");
    // What pits the near rims (the README's and `CircleParams::for_image`'s figures).
    let other = holes.holes - holes.rims; // every rim's one hole is its white ring
    let share = |n: usize| 100.0 * n as f64 / other as f64;
    eprintln!(
        "at 1.0-1.2 m under the shadow, {} rims: {:.1} holes each besides the ring, {} with more than −3…0 allows; of those holes {:.0} % of 1 px, {:.0} % of 2-3 px, {:.0} % of 4-5 px, {:.0} % larger",
        holes.rims,
        other as f64 / holes.rims as f64,
        holes.over,
        share(holes.up_to[0]),
        share(holes.up_to[1] - holes.up_to[0]),
        share(holes.up_to[2] - holes.up_to[1]),
        share(other - holes.up_to[2]),
    );
    assert!(holes.rims >= 40, "{} rims measured", holes.rims);
    assert!(holes.over * 10 >= holes.rims, "a tenth of the rims or more fail −3…0");
    assert!(share(holes.up_to[0]) >= 80.0, "mostly single pixels");
    assert!(share(holes.up_to[2]) >= 95.0, "nearly all within 5 px");
    assert!(
        lost_unfilled >= 4,
        "pinholes cost {lost_unfilled} marks: the shadow no longer tests them"
    );
}

/// Hole counts of the black rims of the marks a detector finds: every hole (1 − the Euler
/// number) and those of at most 1, 3 and 5 px ([`RunIndex::pinholes`]).
#[derive(Default)]
struct RimHoles {
    rims: usize,
    /// Rims with more holes than −3…0 allows (4 or more besides the ring).
    over: usize,
    holes: usize,
    up_to: [usize; 3],
}

impl RimHoles {
    /// Detects the marks of `im` with `params` and adds their rims' holes.
    fn add(&mut self, im: &RgbImage, params: CircleParams) {
        let (w, h) = (im.width(), im.height());
        let mut det = CircleDetector::new(w, h, params);
        let marks = det.detect(&im.view()).expect("detect").to_vec();
        let black = &det.masks()[0];
        let mut labeler = Labeler::new(w, h);
        labeler.label(black).expect("label");
        let mut index = RunIndex::new(w, h);
        index.build(&labeler);
        let mut fill = Vec::new();
        for m in &marks {
            // A point a tenth of the way in from the rim's outer edge is the rim's.
            let e = &m.ellipse;
            let edge = e.point(0.0);
            let (x, y) = (
                (e.centre[0] + 0.9 * (edge[0] - e.centre[0])) as u32,
                (e.centre[1] + 0.9 * (edge[1] - e.centre[1])) as u32,
            );
            let Some(rim) = (0..labeler.components().len()).find(|&l| index.contains(&labeler, l, x, y)) else {
                continue;
            };
            self.rims += 1;
            let holes = (1 - index.euler(rim)) as usize;
            self.holes += holes;
            self.over += usize::from(holes > 4);
            for (k, max) in [1, 3, 5].into_iter().enumerate() {
                self.up_to[k] += index.pinholes(&labeler, black, rim, max, &mut fill) as usize;
            }
        }
    }
}
