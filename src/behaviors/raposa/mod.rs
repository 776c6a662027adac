//! RAPOSA's docking (seed 001) as a composition: the seven-state vision servo onto the
//! tether pyramid, its phase schemas one file each in this folder, combined by the
//! arbiters the way `profiles/raposa.toml` declares in `[behavior.tree]`.
//!
//! Every tick the [pyramid schema](crate::schemas::PyramidSchema) reports the best
//! (ellipse, blue region) pair, or an ellipse or blue region alone, with distance and α,
//! into the shared [`Memory`]; on a profile whose fiducial is Bujold's two-block flap,
//! the two-block schema does, through the adapter of [`source`] (which of the pyramid's
//! cues a flap gives, and which it cannot, is listed there). The `servo` sequencer's
//! selector ([`selector`], the rules of [`states`]) picks one of seven states each tick
//! unless the current one is latched:
//!
//! 1. **approach** (region I): the servo law of [`ServoLaw`](crate::schemas::ServoLaw)
//!    (constant speed beyond 1 m, v = K_lin·√(A₁/A) closer, ω = −K_ang·x_dev);
//! 2. **align** (region II, α > 15° beyond the dead zone): plan the manoeuvre of
//!    [`region2`] (rotate −β, travel d, rotate φ, landing on the axis at δ) and run it as
//!    the latched `region_2` sequence;
//! 3. **far ellipse** alone: approach it at the far speed;
//! 4. **blue only**: turn toward the blue region, creep once centred;
//! 5. **search** (nothing): slow search, alternating sides and doubling the sweep (below
//!    360°);
//! 6. **final** (latched), from the 0.3 m area threshold: arm to −K_arm·y_dev, lights on,
//!    slow constant speed for a set time, then stop; without the dock switch by then,
//!    `retreat` and retry (up to `max_retries`);
//! 7. **rotate_7** (the first state of `region_2`): the part of −β that keeps the ellipse
//!    in view, ended by a one-frame predictor before the ellipse leaves the image; the
//!    odometry origin is then reset with the angle vision measured. The rest of −β
//!    (`rotate_odo`), the travel (`travel`, the inverse (x_ref, y_ref) controller of
//!    [`PointController`](crate::schemas::PointController)) and φ (`rotate_phi`) run on
//!    odometry; then the robot `look`s, and searches slowly if the pyramid is not in view.
//!
//! The `dock_switch` subsumes every docking phase. The departure (`depart`, `imprint`)
//! drives out of the pyramid and imprints its colours (not in `fixed` segmentation).
//!
//! Beyond the paper (profile switch `leave_dead_zone`): a robot misaligned inside the dead
//! zone backs away to `dead_zone_exit_m` first, so that region II can align it; the paper's
//! points 1 and 3 never docked. A robot that sees only the ball inside the dead zone (no
//! pair, so no side) probes around it (`probe`) until the pair comes into view.
//!
//! Simplified relative to the paper: the simulator is planar, so the arm command and the
//! lights are issued but do not change what the camera sees.

pub mod align;
pub mod departure;
pub mod docking;
pub mod final_approach;
pub mod manoeuvre;
pub mod memory;
pub mod params;
pub mod probe;
pub mod region2;
pub mod rotate7;
pub mod search;
pub mod selector;
pub mod servo;
pub mod source;
pub mod states;
pub mod tuning;

pub use memory::Memory;
pub use region2::Region2Plan;
pub use source::{Source, TwoBlockCues};
pub use states::{ServoState, select_state};

use super::common::docking::{DockSwitch, Imprint, ImprintEnd};
use super::common::motion::{AimFn, BackOff, Distance, End, Hooks, TurnTo};
use super::common::search::{Search, SearchParams};
use super::registry::{LeafArgs, Registry};
use crate::profile::Profile;

