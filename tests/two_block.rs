//! The two-block detector's rules and the perceptual schema built from a profile.

use crate::common;
use common::*;
use marsupial::perception::{ColorMode, PairLimits, TwoBlockDetector};
use marsupial::profile::Profile;
use marsupial::schemas::TwoBlockSchema;
use std::path::Path;

fn limits() -> PairLimits {
    PairLimits {
        min_component_px: 20,
        max_gap_frac: 0.5,
        gap_slack_px: 3.0,
        max_vertical_frac: 0.5,
        max_height_ratio: 2.0,
        min_count_ratio: 0.2,
        max_candidates: 64,
    }
}

fn detect(im: &marsupial::perception::RgbImage) -> Option<marsupial::perception::Pair> {
    let mut d = TwoBlockDetector::new(im.width(), im.height(), limits());
    d.detect(&im.view(), &ranges()).unwrap()
}

#[test]
fn finds_a_plain_fiducial() {
    let mut im = background(120, 80);
    fiducial(&mut im, 30, 20, 20, 25, CYAN, MAGENTA);
    let p = detect(&im).expect("found");
    assert_eq!((p.left.count, p.right.count), (500, 500));
    assert_eq!(p.ratio, 1.0);
    assert_eq!(p.left.centroid, [39.5, 32.0]);
    assert_eq!(p.right.bbox, [50, 20, 69, 44]);
}

#[test]
fn components_under_twenty_pixels_are_dropped() {
    let mut im = background(60, 40);
    fiducial(&mut im, 10, 10, 4, 5, CYAN, MAGENTA); // 20 px each
    assert!(detect(&im).is_some());
    im.put(10, 10, GREY); // left block now 19 px
    assert!(detect(&im).is_none());
}

#[test]
fn gap_limit() {
    // Blocks 10 px tall: allowed |gap − 1| ≤ 3 + 0.5·10 = 8 px.
    for (gap, ok) in [(0usize, true), (8, true), (9, false), (20, false)] {
        let mut im = background(100, 40);
        rect(&mut im, 10, 10, 30, 20, CYAN);
        rect(&mut im, 30 + gap, 10, 50 + gap, 20, MAGENTA);
        assert_eq!(detect(&im).is_some(), ok, "gap {gap}");
    }
}

#[test]
fn vertical_alignment_limit() {
    // Blocks 10 px tall: centroids may differ by at most 5 px.
    for (dy, ok) in [(0usize, true), (5, true), (6, false)] {
        let mut im = background(100, 60);
        rect(&mut im, 10, 10, 30, 20, CYAN);
        rect(&mut im, 30, 10 + dy, 50, 20 + dy, MAGENTA);
        assert_eq!(detect(&im).is_some(), ok, "dy {dy}");
    }
}

#[test]
fn height_ratio_limit() {
    // A 10 px tall left block beside right blocks of growing height, centred on it: at
    // most 2× taller pairs (the flap's blocks are equally tall, perspective makes 1.35×).
    for (h, ok) in [(10usize, true), (20, true), (21, false), (30, false)] {
        let mut im = background(100, 60);
        rect(&mut im, 10, 25, 40, 35, CYAN);
        let top = 30 - h / 2;
        rect(&mut im, 40, top, 55, top + h, MAGENTA);
        assert_eq!(detect(&im).is_some(), ok, "right height {h}");
    }
}

#[test]
fn count_ratio_limit() {
    // 10 px tall blocks, the left one 50 px wide (500 px): a right block of 100 px pairs
    // (ratio 0.2), one of 90 px does not.
    for (w, ok) in [(50usize, true), (10, true), (9, false)] {
        let mut im = background(100, 40);
        rect(&mut im, 10, 10, 60, 20, CYAN);
        rect(&mut im, 60, 10, 60 + w, 20, MAGENTA);
        assert_eq!(detect(&im).is_some(), ok, "right width {w}");
    }
}

#[test]
fn wrong_colour_order_is_rejected() {
    let mut im = background(100, 40);
    fiducial(&mut im, 10, 10, 20, 15, MAGENTA, CYAN);
    assert!(detect(&im).is_none());
}

