//! `marsupial detect` end to end: PNG and JPEG input, grey and RGBA conversion, JSON
//! fields, imprinting, static mode, overlays, and clear errors for bad files; and for
//! Axel's circle fiducials (profiles/axel.toml), the marks, labels and pose on frames the
//! simulator renders from known poses, none on real photos, the overlay, and clean
//! failures with fewer than 5 marks.

use crate::common;
use common::axel::{facing, render};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("marsupial-detect-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

fn profile() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/bujold.toml")
}

fn save(im: &marsupial::perception::RgbImage, path: &Path) {
    image::RgbImage::from_raw(im.width() as u32, im.height() as u32, im.as_bytes().to_vec())
        .unwrap()
        .save(path)
        .unwrap();
}

fn scene() -> marsupial::perception::RgbImage {
    let mut im = common::background(256, 240);
    // As Bujold's flipped camera sees it: magenta on the image's left.
    common::fiducial(&mut im, 90, 100, 38, 46, [225, 25, 215], [15, 215, 225]);
    im
}

/// `marsupial detect --profile PROFILE ARGS... IMAGES...`.
fn detect_with(profile: &Path, args: &[&str], images: &[&Path]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_marsupial"))
        .arg("detect")
        .arg("--profile")
        .arg(profile)
        .args(args)
        .args(images)
        .output()
        .unwrap()
}

fn detect(args: &[&str], images: &[&Path]) -> Output {
    detect_with(&profile(), args, images)
}

