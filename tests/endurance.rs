//! Endurance outings (`[endurance]`, `marsupial::sim::endurance`), smoke version: the
//! first three cycles of the shipped Bujold outing. The full 100-cycle outings belong to
//! the CLI (`marsupial trials scenarios/bujold-endurance.toml`, README "Reliability").

use marsupial::behaviors::agent_for;
use marsupial::sim::SimError;
use marsupial::sim::campaign::{self, CampaignOptions, Prepared, RunRecord};
use marsupial::sim::endurance::{OutingRecording, run_outing};
use marsupial::sim::run::Recording;
use marsupial::sim::scenario::Scenario;
use std::path::Path;

fn prepared(cycles: usize) -> Prepared {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/bujold-endurance.toml");
    let mut loaded = Scenario::load(&file).unwrap();
    loaded.scenario.endurance.as_mut().unwrap().cycles = cycles;
    campaign::prepare(loaded).unwrap()
}

fn outing(p: &Prepared) -> Vec<RunRecord> {
    let mut out = Vec::new();
    let mut blank = Recording::default();
    run_outing(
        p,
        &agent_for,
        p.runs.len() - 1,
        OutingRecording {
            traced: None,
            recording: &mut blank,
            mcap_for: &|_| None,
        },
        &mut |r| {
            out.push(r);
            Ok(())
        },
    )
    .unwrap();
    out
}

#[test]
fn three_cycles_dock_carry_state_over_and_repeat_exactly() {
    let p = prepared(3);
    let a = outing(&p);
    assert_eq!(a.len(), 3);
    for r in &a {
        assert!(r.success, "cycle {:?}: {} after {:.1} s", r.cycle, r.outcome, r.time_s);
        assert_eq!(r.imprinted, Some(true), "cycle {:?} departed and imprinted", r.cycle);
        assert_eq!(r.excursion_reached, Some(true), "cycle {:?}", r.cycle);
        assert_eq!(r.carried_back, Some(false));
    }
    // One clock: each cycle begins after the previous one's departure, excursion and
    // docking.
    let clocks: Vec<f64> = a.iter().map(|r| r.outing_clock_s.unwrap()).collect();
    assert_eq!(clocks[0], 0.0);
    assert!(
        clocks[1] > a[0].time_s && clocks[2] > clocks[1] + a[1].time_s,
        "{clocks:?}"
    );

    // Determinism: the same outing again, record for record.
    assert_eq!(outing(&p), a);

    // State carried over: the third cycle run by a fresh robot (an outing of that cycle
    // alone) starts its docking with a different odometry error, on a fresh clock.
    let mut fresh = prepared(3);
    fresh.runs = vec![fresh.runs[2].clone()];
    let b = outing(&fresh);
    let (carried, reset) = (a[2].odometry_error_m.unwrap(), b[0].odometry_error_m.unwrap());
    assert!(carried > 0.0 && reset > 0.0);
    assert_ne!(carried, reset, "odometry must not restart between cycles");
    assert_eq!(b[0].outing_clock_s, Some(0.0));

    // The summary reports the outing.
    let e = campaign::summary("x", &a).endurance.unwrap();
    assert_eq!((e.cycles, e.docked, e.carried_back), (3, 3, 0));
    assert!(e.slope_s_per_cycle.is_some() && e.first_quarter_mean_s == Some(a[0].time_s));
}

#[test]
fn an_outing_is_not_resumed_midway() {
    let p = prepared(2);
    let dir = std::env::temp_dir().join(format!("marsupial-endurance-{}", std::process::id()));
    let e = campaign::run_campaign(
        &p,
        &agent_for,
        &CampaignOptions {
            out: Some(dir.clone()),
            resume: true,
            ..Default::default()
        },
    )
    .unwrap_err();
    assert!(matches!(e, SimError::InvalidArgument(_)), "{e}");
    assert!(e.to_string().contains("cannot be resumed midway"), "{e}");
    let _ = std::fs::remove_dir_all(dir);
}
