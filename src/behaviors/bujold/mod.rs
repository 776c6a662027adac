//! Bujold's docking (seed 004) as a composition: the phase schemas of this folder, one
//! file each, combined by the arbiters the way `profiles/bujold.toml` declares in
//! `[behavior.tree]`.
//!
//! The shipped tree (seed 004 Fig. 1 regions, Fig. 9 sequence):
//!
//! * **departure** (sequencer): `undock` lowered, `drive_out` raised, `imprint` the
//!   blocks' colours at the profile's imprint distance, drive on out;
//! * **docking** (priority): the `dock_switch` subsumes the **close dock** (sequencer):
//!   `ballistic` (only with an a-priori dock pose, [`Mission::Docking`](crate::schemas::Mission)) → `search`
//!   ⇄ `unjam` → `approach` → `decide` → `back_in`, with `reposition`, `move_away` and
//!   `give_up` as the retry loops, and per-state timeouts.
//!
//! The robot (a [`Composed`](super::Composed) behavior the catalog builds for
//! [`Bujold`]) runs the two-block perceptual schema once per tick into the shared
//! [`Memory`] and then ticks the tree; [`register`] puts the phase schemas in a
//! [`Registry`] under `bujold.*` names.

pub mod approach;
pub mod back_in;
pub mod decide;
pub mod departure;
pub mod docking;
pub mod memory;
pub mod motor;
pub mod params;
pub mod reposition;
pub mod search;
pub mod tuning;

pub use decide::{Decision, at_dock_decision};

use super::common::docking::{DockSwitch, Imprint, ImprintEnd};
use super::common::motion::{Aim, AimFn, BackOff, BackOffParams, Distance, End, Hooks, TurnParams, TurnTo};
use super::common::search::{Search, SearchParams};
use super::registry::{LeafArgs, Registry};
use crate::perception::two_block_pose::TwoBlockGeometry;
use crate::profile::Profile;
use crate::schemas::FailureReason;
pub use memory::Memory;