fn json_lines(out: &Output) -> Vec<serde_json::Value> {
    assert!(out.status.success(), "stderr: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout.clone())
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

#[test]
fn png_and_jpeg_stream_with_json() {
    let (png, jpg) = (tmp("scene.png"), tmp("scene.jpg"));
    save(&scene(), &png);
    save(&scene(), &jpg);
    let out = detect(&["--json", "--repeat", "3"], &[&png, &jpg, &png]);
    let v = json_lines(&out);
    assert_eq!(v.len(), 3);
    for key in [
        "image",
        "found",
        "left_px",
        "right_px",
        "ratio",
        "left_centroid",
        "right_centroid",
        "offset_px",
        "mode",
        "us_per_frame",
    ] {
        assert!(v[0].get(key).is_some(), "missing {key}");
    }
    assert!(v.iter().all(|r| r["found"] == true), "{v:?}");
    assert_eq!(v[0]["mode"], "table");
    assert_eq!(v[1]["mode"], "adapted", "adaptation carries from one image to the next");
    assert_eq!(v[0]["left_px"], 38 * 46);
    assert!(v[0]["us_per_frame"].as_f64().unwrap() > 0.0);
    assert!(v[0]["offset_px"].as_f64().unwrap().abs() < 1.0);
}

/// The scene as a raw camera frame: a Bayer mosaic (`rggb`) and BT.601 limited-range YUYV
/// (chroma averaged over each pixel pair), rows packed.
fn raw_scene() -> (Vec<u8>, Vec<u8>) {
    let s = scene();
    let px = |x: usize, y: usize| &s.as_bytes()[(y * 256 + x) * 3..][..3];
    let bayer = (0..240 * 256)
        .map(|i| {
            let (x, y) = (i % 256, i / 256);
            px(x, y)[[0, 1, 1, 2][(y % 2) * 2 + x % 2]]
        })
        .collect();
    let ycc = |p: &[u8]| {
        let [r, g, b] = [p[0], p[1], p[2]].map(|c| f64::from(c) / 255.0);
        let y = 0.299 * r + 0.587 * g + 0.114 * b;
        [
            16.0 + 219.0 * y,
            128.0 + 224.0 * (b - y) / 1.772,
            128.0 + 224.0 * (r - y) / 1.402,
        ]
    };
    let mut yuyv = Vec::new();
    for y in 0..240 {
        for x in (0..256).step_by(2) {
            let (a, b) = (ycc(px(x, y)), ycc(px(x + 1, y)));
            let q = |v: f64| v.round().clamp(0.0, 255.0) as u8;
            yuyv.extend([q(a[0]), q((a[1] + b[1]) / 2.0), q(b[0]), q((a[2] + b[2]) / 2.0)]);
        }
    }
    (bayer, yuyv)
}

#[test]
fn raw_camera_frames_are_read_with_raw() {
    let (bayer, yuyv) = raw_scene();
    let (b, y) = (tmp("scene.bayer"), tmp("scene.yuyv"));
    std::fs::write(&b, &bayer).unwrap();
    std::fs::write(&y, &yuyv).unwrap();
    for (enc, file) in [("bayer_rggb8", &b), ("yuyv", &y)] {
        let v = json_lines(&detect(&["--json", "--raw", &format!("{enc}:256x240")], &[file]));
        assert_eq!(v[0]["found"], true, "{enc}: {v:?}");
        assert!(
            (v[0]["left_px"].as_i64().unwrap() - 38 * 46).abs() < 100,
            "{enc}: {v:?}"
        );
    }
    // A short file, an odd 4:2:2 width and an unknown encoding: the file and encoding named.
    std::fs::write(&y, &yuyv[..1000]).unwrap();
    for (raw, want) in [
        ("yuyv:256x240", "yuyv"),
        ("yuyv:255x240", "even"),
        ("nv24:256x240", "nv24"),
    ] {
        let out = detect(&["--raw", raw], &[&y]);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            !out.status.success() && err.contains("scene.yuyv") && err.contains(want),
            "{raw}: {err}"
        );
    }
}

#[test]
fn grey_and_rgba_are_converted() {
    let grey = tmp("grey.png");
    image::GrayImage::from_pixel(64, 48, image::Luma([90]))
        .save(&grey)
        .unwrap();
    let rgba = tmp("rgba.png");
    let s = scene();
    let mut im = image::RgbaImage::new(256, 240);
    for (i, p) in im.pixels_mut().enumerate() {
        let c = &s.as_bytes()[i * 3..i * 3 + 3];
        *p = image::Rgba([c[0], c[1], c[2], 128]);
    }
    im.save(&rgba).unwrap();
    let v = json_lines(&detect(&["--json"], &[&grey, &rgba]));
    assert_eq!(v[0]["found"], false);
    assert_eq!(v[0]["width"], 64);
    assert_eq!(v[1]["found"], true);
}

#[test]
fn imprint_learns_yellow_and_static_keeps_the_imprint() {
    let mut im = common::background(256, 240);
    // The profile's imprint rectangles hold the blocks; right half swapped for yellow.
    common::rect(&mut im, 97, 96, 128, 144, [225, 25, 215]);
    common::rect(&mut im, 128, 96, 159, 144, [220, 210, 25]);
    let f = tmp("yellow.png");
    save(&im, &f);
    let v = json_lines(&detect(&["--json"], &[&f]));
    assert_eq!(v[0]["found"], false, "the table does not know yellow");
    let v = json_lines(&detect(&["--json", "--imprint", f.to_str().unwrap()], &[&f, &f]));
    assert_eq!(
        (v[0]["found"].clone(), v[0]["mode"].clone()),
        (true.into(), "imprinted".into())
    );
    assert_eq!(v[1]["mode"], "adapted");
    let v = json_lines(&detect(
        &["--json", "--static", "--imprint", f.to_str().unwrap()],
        &[&f, &f],
    ));
    assert_eq!(v[1]["mode"], "imprinted");
    assert_eq!(v[1]["found"], true);
}

#[test]
fn overlays_are_written() {
    let f = tmp("ov-in.png");
    save(&scene(), &f);
    let one = tmp("one.png");
    assert!(detect(&["--overlay", one.to_str().unwrap()], &[&f]).status.success());
    let ov = image::open(&one).unwrap().to_rgb8();
    assert_eq!(ov.dimensions(), (256, 240));
    assert_eq!(ov.get_pixel(100, 120).0, [0, 255, 0], "left block painted");
    assert_eq!(ov.get_pixel(140, 120).0, [255, 255, 0], "right block painted");
    let many = tmp("many.png");
    assert!(
        detect(&["--overlay", many.to_str().unwrap()], &[&f, &f])
            .status
            .success()
    );
    assert!(tmp("many-000.png").exists() && tmp("many-001.png").exists());
}

#[test]
fn bad_inputs_give_clear_errors() {
    let text = tmp("not-an-image.png");
    std::fs::write(&text, "hello").unwrap();
    let empty = tmp("empty.jpg");
    std::fs::write(&empty, b"").unwrap();
    let gif = tmp("tiny.gif");
    std::fs::write(&gif, b"GIF89a\x01\x00\x01\x00\x00\x00\x00;").unwrap();
    let missing = tmp("missing.png");
    for (file, want) in [
        (&text, "not-an-image.png: cannot decode image"),
        (&empty, "empty.jpg: cannot decode image"),
        (&gif, "tiny.gif: cannot decode image"),
        (&missing, "missing.png: cannot read image"),
    ] {
        let out = detect(&[], &[file]);
        assert_eq!(out.status.code(), Some(1));
        let err = String::from_utf8(out.stderr).unwrap();
        assert!(err.contains(want), "{err}");
        assert!(!err.contains("panicked"));
    }
    let f = tmp("ok.png");
    save(&scene(), &f);
    let out = detect_with(Path::new("no/such/profile.toml"), &[], &[&f]);
    assert!(
        String::from_utf8(out.stderr)
            .unwrap()
            .contains("no/such/profile.toml: cannot read file")
    );
    let raposa = Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/raposa.toml");
    let out = detect_with(&raposa, &[], &[&f]);
    assert!(
        String::from_utf8(out.stderr)
            .unwrap()
            .contains("has no `two_block` fiducial")
    );
    let out = detect(&["--repeat", "0"], &[&f]);
    assert!(
        String::from_utf8(out.stderr)
            .unwrap()
            .contains("--repeat must be at least 1")
    );
}

// ---- Axel's circle fiducials ----

use marsupial::geometry::Pose2;
use marsupial::perception::camera_model::CameraModel;
use marsupial::sim::camera::camera_pose;
use marsupial::sim::world;
use nalgebra::Point3;

fn axel_profile() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/axel.toml")
}

