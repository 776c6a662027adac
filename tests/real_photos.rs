//! Real photographs (../shared/data/photos): no false positives on real scenes, and the
//! imprint → detect loop on real sensor colour (a ColorChecker's adjacent magenta and cyan
//! patches). Skips with a message when the photo folder is absent.

use marsupial::image_io::load_rgb;
use marsupial::perception::ColorMode;
use marsupial::profile::Profile;
use marsupial::schemas::TwoBlockSchema;
use std::path::Path;

use crate::common::photos;

fn bujold() -> Profile {
    Profile::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/bujold.toml")).unwrap()
}

#[test]
fn no_fiducial_in_real_scenes() {
    let Some(dir) = photos() else { return };
    let mut checked = 0;
    for sub in ["backgrounds", "color", "markers"] {
        let mut files: Vec<_> = std::fs::read_dir(dir.join(sub))
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        files.sort();
        for f in files {
            let Ok(im) = load_rgb(&f) else { continue };
            let mut s = TwoBlockSchema::from_profile(&bujold(), 0).unwrap();
            s.detector_mut().resize(im.width(), im.height());
            let p = s.process(&im.view(), 0.0).unwrap();
            assert!(!p.found, "false positive in {}: {p:?}", f.display());
            checked += 1;
        }
    }
    assert!(checked >= 30, "only {checked} photos read");
}

#[test]
fn imprint_then_detect_on_a_real_colour_checker() {
    let Some(dir) = photos() else { return };
    let im = load_rgb(&dir.join("color/mcc_ccm_test.jpg")).unwrap();
    assert_eq!((im.width(), im.height()), (900, 463));
    let mut p = bujold();
    // Third row of the chart: magenta (x ≈ 505–562) then cyan (x ≈ 568–627), y ≈ 215–270.
    p.perception.imprint.left_rect = [505.0 / 900.0, 215.0 / 463.0, 562.0 / 900.0, 270.0 / 463.0];
    p.perception.imprint.right_rect = [568.0 / 900.0, 215.0 / 463.0, 627.0 / 900.0, 270.0 / 463.0];
    let mut s = TwoBlockSchema::from_profile(&p, 0).unwrap();
    s.detector_mut().resize(900, 463);
    // The table defaults (ideal paint) miss the chart's muted magenta …
    assert!(!s.process(&im.view(), 0.0).unwrap().found);
    // … imprinting learns the real colours.
    s.imprint_frame(&im.view());
    assert!(s.finish_imprint(0.1));
    let pc = s.process(&im.view(), 0.2).unwrap();
    assert!(pc.found, "{pc:?}");
    assert_eq!(pc.mode, ColorMode::Imprinted);
    assert!(
        (500.0..570.0).contains(&pc.left_centroid[0]) && (565.0..630.0).contains(&pc.right_centroid[0]),
        "{pc:?}"
    );
    assert!((215.0..270.0).contains(&pc.left_centroid[1]));
    assert!(pc.ratio > 0.8, "{pc:?}");
    // Adaptation keeps it.
    for k in 0..5 {
        let pk = s.process(&im.view(), 0.3 + k as f64 * 0.1).unwrap();
        assert!(pk.found && pk.mode == ColorMode::Adapted);
    }
}

#[test]
fn no_circle_fiducial_in_real_photos() {
    // Axel's circle marks appear in none of the photos: the detector reports no mark and
    // the correspondence no module, in every folder (real edges, blur, ArUco squares,
    // chessboards, gauges, text).
    use marsupial::perception::circles::{CircleDetector, CircleModel, CircleParams, CorrespondenceParams, correspond};
    let Some(dir) = photos() else { return };
    let axel = Profile::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/axel.toml")).unwrap();
    let model = CircleModel::from_profile(&axel).unwrap();
    let (mut checked, mut marks_seen) = (0, 0);
    for sub in ["backgrounds", "color", "markers", "homography", "sequences"] {
        let mut files: Vec<_> = std::fs::read_dir(dir.join(sub))
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        files.sort();
        for f in files {
            let Ok(im) = load_rgb(&f) else { continue };
            let mut det = CircleDetector::new(im.width(), im.height(), CircleParams::for_image(im.width()));
            let marks = det.detect(&im.view()).unwrap();
            marks_seen += marks.len();
            assert!(marks.is_empty(), "{}: {marks:?}", f.display());
            assert!(correspond(&model, marks, &CorrespondenceParams::default()).is_err());
            checked += 1;
        }
    }
    assert!(checked >= 60, "only {checked} photos read");
    assert_eq!(marks_seen, 0);
}
