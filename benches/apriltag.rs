//! The AprilTag detector (issue 45): detection, decoding and pose of one tag36h11 tag on
//! a 640 × 480 frame, one core. Target: ≤ 4 ms per frame. Two frames: the tag 1 m away,
//! 20° off its axis, on a plain grey background (`plain`), and the same tag pasted into a
//! real cluttered scene (`cluttered`, ../shared/data/photos/backgrounds/home.jpg tiled to
//! 640 × 480; skipped when the photos are absent). Both frames are written as PNG to
//! target/apriltag/ so that scripts/apriltag_opencv.py times OpenCV's AprilTag detector
//! on the very same pixels.
//!
//! Run: `cargo bench --bench apriltag` (add `-- --quick` for a fast pass), then
//! `python3 scripts/apriltag_opencv.py target/apriltag/*.png` for OpenCV's times.

use criterion::{Criterion, criterion_group, criterion_main};
use marsupial::image_io::{load_rgb, save_png};
use marsupial::perception::apriltag::{AprilTagDetector, AprilTagParams, TagFamily, TagSprite, draw_tag};
use marsupial::perception::{Pinhole, RgbImage};
use nalgebra::{Matrix3, Rotation3, Vector3};
use std::hint::black_box;
use std::path::Path;

fn camera() -> Pinhole {
    Pinhole::ideal(600.0, 640, 480)
}

fn with_tag(mut im: RgbImage) -> RgbImage {
    let r = Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, -1.0))
        * Rotation3::from_axis_angle(&Vector3::y_axis(), 20f64.to_radians()).into_inner();
    let tag = TagSprite {
        family: TagFamily::Tag36h11,
        id: 7,
        size_m: 0.16,
        supersample: 4,
    };
    draw_tag(&mut im, &camera(), &tag, &r, &Vector3::new(0.1, 0.0, 1.0));
    im
}

fn frames() -> Vec<(&'static str, RgbImage)> {
    let mut plain = RgbImage::new(640, 480);
    plain.fill([128; 3]);
    let mut out = vec![("plain", with_tag(plain))];
    let photo = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/photos/backgrounds/home.jpg");
    if let Ok(bg) = load_rgb(&photo) {
        let mut im = RgbImage::new(640, 480);
        for y in 0..480 {
            for x in 0..640 {
                im.put(x, y, bg.view().get(x % bg.width(), y % bg.height()).unwrap_or([0; 3]));
            }
        }
        out.push(("cluttered", with_tag(im)));
    } else {
        eprintln!("no {}: the cluttered frame is skipped", photo.display());
    }
    out
}

fn benches(c: &mut Criterion) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/apriltag");
    let _ = std::fs::create_dir_all(&dir);
    let cam = camera();
    for (name, frame) in frames() {
        let _ = save_png(&dir.join(format!("{name}_640x480.png")), &frame);
        let mut det = AprilTagDetector::new(AprilTagParams {
            expected_id: Some(7),
            ..AprilTagParams::default()
        });
        let found = det.detect(&frame.view(), &cam).map(|d| d.to_vec()).unwrap_or_default();
        assert_eq!(found.len(), 1, "{name}: the tag must be found once");
        // For the comparison with OpenCV's (same frame, same camera): corners and pose.
        if let Some(p) = found[0].pose {
            let tilt = (-p.rotation[(2, 2)]).clamp(-1.0, 1.0).acos().to_degrees();
            eprintln!(
                "{name}: id {} corners {:.2?} t {:.4?} m tilt {tilt:.2}° (truth (0.1, 0, 1) m, 20°)",
                found[0].id,
                found[0].corners,
                p.translation.as_slice()
            );
        }
        let view = frame.view();
        c.bench_function(&format!("apriltag/{name}_640x480"), |b| {
            b.iter(|| black_box(det.detect(black_box(&view), &cam).map(|d| d.len()).unwrap_or(0)))
        });
    }
}

criterion_group!(apriltag, benches);
criterion_main!(apriltag);