#[test]
fn upside_down_copy_beside_the_fiducial_is_ignored() {
    for copy_left in [true, false] {
        let mut im = background(200, 60);
        let (fx, cx) = if copy_left { (110, 20) } else { (20, 110) };
        fiducial(&mut im, fx, 15, 20, 25, CYAN, MAGENTA);
        fiducial(&mut im, cx, 15, 20, 25, MAGENTA, CYAN); // the copy, turned 180°
        let p = detect(&im).expect("the real fiducial is found");
        assert_eq!(p.left.bbox[0] as usize, fx, "copy_left={copy_left}");
        assert_eq!(p.right.bbox[0] as usize, fx + 20);
    }
    // Adjacent copy and fiducial (M C C M and C M M C): only the real pair is accepted.
    let mut im = background(200, 60);
    fiducial(&mut im, 20, 15, 20, 25, MAGENTA, CYAN);
    fiducial(&mut im, 60, 15, 20, 25, CYAN, MAGENTA);
    // The two cyan blocks merge into one component of 40 × 25 next to a 20 × 25 magenta:
    // ratio 0.5, but it is the only correctly ordered pair.
    let p = detect(&im).expect("found");
    assert_eq!(p.right.bbox[0], 80);
}

#[test]
fn ratio_closest_to_one_wins_then_larger_total() {
    let mut im = background(300, 60);
    rect(&mut im, 10, 10, 30, 30, CYAN); // 400
    rect(&mut im, 30, 10, 46, 30, MAGENTA); // 320 → ratio 0.8
    rect(&mut im, 100, 10, 120, 30, CYAN); // 400
    rect(&mut im, 120, 10, 139, 30, MAGENTA); // 380 → ratio 0.95
    let p = detect(&im).unwrap();
    assert_eq!(p.left.bbox[0], 100);
    assert!((p.ratio - 0.95).abs() < 1e-12);
    // Equal ratios: the larger pair wins.
    let mut im = background(300, 60);
    fiducial(&mut im, 10, 10, 10, 10, CYAN, MAGENTA);
    fiducial(&mut im, 100, 10, 20, 20, CYAN, MAGENTA);
    assert_eq!(detect(&im).unwrap().left.bbox[0], 100);
}

#[test]
fn tolerates_roll() {
    for roll_deg in [-20.0f64, -10.0, 0.0, 10.0, 20.0] {
        let mut im = background(160, 120);
        rolled_fiducial(
            &mut im,
            (80.0, 60.0),
            (60.0, 36.0),
            roll_deg.to_radians(),
            CYAN,
            MAGENTA,
        );
        let p = detect(&im).unwrap_or_else(|| panic!("roll {roll_deg}"));
        assert!(p.ratio > 0.9);
    }
}

#[test]
fn errors_on_bad_frames() {
    let mut d = TwoBlockDetector::new(10, 10, limits());
    let im = background(12, 10);
    assert!(d.detect(&im.view(), &ranges()).is_err());
    let empty = marsupial::perception::RgbImage::new(0, 0);
    assert!(d.detect(&empty.view(), &ranges()).is_err());
}

fn bujold() -> Profile {
    Profile::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/bujold.toml")).unwrap()
}

#[test]
fn schema_uses_the_camera_flip_for_table_order() {
    // Bujold's camera is rolled 180°: the fiducial's right colour (magenta) appears on the
    // image's left. With table defaults, magenta|cyan is found and cyan|magenta is not.
    let mut s = TwoBlockSchema::from_profile(&bujold(), 0).unwrap();
    assert_eq!(s.model().mode(), ColorMode::Table);
    let mut im = background(256, 240);
    fiducial(&mut im, 90, 100, 38, 46, [230, 20, 220], [10, 220, 230]);
    let p = s.process(&im.view(), 0.0).unwrap();
    assert!(p.found, "{p:?}");
    assert_eq!(p.mode, ColorMode::Table);
    assert!((p.offset_px - (128.0 - 128.0)).abs() < 1.0);
    assert_eq!(s.model().mode(), ColorMode::Adapted);

    let mut s = TwoBlockSchema::from_profile(&bujold(), 0).unwrap();
    let mut im = background(256, 240);
    fiducial(&mut im, 90, 100, 38, 46, [10, 220, 230], [230, 20, 220]);
    assert!(!s.process(&im.view(), 0.0).unwrap().found);
}

