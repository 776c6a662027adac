//! The dock judge at the edge of each shipped robot's tolerance: arrivals just inside the
//! lateral and heading limits of the profile's `[success]` are accepted, arrivals just
//! outside are not. The geometry is the one the simulator builds from the shipped profile
//! (`world::build`), so a tolerance that drifted in the profile, in the world or in the
//! judge fails here. Bujold's pouch is a closed dock (the rear crosses the entrance plane);
//! RAPOSA's pyramid an open one (the target meets the socket's mouth).

use marsupial::geometry::Pose2;
use marsupial::profile::Profile;
use marsupial::sim::dock::{Contact, judge};
use marsupial::sim::world::{self, DockGeometry};
use std::path::Path;

struct Robot {
    dock: DockGeometry,
    length: f64,
    width: f64,
}

fn robot(name: &str) -> Robot {
    let profile = Profile::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("profiles/{name}.toml"))).unwrap();
    let w = world::build(&profile, &[], &[]).unwrap();
    Robot {
        dock: w.dock,
        length: profile.body.length_m,
        width: profile.body.width_m,
    }
}

/// Bujold (closed dock): the robot backing in with its rear centre 1 mm past the entrance
/// plane at `lateral_m` off the axis, heading `heading_deg` off it, lowered or not.
fn bujold_arrives_posed(r: &Robot, lateral_m: f64, heading_deg: f64, lowered: bool) -> Contact {
    let h = heading_deg.to_radians();
    let half = r.length / 2.0;
    // Rear centre at (−1 mm, lateral): the centre is half a body ahead along the heading.
    let to = Pose2::new(-0.001 + half * h.cos(), lateral_m + half * h.sin(), h);
    let from = Pose2::new(to.x + 0.005 * h.cos(), to.y + 0.005 * h.sin(), h);
    let (rx, ry) = to.to_world(-half, 0.0);
    assert!((rx + 0.001).abs() < 1e-12 && (ry - lateral_m).abs() < 1e-12);
    judge(&r.dock, false, &from, &to, r.length, r.width, lowered)
}

/// As [`bujold_arrives_posed`], lowered (as she backs in).
fn bujold_arrives(r: &Robot, lateral_m: f64, heading_deg: f64) -> Contact {
    bujold_arrives_posed(r, lateral_m, heading_deg, true)
}

/// RAPOSA (open dock): the pyramid's ball at the robot's rear plane, `lateral_m` off the
/// robot's axis, the robot's heading `heading_deg` off the pyramid's.
fn raposa_arrives(r: &Robot, lateral_m: f64, heading_deg: f64) -> Contact {
    let h = heading_deg.to_radians();
    let (lx, ly) = (-r.length / 2.0, lateral_m);
    // The pose whose local point (lx, ly) is the world origin (the ball).
    let (s, c) = h.sin_cos();
    let to = Pose2::new(-(c * lx - s * ly), -(s * lx + c * ly), h);
    let (bx, by) = to.to_local(0.0, 0.0);
    assert!((bx - lx).abs() < 1e-12 && (by - ly).abs() < 1e-12);
    let from = Pose2::new(to.x + 0.005 * c, to.y + 0.005 * s, h);
    judge(&r.dock, false, &from, &to, r.length, r.width, false)
}

#[test]
fn bujold_enters_within_2_cm_and_5_degrees_and_catches_the_edge_just_outside() {
    let r = robot("bujold");
    // The README's and the paper's tolerance, as the shipped profile states it.
    assert!((r.dock.tol_lateral - 0.02).abs() < 1e-12, "{}", r.dock.tol_lateral);
    assert!((r.dock.tol_heading.to_degrees() - 5.0).abs() < 1e-9);
    assert!(!r.dock.open && r.dock.needs_lowered);
    for sign in [1.0, -1.0] {
        for (lat_cm, head_deg) in [(0.0, 0.0), (1.9, 0.0), (0.0, 4.9), (1.9, 4.9), (1.9, -4.9)] {
            let c = bujold_arrives(&r, sign * lat_cm / 100.0, sign * head_deg);
            assert_eq!(c, Contact::Inside, "{:+} cm, {:+}°", sign * lat_cm, sign * head_deg);
        }
        for (lat_cm, head_deg) in [(2.1, 0.0), (0.0, 5.1), (2.1, 4.9), (1.9, 5.1), (2.1, 5.1)] {
            let c = bujold_arrives(&r, sign * lat_cm / 100.0, sign * head_deg);
            let Contact::Stuck { lateral, heading } = c else {
                panic!("{:+} cm, {:+}°: {c:?}", sign * lat_cm, sign * head_deg)
            };
            // The judge reports the arrival it refused.
            assert!((lateral - sign * lat_cm / 100.0).abs() < 1e-9, "{lateral}");
            assert!((heading.to_degrees() - sign * head_deg).abs() < 1e-9, "{heading}");
        }
    }
    // Within tolerance but raised: the entrance catches her.
    for (lat_cm, head_deg) in [(0.0, 0.0), (1.9, 4.9)] {
        let c = bujold_arrives_posed(&r, lat_cm / 100.0, head_deg, false);
        assert!(
            matches!(c, Contact::Stuck { .. }),
            "raised, {lat_cm} cm, {head_deg}°: {c:?}"
        );
    }
}

#[test]
fn raposa_docks_within_4_cm_and_20_degrees_and_collides_just_outside() {
    let r = robot("raposa");
    assert!((r.dock.tol_lateral - 0.04).abs() < 1e-12, "{}", r.dock.tol_lateral);
    assert!((r.dock.tol_heading.to_degrees() - 20.0).abs() < 1e-9);
    assert!(r.dock.open && !r.dock.needs_lowered);
    // The socket's mouth is wider than the tolerance, so the limit is the judge's, not
    // the mouth's: 4.1 cm off still meets the mouth and is judged.
    assert!(r.dock.entrance_half > 0.041, "{}", r.dock.entrance_half);
    for sign in [1.0, -1.0] {
        for (lat_cm, head_deg) in [(0.0, 0.0), (3.9, 0.0), (0.0, 19.9), (3.9, 19.9), (3.9, -19.9)] {
            let c = raposa_arrives(&r, sign * lat_cm / 100.0, sign * head_deg);
            assert_eq!(c, Contact::Docked, "{:+} cm, {:+}°", sign * lat_cm, sign * head_deg);
        }
        for (lat_cm, head_deg) in [(4.1, 0.0), (0.0, 20.1), (4.1, 19.9), (3.9, 20.1), (4.1, 20.1)] {
            let c = raposa_arrives(&r, sign * lat_cm / 100.0, sign * head_deg);
            let Contact::Stuck { lateral, heading } = c else {
                panic!("{:+} cm, {:+}°: {c:?}", sign * lat_cm, sign * head_deg)
            };
            assert!((lateral - sign * lat_cm / 100.0).abs() < 1e-9, "{lateral}");
            assert!((heading.to_degrees() - sign * head_deg).abs() < 1e-9, "{heading}");
        }
    }
}
