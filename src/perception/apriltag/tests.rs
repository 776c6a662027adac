//! The detector on rendered frames: ids, corners and poses against the truth, the
//! rejections a schema relies on, and frames that must give nothing.

use super::*;
use crate::perception::RgbImage;
use crate::perception::camera_model::Pinhole;
use nalgebra::{Matrix3, Rotation3, Vector3};

const SIZE: f64 = 0.16;

fn camera() -> Pinhole {
    Pinhole::ideal(600.0, 640, 480)
}

/// camera_from_tag for a tag facing the camera, then turned by yaw (about the tag's
/// up axis), pitch (about its right axis) and roll (about its normal), degrees.
fn facing(yaw: f64, pitch: f64, roll: f64) -> Matrix3<f64> {
    let base = Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, -1.0));
    let turn = Rotation3::from_axis_angle(&Vector3::y_axis(), yaw.to_radians())
        * Rotation3::from_axis_angle(&Vector3::x_axis(), pitch.to_radians())
        * Rotation3::from_axis_angle(&Vector3::z_axis(), roll.to_radians());
    base * turn.into_inner()
}

fn frame(cam: &Pinhole, id: u32, r: &Matrix3<f64>, t: &Vector3<f64>, bg: u8) -> RgbImage {
    let mut im = RgbImage::new(640, 480);
    im.fill([bg; 3]);
    let tag = TagSprite {
        family: TagFamily::Tag36h11,
        id,
        size_m: SIZE,
        supersample: 4,
    };
    assert!(draw_tag(&mut im, cam, &tag, r, t));
    im
}

fn angle_deg(a: &Matrix3<f64>, b: &Matrix3<f64>) -> f64 {
    Rotation3::from_matrix_unchecked(a.transpose() * b).angle().to_degrees()
}

fn detector() -> AprilTagDetector {
    AprilTagDetector::new(AprilTagParams {
        tag_size_m: SIZE,
        ..AprilTagParams::default()
    })
}

#[test]
fn poses_at_one_metre_are_within_a_centimetre_and_a_degree() {
    let cam = camera();
    let mut det = detector();
    let mut worst = (0.0f64, 0.0f64);
    let cases: [(f64, f64, f64, [f64; 2]); 7] = [
        (0.0, 0.0, 0.0, [0.0, 0.0]),
        (0.0, 0.0, 37.0, [0.1, -0.05]),
        (30.0, 0.0, 0.0, [-0.15, 0.0]),
        (-40.0, 10.0, 5.0, [0.2, 0.1]),
        (15.0, -25.0, -60.0, [0.0, 0.12]),
        (50.0, 0.0, 180.0, [-0.1, -0.1]),
        (-20.0, 20.0, 95.0, [0.25, -0.15]),
    ];
    for (i, (yaw, pitch, roll, off)) in cases.into_iter().enumerate() {
        let r = facing(yaw, pitch, roll);
        let t = Vector3::new(off[0], off[1], (1.0 - off[0] * off[0] - off[1] * off[1]).sqrt());
        let id = (37 * i as u32) % 587;
        let im = frame(&cam, id, &r, &t, 120);
        let found = det.detect(&im.view(), &cam).unwrap();
        assert_eq!(found.len(), 1, "case {i}: {found:?}");
        let d = found[0];
        assert_eq!(d.id, id, "case {i}");
        assert_eq!(d.hamming, 0);
        // The corners come in the tag's own order.
        let truth = project_corners(&cam, &r, &t, SIZE).unwrap();
        for (c, q) in d.corners.iter().zip(&truth) {
            let e = (c[0] - q[0]).hypot(c[1] - q[1]);
            assert!(e < 0.3, "case {i}: corner {c:?} vs {q:?}");
        }
        let pose = d.pose.expect("pose");
        let (dp, da) = ((pose.translation - t).norm(), angle_deg(&pose.rotation, &r));
        assert!(dp < 0.01 && da < 1.0, "case {i}: {dp} m, {da}°");
        worst = (worst.0.max(dp), worst.1.max(da));
        assert!(pose.reprojection_px < 0.3, "case {i}: {}", pose.reprojection_px);
    }
    eprintln!("worst at 1 m: {:.2} mm, {:.3}°", worst.0 * 1e3, worst.1);
}

#[test]
fn tags_are_found_from_half_a_metre_to_four_metres() {
    let cam = camera();
    let mut det = detector();
    for (z, yaw) in [(0.5, 20.0), (2.0, -30.0), (3.0, 0.0), (4.0, 10.0)] {
        let (r, t) = (facing(yaw, 5.0, 10.0), Vector3::new(0.05, -0.03, z));
        let found = det.detect(&frame(&cam, 300, &r, &t, 160).view(), &cam).unwrap();
        assert_eq!(found.len(), 1, "at {z} m");
        assert_eq!(found[0].id, 300);
        let pose = found[0].pose.unwrap();
        // Relative errors stay within 1 % of the range.
        assert!(
            (pose.translation - t).norm() < 0.01 * z,
            "at {z} m: {:?}",
            pose.translation
        );
    }
}

