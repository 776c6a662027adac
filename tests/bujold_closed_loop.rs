//! Bujold's whole docking (undock, imprint on departure, placement, close-dock) closed in
//! the simulator from starts across the approach zone: on the axis near and far, and 30°
//! to either side. Each must dock within the profile's tolerance (±2 cm, ±5°).

use marsupial::behaviors::agent_for;
use marsupial::sim::campaign;
use marsupial::sim::scenario::Scenario;
use std::path::Path;

#[test]
fn docks_from_starts_across_the_approach_zone() {
    let dir = std::env::temp_dir().join(format!("marsupial-closed-loop-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let profile = Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/bujold.toml");
    let s = dir.join("s.toml");
    std::fs::write(
        &s,
        format!(
            "name = \"closed-loop\"\nprofile = \"{}\"\nseed = 11\ntrials = 1\n[starts]\ngrid = \"paper16\"\nselect = [2, 5, 6, 8, 9, 14]\nposition_jitter_m = 0.02\nheading_jitter_deg = 3.0\n",
            profile.display()
        ),
    )
    .unwrap();
    let p = campaign::prepare(Scenario::load(&s).unwrap()).unwrap();
    let (records, summary) = campaign::run_campaign(&p, &agent_for, &Default::default()).unwrap();
    for r in &records {
        assert!(r.success, "start {}: {} after {:.1} s", r.start, r.outcome, r.time_s);
        assert_eq!(r.imprinted, Some(true));
        assert!(r.entrance_lateral_m.unwrap().abs() <= 0.02 && r.entrance_heading_deg.unwrap().abs() <= 5.0);
    }
    assert_eq!(summary.overall.successes, 6);
}
