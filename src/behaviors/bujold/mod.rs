//! Bujold's docking (seed 004) as a composition: the phase schemas of this folder, one
//! file each, combined by the arbiters the way `profiles/bujold.toml` declares in
//! `[behavior.tree]`.
//!
//! The shipped tree (seed 004 Fig. 1 regions, Fig. 9 sequence):
//!
//! * **departure** (sequencer): `undock` lowered, `drive_out` raised, `imprint` the
//!   blocks' colours at the profile's imprint distance, drive on out;
//! * **docking** (priority): the `dock_switch` subsumes the **close dock** (sequencer):
//!   `ballistic` (only with an a-priori dock pose, [`Agent::set_dock_hint`]) → `search`
//!   ⇄ `unjam` → `approach` → `decide` → `back_in`, with `reposition`, `move_away` and
//!   `give_up` as the retry loops, and per-state timeouts.
//!
//! The root, [`BujoldAgent`], runs the two-block perceptual schema once per tick into the
//! shared [`Memory`](memory::Memory) and then ticks the tree; [`register`] puts the
//! phase schemas in a [`Registry`] under `bujold.*` names.

pub mod approach;
pub mod back_in;
pub mod contact;
pub mod decide;
pub mod departure;
pub mod memory;
pub mod move_away;
pub mod params;
pub mod reposition;
pub mod search;
pub mod unjam;

pub use decide::{Decision, at_dock_decision};

use super::agent::{Agent, BuildError};
use super::registry::{LeafArgs, Registry};
use crate::arbiter::Blackboard;
use crate::geometry::Pose2;
use crate::perception::TwoBlockSchema;
use crate::perception::two_block_pose::TwoBlockGeometry;
use crate::profile::Profile;
use crate::schemas::{Behavior, Inputs, SearchRotation, Status, Step};
use memory::Memory;
use reposition::PlanFrom;

/// Registers Bujold's phase schemas (`bujold.undock`, `bujold.search`, ...) in `registry`;
/// each takes its tuning from its node's `params` (see [`params`]).
pub fn register(registry: &mut Registry<Blackboard<Memory>>) {
    fn with<T: serde::de::DeserializeOwned>(args: &LeafArgs<'_>) -> Result<T, String> {
        args.params()
    }
    let depth = |a: &LeafArgs<'_>| a.profile.dock.map(|d| d.depth_m).ok_or("needs [dock]");
    registry
        .register("bujold.undock", move |m: &Blackboard<Memory>, a: &LeafArgs<'_>| {
            Ok(Box::new(departure::Undock::new(a.node, m.clone(), with(a)?, depth(a)?)))
        })
        .register("bujold.drive_out", |m: &Blackboard<Memory>, a: &LeafArgs<'_>| {
            let imprint_at = imprint_distance(a.profile).ok_or("needs [dock] and a camera")?;
            Ok(Box::new(departure::DriveOut::new(
                a.node,
                m.clone(),
                with(a)?,
                imprint_at,
            )))
        })
        .register("bujold.imprint", |m: &Blackboard<Memory>, a: &LeafArgs<'_>| {
            with::<toml::Table>(a).and_then(|t| no_params(&t))?;
            Ok(Box::new(departure::Imprint::new(
                a.node,
                m.clone(),
                a.profile.perception.imprint.frames,
            )))
        })
        .register("bujold.search", |m: &Blackboard<Memory>, a: &LeafArgs<'_>| {
            let rate = m.lock().approach.steering.turn_rate;
            let rotation = SearchRotation {
                rate,
                first_sweep: 0.0,
                doubling: false,
            };
            let timeout = a.profile.behavior.search_timeout_s;
            Ok(Box::new(search::Search::new(
                a.node,
                m.clone(),
                with(a)?,
                rotation,
                timeout,
            )))
        })
        .register("bujold.unjam", |m: &Blackboard<Memory>, a: &LeafArgs<'_>| {
            Ok(Box::new(unjam::Unjam::new(a.node, m.clone(), with(a)?)))
        })
        .register("bujold.approach", |m: &Blackboard<Memory>, a: &LeafArgs<'_>| {
            let dock_total = m.lock().approach.steering.dock_total_px;
            let retries = a.profile.behavior.max_retries;
            Ok(Box::new(approach::Approach::new(
                a.node,
                m.clone(),
                with(a)?,
                dock_total,
                retries,
            )))
        })
        .register("bujold.decide", |m: &Blackboard<Memory>, a: &LeafArgs<'_>| {
            let s = &a.profile.success;
            Ok(Box::new(decide::Decide::new(
                a.node,
                m.clone(),
                with(a)?,
                s.lateral_tolerance_m,
                s.heading_tolerance_deg.to_radians(),
                a.profile.behavior.max_retries,
            )))
        })
        .register("bujold.back_in", move |m: &Blackboard<Memory>, a: &LeafArgs<'_>| {
            Ok(Box::new(back_in::BackIn::new(a.node, m.clone(), with(a)?, depth(a)?)))
        })
        .register("bujold.reposition", |m: &Blackboard<Memory>, a: &LeafArgs<'_>| {
            Ok(Box::new(reposition::Reposition::new(
                a.node,
                m.clone(),
                with(a)?,
                PlanFrom::Memory,
            )))
        })
        .register("bujold.ballistic", |m: &Blackboard<Memory>, a: &LeafArgs<'_>| {
            Ok(Box::new(reposition::Reposition::new(
                a.node,
                m.clone(),
                with(a)?,
                PlanFrom::DockHint,
            )))
        })
        .register("bujold.move_away", |m: &Blackboard<Memory>, a: &LeafArgs<'_>| {
            Ok(Box::new(move_away::MoveAway::new(a.node, m.clone(), with(a)?, false)))
        })
        .register("bujold.give_up", |m: &Blackboard<Memory>, a: &LeafArgs<'_>| {
            Ok(Box::new(move_away::MoveAway::new(a.node, m.clone(), with(a)?, true)))
        })
        .register("bujold.dock_switch", |m: &Blackboard<Memory>, a: &LeafArgs<'_>| {
            with::<toml::Table>(a).and_then(|t| no_params(&t))?;
            Ok(Box::new(contact::DockSwitch::new(a.node, m.clone())))
        });
}

