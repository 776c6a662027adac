//! RAPOSA's seven-state docking closed in the simulator from starts across region I (on
//! the axis, near and far, 15° off) and region II (30°, 60° and 90° on either side, and
//! inside δ where the manoeuvre backs away). Each must dock within the profile's
//! tolerance, region-II starts through at least one alignment manoeuvre. And from the
//! paper's dead zone (0.33 m, far off the axis, where only the ball is in view), which
//! the paper never docked: by probing around the ball until the pair shows its side.

use crate::common;

use marsupial::behaviors::agent_for;
use marsupial::sim::campaign;
use marsupial::sim::scenario::Scenario;

/// Runs the profile from `points` (distance m, angle °), one trial each, and checks that
/// every run docked within the profile's tolerance; the records, in the points' order.
fn docked_from(tag: &str, points: &[(f64, f64)]) -> Vec<campaign::RunRecord> {
    let dir = std::env::temp_dir().join(format!("marsupial-raposa-{tag}-{}", std::process::id()));
    let list: Vec<String> = points
        .iter()
        .map(|(d, a)| format!("{{ distance_m = {d}, angle_deg = {a} }}"))
        .collect();
    let s = common::scenario_file(
        &dir,
        &format!("raposa-{tag}"),
        "raposa.toml",
        &format!(
            "seed = 5\ntrials = 1\ntimeout_s = 300.0\n[starts]\nposition_jitter_m = 0.02\nheading_jitter_deg = 2.0\npoints = [{}]\n[imprint]\nenabled = false\n",
            list.join(", ")
        ),
    );
    let p = campaign::prepare(Scenario::load(&s).unwrap()).unwrap();
    let (records, summary) = campaign::run_campaign(&p, &agent_for, &Default::default()).unwrap();
    let tol = p.loaded.profile.success;
    for (r, (_, a)) in records.iter().zip(points) {
        assert!(
            r.success,
            "start {} ({a}°): {} after {:.1} s",
            r.start, r.outcome, r.time_s
        );
        assert!(r.entrance_lateral_m.unwrap().abs() <= tol.lateral_tolerance_m);
        assert!(r.entrance_heading_deg.unwrap().abs() <= tol.heading_tolerance_deg);
    }
    assert_eq!(summary.overall.successes, points.len());
    records
}

#[test]
fn docks_from_starts_across_regions_one_and_two() {
    let points: [(f64, f64); 8] = [
        (0.5, 0.0),
        (2.0, 0.0),
        (1.2, 10.0),
        (0.5, -30.0),
        (1.33, 30.0),
        (2.0, -60.0),
        (1.5, 60.0),
        (1.5, -90.0),
    ];
    for (r, (_, a)) in docked_from("loop", &points).iter().zip(points) {
        if a.abs() >= 30.0 {
            assert!(r.manoeuvres >= 1, "start {} ({a}°) docked without region II", r.start);
        } else {
            assert_eq!(r.manoeuvres, 0, "start {} ({a}°) is region I", r.start);
        }
    }
}

/// The paper's points 1 and 3 (0.33 m, ±70°) and one between them and the axis: only the
/// ball is in view, so the robot probes (at least one manoeuvre) and docks.
#[test]
fn docks_from_the_dead_zone_by_probing() {
    let points: [(f64, f64); 3] = [(0.33, -70.0), (0.33, 70.0), (0.4, -62.0)];
    for (r, (_, a)) in docked_from("dead-zone", &points).iter().zip(points) {
        assert!(
            r.manoeuvres >= 1,
            "start {} ({a}°) docked without moving around",
            r.start
        );
    }
}
