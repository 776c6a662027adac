//! Imprinting and adapting RAPOSA's HSV bands on rendered frames: a ball repainted red is
//! invisible to the operator's orange bands, and imprinting at the departure pose learns
//! it under lab and dusk light; imprinting refuses a pyramid that is not where the
//! departure geometry puts it; `fixed` segmentation never imprints; adaptation narrows
//! the bands, keeps the pair from other poses and falls back to the table when the
//! pyramid is gone; a failed departure imprint is recorded as failed.

use crate::common;

use common::pose_seeing_origin;
use marsupial::geometry::Pose2;
use marsupial::perception::camera_model::CameraModel;
use marsupial::perception::{ColorMode, RgbImage};
use marsupial::profile::{Profile, SegmentationMode};
use marsupial::schemas::PyramidSchema;
use marsupial::sim::camera::camera_pose;
use marsupial::sim::lighting::{Illuminant, LightingPreset, LightingRun, LightingSpec};
use marsupial::sim::render::{Renderer, SensorParams, WhiteBalance};
use marsupial::sim::rng::Rng;
use marsupial::sim::world;
use std::path::Path;

fn load(rel: &str) -> Profile {
    Profile::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)).unwrap()
}

fn render(p: &Profile, pose: &Pose2, preset: LightingPreset, seed: u64) -> RgbImage {
    let w = world::build(p, &[], &[]).unwrap();
    let cam = &p.cameras[0];
    let mut r = Renderer::new(CameraModel::from_spec(cam), cam.width_px, cam.height_px, seed);
    let spec = LightingSpec {
        preset: Some(preset),
        ..LightingSpec::default()
    };
    let lighting = spec.resolve();
    let light = LightingRun::new(lighting, &mut Rng::new(seed), 10.0);
    // White balance fixed for daylight: dusk's warm light reaches the colours.
    let sensor = SensorParams {
        white_balance: WhiteBalance::Fixed(Illuminant::Daylight.rgb().map(|c| 1.0 / c)),
        ..SensorParams::default()
    };
    let mut out = RgbImage::default();
    r.render(
        &w.scene,
        &camera_pose(pose, &cam.mount),
        &light.at(0.0),
        &sensor,
        seed,
        &mut out,
    );
    out
}

fn schema(p: &Profile, mode: SegmentationMode) -> PyramidSchema {
    let mut p = p.clone();
    p.perception.mode = mode;
    PyramidSchema::from_profile(&p, 0).unwrap()
}

#[test]
fn imprint_learns_a_repainted_ball() {
    let red = marsupial::sim::scenario::Scenario::load(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/raposa-repaint.toml"),
    )
    .unwrap()
    .profile;
    assert_eq!(red.name, "raposa-red");
    for preset in [LightingPreset::Lab, LightingPreset::Dusk] {
        let mut s = schema(&red, SegmentationMode::Static);
        let d = s.imprint_distance();
        // Under lab light the orange bands do not see the red ball from the departure
        // pose (dusk's warm light and the fixed white balance push it back to orange) …
        if preset == LightingPreset::Lab {
            let depart = render(&red, &pose_seeing_origin(&red, d, 0.0, 0.0), preset, 3);
            assert!(s.process(&depart.view(), 0.0).unwrap().view.is_none());
        }
        // … the imprint does, and from the grid's starts too.
        let frames = s.imprint_frames_wanted();
        for k in 0..frames {
            let im = render(&red, &pose_seeing_origin(&red, d, 0.0, 0.0), preset, 10 + k as u64);
            assert!(s.imprint_frame(&im.view()).unwrap(), "{preset:?} frame {k}");
        }
        assert!(s.finish_imprint(1.0));
        assert_eq!(s.model().mode(), ColorMode::Imprinted);
        let [o, _] = s.bands();
        if preset == LightingPreset::Lab {
            assert!(o.h[0] > o.h[1] || o.h[0] < 8.0, "band around red: {o:?}");
        }
        for (dist, a) in [(1.0, 0.0), (1.33, 0.0), (1.5, 30.0), (2.0, -20.0)] {
            let im = render(&red, &pose_seeing_origin(&red, dist, a, 0.0), preset, 99);
            let pc = s.process(&im.view(), 2.0).unwrap();
            assert!(pc.detection.pair.is_some(), "{preset:?} {dist} m {a}°");
        }
    }
}