/// Registers RAPOSA's phase schemas (`raposa.approach`, `raposa.rotate_7`, ...) and the
/// `raposa.seven_state` selector in `registry`; each schema takes its tuning from its
/// node's `params` (see [`params`]) and the robot-wide `[robot.seven_state]`.
pub fn register(registry: &mut Registry<Memory>) {
    type Ctx = Memory;
    registry
        .register("raposa.depart", |m: &Ctx, a: &LeafArgs<'_>| {
            a.no_params()?;
            Ok(Box::new(departure::Depart::new(m)))
        })
        .register("raposa.imprint", |m: &Ctx, a: &LeafArgs<'_>| {
            a.no_params()?;
            // The first frame after stopping is skipped (motion blur); the imprint's
            // result is the departure's.
            let frames = m.source.imprint_frames_wanted();
            Ok(Box::new(Imprint::new(1, frames, ImprintEnd::Outcome)))
        })
        .register("raposa.dock_switch", |_: &Ctx, a: &LeafArgs<'_>| {
            a.no_params()?;
            Ok(Box::new(DockSwitch))
        })
        .register("raposa.approach", |_: &Ctx, a: &LeafArgs<'_>| {
            a.no_params()?;
            Ok(Box::new(servo::Approach))
        })
        .register("raposa.align", |_: &Ctx, a: &LeafArgs<'_>| {
            a.no_params()?;
            Ok(Box::new(align::Align))
        })
        .register("raposa.far_ellipse", |_: &Ctx, a: &LeafArgs<'_>| {
            a.no_params()?;
            Ok(Box::new(servo::FarEllipse))
        })
        .register("raposa.blue_only", |_: &Ctx, a: &LeafArgs<'_>| {
            Ok(Box::new(servo::BlueOnly::new(a.params()?)))
        })
        .register("raposa.search", move |m: &Ctx, a: &LeafArgs<'_>| {
            let p: params::SearchParams = a.params()?;
            let search = SearchParams {
                grace_frames: p.grace_frames,
                resume_clock: true,
                ..slow_search(m, a)
            };
            Ok(Box::new(Search::new("state_5", search, ())))
        })
        .register("raposa.final", |_: &Ctx, a: &LeafArgs<'_>| {
            Ok(Box::new(final_approach::FinalApproach::new(a.params()?)))
        })
        // The back-aways (latched): body forward for the backward camera at the far
        // speed, keeping the ellipse centred; then event `cleared` with the detector's
        // tracking forgotten (the servo selects again). Out of the dead zone (ours): a
        // pair closer than `distance_threshold_m` shows misalignment, where α is
        // unreliable and region II cannot run, so back off until the socket is
        // `dead_zone_exit_m` from the ball (at least `min_distance_m`), measured from
        // the view on entry. The retreat: a final approach ended without the dock
        // switch backs off `distance_m`.
        .register("raposa.leave_dead_zone", |m: &Ctx, a: &LeafArgs<'_>| {
            let p: params::LeaveDeadZoneParams = a.params()?;
            let exit = Distance::AtEntry(Box::new(move |m: &Ctx| {
                let socket = m.percept.view.map_or(0.0, |v| v.ball_distance_m - m.socket_inset);
                (m.gains.dead_zone_exit_m - socket).max(p.min_distance_m)
            }));
            Ok(Box::new(back_away("leave_dead_zone", exit, m)))
        })
        .register("raposa.probe", |_: &Ctx, a: &LeafArgs<'_>| {
            Ok(Box::new(probe::Probe::new(a.params()?)))
        })
        .register("raposa.retreat", |m: &Ctx, a: &LeafArgs<'_>| {
            let p: params::RetreatParams = a.params()?;
            Ok(Box::new(back_away("retreat", Distance::Fixed(p.distance_m), m)))
        })
        .register("raposa.rotate_7", |_: &Ctx, a: &LeafArgs<'_>| {
            a.no_params()?;
            Ok(Box::new(rotate7::Rotate7::default()))
        })
        .register("raposa.rotate_odo", |_: &Ctx, a: &LeafArgs<'_>| {
            a.no_params()?;
            let aim: AimFn<Ctx> = Box::new(manoeuvre::rotate_odo);
            let hooks = Hooks {
                enter: manoeuvre::look_away,
                ..Hooks::default()
            };
            Ok(Box::new(
                TurnTo::new("state_2_rotate", aim, None, "rotated").hooks(hooks),
            ))
        })
        .register("raposa.travel", |_: &Ctx, a: &LeafArgs<'_>| {
            a.no_params()?;
            Ok(Box::new(manoeuvre::Travel))
        })
        .register("raposa.rotate_phi", |_: &Ctx, a: &LeafArgs<'_>| {
            a.no_params()?;
            let aim: AimFn<Ctx> = Box::new(manoeuvre::rotate_phi);
            let hooks = Hooks {
                enter: manoeuvre::look_away,
                end: |m: &mut Ctx| m.source.reset(),
                ..Hooks::default()
            };
            Ok(Box::new(
                TurnTo::new("state_2_rotate_phi", aim, None, "facing").hooks(hooks),
            ))
        })
        // After the region-II manoeuvre, which ends facing where the pyramid should be:
        // stand still `settle_s` for the image to settle, then the slow search, first
        // opposite to the manoeuvre's last turn. The selector leaves it, with the angle
        // threshold widened (settling), as soon as the ellipse is seen.
        .register("raposa.look", move |m: &Ctx, a: &LeafArgs<'_>| {
            let p: params::LookParams = a.params()?;
            let look = SearchParams {
                settle_s: p.settle_s,
                ..slow_search(m, a)
            };
            let see_again = |m: &mut Ctx| m.blind = false;
            Ok(Box::new(Search::new("state_2_look", look, ()).on_enter(see_again)))
        })
        .register_selector("raposa.seven_state", |_: &Ctx, a| {
            Ok(Box::new(selector::SevenState::new(a)?))
        });
}

/// RAPOSA's slow search: the doubling sweep at `[robot.seven_state]`'s rate and first
/// sweep, failing after the profile's `behavior.search_timeout_s`.
fn slow_search(m: &Memory, a: &LeafArgs<'_>) -> SearchParams {
    SearchParams {
        rate: m.gains.search_rate_dps.to_radians(),
        first_sweep: m.gains.search_sweep_deg.to_radians(),
        doubling: true,
        grace_frames: 0,
        settle_s: 0.0,
        resume_clock: false,
        timeout_s: a.profile.behavior.search_timeout_s,
    }
}

/// A back-away leg at the far speed, ending with `cleared` and the tracking forgotten.
fn back_away(phase: &'static str, distance: Distance<Memory>, m: &Memory) -> BackOff<Memory> {
    let forget = Hooks {
        end: |m: &mut Memory| m.source.reset(),
        ..Hooks::default()
    };
    BackOff::new(phase, distance, m.gains.far_speed_mps, End::Event("cleared")).hooks(forget)
}

/// Raposa's robot kind, `[robot] kind = "raposa"`: its tuning is [`RaposaRobot`](tuning::RaposaRobot), its
/// memory [`Memory`], its leaves those [`register`] adds.
#[derive(Debug, Clone, Copy, Default)]
pub struct Raposa;

impl super::catalog::RobotKind for Raposa {
    const NAME: &'static str = "raposa";
    type Tuning = tuning::RaposaRobot;
    type Memory = Memory;

    fn memory(&self, profile: &Profile, tuning: &tuning::RaposaRobot) -> Result<Memory, String> {
        Memory::new(profile, tuning)
    }

    fn leaves(&self, registry: &mut super::catalog::LeafRegistry<Memory>) {
        register(registry);
    }
}
