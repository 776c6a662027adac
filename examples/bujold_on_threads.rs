//! # Bujold on the threaded runtime
//!
//! The composed Bujold behavior (`profiles/bujold.toml`'s `[behavior.tree]`) driving the
//! simulated robot through the same hardware traits a real robot implements, on the
//! threaded runtime a real robot uses: one thread per camera, one for the slow sensors,
//! one for the actuators, the loop at the profile's 10 Hz on the wall clock. A fourth
//! party, standing in for the world, advances the simulator's physics in real time.
//!
//! Two missions run back to back through the public API ([`run_missions`]): the
//! departure (out of the pouch lowered, raise, stop at the imprint distance and imprint
//! the flap's colours, drive on out to 1.2 m), then the docking (search, approach by ratio
//! steering, decide at the dock's pixel count, back in blind until the pressure plates
//! close). Nothing moves the robot between them.
//!
//! Run it with `cargo run --release --example bujold_on_threads` (about a minute and a
//! half of real time). It exits with status 0 only when the robot docked.

use marsupial::arbiter::ReactiveLoop;
use marsupial::arbiter::runtime::{RuntimeConfig, RuntimeEvent, StopHandle, run_missions};
use marsupial::behaviors::agent_for;
use marsupial::schemas::{Agent, Mission, Outcome};
use marsupial::sim::campaign;
use marsupial::sim::robot::SimDevices;
use marsupial::sim::run::docked_robot;
use marsupial::sim::scenario::Scenario;
use std::path::Path;
use std::time::Duration;

fn main() {
    if let Err(e) = dock() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn dock() -> Result<(), Box<dyn std::error::Error>> {
    // The world of Table I's lab runs: the mother, her flap, lab light, lab floor.
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/bujold-table1.toml");
    let prepared = campaign::prepare(Scenario::load(&scenario)?)?;
    let profile = &prepared.loaded.profile;
    let sim = docked_robot(&prepared, &prepared.runs[0]);

    // The robot, as the runtime sees it: hardware traits only.
    let mut robot = sim.realtime_robot(&SimDevices::default())?;
    let agent: Box<dyn Agent> = agent_for(profile)?;
    let mut lp = ReactiveLoop::new(agent, profile.loop_config());

    // The world runs on the wall clock until the robot docks or the run ends.
    let world_stop = StopHandle::new();
    let physics = {
        let (sim, stop) = (sim.clone(), world_stop.clone());
        std::thread::spawn(move || sim.run_physics(|| stop.is_stopped()))
    };
    let config = RuntimeConfig {
        max_duration: Some(Duration::from_secs(240)),
        ..RuntimeConfig::default()
    };
    println!("Bujold departs, imprints and docks on threads (real time, up to 4 min)…");
    let missions = [Mission::Departure, Mission::docking()];
    let report = run_missions(&mut robot, &mut lp, &missions, &config, &StopHandle::new());
    world_stop.stop();
    let _ = physics.join();

    for e in &report.events {
        println!("{e}");
    }
    let (docked, entrance) = sim.with(|s| (s.docked(), s.entrance));
    let imprinted = departure_completed(&report.events);
    println!(
        "{} ticks in {:.1} s ({} overruns, slowest tick {:.2} ms); imprinted on departure: {imprinted}",
        report.ticks,
        report.elapsed_s,
        report.overruns,
        report.max_tick_s * 1e3
    );
    if let Some((lateral, heading)) = entrance {
        println!(
            "entrance error {:+.1} cm, {:+.1}° (tolerance ±{:.0} cm, ±{:.0}°)",
            lateral * 100.0,
            heading.to_degrees(),
            profile.success.lateral_tolerance_m * 100.0,
            profile.success.heading_tolerance_deg
        );
    }
    match (report.outcome, docked) {
        (Some(Outcome::Docked), true) => {
            println!("docked");
            Ok(())
        }
        (outcome, _) => Err(format!("did not dock: outcome {outcome:?}, plates closed: {docked}").into()),
    }
}

/// The departure completed (it completes only when the imprint succeeded).
fn departure_completed(events: &[RuntimeEvent]) -> bool {
    events.iter().any(|e| {
        matches!(
            e,
            RuntimeEvent::Finished {
                outcome: Outcome::Completed,
                ..
            }
        )
    })
}