#[test]
fn the_covariance_follows_the_corner_noise_and_the_range() {
    let cam = camera();
    let r = facing(20.0, 0.0, 0.0);
    let near = tag_pose(
        &project_corners(&cam, &r, &Vector3::new(0.0, 0.0, 1.0), SIZE).unwrap(),
        &cam,
        SIZE,
        0.5,
    )
    .unwrap();
    let far = tag_pose(
        &project_corners(&cam, &r, &Vector3::new(0.0, 0.0, 3.0), SIZE).unwrap(),
        &cam,
        SIZE,
        0.5,
    )
    .unwrap();
    assert!(near.reprojection_px < 1e-6);
    assert!((near.rotation - r).norm() < 1e-6 && (near.translation.z - 1.0).abs() < 1e-6);
    // Depth's σ grows as the range squared (z² σ / (f s)): 9× at 3 m.
    let (sz_near, sz_far) = (near.covariance[(5, 5)].sqrt(), far.covariance[(5, 5)].sqrt());
    assert!((sz_far / sz_near - 9.0).abs() < 1.0, "{sz_near} {sz_far}");
    // Twice the pixel noise, twice every σ.
    let twice = tag_pose(
        &project_corners(&cam, &r, &Vector3::new(0.0, 0.0, 1.0), SIZE).unwrap(),
        &cam,
        SIZE,
        1.0,
    )
    .unwrap();
    assert!((twice.position_sigma_m() / near.position_sigma_m() - 2.0).abs() < 1e-6);
    assert!(near.position_sigma_m() < 0.01 && near.angle_sigma_rad() < 0.05);
}

#[test]
fn the_schema_check_rejects_a_wrong_id_a_small_tag_and_a_bad_pose() {
    let cam = camera();
    let (r, t) = (facing(10.0, 0.0, 0.0), Vector3::new(0.0, 0.0, 1.0));
    let mut det = detector();
    let d = det.detect(&frame(&cam, 5, &r, &t, 128).view(), &cam).unwrap()[0];
    let p = AprilTagParams {
        expected_id: Some(5),
        ..*det.params()
    };
    assert!(p.accept(&d).is_ok());
    let wrong = AprilTagParams {
        expected_id: Some(6),
        ..p
    };
    assert_eq!(wrong.accept(&d), Err(TagRejection::WrongId { found: 5, expected: 6 }));
    let fussy = AprilTagParams {
        min_trusted_side_px: 200.0,
        ..p
    };
    assert!(matches!(fussy.accept(&d), Err(TagRejection::TooSmall { .. })));
    let mut nan = d;
    nan.pose.as_mut().unwrap().translation.x = f64::NAN;
    assert_eq!(p.accept(&nan), Err(TagRejection::NotFinite));
    let mut nan_cov = d;
    nan_cov.pose.as_mut().unwrap().covariance[(2, 3)] = f64::NAN;
    assert_eq!(p.accept(&nan_cov), Err(TagRejection::NotFinite));
    let mut huge = d;
    huge.pose.as_mut().unwrap().covariance *= 1e6;
    assert!(matches!(p.accept(&huge), Err(TagRejection::Uncertain { .. })));
    let mut none = d;
    none.pose = None;
    assert_eq!(p.accept(&none), Err(TagRejection::NoPose));
    // A tag far away is decoded but not trusted by default: 14 px across at 7 m.
    let far = frame(&cam, 5, &r, &Vector3::new(0.0, 0.0, 7.0), 128);
    let found = det.detect(&far.view(), &cam).unwrap();
    if let Some(d) = found.first() {
        assert!(matches!(p.accept(d), Err(TagRejection::TooSmall { .. })), "{d:?}");
    }
}

#[test]
fn frames_without_tags_give_nothing_and_never_panic() {
    let cam = camera();
    let mut det = detector();
    assert_eq!(
        det.detect(&RgbImage::new(0, 0).view(), &cam),
        Err(crate::perception::VisionError::EmptyImage)
    );
    assert!(det.detect_grey(&[0; 5], 2, 2, &cam).is_err());
    for (w, h) in [(1, 1), (3, 2), (640, 480)] {
        for level in [0u8, 255] {
            let mut im = RgbImage::new(w, h);
            im.fill([level; 3]);
            assert!(det.detect(&im.view(), &cam).unwrap().is_empty());
        }
    }
    let mut s = 0x9e37_79b9_7f4a_7c15u64;
    for block in [1usize, 3, 8] {
        let mut im = RgbImage::new(320, 240);
        for y in 0..240 {
            for x in 0..320 {
                let mut h = s ^ ((x / block) as u64 * 0x1000_0000_01b3) ^ ((y / block) as u64 * 0x9e37_79b9);
                h ^= h >> 29;
                h = h.wrapping_mul(0xbf58_476d_1ce4_e5b9);
                h ^= h >> 32;
                im.put(x, y, [(h >> 8) as u8, (h >> 16) as u8, (h >> 24) as u8]);
            }
        }
        s = s.rotate_left(7);
        assert!(
            det.detect(&im.view(), &cam).unwrap().is_empty(),
            "noise in blocks of {block}"
        );
    }
}

#[test]
fn a_tag_cut_by_the_frame_edge_or_a_blank_square_is_not_reported() {
    let cam = camera();
    let mut det = detector();
    let r = facing(0.0, 0.0, 0.0);
    // Half out of the frame on the left.
    let im = frame(&cam, 9, &r, &Vector3::new(-0.55, 0.0, 1.0), 128);
    assert!(det.detect(&im.view(), &cam).unwrap().is_empty());
    // A black square with a white ring but no code.
    let mut im = RgbImage::new(200, 200);
    im.fill([128; 3]);
    for y in 40..160 {
        for x in 40..160 {
            let ring = !(52..148).contains(&x) || !(52..148).contains(&y);
            im.put(x, y, [if ring { 230 } else { 20 }; 3]);
        }
    }
    assert!(det.detect(&im.view(), &cam).unwrap().is_empty());
}
