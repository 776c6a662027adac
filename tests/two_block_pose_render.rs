//! Bujold's viewing-angle cue on rendered frames: α from the two blocks against the true
//! pose, across the distances and angles of the close dock, with the robot turned off the
//! line of sight as the approach leaves it.

use marsupial::geometry::Pose2;
use marsupial::perception::RgbImage;
use marsupial::perception::camera_model::CameraModel;
use marsupial::perception::two_block_pose::{FiducialView, TwoBlockGeometry};
use marsupial::profile::Profile;
use marsupial::schemas::TwoBlockSchema;
use marsupial::sim::camera::camera_pose;
use marsupial::sim::lighting::{LightingRun, LightingSpec};
use marsupial::sim::render::{Renderer, SensorParams};
use marsupial::sim::rng::Rng;
use marsupial::sim::world;
use std::path::Path;

fn bujold() -> Profile {
    Profile::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/bujold.toml")).unwrap()
}

/// Robot pose with its (rear) camera at distance `d` from the flap at angle `alpha_deg`
/// off the dock axis, turned `turn_deg` away from facing the flap squarely.
fn pose_at(p: &Profile, d: f64, alpha_deg: f64, turn_deg: f64) -> Pose2 {
    let a = alpha_deg.to_radians();
    let (cx, cy) = (d * a.cos(), d * a.sin());
    let theta = a + turn_deg.to_radians();
    let mount = &p.cameras[0].mount;
    Pose2::new(cx - mount.x_m * theta.cos(), cy - mount.x_m * theta.sin(), theta)
}

fn render(p: &Profile, w: &world::World, r: &mut Renderer, pose: &Pose2, seed: u64) -> RgbImage {
    let cam = &p.cameras[0];
    let light = LightingRun::new(LightingSpec::default().resolve(), &mut Rng::new(seed), 10.0);
    let mut out = RgbImage::default();
    for k in 0..4 {
        // A few frames so auto-exposure settles.
        r.render(
            &w.scene,
            &camera_pose(pose, &cam.mount),
            &light.at(0.0),
            &SensorParams::default(),
            seed + k,
            &mut out,
        );
    }
    out
}

/// Near the gate, where the at-dock decision is made, the ratio cue gives α within 2°
/// over ±10° of viewing angle, with the robot turned ±8° off the line of sight (the
/// approach's dead band and understeer leave it so); at 0.5 m, where a boundary column is 1.5 % of a block, within 5°. The first
/// version's perspective-only model read 5° as 8° at 0.38 m and as 12° at 0.5 m.
#[test]
fn alpha_tracks_the_true_pose_near_the_gate() {
    let p = bujold();
    let w = world::build(&p, &[], &[]).unwrap();
    let cam = &p.cameras[0];
    let fid = p.fiducial.two_block.unwrap();
    let g = TwoBlockGeometry::new(cam, &fid);
    let mut r = Renderer::new(CameraModel::from_spec(cam), cam.width_px, cam.height_px, 1);
    let mut s = TwoBlockSchema::from_profile(&p, 0).unwrap();
    // Imprint head-on at the profile's imprint distance, as on departure.
    let im = render(
        &p,
        &w,
        &mut r,
        &pose_at(&p, p.perception.imprint.at_distance_m, 0.0, 0.0),
        3,
    );
    s.imprint_frame(&im.view());
    assert!(s.finish_imprint(0.0));
    let mut worst: [f64; 2] = [0.0; 2];
    for (k, d, tol) in [(0, 0.38, 2.0), (0, 0.42, 2.0), (1, 0.5, 5.0)] {
        for a in [-10.0, -5.0, -2.0, 0.0, 2.0, 5.0, 10.0] {
            for turn in [-8.0, 0.0, 8.0] {
                let im = render(&p, &w, &mut r, &pose_at(&p, d, a, turn), 11);
                let pc = s.process(&im.view(), 0.1).unwrap();
                let v = FiducialView::from_percept(&pc, &g).expect("flap seen");
                let err = v.alpha.to_degrees() - a;
                assert!(
                    err.abs() < tol,
                    "{d} m, α {a}°, turned {turn}°: α̂ {:.2}°",
                    v.alpha.to_degrees()
                );
                // The heading follows: α less the bearing of the flap.
                let h_err = v.heading.to_degrees() - (a + turn);
                assert!(
                    h_err.abs() < tol + 1.0,
                    "{d} m, α {a}°, turned {turn}°: heading {:.2}°",
                    v.heading.to_degrees()
                );
                worst[k] = worst[k].max(err.abs());
            }
        }
    }
    println!(
        "worst α error: {:.2}° at 0.38–0.42 m, {:.2}° at 0.5 m",
        worst[0], worst[1]
    );
}