fn detect_axel(args: &[&str], images: &[&Path]) -> Output {
    detect_with(&axel_profile(), args, images)
}

/// Camera `cam` of Axel at `robot`, rendered by the simulator (default noisy sensor,
/// four frames of auto-exposure), and each mark's projected centre, px.
fn render_axel(cam: usize, robot: &Pose2, seed: u64) -> (marsupial::perception::RgbImage, Vec<[f64; 2]>) {
    let p = common::shipped_profile("axel");
    let w = world::build(&p, &[], &[]).expect("axel world");
    let im = render(&p, &w, cam, robot, seed);
    let spec = &p.cameras[cam];
    let model = CameraModel::from_spec(spec);
    let pose = camera_pose(robot, &spec.mount);
    let truth = p
        .fiducial
        .get::<marsupial::profile::CirclesSpec>()
        .expect("circles")
        .placements
        .iter()
        .map(|pl| {
            let q = Point3::new(0.0, pl.y_m, pl.z_m);
            model
                .project(&(pose.rotation.transpose() * (q - pose.position)))
                .expect("mark in front")
        })
        .collect();
    (im, truth)
}

fn wrap_deg(a: f64) -> f64 {
    (a + 180.0).rem_euclid(360.0) - 180.0
}

/// Position (m) and heading (°) errors of a pose record's `rover_in_module` against
/// the rover's true pose in the module frame.
fn rover_error(pose: &serde_json::Value, robot: &Pose2) -> (f64, f64) {
    let rim = pose["rover_in_module"].as_array().unwrap();
    let [x, y, h] = [0, 1, 2].map(|i| rim[i].as_f64().unwrap());
    let e = (x - robot.x).hypot(y - robot.y);
    (e, wrap_deg(h - robot.theta.to_degrees()).abs())
}

