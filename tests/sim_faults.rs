//! Faults injected into closed-loop docking runs (`[[faults]]`, `sim::faults`): from the
//! three starts of `scenarios/bujold-faults.toml`, a camera that goes silent, frames that
//! arrive late, wrong-sized frames, a camera driver and an odometer that re-send one
//! reading as new, odometry that reads NaN, a latency spike and a person standing in the
//! line of sight each end in a dock after the fault passes, with no motion commanded while an
//! input was invalid; the per-fault summary counts them. The full campaign (every kind at
//! two phases) is `marsupial trials scenarios/bujold-faults.toml`.

use marsupial::behaviors::agent_for;
use marsupial::sim::campaign;
use marsupial::sim::scenario::Scenario;
use std::path::Path;

#[test]
fn transient_faults_end_in_a_recovered_dock_with_no_motion_on_invalid_input() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/bujold-faults.toml");
    let mut loaded = Scenario::load(&file).unwrap();
    // In the scenario's order, which is the summary's.
    let keep = [
        "camera_silent@3s",
        "odometry_nan@3s",
        "command_latency@3s",
        "camera_frozen@3s",
        "odometry_frozen@3s",
        "camera_late@12s",
        "camera_wrong_size@12s",
        "occluder@12s",
    ];
    loaded.scenario.faults.retain(|f| keep.contains(&f.name.as_str()));
    assert_eq!(loaded.scenario.faults.len(), keep.len());
    let p = campaign::prepare(loaded).unwrap();
    let (records, summary) = campaign::run_campaign(&p, &agent_for, &Default::default()).unwrap();
    assert_eq!(records.len(), 3 * keep.len());
    for r in &records {
        let fault = r.fault.as_deref().unwrap();
        assert!(
            r.success && r.fault_as_expected == Some(true),
            "start {} with {fault}: {} after {:.1} s",
            r.start,
            r.outcome,
            r.time_s
        );
        assert_eq!(r.stale_motion_ticks, Some(0), "start {} with {fault}", r.start);
        // The faults that leave an input invalid stop the robot for about their length
        // (a silent or frozen camera's last frame, and frozen odometry, stay usable for
        // the 0.5 s staleness limit).
        let stop = r.safe_stop_s.unwrap();
        match fault {
            "camera_silent@3s" | "camera_frozen@3s" => assert!((1.3..=1.7).contains(&stop), "{fault}: {stop} s"),
            "camera_late@12s" => assert!((2.3..=2.7).contains(&stop), "{fault}: {stop} s"),
            "camera_wrong_size@12s" | "odometry_nan@3s" | "odometry_frozen@3s" => {
                assert!((1.8..=2.2).contains(&stop), "{fault}: {stop} s")
            }
            _ => assert!(stop < 0.2, "{fault}: {stop} s"),
        }
    }
    let names: Vec<&str> = summary.by_fault.iter().map(|f| f.fault.as_str()).collect();
    assert_eq!(names, keep);
    assert!(
        summary
            .by_fault
            .iter()
            .all(|f| f.runs == 3 && f.as_expected == 3 && f.other == 0)
    );
}
