//! The AutoKrawler's running gear under its belly fisheye: the eight magenta markers
//! appear where the fisheye model projects the state's marker positions, steering shifts
//! the tie-rod markers against the plate markers as the paper's ratio reads it, and the
//! white correction face shows on top of a wheel and hides under it.

use crate::common;

use marsupial::geometry::Pose2;
use marsupial::perception::RgbImage;
use marsupial::perception::camera_model::CameraModel;
use marsupial::profile::Profile;
use marsupial::sim::camera::camera_pose;
use marsupial::sim::krawler::{KrawlerState, build};
use marsupial::sim::lighting::LightState;
use marsupial::sim::render::{CameraPose, Renderer};
use nalgebra::Point3;

fn krawler() -> Profile {
    common::shipped_profile("autokrawler")
}

struct View {
    image: RgbImage,
    model: CameraModel,
    pose: CameraPose,
}

impl View {
    fn project(&self, p: &Point3<f64>) -> [f64; 2] {
        let c = self.pose.rotation.transpose() * (p - self.pose.position);
        self.model.project(&c).expect("in the fisheye's field")
    }

    /// Weighted centroid of magenta pixels (red and blue well above green) within
    /// `reach` px of `around`.
    fn magenta_centroid(&self, around: [f64; 2], reach: f64) -> Option<[f64; 2]> {
        common::weighted_centroid(&self.image, around, reach, |p| {
            (p[0].min(p[2]) as f64 - p[1] as f64 - 60.0).max(0.0)
        })
    }
}

fn view(p: &Profile, state: &KrawlerState) -> (View, marsupial::sim::krawler::KrawlerScene) {
    let gear = build(p, state).expect("autokrawler gear");
    let cam = &p.cameras[0];
    let model = CameraModel::from_spec(cam);
    let mut r = Renderer::new(model.clone(), cam.width_px, cam.height_px, 1);
    let pose = camera_pose(&Pose2::new(0.0, 0.0, 0.0), &cam.mount);
    let mut image = RgbImage::default();
    r.render(
        &gear.scene,
        &pose,
        &LightState::uniform(1.0),
        &common::quiet_sensor(),
        0,
        &mut image,
    );
    (View { image, model, pose }, gear)
}

#[test]
fn every_marker_appears_where_the_fisheye_projects_it_in_any_state() {
    let p = krawler();
    let rest = KrawlerState::rest(&p).expect("autokrawler gear");
    let states = [
        rest,
        KrawlerState {
            steer: [0.45, -0.3],
            ..rest
        },
        KrawlerState {
            roll: [0.12, -0.08],
            drop: [rest.drop[0] - 0.03, rest.drop[1] + 0.02],
            ..rest
        },
        KrawlerState {
            steer: [-0.5, 0.5],
            roll: [-0.1, 0.1],
            wheel: [1.0, 2.0, 3.0, 4.0],
            ..rest
        },
    ];
    for (k, state) in states.iter().enumerate() {
        let (v, gear) = view(&p, state);
        for (i, m) in gear.markers.iter().enumerate() {
            let at = v.project(m);
            let c = v
                .magenta_centroid(at, 12.0)
                .unwrap_or_else(|| panic!("state {k} marker {i}: nothing magenta at {at:?}"));
            let err = ((c[0] - at[0]).powi(2) + (c[1] - at[1]).powi(2)).sqrt();
            assert!(
                err < 1.0,
                "state {k} marker {i}: centroid {c:?} vs projected {at:?} ({err:.2} px)"
            );
        }
    }
}

/// The paper's steering cue: on each axle, the distance from a tie-rod marker to the
/// plate marker on the same side, left over right, is 1 straight and moves away from 1
/// with the steering's sign; measured here on the image, from the centroids.
#[test]
fn steering_shifts_the_tie_rod_markers_against_the_plate_markers() {
    let p = krawler();
    let rest = KrawlerState::rest(&p).expect("autokrawler gear");
    let ratio = |steer: f64| {
        let (v, gear) = view(
            &p,
            &KrawlerState {
                steer: [steer, steer],
                ..rest
            },
        );
        let at = |i: usize| {
            v.magenta_centroid(v.project(&gear.markers[i]), 12.0)
                .expect("marker seen")
        };
        let dist = |a: [f64; 2], b: [f64; 2]| ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt();
        // Front axle: plate left 0, right 1; rod left 2, right 3.
        dist(at(2), at(0)) / dist(at(3), at(1))
    };
    let straight = ratio(0.0);
    assert!((straight - 1.0).abs() < 0.03, "straight: {straight}");
    let (left, right) = (ratio(0.4), ratio(-0.4));
    assert!(
        (left - 1.0) * (right - 1.0) < 0.0,
        "opposite sides of 1: {left}, {right}"
    );
    assert!((left - 1.0).abs() > 0.1 && (right - 1.0).abs() > 0.1, "{left}, {right}");
}