#[test]
fn circles_marks_ids_and_pose_on_rendered_frames() {
    let p = common::shipped_profile("axel");
    let placements = &p.fiducial.get::<marsupial::profile::CirclesSpec>().unwrap().placements;
    // Two poses, through each camera (the mono pose through that camera's fish-eye).
    let cases = [
        (1.8, 15.0, 4.0, 0usize),
        (2.4, -20.0, -5.0, 1usize),
        (2.0, 0.0, 0.0, 0usize),
    ];
    for (k, &(d, a, turn, cam)) in cases.iter().enumerate() {
        let robot = facing(d, a, turn);
        let (im, truth) = render_axel(cam, &robot, 40 + k as u64);
        let f = tmp(&format!("axel-{k}.png"));
        save(&im, &f);
        let cam_arg = cam.to_string();
        let v = json_lines(&detect_axel(&["--json", "--camera", &cam_arg], &[&f]));
        assert_eq!(v.len(), 1);
        let r = &v[0];
        let label = format!("camera {cam} at {d} m, α {a}°, turned {turn}°: {r}");
        assert_eq!(r["found"], true, "{label}");
        assert!(r["reason"].is_null());
        assert_eq!((r["width"].clone(), r["height"].clone()), (1024.into(), 768.into()));
        assert_eq!(r["camera"], cam);
        let marks = r["marks"].as_array().unwrap();
        assert_eq!(marks.len(), 8, "{label}");
        for (j, m) in marks.iter().enumerate() {
            assert_eq!(m["id"], j, "{label}");
            assert_eq!(m["detected"], true, "{label}");
            assert_eq!(
                m["rotation_deg"].as_f64().unwrap(),
                placements[j].rotation_deg,
                "{label}"
            );
            let c = [m["centroid"][0].as_f64().unwrap(), m["centroid"][1].as_f64().unwrap()];
            let e = (c[0] - truth[j][0]).hypot(c[1] - truth[j][1]);
            assert!(e < 1.0, "{label}: mark {j} {e:.2} px from its projection");
        }
        assert!(r["unlabelled"].as_array().unwrap().is_empty(), "{label}");
        assert_eq!(r["inliers"], 8);
        assert!(r["hypothesis"].as_u64().unwrap() < 16);
        assert!((1..=16).contains(&r["hypotheses_tried"].as_u64().unwrap()));
        assert!(r["reprojection_px"].as_f64().unwrap() < 3.0, "{label}");
        let pose = &r["pose"];
        assert_eq!(pose["source"], "mono");
        assert_eq!(pose["camera"], cam);
        assert_eq!(pose["marks_used"], 8);
        assert!(pose["reprojection_px"].as_f64().unwrap() < 1.0, "{label}");
        let (e, eh) = rover_error(pose, &robot);
        assert!(e < 0.03 && eh < 1.0, "{label}: rover {e:.4} m, {eh:.2}° off the truth");
        // The module in the rover frame: its face looks back at the rover.
        let hd = pose["heading_deg"].as_f64().unwrap();
        assert!((wrap_deg(hd + robot.theta.to_degrees())).abs() < 1.0, "{label}");
        let dist = pose["position_m"][0]
            .as_f64()
            .unwrap()
            .hypot(pose["position_m"][1].as_f64().unwrap());
        assert!((dist - d).abs() < 0.03, "{label}");
        assert!(r["us_per_frame"].as_f64().unwrap() > 0.0);
    }
}