#[test]
fn imprint_refuses_a_pyramid_off_the_departure_pose() {
    let p = load("profiles/raposa.toml");
    let mut s = schema(&p, SegmentationMode::Adaptive);
    let d = s.imprint_distance();
    // Twice as far and 40° off: the geometry check rejects every frame.
    for (dist, a) in [(2.0 * d, 0.0), (d, 40.0)] {
        let im = render(&p, &pose_seeing_origin(&p, dist, a, 0.0), LightingPreset::Lab, 5);
        assert!(!s.imprint_frame(&im.view()).unwrap(), "{dist} m {a}°");
    }
    assert!(!s.finish_imprint(1.0));
    assert_eq!(s.model().mode(), ColorMode::Table);
}

#[test]
fn fixed_mode_never_imprints_or_adapts() {
    let p = load("profiles/raposa.toml");
    let mut s = schema(&p, SegmentationMode::Fixed);
    let table = s.bands();
    let im = render(
        &p,
        &pose_seeing_origin(&p, s.imprint_distance(), 0.0, 0.0),
        LightingPreset::Lab,
        5,
    );
    assert!(s.imprint_frame(&im.view()).unwrap());
    assert!(!s.finish_imprint(1.0));
    for t in 0..5 {
        assert!(s.process(&im.view(), t as f64).unwrap().detection.pair.is_some());
    }
    assert_eq!(s.bands(), table);
}

#[test]
fn adaptation_follows_the_target_and_falls_back_when_lost() {
    let p = load("profiles/raposa.toml");
    let mut s = schema(&p, SegmentationMode::Adaptive);
    let near = render(&p, &pose_seeing_origin(&p, 1.0, 10.0, 0.0), LightingPreset::Lab, 5);
    assert!(s.process(&near.view(), 0.0).unwrap().detection.pair.is_some());
    assert_eq!(s.model().mode(), ColorMode::Adapted);
    let adapted = s.bands();
    // The adapted orange band is narrower than the operator's and still holds the ball
    // (hue around 30°).
    let table = schema(&p, SegmentationMode::Fixed).bands();
    let width = |r: [f32; 2]| r[1] - r[0];
    assert!(width(adapted[0].h) < width(table[0].h), "{adapted:?}");
    assert!(adapted[0].h[0] < 30.0 && adapted[0].h[1] > 30.0);
    // From other poses under the same light the adapted bands still find the pair.
    for (dist, a) in [(1.5, -20.0), (0.7, 0.0), (2.0, 30.0)] {
        let im = render(&p, &pose_seeing_origin(&p, dist, a, 0.0), LightingPreset::Lab, 6);
        assert!(
            s.process(&im.view(), 0.1).unwrap().detection.pair.is_some(),
            "{dist} m {a}°"
        );
    }
    // An empty view for longer than the timeout falls back to the table (no imprint).
    let empty = render(&p, &Pose2::new(3.0, 3.0, 0.0), LightingPreset::Lab, 7);
    let t1 = p.perception.timeout1_s;
    for k in 1..=((t1 + 0.5) * 10.0) as usize {
        s.process(&empty.view(), 0.1 + k as f64 * 0.1).unwrap();
    }
    assert_eq!(s.model().mode(), ColorMode::Table);
    assert_eq!(s.bands(), table);
}

#[test]
fn a_failed_imprint_is_recorded_as_failed() {
    use marsupial::sim::campaign::{self, CampaignOptions};
    use marsupial::sim::scenario::Scenario;
    // The pyramid hidden from the departure pose (bands that match nothing): the run
    // record must say the imprint failed, not that the departure completed.
    let dir = std::env::temp_dir().join(format!("marsupial-imprint-fail-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut profile =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/raposa.toml")).unwrap();
    profile = profile.replace(
        "orange = { h_deg = [8.0, 45.0], s = [0.45, 1.0], v = [0.25, 1.0] }",
        "orange = { h_deg = [100.0, 110.0], s = [0.95, 1.0], v = [0.9, 1.0] }",
    );
    std::fs::write(dir.join("p.toml"), profile).unwrap();
    let sc = "name = \"f\"\ndescription = \"f\"\nprofile = \"p.toml\"\nseed = 1\ntrials = 1\ntimeout_s = 5\n[starts]\npoints = [{ distance_m = 1.0, angle_deg = 0.0 }]\n[axes]\nsegmentation = [\"static\"]\n";
    std::fs::write(dir.join("s.toml"), sc).unwrap();
    let p = campaign::prepare(Scenario::load(&dir.join("s.toml")).unwrap()).unwrap();
    let (runs, _) = campaign::run_campaign(&p, &marsupial::behaviors::agent_for, &CampaignOptions::default()).unwrap();
    assert_eq!(runs.len(), 1);
    assert_eq!(runs[0].imprinted, Some(false));
}
