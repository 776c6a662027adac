//! The central module's pose from Axel's circle marks (seed 000 §III.B).
//!
//! * Property tests: the rigid fit recovers random poses from noisy 3-D points (bounds
//!   stated below); the monocular pose recovers random planar poses through a distorted
//!   pin-hole and a fisheye lens, and ignoring the distortion does worse.
//! * Rendered frames: both Axel cameras rendered by the simulator from 1 m to as far as
//!   detection works, at several angles; detect → correspond → pose against the
//!   simulator's ground truth. Stereo must beat the paper (2.56 cm / 2.5° at 1 m,
//!   4.12 cm / 4.58° at 2 m); mono is reported. `cargo test --release --features sim
//!   --test sim circles_pose:: -- --nocapture` prints the table.
//!
//! Errors are of the module's pose in the rover frame: position = distance between the
//! estimated and true module origin (x, y on the ground), heading = the module's yaw, and
//! rotation = the angle of R̂ᵀR (all three axes).

use crate::common;
use common::axel::{facing, render};

use marsupial::geometry::Pose2;
use marsupial::perception::camera_model::{CameraModel, Fisheye, MountAngles, Pinhole};
use marsupial::perception::circles::{
    CircleDetector, CircleModel, CircleParams, CorrespondenceParams, LensPlane, MarkObservations, PoseBuffers,
    PoseParams, PoseSource, RigCamera, correspond_through, mono_pose, rigid_fit, stereo_pose,
};
use marsupial::sim::world;
use nalgebra::{Matrix3, Rotation3, Vector3};
use proptest::prelude::*;

