//! `profiles/bujold-avoid.toml` is Bujold composed with an avoid-obstacle schema, written
//! in TOML only. Two things must hold for its campaign to mean what the README says:
//!
//! * it is `profiles/bujold.toml` except for the keys its header lists (the drift test), so
//!   that "with avoid" and "Bujold" differ only by the composition;
//! * in the simulator, the summed approach steers round a box that the plain approach
//!   drives into, from the same starts and seeds.

use marsupial::behaviors::agent_for;
use marsupial::robot::{HardwareError, Sensor};
use marsupial::sim::campaign;
use marsupial::sim::robot::SimDevices;
use marsupial::sim::scenario::Scenario;
use std::path::Path;
use std::sync::Arc;
use toml::Table;

fn read_table(file: &str) -> Table {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(file);
    std::fs::read_to_string(&path).unwrap().parse::<Table>().unwrap()
}

/// Removes `path` (dotted) from `t`, returning what was there.
fn take(t: &mut Table, path: &str) -> Option<toml::Value> {
    let mut keys: Vec<&str> = path.split('.').collect();
    let last = keys.pop().unwrap();
    let mut at = t;
    for k in keys {
        at = at.get_mut(k)?.as_table_mut()?;
    }
    at.remove(last)
}

#[test]
fn bujold_avoid_is_bujold_but_for_the_listed_keys() {
    let mut plain = read_table("profiles/bujold.toml");
    let mut avoid = read_table("profiles/bujold-avoid.toml");
    // The header's list, key by key.
    for key in ["name", "description", "robot.approach"] {
        assert!(take(&mut plain, key).is_some(), "bujold.toml lacks {key}");
        assert!(take(&mut avoid, key).is_some(), "bujold-avoid.toml lacks {key}");
    }
    // The field's gains are bujold-potential's, so the field alone is a tested approach.
    let field = take(&mut avoid, "robot.potential_field").expect("a potential_field table");
    let mut potential = read_table("scenarios/bujold-potential.toml");
    assert_eq!(
        Some(field),
        take(&mut potential, "profile_patch.robot.potential_field"),
        "bujold-avoid's field gains drifted from scenarios/bujold-potential.toml"
    );
    // One new state, approach_near, after approach; the rest of the machine is Bujold's.
    let states = |t: &mut Table| -> Vec<String> {
        take(t, "behavior.tree.nodes.close_dock.states")
            .and_then(|v| v.as_array().cloned())
            .unwrap()
            .iter()
            .map(|s| s.as_str().unwrap().to_owned())
            .collect()
    };
    let mut expected = states(&mut plain);
    let at = expected.iter().position(|s| s == "approach").unwrap() + 1;
    expected.insert(at, "approach_near".into());
    assert_eq!(states(&mut avoid), expected);
    // The approach node and the nodes it is built of; the range finder.
    take(&mut plain, "behavior.tree.nodes.approach").unwrap();
    for key in [
        "behavior.tree.nodes.approach",
        "behavior.tree.nodes.approach_field",
        "behavior.tree.nodes.avoid",
        "behavior.tree.nodes.approach_near",
    ] {
        assert!(take(&mut avoid, key).is_some(), "bujold-avoid.toml lacks {key}");
    }
    // Her sensors are Bujold's (the dock switch) after the range finder.
    let sensors = |t: &mut Table| take(t, "sensors").and_then(|v| v.as_array().cloned()).unwrap();
    let (plain_sensors, avoid_sensors) = (sensors(&mut plain), sensors(&mut avoid));
    assert_eq!(
        avoid_sensors[1..],
        plain_sensors[..],
        "bujold-avoid's sensors after the range finder"
    );
    assert_eq!(
        avoid, plain,
        "bujold-avoid.toml differs from bujold.toml outside its listed keys"
    );
}

/// Runs two of `scenarios/bujold-avoid.toml`'s starts, one trial each; `avoid_off` sets
/// the avoid schema's gain to 0 as `scenarios/bujold-avoid-off.toml` does.
fn run(avoid_off: bool) -> Vec<campaign::RunRecord> {
    run_with(avoid_off, |_| {})
}

/// As [`run`], letting `devices` change how the simulator simulates sensor kinds.
fn run_with(avoid_off: bool, devices: impl FnOnce(&mut SimDevices)) -> Vec<campaign::RunRecord> {
    let file = if avoid_off {
        "scenarios/bujold-avoid-off.toml"
    } else {
        "scenarios/bujold-avoid.toml"
    };
    let mut loaded = Scenario::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(file)).unwrap();
    loaded.scenario.trials = 1;
    let keep = ["2.0m 0", "2.0m +10"];
    loaded
        .scenario
        .starts
        .points
        .retain(|p| keep.contains(&p.label.as_deref().unwrap_or("")));
    assert_eq!(loaded.scenario.starts.points.len(), keep.len());
    let mut p = campaign::prepare(loaded).unwrap();
    let mut sim_devices = SimDevices::default();
    devices(&mut sim_devices);
    p.devices = Arc::new(sim_devices);
    campaign::run_campaign(&p, &agent_for, &Default::default()).unwrap().0
}

#[test]
fn the_summed_approach_goes_round_the_box_that_stops_the_plain_one() {
    for r in run(false) {
        assert!(
            r.success,
            "with avoid, start {}: {} after {:.1} s",
            r.start, r.outcome, r.time_s
        );
    }
    for r in run(true) {
        assert_eq!(
            r.outcome, "collision",
            "without avoid, start {} should hit the box: {} after {:.1} s",
            r.start, r.outcome, r.time_s
        );
    }
}

/// A range finder that never sees anything: every beam reads its maximum range.
struct Blind {
    beams: usize,
    max: f64,
}

impl Sensor for Blind {
    fn read(&mut self, values: &mut Vec<f64>) -> Result<(), HardwareError> {
        values.extend(std::iter::repeat_n(self.max, self.beams));
        Ok(())
    }
}

#[test]
fn a_campaign_simulates_the_sensor_kinds_its_caller_registers() {
    // The caller's `range` replaces the built-in one: blind, so avoid never acts, and the
    // starts that go round the box with the built-in range finder hit it.
    let records = run_with(false, |d| {
        d.register_sensor("range", |_, spec| {
            let p = marsupial::profile::RangeParams::from_table(&spec.params)?;
            Ok(Box::new(Blind {
                beams: p.beams,
                max: p.max_range_m,
            }))
        });
    });
    for r in records {
        assert_eq!(
            r.outcome, "collision",
            "with a blind range finder, start {} should hit the box: {} after {:.1} s",
            r.start, r.outcome, r.time_s
        );
    }
}