#[test]
fn imprinting_learns_swapped_colours() {
    // Swap one half for yellow: the table (cyan/magenta) cannot see it, the imprint can.
    let yellow = [220, 210, 20];
    let magenta = [230, 20, 220];
    let p = bujold();
    let mut im = background(256, 240);
    // Where the profile's imprint rectangles say the blocks are.
    let [l, r] = [p.perception.imprint.left_rect, p.perception.imprint.right_rect];
    let px = |f: f64, n: usize| (f * n as f64) as usize;
    rect(
        &mut im,
        px(l[0], 256),
        px(l[1], 240),
        px(l[2], 256),
        px(l[3], 240),
        magenta,
    );
    rect(
        &mut im,
        px(r[0], 256),
        px(r[1], 240),
        px(r[2], 256),
        px(r[3], 240),
        yellow,
    );
    let mut s = TwoBlockSchema::from_profile(&p, 0).unwrap();
    assert!(
        !s.process(&im.view(), 0.0).unwrap().found,
        "table defaults do not know yellow"
    );
    for _ in 0..s.imprint_frames_wanted() {
        s.imprint_frame(&im.view());
    }
    assert!(s.finish_imprint(1.0));
    let pc = s.process(&im.view(), 1.1).unwrap();
    assert!(pc.found && pc.mode == ColorMode::Imprinted);
    assert_eq!(s.model().mode(), ColorMode::Adapted);
}

#[test]
fn same_input_same_output_bit_for_bit() {
    let mut frames = Vec::new();
    for k in 0..20 {
        let mut im = background(256, 240);
        let w = 10 + k * 2;
        fiducial(&mut im, 60 + k, 80, w, w + 5, [230, 20, 220], [10, 220, 230]);
        // Sensor-like noise from a fixed generator.
        let mut s = 0x9E3779B97F4A7C15u64.wrapping_mul(k as u64 + 1);
        for b in im.as_bytes_mut().iter_mut() {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            *b = b.saturating_add((s % 9) as u8).saturating_sub(4);
        }
        frames.push(im);
    }
    let run = || {
        let mut s = TwoBlockSchema::from_profile(&bujold(), 0).unwrap();
        frames
            .iter()
            .enumerate()
            .map(|(k, f)| serde_json::to_string(&s.process(&f.view(), k as f64 * 0.1).unwrap()).unwrap())
            .collect::<Vec<_>>()
            .join("\n")
    };
    let (a, b) = (run(), run());
    assert!(a == b);
    assert!(a.contains("\"found\":true"));
}

/// A frame of Bujold's camera: the flap (image-left magenta, image-right cyan) on a
/// brown dock body, every pixel scaled per channel by `light` (a coloured light on the
/// whole scene), with a little fixed noise.
fn lit_flap(light: [f64; 3], k: u64) -> marsupial::perception::RgbImage {
    let mut im = background(256, 240);
    rect(&mut im, 0, 0, 256, 240, [70, 55, 40]);
    fiducial(&mut im, 80, 90, 44, 52, [200, 40, 150], [30, 160, 140]);
    let mut s = 0x9E3779B97F4A7C15u64.wrapping_mul(k + 1);
    for (i, b) in im.as_bytes_mut().iter_mut().enumerate() {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        let v = (*b as f64 * light[i % 3] + (s % 5) as f64 - 2.0).round();
        *b = v.clamp(0.0, 255.0) as u8;
    }
    im
}

#[test]
fn a_coloured_flash_is_compensated_before_segmentation() {
    // Adapted to the flap under white light for 3 s, the tracker then sees one frame
    // under a strong yellow-green flash (blue falls to 70 %): both blocks move by
    // several degrees of SCT angle A at once, far outside the adapted ranges. With the
    // cast compensation the frame is brought back to the light the ranges were learnt
    // under and the flap is found; without it, it is lost.
    let found_under_flash = |cast_tau_s: f64| {
        let mut p = bujold();
        p.perception.cast_tau_s = cast_tau_s;
        let mut s = TwoBlockSchema::from_profile(&p, 0).unwrap();
        for k in 0..30 {
            let pc = s.process(&lit_flap([1.0, 1.0, 1.0], k).view(), k as f64 * 0.1).unwrap();
            assert!(pc.found, "steady light, frame {k}");
        }
        assert_eq!(s.model().mode(), ColorMode::Adapted);
        s.process(&lit_flap([1.15, 1.1, 0.7], 30).view(), 3.0).unwrap().found
    };
    assert!(found_under_flash(2.0));
    assert!(!found_under_flash(0.0));
}
