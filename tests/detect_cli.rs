//! `marsupial detect` end to end: PNG and JPEG input, grey and RGBA conversion, JSON
//! fields, imprinting, static mode, overlays, and clear errors for bad files.

mod common;
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

fn detect(args: &[&str], images: &[&Path]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_marsupial"))
        .arg("detect")
        .arg("--profile")
        .arg(profile())
        .args(args)
        .args(images)
        .output()
        .unwrap()
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
    let out = Command::new(env!("CARGO_BIN_EXE_marsupial"))
        .args(["detect", "--profile", "no/such/profile.toml"])
        .arg(&f)
        .output()
        .unwrap();
    assert!(
        String::from_utf8(out.stderr)
            .unwrap()
            .contains("no/such/profile.toml: cannot read file")
    );
    let raposa = Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/raposa.toml");
    let out = Command::new(env!("CARGO_BIN_EXE_marsupial"))
        .args(["detect", "--profile"])
        .arg(raposa)
        .arg(&f)
        .output()
        .unwrap();
    assert!(
        String::from_utf8(out.stderr)
            .unwrap()
            .contains("has no [fiducial.two_block]")
    );
    let out = detect(&["--repeat", "0"], &[&f]);
    assert!(
        String::from_utf8(out.stderr)
            .unwrap()
            .contains("--repeat must be at least 1")
    );
}