fn wrap(a: f64) -> f64 {
    (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
}

/// Angle of the rotation taking `a` to `b`, degrees.
fn rot_err_deg(a: &Matrix3<f64>, b: &Matrix3<f64>) -> f64 {
    let c = ((a.transpose() * b).trace() - 1.0) / 2.0;
    c.clamp(-1.0, 1.0).acos().to_degrees()
}

fn xorshift(seed: u64) -> impl FnMut() -> f64 {
    let mut s = seed | 1;
    move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn axel_model() -> CircleModel {
    CircleModel::from_profile(&common::shipped_profile("axel")).expect("model")
}

fn model_points(m: &CircleModel) -> Vec<Vector3<f64>> {
    m.centres().iter().map(|c| Vector3::new(0.0, c[0], c[1])).collect()
}

/// RMS distance of the face points from their best line, m.
fn spread(pts: &[Vector3<f64>]) -> f64 {
    let n = pts.len() as f64;
    let c = pts.iter().sum::<Vector3<f64>>() / n;
    let (mut a, mut b, mut d) = (0.0, 0.0, 0.0);
    for p in pts {
        let q = p - c;
        a += q.y * q.y / n;
        b += q.y * q.z / n;
        d += q.z * q.z / n;
    }
    let h = 0.5 * (a + d);
    (h - (h * h - (a * d - b * b)).sqrt()).sqrt()
}

/// A camera 512 px focal length, 1024 × 768, at the rover-frame origin looking forward.
fn pinhole(k1: f64, k2: f64) -> Pinhole {
    Pinhole {
        fx: 512.0,
        fy: 512.0,
        cx: 512.0,
        cy: 384.0,
        k1,
        k2,
    }
}

/// The module `dist` m ahead of a forward camera, turned `yaw` about the vertical and
/// tilted `pitch`/`roll` (small), offset `side` m and `up` m: rover_from_module.
fn module_ahead(dist: f64, side: f64, up: f64, yaw: f64, pitch: f64, roll: f64) -> (Matrix3<f64>, Vector3<f64>) {
    let r = Rotation3::from_euler_angles(roll, pitch, std::f64::consts::PI + yaw);
    (*r.matrix(), Vector3::new(dist, side, up))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// Kabsch on the model's 8 (coplanar) marks and on random non-planar point sets,
    /// with every coordinate moved by up to ±σ (uniform, σ ≤ 1 cm). The fit maps the
    /// model's centroid onto the measured centroid, so the translation error *at the
    /// centroid* is the mean noise, at most σ√3; the rotation error is bounded by
    /// 4σ√3 over the points' spread across their best line (a lever-arm bound with a
    /// factor of 4 for the few-point worst case). Noise-free, the pose is exact, and the
    /// rotation is always proper (det = +1).
    #[test]
    fn the_rigid_fit_recovers_random_poses_from_noisy_points(
        ax in -1.0f64..1.0, ay in -1.0f64..1.0, az in -1.0f64..1.0, angle in -3.1f64..3.1,
        tx in -5.0f64..5.0, ty in -5.0f64..5.0, tz in -2.0f64..2.0,
        sigma in 0.0f64..0.01, planar in any::<bool>(), n in 4usize..12, seed in any::<u64>(),
    ) {
        let axis = Vector3::new(ax, ay, az);
        prop_assume!(axis.norm() > 0.1);
        let r = *Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), angle).matrix();
        let t = Vector3::new(tx, ty, tz);
        let mut u = xorshift(seed);
        let model: Vec<Vector3<f64>> = if planar {
            model_points(&axel_model())
        } else {
            (0..n).map(|_| Vector3::new(u() - 0.5, u() - 0.5, u() - 0.5)).collect()
        };
        let exact: Vec<Vector3<f64>> = model.iter().map(|m| r * m + t).collect();
        let (r0, t0) = rigid_fit(&model, &exact).expect("exact fit");
        prop_assert!((r0 - r).norm() < 1e-9 && (t0 - t).norm() < 1e-9);
        let noisy: Vec<Vector3<f64>> = exact
            .iter()
            .map(|p| p + Vector3::new(u() - 0.5, u() - 0.5, u() - 0.5) * (2.0 * sigma))
            .collect();
        let (rh, th) = rigid_fit(&model, &noisy).expect("noisy fit");
        prop_assert!((rh.determinant() - 1.0).abs() < 1e-9);
        prop_assert!((rh.transpose() * rh - Matrix3::identity()).norm() < 1e-9);
        let c = model.iter().sum::<Vector3<f64>>() / model.len() as f64;
        let terr = ((rh * c + th) - (r * c + t)).norm();
        prop_assert!(terr <= sigma * 3f64.sqrt() + 1e-12, "centroid error {terr} σ {sigma}");
        let lever = if planar { spread(&model) } else {
            // Smallest principal RMS extent of the cloud.
            let mut cov = Matrix3::zeros();
            for m in &model { cov += (m - c) * (m - c).transpose() / model.len() as f64; }
            cov.symmetric_eigenvalues().min().max(0.0).sqrt()
        };
        prop_assume!(lever > 0.05);
        let rerr = rot_err_deg(&rh, &r).to_radians();
        prop_assert!(rerr <= 4.0 * sigma * 3f64.sqrt() / lever + 1e-9, "rotation error {rerr} rad, σ {sigma}, spread {lever}");
    }

    /// The monocular pose through a pin-hole with barrel distortion (k1 −0.25 to −0.1,
    /// k2 up to 0.05) and up to ±σ = 0.3 px uniform noise, module 1–3.5 m ahead and up
    /// to 40° off square. Using the lens model, the module's origin is within
    /// 0.1 mm + 0.021 m·σ·d² and its rotation within 0.01° + 1.7°·σ·d² (σ in px, d in m).
    /// The error grows as σd² because the face's image shrinks as 1/d and a planar
    /// pose's depth and tilt are conditioned on its size squared; the constants are the
    /// worst of 390 000 random draws (0.0163 and 1.29) with a 30 % margin. At 3.5 m
    /// the face is about 120 px wide. On the same pixels without noise the lens model gives the pose to 0.1 mm,
    /// and treating them as undistorted is off by more than 2 mm (position plus rotation
    /// times distance) and reprojects worse. (With noise, the comparison is not a fair
    /// one: at 3 m, ±0.3 px moves the pose by about as much as k1 = −0.05 does.)
    #[test]
    fn the_mono_pose_recovers_planar_poses_through_a_distorted_lens(
        dist in 1.0f64..3.5, side in -0.4f64..0.4, up in -0.5f64..0.0,
        yaw in -0.7f64..0.7, pitch in -0.1f64..0.1, roll in -0.1f64..0.1,
        k1 in -0.25f64..-0.1, k2 in 0.0f64..0.05, noise in 0.0f64..0.3, seed in any::<u64>(),
    ) {
        let model = axel_model();
        let (r, t) = module_ahead(dist, side, up, yaw, pitch, roll);
        let lens = pinhole(k1, k2);
        let cam = RigCamera::new(CameraModel::Pinhole(lens), MountAngles::default(), [0.0; 3]);
        let ignorant = RigCamera::new(CameraModel::Pinhole(pinhole(0.0, 0.0)), MountAngles::default(), [0.0; 3]);
        let mut u = xorshift(seed);
        let mut obs = MarkObservations::new(model.len());
        let mut exact = MarkObservations::new(model.len());
        for (j, m) in model_points(&model).iter().enumerate() {
            let pc = cam.body_from_camera.transpose() * (r * m + t - cam.position);
            // Keep to where the distortion is monotonic and the image is.
            prop_assume!((pc.x / pc.z).hypot(pc.y / pc.z) < 0.9);
            let p = cam.project(&(r * m + t)).expect("in front");
            prop_assume!(p[0] > 0.0 && p[1] > 0.0 && p[0] < 1024.0 && p[1] < 768.0);
            exact.set(j, Some(p));
            obs.set(j, Some([p[0] + noise * (2.0 * u() - 1.0), p[1] + noise * (2.0 * u() - 1.0)]));
        }
        let mut buf = PoseBuffers::new();
        let params = PoseParams::default();
        let good = mono_pose(&model, &cam, 0, &obs, &params, &mut buf).expect("mono pose");
        let (ge, gr) = ((good.translation - t).norm(), rot_err_deg(&good.rotation, &r));
        let d2 = noise * dist * dist;
        prop_assert!(
            ge < 1e-4 + 0.021 * d2 && gr < 0.01 + 1.7 * d2,
            "with the lens model: {ge} m, {gr}° at {dist} m, σ {noise} px"
        );
        prop_assert!(good.reprojection_px < 1.0, "{}", good.reprojection_px);
        let good = mono_pose(&model, &cam, 0, &exact, &params, &mut buf).expect("mono pose");
        let bad = mono_pose(&model, &ignorant, 0, &exact, &params, &mut buf).expect("mono pose ignoring distortion");
        let ge = (good.translation - t).norm() + rot_err_deg(&good.rotation, &r).to_radians() * dist;
        let be = (bad.translation - t).norm() + rot_err_deg(&bad.rotation, &r).to_radians() * dist;
        prop_assert!(ge < 1e-4, "exact pixels with the lens model: {ge} m");
        prop_assert!(be > 0.002 && be > ge, "ignoring distortion {be} m vs {ge} m");
        prop_assert!(bad.reprojection_px > good.reprojection_px);
    }

    /// The same through an omnidirectional (Scaramuzza) lens, about 175 px focal length
    /// on axis, with up to ±σ = 0.2 px noise, module 1–2.5 m ahead: within
    /// 0.1 mm + 0.07 m·σ·d² and 0.01° + 6°·σ·d² (0.2 px is 1.1 mrad on this lens, three
    /// times the pin-hole's; the constants are the worst of 400 000 random draws, 0.055
    /// and 4.73, with a 30 % margin; at 2.5 m and 0.2 px that is 8.8 cm and 7.5°, and the
    /// worst drawn was 4.4 cm and 3.8°). On exact pixels the lens model gives the pose to 0.1 mm,
    /// and a pin-hole of the on-axis focal length is off by more than 1 cm.
    #[test]
    fn the_mono_pose_recovers_planar_poses_through_a_fisheye(
        dist in 1.0f64..2.5, side in -0.5f64..0.5, up in -0.6f64..0.0,
        yaw in -0.7f64..0.7, pitch in -0.1f64..0.1, noise in 0.0f64..0.2, seed in any::<u64>(),
    ) {
        let model = axel_model();
        let (r, t) = module_ahead(dist, side, up, yaw, pitch, 0.0);
        let fe = Fisheye::new(vec![-175.0, 0.0, 1.6e-3, -1.2e-6, 2.5e-9], [320.0, 240.0], [1.0, 0.0, 0.0], 800.0);
        let cam = RigCamera::new(CameraModel::Fisheye(fe), MountAngles::default(), [0.0; 3]);
        let ignorant = RigCamera::new(
            CameraModel::Pinhole(Pinhole { fx: 175.0, fy: 175.0, cx: 320.0, cy: 240.0, k1: 0.0, k2: 0.0 }),
            MountAngles::default(),
            [0.0; 3],
        );
        let mut u = xorshift(seed);
        let mut obs = MarkObservations::new(model.len());
        let mut exact = MarkObservations::new(model.len());
        for (j, m) in model_points(&model).iter().enumerate() {
            let p = cam.project(&(r * m + t)).expect("in view");
            exact.set(j, Some(p));
            obs.set(j, Some([p[0] + noise * (2.0 * u() - 1.0), p[1] + noise * (2.0 * u() - 1.0)]));
        }
        let mut buf = PoseBuffers::new();
        let params = PoseParams::default();
        let good = mono_pose(&model, &cam, 0, &obs, &params, &mut buf).expect("mono pose");
        let (ge, gr) = ((good.translation - t).norm(), rot_err_deg(&good.rotation, &r));
        let d2 = noise * dist * dist;
        prop_assert!(
            ge < 1e-4 + 0.07 * d2 && gr < 0.01 + 6.0 * d2,
            "with the lens model: {ge} m, {gr}° at {dist} m, σ {noise} px"
        );
        let good = mono_pose(&model, &cam, 0, &exact, &params, &mut buf).expect("mono pose");
        let ge = (good.translation - t).norm() + rot_err_deg(&good.rotation, &r).to_radians() * dist;
        prop_assert!(ge < 1e-4, "exact pixels with the lens model: {ge} m");
        // Ignoring the lens may also fail outright (a mark beyond 90° of the pin-hole).
        if let Ok(bad) = mono_pose(&model, &ignorant, 0, &exact, &params, &mut buf) {
            let be = (bad.translation - t).norm() + rot_err_deg(&bad.rotation, &r).to_radians() * dist;
            prop_assert!(be > 0.01, "ignoring distortion {be} m vs {ge} m");
        }
    }
}