/// Refuses params for a schema that takes none.
fn no_params(t: &toml::Table) -> Result<(), String> {
    match t.keys().next() {
        None => Ok(()),
        Some(k) => Err(format!("params: unknown field `{k}`: this schema takes no params")),
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
    let fid = profile.fiducial.two_block?;
    let cam = profile.cameras.first()?;
    let g = TwoBlockGeometry::new(cam, &fid);
    Some(profile.perception.imprint.at_distance_m + profile.dock?.depth_m - rear_behind_camera(profile, &g)?)
}

/// Bujold's robot: the two-block perceptual schema and the composed tree.
pub struct BujoldAgent {
    memory: Blackboard<Memory>,
    tree: Box<dyn Behavior>,
    departure: Option<String>,
    docking: String,
    ballistic: Option<String>,
    /// A departure or a docking is running.
    active: bool,
}

impl BujoldAgent {
    /// Builds the agent from a profile with a `[fiducial.two_block]`,
    /// `[behavior.ratio_steering]` (and `[behavior.potential_field]` when selected) and a
    /// `[behavior.tree]` of Bujold's schemas (or the user's, registered in `registry`).
    ///
    /// # Errors
    /// [`BuildError`] when something it needs is missing or the tree does not build.
    pub fn with_registry(profile: &Profile, registry: &Registry<Blackboard<Memory>>) -> Result<Self, BuildError> {
        let tree_spec = profile.behavior.tree.as_ref().ok_or_else(|| BuildError::Profile {
            profile: profile.name.clone(),
            what: "needs [behavior.tree]".into(),
        })?;
        let memory = Blackboard::new(Memory::from_profile(profile)?);
        let tree = registry.build(profile, &memory).map_err(BuildError::Tree)?;
        Ok(Self {
            memory,
            tree,
            departure: tree_spec.departure.clone(),
            docking: tree_spec.docking.clone(),
            ballistic: tree_spec.ballistic.clone(),
            active: false,
        })
    }

    /// Builds the agent with Bujold's own schemas (see [`BujoldAgent::with_registry`]).
    ///
    /// # Errors
    /// As [`BujoldAgent::with_registry`].
    pub fn new(profile: &Profile) -> Result<Self, BuildError> {
        let mut registry = Registry::new();
        register(&mut registry);
        Self::with_registry(profile, &registry)
    }

    /// The perceptual schema's state (colour model, last detection), read under the
    /// memory's lock.
    pub fn with_schema<R>(&self, f: impl FnOnce(&TwoBlockSchema) -> R) -> R {
        f(&self.memory.lock().schema)
    }

    /// True once a departure imprinted successfully.
    pub fn imprinted(&self) -> bool {
        self.memory.lock().imprinted
    }
}

impl Behavior for BujoldAgent {
    fn name(&self) -> &str {
        "bujold"
    }

    fn tick(&mut self, inputs: &Inputs<'_>) -> Option<Step> {
        // Perception runs every tick, so adaptation follows the light in every phase.
        self.memory.with(|m| m.perceive(inputs));
        if !self.active {
            return None;
        }
        let step = self.tree.tick(inputs)?;
        if matches!(step.status, Status::Done(_)) {
            self.active = false;
        }
        Some(step)
    }

    fn explain(&self, out: &mut Vec<crate::arbiter::NodeTrace>) {
        self.tree.explain(out);
    }

    fn reset(&mut self) {
        self.active = false;
        self.memory.with(|m| {
            m.run_start = None;
            m.retries = 0;
        });
    }
}

impl Agent for BujoldAgent {
    fn begin_departure(&mut self) -> bool {
        let Some(state) = self.departure.clone() else {
            return false;
        };
        self.memory.with(|m| {
            m.run_start = None;
            m.imprinted = false;
        });
        self.active = self.tree.start(&state);
        self.active
    }

    fn begin_docking(&mut self) {
        let staging = self.memory.with(|m| {
            m.run_start = None;
            m.alpha_filtered = None;
            m.alpha_window.clear();
            m.retries = 0;
            m.unjams = 0;
            m.ever_seen = false;
            m.last_seen = None;
            m.failing = None;
            m.plan = None;
            // Ballistic region: drive by odometry to the approach zone's staging point and
            // face along the axis, then look.
            let staging = m
                .dock_hint
                .map(|dock| dock.compose(&Pose2::new(m.tuning.ballistic_staging_m, 0.0, 0.0)));
            m.start_heading = staging.map(|t| t.theta);
            m.docking_first_tick = true;
            staging
        });
        let state = match (&staging, &self.ballistic) {
            (Some(_), Some(b)) => b.clone(),
            _ => self.docking.clone(),
        };
        self.active = self.tree.start(&state);
    }

    fn set_dock_hint(&mut self, hint: Option<Pose2>) {
        self.memory.with(|m| m.dock_hint = hint);
    }
}
