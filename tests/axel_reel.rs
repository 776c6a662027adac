//! Axel's no-vision baseline, pure reeling (seed 000 §V-C), through the simulator's
//! engine: wheels in free rotation, the reel winding in at its top rate, no camera read and
//! no behavior. The paper's two limits must come out of the tether and cone physics
//! (`sim::tether`, `sim::dock::Cone`): from up to 4 m it docks for |α| < 5° and tolerates
//! |h| < 90°, and fails outside. α is the arm tip's angle about the module's axis (see
//! `reel_only`), h the rover's heading from that axis (h = 0: facing the module's face
//! squarely, whatever α).

use crate::common;

use marsupial::geometry::Pose2;
use marsupial::profile::Profile;
use marsupial::schemas::{DriveCommand, TetherCommand};
use marsupial::sim::engine::{PhaseEnd, Sim};
use marsupial::sim::lighting::{LightingRun, LightingSpec};
use marsupial::sim::motion::{Motion, Terrain};
use marsupial::sim::render::SensorParams;
use marsupial::sim::rng::Rng;
use marsupial::sim::world;
use std::f64::consts::PI;
use std::sync::Arc;

/// Pure reeling on `terrain` with seed `seed`, the arm's tip starting `r` m from the
/// cone's mouth at `alpha_deg` about the module's axis and the rover's heading `h_deg`
/// from that axis: how it ended (`None`: not docked after the time a 5 cm/s reel needs
/// for the distance, twice over, the wheels held against the module's face).
///
/// α is the tip's, not the axle's: the tether pulls at the tip, so the tip's bearing is
/// the tether's line, and the axle sits `arm · sin h` to the side of it. From 2.5 m an
/// 80° heading puts the axle 12° off the tip's bearing.
fn reel_only(p: &Profile, r: f64, alpha_deg: f64, h_deg: f64, terrain: Terrain, seed: u64) -> Option<PhaseEnd> {
    let world = Arc::new(world::build(p, &[], &[]).expect("axel world"));
    let mut rng = Rng::new(seed);
    let light = LightingRun::new(LightingSpec::default().resolve(), &mut rng, 1000.0);
    let motion = Motion::new(p.drive.model(), p.drive.limits(), terrain.slip(), 0.0, 1.0, 1.0);
    let mut sim = Sim::new(
        Arc::new(p.clone()),
        world,
        light,
        SensorParams::noiseless(),
        motion,
        0.02,
        seed,
    );
    let (a, h) = (alpha_deg.to_radians(), h_deg.to_radians());
    let arm = p.tether.expect("axel has a tether").arm_m;
    let theta = PI + h;
    let tip = (r * a.cos(), r * a.sin());
    sim.place(
        Pose2::new(tip.0 - arm * theta.cos(), tip.1 - arm * theta.sin(), theta),
        false,
    );
    sim.command_drive(DriveCommand::Stop);
    let tether = p.tether.expect("axel has a tether");
    sim.command_reel(TetherCommand {
        reel_rate: tether.max_reel_rate_mps,
        free_wheel: true,
    });
    let ticks = (2.0 * r / tether.max_reel_rate_mps * p.loop_.rate_hz) as usize;
    (0..ticks).find_map(|_| sim.advance())
}

#[test]
fn pure_reeling_docks_for_small_alpha_and_tolerates_heading_below_90() {
    let p = common::shipped_profile("axel");
    let mut table = String::new();
    for r in [2.5, 4.0] {
        for alpha in [-10.0, -7.0, -3.0, 0.0, 3.0, 7.0, 20.0] {
            for h in [-135.0, -120.0, -80.0, -45.0, 0.0, 45.0, 80.0, 120.0] {
                let end = reel_only(&p, r, alpha, h, Terrain::Sand, 7);
                let docked = end == Some(PhaseEnd::Docked);
                let inside = f64::abs(alpha) < 5.0 && f64::abs(h) < 90.0;
                if docked != inside {
                    table.push_str(&format!("r {r} α {alpha} h {h}: {end:?}\n"));
                }
                // A failure is contact: the arm against the cone, the tip on its face, the
                // tether on the wheels (stuck), or the wheels held against the module's
                // face by the stalled reel (blocked until the time runs out).
                assert!(
                    docked || matches!(end, Some(PhaseEnd::Stuck { .. }) | None),
                    "r {r} α {alpha} h {h}: {end:?}"
                );
            }
        }
    }
    assert!(table.is_empty(), "pure reeling off the paper's limits:\n{table}");
}

#[test]
fn the_cone_snags_the_tip_unless_the_station_is_tipped_forward() {
    let mut p = common::shipped_profile("axel");
    assert_eq!(reel_only(&p, 3.0, 0.0, 0.0, Terrain::Sand, 1), Some(PhaseEnd::Docked));
    // Upright, the tip meeting the flat face above the mouth cannot slide down into it.
    p.dock.as_mut().and_then(|d| d.cone.as_mut()).expect("a cone").tilt_deg = 0.0;
    assert!(matches!(
        reel_only(&p, 3.0, 0.0, 0.0, Terrain::Sand, 1),
        Some(PhaseEnd::Stuck { lateral, .. }) if lateral.abs() < 0.01
    ));
}

#[test]
fn compact_ground_rocks_the_rover_off_the_cone_where_loose_sand_does_not() {
    // Near the limit (α 4°), grousers on compact sand/gravel rock the dragged rover out of
    // the seat's clearance in some runs; on loose sand every run docks.
    let p = common::shipped_profile("axel");
    let docks = |terrain| {
        (0..8)
            .filter(|&seed| reel_only(&p, 4.0, 4.0, 0.0, terrain, seed) == Some(PhaseEnd::Docked))
            .count()
    };
    let (sand, compact) = (docks(Terrain::Sand), docks(Terrain::CompactSandGravel));
    eprintln!("pure reeling at 4 m, α 4°, h 0°: {sand}/8 on loose sand, {compact}/8 on compact sand/gravel");
    assert_eq!(sand, 8);
    assert!(compact < 8, "compact: {compact}/8");
}