#[test]
fn circles_text_output_and_overlay() {
    let robot = facing(2.0, 10.0, 3.0);
    let (im, _) = render_axel(0, &robot, 7);
    let f = tmp("axel-ov-in.png");
    save(&im, &f);
    let ov = tmp("axel-ov.png");
    let out = detect_axel(&["--overlay", ov.to_str().unwrap()], &[&f]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.contains("found  8 marks (0 filled in, 0 unlabelled)") && text.contains("[mono, camera 0"),
        "{text}"
    );
    let drawn = image::open(&ov).unwrap().to_rgb8();
    let input = image::open(&f).unwrap().to_rgb8();
    assert_eq!(drawn.dimensions(), input.dimensions());
    let changed = drawn.pixels().zip(input.pixels()).filter(|(a, b)| a != b).count();
    assert!(changed > 1000, "only {changed} pixels drawn");
    let count = |c: [u8; 3]| drawn.pixels().filter(|p| p.0 == c).count();
    use marsupial::perception::overlay::{MARK_PAINT, MODEL_PAINT};
    assert!(count(MARK_PAINT) > 200, "marks drawn: {}", count(MARK_PAINT));
    assert!(count(MODEL_PAINT) > 200, "model drawn: {}", count(MODEL_PAINT));
}

#[test]
fn circles_fewer_than_five_marks_is_a_clean_not_found() {
    let robot = facing(1.8, 5.0, 0.0);
    let (mut im, truth) = render_axel(0, &robot, 11);
    // Paint over four of the eight marks (each about 40 px across here).
    for c in &truth[..4] {
        let (x0, y0) = (c[0] as usize - 35, c[1] as usize - 35);
        common::rect(&mut im, x0, y0, x0 + 70, y0 + 70, [128, 128, 128]);
    }
    let f = tmp("axel-four.png");
    save(&im, &f);
    let v = json_lines(&detect_axel(&["--json"], &[&f]));
    let r = &v[0];
    assert_eq!(r["found"], false, "{r}");
    assert_eq!(r["detected"], 4, "{r}");
    assert_eq!(r["reason"], "4 marks detected, a fit needs 5");
    assert!(r["marks"].as_array().unwrap().is_empty());
    assert_eq!(r["unlabelled"].as_array().unwrap().len(), 4);
    assert!(r["pose"].is_null() && r["hypothesis"].is_null());
    let out = detect_axel(&[], &[&f]);
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("not found: 4 marks detected, a fit needs 5"), "{text}");
}

#[test]
fn circles_undetected_marks_are_filled_in_from_the_reprojection() {
    let p = common::shipped_profile("axel");
    let placements = &p.fiducial.get::<marsupial::profile::CirclesSpec>().unwrap().placements;
    let robot = facing(2.0, -10.0, 2.0);
    let (mut im, truth) = render_axel(1, &robot, 23);
    // Hide marks 2 and 5: six remain, enough for a fit, and the two are filled in.
    for &j in &[2usize, 5] {
        let (x0, y0) = (truth[j][0] as usize - 32, truth[j][1] as usize - 32);
        common::rect(&mut im, x0, y0, x0 + 64, y0 + 64, [128, 128, 128]);
    }
    let f = tmp("axel-six.png");
    save(&im, &f);
    let v = json_lines(&detect_axel(&["--json", "--camera", "1"], &[&f]));
    let r = &v[0];
    assert_eq!(r["found"], true, "{r}");
    assert_eq!(
        (r["detected"].clone(), r["inliers"].clone()),
        (6.into(), 6.into()),
        "{r}"
    );
    let marks = r["marks"].as_array().unwrap();
    assert_eq!(marks.len(), 8);
    for (j, m) in marks.iter().enumerate() {
        let hidden = j == 2 || j == 5;
        assert_eq!(m["detected"], !hidden, "{r}");
        assert_eq!(m["rotation_deg"].as_f64().unwrap(), placements[j].rotation_deg);
        let c = [m["centroid"][0].as_f64().unwrap(), m["centroid"][1].as_f64().unwrap()];
        let e = (c[0] - truth[j][0]).hypot(c[1] - truth[j][1]);
        // A filled-in centre is the homography's: it ignores the fish-eye's bending.
        assert!(e < if hidden { 4.0 } else { 1.0 }, "mark {j}: {e:.2} px off: {r}");
    }
    assert_eq!(r["pose"]["marks_used"], 6, "{r}");
    let rim = r["pose"]["rover_in_module"].as_array().unwrap();
    let e = (rim[0].as_f64().unwrap() - robot.x).hypot(rim[1].as_f64().unwrap() - robot.y);
    assert!(e < 0.03, "{e} m: {r}");
}