#[test]
fn the_white_correction_face_shows_on_top_and_hides_underneath() {
    let p = krawler();
    let rest = KrawlerState::rest(&p).expect("autokrawler gear");
    // Where the front-left wheel's correction face is at θ = 0: on top.
    let on_top_at = build(&p, &rest).unwrap().correction[0];
    let whiteness = |theta: f64| {
        let (v, gear) = view(
            &p,
            &KrawlerState {
                wheel: [theta; 4],
                ..rest
            },
        );
        let at = v.project(&on_top_at);
        let px = v.image.view().get(at[0] as usize, at[1] as usize).unwrap();
        (px[0].min(px[1]).min(px[2]), gear.correction[0])
    };
    let (on_top, p0) = whiteness(0.0);
    let (underneath, p1) = whiteness(std::f64::consts::PI);
    assert!(on_top > 200, "the white face on top: {on_top}");
    assert!(underneath < 120, "rubber where it was: {underneath}");
    assert!(p1.z < p0.z - 0.2, "the face went under: {} → {}", p0.z, p1.z);
}

#[test]
fn a_profile_without_the_gear_is_refused_with_what_it_lacks() {
    let bujold = common::shipped_profile("bujold");
    let e = KrawlerState::rest(&bujold).unwrap_err().to_string();
    assert!(e.contains("double-Ackermann") && e.contains("bujold"), "{e}");
    let mut no_radius = krawler();
    no_radius.drive.wheel_radius_m = None;
    let e = build(&no_radius, &KrawlerState::rest(&krawler()).unwrap())
        .unwrap_err()
        .to_string();
    assert!(e.contains("wheel_radius_m"), "{e}");
}

/// The Ackermann trapezoid makes the paper's ratio (eq. 5) a steering cue in world
/// coordinates, with no camera involved: on each axle, d(rod left, plate left) over
/// d(rod right, plate right) is 1 straight and moves monotonically away from 1 as |λ|
/// grows to 30°, above 1 one way and below 1 the other. Prints the table λ → ratio.
#[test]
fn the_world_ratio_of_tie_rod_to_plate_marker_distances_moves_away_from_1_with_steering() {
    let p = krawler();
    let rest = KrawlerState::rest(&p).expect("autokrawler gear");
    let ratio = |steer: f64, roll: f64| {
        let gear = build(
            &p,
            &KrawlerState {
                steer: [steer; 2],
                roll: [roll, -roll],
                ..rest
            },
        )
        .unwrap();
        let m = gear.markers;
        [0, 4].map(|a| (m[a + 2] - m[a]).norm() / (m[a + 3] - m[a + 1]).norm())
    };
    for roll in [0.0, 0.15] {
        let straight = ratio(0.0, roll);
        for r in straight {
            assert!((r - 1.0).abs() < 1e-9, "straight, roll {roll}: {r}");
        }
        for sign in [1.0, -1.0] {
            let mut last = [1.0, 1.0];
            let mut side = [0.0, 0.0];
            for deg in (1..=30).map(f64::from) {
                let lambda = sign * deg.to_radians();
                let r = ratio(lambda, roll);
                if deg % 5.0 == 0.0 && roll == 0.0 {
                    println!("λ = {:+3}°: front {:.4}, rear {:.4}", sign * deg, r[0], r[1]);
                }
                for axle in 0..2 {
                    assert!(
                        (r[axle] - 1.0).abs() > (last[axle] - 1.0_f64).abs(),
                        "axle {axle}, roll {roll}: λ = {}°: {} not further from 1 than {}",
                        sign * deg,
                        r[axle],
                        last[axle]
                    );
                    if deg == 1.0 {
                        side[axle] = (r[axle] - 1.0).signum();
                    }
                    assert_eq!((r[axle] - 1.0).signum(), side[axle], "stays on one side of 1");
                }
                last = r;
            }
            if sign < 0.0 {
                continue;
            }
            // The other direction lands on the other side of 1.
            let other = ratio(-0.3, roll);
            for axle in 0..2 {
                assert!((other[axle] - 1.0) * side[axle] < 0.0, "axle {axle}: {other:?}");
            }
        }
    }
}