/// Position (m), heading (°) and rotation (°) errors of `est` against the module's
/// true pose in the rover frame at robot pose `robot` (the module frame is the world's).
fn errors(est: &marsupial::perception::circles::ModulePose, robot: &Pose2) -> (f64, f64, f64) {
    let r = *Rotation3::from_axis_angle(&Vector3::z_axis(), -robot.theta).matrix();
    let t = r * Vector3::new(-robot.x, -robot.y, 0.0);
    let pos = (est.x() - t.x).hypot(est.y() - t.y);
    let heading = wrap(est.heading() - (-robot.theta)).to_degrees().abs();
    (pos, heading, rot_err_deg(&est.rotation, &r))
}

#[test]
fn rendered_stereo_pose_beats_the_paper_and_mono_is_reported() {
    let p = common::shipped_profile("axel");
    let w = world::build(&p, &[], &[]).expect("axel world");
    let model = CircleModel::from_profile(&p).expect("model");
    let cams = [
        RigCamera::from_profile(&p, 0).expect("left"),
        RigCamera::from_profile(&p, 1).expect("right"),
    ];
    // The rig with the right camera's yaw off by 0.1° (1.7 mrad, about 0.9 px): what a
    // small calibration error does, which the rendered frames otherwise do not have.
    let mut off = cams[1].clone();
    off.body_from_camera =
        *Rotation3::from_axis_angle(&Vector3::z_axis(), 0.1f64.to_radians()).matrix() * off.body_from_camera;
    let params = PoseParams::default();
    let mut dets: Vec<CircleDetector> = p
        .cameras
        .iter()
        .map(|s| CircleDetector::new(s.width_px, s.height_px, CircleParams::for_image(s.width_px)))
        .collect();
    let mut buf = PoseBuffers::new();
    // Labelled through each camera's lens, as the robot does.
    let mut lenses = [
        LensPlane::new(cams[0].model.clone()),
        LensPlane::new(cams[1].model.clone()),
    ];
    // (distance, α, turn); the paper's bound where it gives one.
    let distances = [1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0];
    let angles = [(0.0, 0.0), (20.0, 5.0), (-30.0, -8.0)];
    eprintln!(
        "{:>5} {:>5} {:>5} | {:>5} | {:>22} | {:>22} | {:>22}",
        "d m", "α °", "turn", "marks", "stereo cm / ° / ° / px", "mono L cm / ° / ° / px", "mono R cm / ° / ° / px"
    );
    let mut worst = std::collections::BTreeMap::<u32, [f64; 6]>::new();
    for &d in &distances {
        for (k, &(a, turn)) in angles.iter().enumerate() {
            let robot = facing(d, a, turn);
            let mut obs = [MarkObservations::new(model.len()); 2];
            for c in 0..2 {
                let im = render(&p, &w, c, &robot, 300 + 10 * k as u64 + (d * 100.0) as u64);
                let marks = dets[c].detect(&im.view()).expect("detect").to_vec();
                if let Ok(fit) = correspond_through(&model, &marks, &mut lenses[c], &CorrespondenceParams::default()) {
                    obs[c] = MarkObservations::from_fit(&fit, &marks);
                }
            }
            let cell = |r: Result<marsupial::perception::circles::ModulePose, _>| match r {
                Ok(pose) => {
                    let (e, h, rr) = errors(&pose, &robot);
                    (
                        format!("{:5.2} {:5.2} {:5.2} {:4.2}", 100.0 * e, h, rr, pose.reprojection_px),
                        Some((e, h, rr, pose)),
                    )
                }
                Err(_) => (format!("{:>22}", "—"), None),
            };
            let (s, st) = cell(stereo_pose(
                &model,
                [&cams[0], &cams[1]],
                [&obs[0], &obs[1]],
                &params,
                &mut buf,
            ));
            let (ml, _) = cell(mono_pose(&model, &cams[0], 0, &obs[0], &params, &mut buf));
            let (mr, _) = cell(mono_pose(&model, &cams[1], 1, &obs[1], &params, &mut buf));
            eprintln!(
                "{d:5.1} {a:5.0} {turn:5.0} | {:>2}/{:<2} | {s:>22} | {ml:>22} | {mr:>22}",
                obs[0].count(),
                obs[1].count()
            );
            let key = (d * 10.0) as u32;
            if let Some((e, h, rr, pose)) = st {
                assert_eq!(pose.source, PoseSource::Stereo);
                let w = worst.entry(key).or_insert([0.0; 6]);
                *w = [w[0].max(e), w[1].max(h), w[2].max(rr), w[3] + 1.0, w[4], w[5]];
                if let Ok(q) = stereo_pose(&model, [&cams[0], &off], [&obs[0], &obs[1]], &params, &mut buf) {
                    let (e, h, _) = errors(&q, &robot);
                    w[4] = w[4].max(e);
                    w[5] = w[5].max(h);
                }
            }
            // The paper's figures at 1 m and 2 m: stereo must beat them wherever it works,
            // and it must work there.
            let bound = match key {
                10 => Some((0.0256, 2.5)),
                20 => Some((0.0412, 4.58)),
                _ => None,
            };
            if let Some((be, bh)) = bound {
                let (e, h, _, _) = st.unwrap_or_else(|| panic!("no stereo pose at {d} m, α {a}°"));
                assert!(
                    e < be && h < bh,
                    "{d} m, α {a}°: {e:.4} m, {h:.2}° against {be} m, {bh}°"
                );
            }
        }
    }
    for (k, w) in &worst {
        eprintln!(
            "stereo at {:.1} m: worst position {:.2} cm, heading {:.2}°, rotation {:.2}° over {} poses; with the right camera's yaw off by 0.1°: {:.2} cm, {:.2}°",
            *k as f64 / 10.0,
            100.0 * w[0],
            w[1],
            w[2],
            w[3],
            100.0 * w[4],
            w[5]
        );
    }
}
