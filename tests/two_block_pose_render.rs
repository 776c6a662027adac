//! Bujold's viewing-angle cue on rendered frames: α from the two blocks against the true
//! pose, across the distances and angles of the close dock, with the robot turned off the
//! line of sight as the approach leaves it.

use crate::common;

use common::{pose_seeing_origin, render_lab, renderer, shipped_profile};
use marsupial::perception::two_block_pose::{FiducialView, TwoBlockGeometry};
use marsupial::schemas::TwoBlockSchema;
use marsupial::sim::world;

/// Near the gate, where the at-dock decision is made, the ratio cue gives α within 2.1°
/// over ±10° of viewing angle, with the robot turned ±8° off the line of sight (the
/// approach's dead band and understeer leave it so); at 0.5 m, where a boundary column is
/// 1.5 % of a block, within 5°. Measured worst: 2.01° and 4.36° (1.89° and 4.27° before a
/// block's spurs left its count, README "A block's spurs"). The perspective-only model this replaced read 5° as 8° at
/// 0.38 m and as 12° at 0.5 m.
#[test]
fn alpha_tracks_the_true_pose_near_the_gate() {
    let p = shipped_profile("bujold");
    let w = world::build(&p, &[], &[]).unwrap();
    let cam = &p.cameras[0];
    let fid = p.fiducial.get::<marsupial::profile::TwoBlockSpec>().copied().unwrap();
    let g = TwoBlockGeometry::new(cam, &fid);
    let mut r = renderer(&p, 1);
    let mut s = TwoBlockSchema::from_profile(&p, 0).unwrap();
    // Imprint head-on at the profile's imprint distance, as on departure.
    let depart = pose_seeing_origin(&p, p.perception.imprint.at_distance_m, 0.0, 0.0);
    let im = render_lab(&p, &w, &mut r, &depart, 3, 4);
    s.imprint_frame(&im.view());
    assert!(s.finish_imprint(0.0));
    let mut worst: [f64; 2] = [0.0; 2];
    for (k, d, tol) in [(0, 0.38, 2.1), (0, 0.42, 2.1), (1, 0.5, 5.0)] {
        for a in [-10.0, -5.0, -2.0, 0.0, 2.0, 5.0, 10.0] {
            for turn in [-8.0, 0.0, 8.0] {
                let im = render_lab(&p, &w, &mut r, &pose_seeing_origin(&p, d, a, turn), 11, 4);
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
