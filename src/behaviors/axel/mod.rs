//! Axel's tether-assisted docking (seed 000) as a composition: the schemas of this
//! folder, one file each, combined by the arbiters the way `profiles/axel.toml` declares
//! in `[behavior.tree]`.
//!
//! The shipped tree (seed 000 §II, §IV, Fig. 4):
//!
//! * **axel** (priority): the reel's `stall` guard (motor current, never tension)
//!   subsumes the **docking** (sequencer):
//!   `acquire` (turn and look until the circle marks give a trusted pose; the module may
//!   start outside the view) → `approach` (plan the two-arc manoeuvre, drive one arc step
//!   reeling by the tether's change of length) → `align` (the same within the alignment
//!   radius, to the look pose on the axis; reverse and realign when misaligned near the
//!   cone, bounded retries) → `mate` (blind to the cone, wheels free, reel in), with
//!   `lost` and `far` leading back.
//! * Each sensing phase is itself a sequence, the paper's sense-plan-act cycle ([`look`]):
//!   `settle` (stopped) → the phase's look (perception runs, then the phase's leaf
//!   decides) → `step` (one motion by odometry: an arc, a turn in place, or reeling) →
//!   `settle` again.
//!
//! Typed failures: `target_never_detected` / `target_lost` (acquisition timed out),
//! `retries_exhausted` (alignment), `stuck_contact` (stall), `timeout` (a state overran
//! `behavior.phase_timeout_s`). The planning is the core's
//! ([`crate::kinematics::two_arc`], [`crate::kinematics::tether_length`]); the shared
//! [`Memory`] runs the circle perception only while a schema looks, stopped.

pub mod acquire;
pub mod align;
pub mod approach;
pub mod geometry;
pub mod legs;
pub mod look;
pub mod mate;
pub mod memory;
pub mod reel;
pub mod sighting;
pub mod stall;
mod stereo;
pub mod tuning;

use super::registry::{LeafArgs, Registry};
use crate::profile::Profile;
pub use memory::Memory;

/// Registers Axel's schemas in `registry`: the looks of the three sensing phases
/// (`axel.acquire`, `axel.approach`, `axel.align`) and the legs of their cycle
/// (`axel.settle`, `axel.step`), the mating (`axel.mate_close`, `axel.mate_reel`), the
/// reel's stall guard (`axel.stall`), and `axel.reel`, the paper's pure-reeling
/// baseline; each takes its tuning from its node's `params`. The cycle's leaves report
/// the phase they are part of (their sequencer's name) in their feedback.
pub fn register(registry: &mut Registry<Memory>) {
    registry
        .register("axel.acquire", |_: &Memory, a: &LeafArgs<'_>| {
            Ok(Box::new(acquire::Acquire::new(a.parent_phase(), a.params()?)))
        })
        .register("axel.approach", |_: &Memory, a: &LeafArgs<'_>| {
            Ok(Box::new(approach::Approach::new(a.parent_phase(), a.params()?)))
        })
        .register("axel.align", |_: &Memory, a: &LeafArgs<'_>| {
            Ok(Box::new(align::Align::new(a.parent_phase(), a.params()?)))
        })
        .register("axel.settle", |_: &Memory, a: &LeafArgs<'_>| {
            let timeout = a.profile.behavior.search_timeout_s;
            Ok(Box::new(legs::Settle::new(a.parent_phase(), a.params()?, timeout)))
        })
        .register("axel.step", |_: &Memory, a: &LeafArgs<'_>| {
            a.no_params()?;
            Ok(Box::new(legs::StepLeg::new(a.parent_phase())))
        })
        .register("axel.mate_close", |_: &Memory, a: &LeafArgs<'_>| {
            Ok(Box::new(mate::Close::new(a.params()?)))
        })
        .register("axel.mate_reel", |_: &Memory, a: &LeafArgs<'_>| {
            a.no_params()?;
            Ok(Box::new(mate::Reel::default()))
        })
        .register("axel.stall", |_: &Memory, a: &LeafArgs<'_>| {
            Ok(Box::new(stall::Stall::new(a.params()?)))
        })
        .register("axel.reel", |_: &Memory, a: &LeafArgs<'_>| {
            a.no_params()?;
            Ok(Box::new(reel::Reel))
        });
}

/// Axel's robot kind, `[robot] kind = "axel"`: its tuning is [`AxelRobot`](tuning::AxelRobot), its
/// memory [`Memory`], its leaves those [`register`] adds.
#[derive(Debug, Clone, Copy, Default)]
pub struct Axel;

impl super::catalog::RobotKind for Axel {
    const NAME: &'static str = "axel";
    type Tuning = tuning::AxelRobot;
    type Memory = Memory;

    fn memory(&self, profile: &Profile, tuning: &tuning::AxelRobot) -> Result<Memory, String> {
        Memory::new(profile, tuning)
    }

    fn leaves(&self, registry: &mut super::catalog::LeafRegistry<Memory>) {
        register(registry);
    }
}