/// Registers Bujold's phase schemas (`bujold.undock`, `bujold.search`, ...) in `registry`;
/// each takes its tuning from its node's `params` (see [`params`]).
pub fn register(registry: &mut Registry<Memory>) {
    let depth = |a: &LeafArgs<'_>| a.profile.dock.map(|d| d.depth_m).ok_or("needs [dock]");
    registry
        .register("bujold.undock", move |_: &Memory, a: &LeafArgs<'_>| {
            Ok(Box::new(departure::Undock::new(a.params()?, depth(a)?)))
        })
        .register("bujold.drive_out", |_: &Memory, a: &LeafArgs<'_>| {
            let imprint_at = imprint_distance(a.profile).ok_or("needs [dock] and a camera")?;
            Ok(Box::new(departure::DriveOut::new(a.params()?, imprint_at)))
        })
        .register("bujold.imprint", |_: &Memory, a: &LeafArgs<'_>| {
            a.no_params()?;
            // Samples from its first tick; the departure goes on whether it worked.
            Ok(Box::new(Imprint::new(
                0,
                a.profile.perception.imprint.frames,
                ImprintEnd::Event("imprinted"),
            )))
        })
        .register("bujold.search", |m: &Memory, a: &LeafArgs<'_>| {
            let params = SearchParams {
                rate: m.approach.steering.turn_rate,
                first_sweep: 0.0,
                doubling: false,
                grace_frames: 0,
                settle_s: 0.0,
                resume_clock: false,
                timeout_s: a.profile.behavior.search_timeout_s,
            };
            let watch = search::JamWatch::new(a.params()?);
            Ok(Box::new(Search::new("search", params, watch)))
        })
        // Unjamming: turn back to the heading the close dock began with (turning back
        // over the ground just swept is free), then drive out front first; the search
        // then turns the other way, which swings the caught corner off the body. Both
        // keep the frame-change cue running, so the search that follows compares its
        // first frame with the one just before it.
        .register("bujold.unjam_turn", |_: &Memory, a: &LeafArgs<'_>| {
            let p: TurnParams = a.params()?;
            let aim: AimFn<Memory> = Box::new(|m| Aim::Heading(m.start_heading.unwrap_or(m.odo.theta)));
            let tol = Some(p.heading_tolerance_deg.to_radians());
            let leg = TurnTo::new(a.phase(), aim, tol, "turned").timeout(p.timeout_s);
            Ok(Box::new(leg.hooks(observing())))
        })
        .register("bujold.unjam_out", |_: &Memory, a: &LeafArgs<'_>| {
            let p: BackOffParams = a.params()?;
            let leg = BackOff::new(
                a.phase(),
                Distance::Fixed(p.distance_m),
                p.speed_mps,
                End::Event("cleared"),
            );
            let timeout = p.timeout_s.unwrap_or(2.0 * p.distance_m / p.speed_mps);
            Ok(Box::new(leg.timeout(timeout).hooks(observing())))
        })
        .register("bujold.approach", |m: &Memory, a: &LeafArgs<'_>| {
            let dock_total = m.approach.steering.dock_total_px;
            Ok(Box::new(approach::Approach::new(m, a.params()?, dock_total)?))
        })
        .register("bujold.decide", |_: &Memory, a: &LeafArgs<'_>| {
            let s = &a.profile.success;
            Ok(Box::new(decide::Decide::new(
                a.params()?,
                s.lateral_tolerance_m,
                s.heading_tolerance_deg.to_radians(),
            )))
        })
        .register("bujold.back_in", move |_: &Memory, a: &LeafArgs<'_>| {
            Ok(Box::new(back_in::BackIn::new(a.params()?, depth(a)?)))
        })
        // "Move away and retry" (seed 004 §V), and giving up: every failure close to
        // the dock first backs off the entrance, then stops, failed with the reason the
        // phase that gave up left in memory (a timeout when none did).
        .register("bujold.move_away", |_: &Memory, a: &LeafArgs<'_>| {
            let p: BackOffParams = a.params()?;
            let leg = BackOff::new(
                "move_away",
                Distance::Fixed(p.distance_m),
                p.speed_mps,
                End::Event("done"),
            );
            Ok(Box::new(leg.timeout(p.timeout_s.unwrap_or(20.0))))
        })
        .register("bujold.give_up", |_: &Memory, a: &LeafArgs<'_>| {
            let p: BackOffParams = a.params()?;
            let why = End::Fail(|m: &Memory| m.failing.unwrap_or(FailureReason::Timeout));
            let leg = BackOff::new("give_up", Distance::Fixed(p.distance_m), p.speed_mps, why);
            Ok(Box::new(leg.timeout(p.timeout_s.unwrap_or(20.0))))
        })
        .register("bujold.dock_switch", |_: &Memory, a: &LeafArgs<'_>| {
            a.no_params()?;
            Ok(Box::new(DockSwitch))
        });
    reposition::register(registry);
}

/// Hooks that keep the frame-change cue running while a leg runs.
fn observing() -> Hooks<Memory> {
    Hooks {
        each: |m: &mut Memory, inputs| {
            m.observe_change(inputs);
        },
        ..Hooks::default()
    }
}

/// Distance from the camera back to the robot's rear, m.
pub(crate) fn rear_behind_camera(profile: &Profile, geometry: &TwoBlockGeometry) -> Option<f64> {
    let cam = profile.cameras.first()?;
    Some(profile.body.length_m / 2.0 + cam.mount.x_m * geometry.drive_dir)
}

/// Odometry travel from the start of departure at which to imprint, m: departure starts
/// with the rear at the plates, so the camera is then depth − rear_behind_camera inside
/// the entrance.
fn imprint_distance(profile: &Profile) -> Option<f64> {
    let fid = profile.fiducial.get::<crate::profile::TwoBlockSpec>().copied()?;
    let cam = profile.cameras.first()?;
    let g = TwoBlockGeometry::new(cam, &fid);
    Some(profile.perception.imprint.at_distance_m + profile.dock?.depth_m - rear_behind_camera(profile, &g)?)
}

/// Bujold's robot kind, `[robot] kind = "bujold"`: its tuning is [`BujoldRobot`](tuning::BujoldRobot), its
/// memory [`Memory`], its leaves those [`register`] adds.
#[derive(Debug, Clone, Copy, Default)]
pub struct Bujold;

impl super::catalog::RobotKind for Bujold {
    const NAME: &'static str = "bujold";
    type Tuning = tuning::BujoldRobot;
    type Memory = Memory;

    fn memory(&self, profile: &Profile, tuning: &tuning::BujoldRobot) -> Result<Memory, String> {
        Memory::new(profile, tuning)
    }

    fn leaves(&self, registry: &mut super::catalog::LeafRegistry<Memory>) {
        register(registry);
    }
}
