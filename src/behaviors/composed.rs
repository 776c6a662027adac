//! A robot's composed behavior: its shared memory, the tree its profile declares, and the
//! missions that start it.
//!
//! Every robot this crate ships, and any a user composes, runs the same way: each tick the
//! robot's perceptual schemas run once into its [`SharedMemory`] (so colour adaptation
//! follows the light whichever phase runs, and between missions too), then the tree of
//! arbiters built from `[behavior.tree]` by a [`Registry`] decides. The [`Composed`] owns
//! the memory and lends it to the tree for the tick (`&mut`), so every node reads and
//! writes it in tick order with no lock. A [`Mission`] starts the tree at the state the
//! profile names for it (`departure`, `docking`, or `ballistic` for a docking with an
//! a-priori dock pose); the mission ends when the tree reports an outcome.

use super::agent::BuildError;
use super::registry::Registry;
use crate::arbiter::NodeTrace;
use crate::profile::Profile;
use crate::schemas::{Agent, AgentStats, Behavior, Inputs, Mission, MissionError, Observation, Status, Step};

/// What one robot's schemas share (see the module docs).
pub trait SharedMemory: Send + 'static {
    /// Runs the robot's perceptual schemas on this tick's inputs, before the tree ticks.
    fn perceive(&mut self, inputs: &Inputs<'_>);

    /// Forgets what a new mission must not inherit (retries, plans, the last sighting) and
    /// takes the mission's data (the dock hint).
    ///
    /// # Errors
    /// [`MissionError::Unavailable`] when the robot cannot do `mission` as configured.
    fn begin(&mut self, mission: &Mission) -> Result<(), MissionError>;

    /// Counters of the current mission.
    fn stats(&self) -> AgentStats {
        AgentStats::default()
    }

    /// This tick's percept and colour ranges ([`Agent::observe`]); `None` by default.
    fn observe(&self) -> Option<Observation> {
        None
    }
}

/// A memory for trees whose schemas share nothing.
impl SharedMemory for () {
    fn perceive(&mut self, _inputs: &Inputs<'_>) {}
    fn begin(&mut self, _mission: &Mission) -> Result<(), MissionError> {
        Ok(())
    }
}

/// The states of the tree each mission starts in (`[behavior.tree]`'s `departure`,
/// `docking` and `ballistic`).
#[derive(Debug, Clone, PartialEq, Eq)]
struct Entries {
    departure: Option<String>,
    docking: String,
    ballistic: Option<String>,
}

/// A robot's composed behavior (see the module docs).
pub struct Composed<M: SharedMemory> {
    name: String,
    memory: M,
    tree: Box<dyn Behavior<M>>,
    entries: Entries,
    /// A mission is running.
    active: bool,
}

impl<M: SharedMemory> Composed<M> {
    /// Builds the profile's `[behavior.tree]` with the schemas of `registry` (their
    /// factories may read `memory`), and keeps `memory` for the tree's ticks.
    ///
    /// # Errors
    /// [`BuildError::Profile`] without a tree, [`BuildError::Tree`] when it does not build
    /// (an unknown schema, params a schema refuses; the error names the profile's line).
    pub fn build(profile: &Profile, registry: &Registry<M>, memory: M) -> Result<Self, BuildError> {
        let spec = profile.behavior.tree.as_ref().ok_or_else(|| BuildError::Profile {
            profile: profile.name.clone(),
            what: "needs [behavior.tree]".into(),
        })?;
        let tree = registry.build(profile, &memory).map_err(BuildError::Tree)?;
        Ok(Self {
            name: profile.name.clone(),
            memory,
            tree,
            entries: Entries {
                departure: spec.departure.clone(),
                docking: spec.docking.clone(),
                ballistic: spec.ballistic.clone(),
            },
            active: false,
        })
    }

    /// The shared memory (to inspect the perceptual schemas' state).
    pub fn memory(&self) -> &M {
        &self.memory
    }

    /// The shared memory, to change (retune the perceptual schemas, or set up a test).
    pub fn memory_mut(&mut self) -> &mut M {
        &mut self.memory
    }

    /// True while a mission runs.
    pub fn is_active(&self) -> bool {
        self.active
    }

    /// One tick with this tick's perception done by `perceive` instead of
    /// [`SharedMemory::perceive`]: for percepts replayed from a log, perception run on
    /// another core, or measuring the decision alone (`benches/tick.rs`). Otherwise the
    /// same as [`Behavior::tick`].
    pub fn tick_perceived(&mut self, inputs: &Inputs<'_>, perceive: impl FnOnce(&mut M)) -> Option<Step> {
        perceive(&mut self.memory);
        if !self.active {
            return None;
        }
        let step = self.tree.tick(&mut self.memory, inputs)?;
        if matches!(step.status, Status::Done(_)) {
            self.active = false;
        }
        Some(step)
    }
}

impl<M: SharedMemory> Behavior for Composed<M> {
    fn name(&self) -> &str {
        &self.name
    }

    fn tick(&mut self, _mem: &mut (), inputs: &Inputs<'_>) -> Option<Step> {
        self.tick_perceived(inputs, |m| m.perceive(inputs))
    }

    fn reset(&mut self) {
        self.active = false;
    }

    fn explain(&self, out: &mut Vec<NodeTrace>) {
        self.tree.explain(out);
    }
}

impl<M: SharedMemory> Agent for Composed<M> {
    fn begin(&mut self, mission: &Mission) -> Result<(), MissionError> {
        let entry = match mission {
            Mission::Departure => self
                .entries
                .departure
                .clone()
                .ok_or_else(|| MissionError::Unavailable {
                    robot: self.name.clone(),
                    mission: mission.name(),
                    why: "its [behavior.tree] declares no `departure` state".into(),
                })?,
            Mission::Docking { dock_hint, stage } => match (dock_hint, &self.entries.ballistic) {
                (Some(_), Some(b)) if *stage => b.clone(),
                _ => self.entries.docking.clone(),
            },
        };
        self.memory.begin(mission)?;
        self.active = self.tree.start(&entry);
        if self.active {
            Ok(())
        } else {
            Err(MissionError::Unavailable {
                robot: self.name.clone(),
                mission: mission.name(),
                why: format!("no state `{entry}` in its tree"),
            })
        }
    }

    fn stats(&self) -> AgentStats {
        self.memory.stats()
    }

    fn observe(&self) -> Option<Observation> {
        self.memory.observe()
    }
}