#[test]
fn circles_none_in_real_photos() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/photos");
    if !dir.is_dir() {
        eprintln!("skipping: {} not found", dir.display());
        return;
    }
    let mut files = Vec::new();
    for sub in ["backgrounds", "markers"] {
        let mut f: Vec<PathBuf> = std::fs::read_dir(dir.join(sub))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "jpg" || e == "png"))
            .collect();
        f.sort();
        files.extend(f.into_iter().take(3));
    }
    assert!(files.len() >= 4, "{files:?}");
    let refs: Vec<&Path> = files.iter().map(|p| p.as_path()).collect();
    let v = json_lines(&detect_axel(&["--json"], &refs));
    assert_eq!(v.len(), files.len());
    for r in &v {
        assert_eq!(r["found"], false, "{r}");
        assert_eq!(r["detected"], 0, "{r}");
        assert!(
            r["reason"].as_str().unwrap().contains("marks detected, a fit needs 5"),
            "{r}"
        );
        assert!(r["pose"].is_null());
    }
}

#[test]
fn circles_bad_inputs_give_clear_errors() {
    let missing = tmp("axel-missing.png");
    let out = detect_axel(&[], &[&missing]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(
        err.contains("axel-missing.png: cannot read image") && !err.contains("panicked"),
        "{err}"
    );
    let f = tmp("axel-bad-opts.png");
    save(&scene(), &f);
    for (args, want) in [
        (
            vec!["--imprint", f.to_str().unwrap()],
            "--imprint applies to `two_block` fiducials only; `axel` has `circles` fiducial",
        ),
        (vec!["--static"], "--static applies to `two_block` fiducials only"),
        (
            vec!["--camera", "2"],
            "--camera 2: profile `axel` has 2 camera(s), numbered from 0",
        ),
    ] {
        let out = detect_axel(&args, &[&f]);
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let err = String::from_utf8(out.stderr).unwrap();
        assert!(err.contains(want), "{args:?}: {err}");
    }
    // A frame of another size than the camera's: the marks are labelled, but no pose is
    // made through a lens model calibrated for another size.
    let (im, _) = render_axel(0, &facing(2.0, 0.0, 0.0), 3);
    let mut big = marsupial::perception::RgbImage::new(1100, 800);
    big.fill([128, 128, 128]);
    for y in 0..im.height() {
        for x in 0..im.width() {
            big.put(x, y, im.view().get(x, y).unwrap());
        }
    }
    let g = tmp("axel-padded.png");
    save(&big, &g);
    let v = json_lines(&detect_axel(&["--json"], &[&g]));
    assert_eq!(v[0]["found"], true, "{}", v[0]);
    assert!(v[0]["pose"].is_null());
    assert_eq!(
        v[0]["pose_error"],
        "the image is 1100×800 px but camera 0 is 1024×768: no pose through its model"
    );
    // A profile with neither fiducial names both.
    let raposa = Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/raposa.toml");
    let out = detect_with(&raposa, &[], &[&f]);
    assert!(
        String::from_utf8(out.stderr)
            .unwrap()
            .contains("has no `two_block` fiducial or `circles` fiducial")
    );
}

#[test]
fn circles_stereo_pairs_give_a_stereo_pose_beside_each_mono_one() {
    // Two pairs rendered from known poses; a third pair with camera 1's marks painted
    // over: its stereo line says why there is no pose.
    let poses = [facing(1.5, 10.0, 3.0), facing(2.5, -15.0, -4.0)];
    let mut files = Vec::new();
    for (k, robot) in poses.iter().enumerate() {
        for cam in 0..2 {
            let (im, _) = render_axel(cam, robot, 60 + 2 * k as u64 + cam as u64);
            let f = tmp(&format!("axel-stereo-{k}-{cam}.png"));
            save(&im, &f);
            files.push(f);
        }
    }
    let (mut hidden, truth) = render_axel(1, &poses[0], 61);
    for c in &truth {
        let (x0, y0) = (c[0] as usize - 40, c[1] as usize - 40);
        common::rect(&mut hidden, x0, y0, x0 + 80, y0 + 80, [128, 128, 128]);
    }
    let hidden_file = tmp("axel-stereo-hidden.png");
    save(&hidden, &hidden_file);
    let args: Vec<&Path> = vec![&files[0], &files[1], &files[2], &files[3], &files[0], &hidden_file];
    let v = json_lines(&detect_axel(&["--json", "--stereo", "--repeat", "2"], &args));
    assert_eq!(v.len(), 9, "two records and a stereo line per pair");
    for (k, robot) in poses.iter().enumerate() {
        let (left, right, stereo) = (&v[3 * k], &v[3 * k + 1], &v[3 * k + 2]);
        assert_eq!((left["camera"].clone(), right["camera"].clone()), (0.into(), 1.into()));
        assert_eq!(left["pose"]["source"], "mono", "{left}");
        assert_eq!(stereo["stereo"][0], files[2 * k].display().to_string());
        assert_eq!(stereo["stereo"][1], files[2 * k + 1].display().to_string());
        assert!(stereo["pose_error"].is_null(), "{stereo}");
        let pose = &stereo["pose"];
        assert_eq!(pose["source"], "stereo");
        assert_eq!(pose["marks_used"], 8, "{stereo}");
        // The paper's stereo error: 2.56 cm / 2.5° at 1 m, 4.12 cm / 4.58° at 2 m.
        let (e, eh) = rover_error(pose, robot);
        assert!(
            e < 0.025 && eh < 1.0,
            "pair {k}: rover {e:.4} m, {eh:.2}° off the truth: {stereo}"
        );
        assert!(stereo["us_per_pair"].as_f64().unwrap() > 0.0);
    }
    let failed = &v[8];
    assert!(failed["pose"].is_null(), "{failed}");
    let why = failed["pose_error"].as_str().unwrap();
    assert!(why.starts_with("camera 1: "), "{why}");
    // Text output: one stereo line per pair.
    let out = detect_axel(&["--stereo"], &[&files[0], &files[1]]);
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains(" + ") && text.contains("stereo module at"), "{text}");
}

#[test]
fn stereo_misuse_gives_clear_errors() {
    let f = tmp("axel-stereo-misuse.png");
    save(&render_axel(0, &facing(2.0, 0.0, 0.0), 5).0, &f);
    let err = |args: &[&str], images: &[&Path], profile: &Path| {
        let out = detect_with(profile, args, images);
        assert!(!out.status.success());
        String::from_utf8(out.stderr).unwrap()
    };
    let e = err(&["--stereo"], &[&f], &axel_profile());
    assert!(
        e.contains("--stereo takes the images in pairs") && e.contains("1 given"),
        "{e}"
    );
    let e = err(&["--stereo", "--camera", "1"], &[&f, &f], &axel_profile());
    assert!(e.contains("leave out --camera"), "{e}");
    let e = err(&["--stereo"], &[&f, &f], &profile());
    assert!(e.contains("--stereo applies to `circles` fiducials only"), "{e}");
}
