//! RAPOSA's seven-state servo on Bujold's two-block flap in Bujold's world
//! (`profiles/bujold-raposa.toml`, `scenarios/bujold-raposa.toml`): the profile differs
//! from Bujold's only in what its header says, `agent_for` builds RAPOSA's robot on the
//! two-block adapter, and the adapter reports RAPOSA's cues. That the robot docks from the
//! starts where it does is the campaign's (`scripts/golden bujold-raposa`: every run
//! imprinted, on the axis every run docked, 30° off it by region II).

use marsupial::behaviors::agent_for;
use marsupial::behaviors::raposa::{self, Source};
use marsupial::perception::{ColorMode, TwoBlockPercept};
use marsupial::profile::Profile;
use std::path::Path;

fn file(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(name)
}

fn profile() -> Profile {
    Profile::load(&file("profiles/bujold-raposa.toml")).unwrap()
}

/// The keys the profile's header lists after "Changed from profiles/bujold.toml ...:".
fn changed_keys(text: &str) -> Vec<String> {
    let header: String = text
        .lines()
        .take_while(|l| l.starts_with('#'))
        .map(|l| l.trim_start_matches('#').trim())
        .collect::<Vec<_>>()
        .join(" ");
    let list = header
        .split_once("differs):")
        .expect("the header lists what differs from bujold.toml")
        .1;
    list.split('.')
        .next()
        .unwrap()
        .split(',')
        .map(|k| k.trim().to_string())
        .collect()
}

#[test]
fn only_the_keys_the_header_lists_differ_from_bujold() {
    let text = std::fs::read_to_string(file("profiles/bujold-raposa.toml")).unwrap();
    let keys = changed_keys(&text);
    assert_eq!(keys, ["name", "description", "robot", "behavior"]);
    let mut ours: toml::Table = text.parse().unwrap();
    let mut bujold: toml::Table = std::fs::read_to_string(file("profiles/bujold.toml"))
        .unwrap()
        .parse()
        .unwrap();
    for k in &keys {
        assert!(ours.remove(k).is_some(), "`{k}` is listed as changed but absent");
        bujold.remove(k);
    }
    assert_eq!(
        ours, bujold,
        "robot, camera, dock, fiducial, perception, loop or success drifted"
    );
}

#[test]
fn agent_for_builds_raposa_on_the_two_block_adapter() {
    let p = profile();
    assert!(agent_for(&p).is_ok());
    let agent = marsupial::behaviors::catalog::shipped()
        .compose(&raposa::Raposa, &p)
        .unwrap();
    let m = agent.memory();
    let Source::TwoBlock(cues) = &m.source else {
        panic!("the two-block flap must select the two-block source");
    };
    // Bujold's camera: f = 128 / tan 35° ≈ 183 px; A₁ is the flap's area at 1 m.
    assert!((m.source.f_px() - 182.8).abs() < 0.1);
    assert!((m.source.distance_from_area(cues.area_1m_px / 4.0) - 2.0).abs() < 1e-9);
    // Docked, the camera sits inside the pouch: the departure drives 0.9 m to imprint at 0.6 m.
    assert!((m.docked_distance - (0.15 - 0.45)).abs() < 1e-9);
}

/// A found pair of two 20 × `h` px blocks whose left block has `left_share` of the pixels,
/// its midpoint `offset` px right of the image centre.
fn pair(h: u32, left_share: f64, offset: f64) -> TwoBlockPercept {
    let (cx, cy) = (128.0 + offset, 120.0);
    let total = 40 * h as u64;
    let left = (total as f64 * left_share) as u64;
    let bbox = |x0: f64| {
        [
            x0 as u32,
            (cy - h as f64 / 2.0) as u32,
            x0 as u32 + 19,
            (cy + h as f64 / 2.0) as u32 - 1,
        ]
    };
    TwoBlockPercept {
        stamp: 0.0,
        found: true,
        left_px: left,
        right_px: total - left,
        total_px: total,
        ratio: 0.0,
        left_centroid: [cx - 10.0, cy],
        right_centroid: [cx + 10.0, cy],
        offset_px: offset,
        left_bbox: bbox(cx - 20.0),
        right_bbox: bbox(cx),
        mode: ColorMode::Adapted,
        image_size: (256, 240),
    }
}

#[test]
fn the_adapter_reports_raposa_cues_and_alpha_only_from_a_run_of_reliable_frames() {
    let p = profile();
    let tuning = marsupial::behaviors::catalog::tuning::<marsupial::behaviors::raposa::Raposa>(&p).unwrap();
    let Source::TwoBlock(mut cues) = Source::from_profile(&p, &tuning.two_block).unwrap() else {
        panic!("two-block source expected");
    };
    let window = tuning.two_block.alpha_window_frames;
    // Far (blocks 12 px tall): distance from the height, no α.
    let far = cues.view(&pair(12, 0.5, 0.0)).unwrap();
    assert!((far.ball_distance_m - 0.11 * 182.8 / 12.0).abs() < 0.05);
    assert_eq!(far.alpha, None);
    // The dev_px sign is RAPOSA's: −f·tan(bearing), whatever the camera's roll.
    let off = cues.view(&pair(12, 0.5, 30.0)).unwrap();
    assert!(off.bearing != 0.0);
    assert!((off.dev_px[0] + 182.8 * off.bearing.tan()).abs() < 0.1);
    // Near (50 px): α once `window` reliable frames came in a row; a far frame restarts it.
    let near = pair(50, 0.55, 0.0);
    for _ in 1..window {
        assert_eq!(cues.view(&near).unwrap().alpha, None);
    }
    let a = cues.view(&near).unwrap().alpha.expect("a full window reports α");
    assert!(a.abs() > 5f64.to_radians(), "an asymmetric pair is off the axis");
    assert_eq!(cues.view(&pair(12, 0.5, 0.0)).unwrap().alpha, None);
    assert_eq!(cues.view(&near).unwrap().alpha, None);
    // One bloomed frame among reliable ones does not move the median.
    let mut cues2 = match Source::from_profile(&p, &tuning.two_block).unwrap() {
        Source::TwoBlock(c) => c,
        Source::Pyramid(_) => unreachable!(),
    };
    let centred = pair(50, 0.5, 0.0);
    for _ in 1..window {
        cues2.view(&centred);
    }
    let bloom = cues2.view(&pair(50, 0.9, 0.0)).unwrap();
    assert!(bloom.alpha.unwrap().abs() < 1f64.to_radians());
}
