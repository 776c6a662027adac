//! Named schemas and selectors, and building a profile's `[behavior.tree]` from them.
//!
//! A [`Registry<M>`] maps the names a profile's leaves use (`bujold.search`) to factories
//! that build the leaf from its `params` table. `M` is the memory the tree's nodes share
//! (for a paper's robot, that robot's memory; for a user's robot, whatever its schemas
//! share): every leaf built is a `Behavior<M>`, handed the memory by `&mut` at each tick
//! and entry, and each factory may read the memory as it builds (a turn rate, a
//! calibration). A user's crate registers its own schemas next to the shipped ones:
//!
//! ```
//! use marsupial::behaviors::registry::{LeafArgs, Registry};
//! use marsupial::schemas::{Behavior, Feedback, Inputs, MotorOutput, Step};
//!
//! struct Creep(f64);
//! // Reads no memory, so it fits in any robot's tree; the tree names it by its node.
//! impl<M: ?Sized> Behavior<M> for Creep {
//!     fn tick(&mut self, _mem: &mut M, inputs: &Inputs<'_>) -> Option<Step> {
//!         Some(Step::running(MotorOutput::twist(self.0, 0.0), Feedback::new("creep", inputs.now)))
//!     }
//! }
//!
//! #[derive(serde::Deserialize, Default)]
//! #[serde(deny_unknown_fields, default)]
//! struct CreepParams { speed_mps: f64 }
//!
//! let mut registry: Registry<()> = Registry::new();
//! registry.register("my.creep", |_: &(), args: &LeafArgs<'_>| {
//!     let p: CreepParams = args.params()?;
//!     Ok(Box::new(Creep(p.speed_mps)))
//! });
//! assert!(registry.names().any(|n| n == "my.creep"));
//! ```

use crate::arbiter::{Next, Priority, Selector, Sequencer, VectorSum};
use crate::config::ConfigError;
use crate::profile::Profile;
use crate::profile::tree::{FINISH, Lead, NodeSpec, TreeSpec};
use crate::schemas::{Behavior, Inputs, Step};
use std::collections::BTreeMap;

pub use super::leaf_args::{LeafArgs, SelectorArgs};

/// Builds one leaf of a tree over memory `M` (which it may read); the error says what is
/// wrong with its params or the profile.
pub type LeafFactory<M> = dyn Fn(&M, &LeafArgs<'_>) -> Result<Box<dyn Behavior<M>>, String> + Send + Sync;

/// Builds one selector of a tree over memory `M` (which it may read); the error says what
/// the sequencer lacks.
pub type SelectorFactory<M> = dyn Fn(&M, &SelectorArgs<'_>) -> Result<Box<dyn Selector<M>>, String> + Send + Sync;

/// Checks a device kind's `params` table; the error names the field.
pub type KindCheck = dyn Fn(&toml::Table) -> Result<(), String> + Send + Sync;

/// Schemas, selectors and device kinds by name, for trees over memory `M` (see the module
/// docs).
pub struct Registry<M> {
    leaves: BTreeMap<String, Box<LeafFactory<M>>>,
    selectors: BTreeMap<String, Box<SelectorFactory<M>>>,
    sensor_kinds: BTreeMap<String, Box<KindCheck>>,
    actuator_kinds: BTreeMap<String, Box<KindCheck>>,
}

impl<M: 'static> Default for Registry<M> {
    fn default() -> Self {
        Self::new()
    }
}

impl<M: 'static> Registry<M> {
    /// A registry with no schemas, knowing the device kinds the crate ships
    /// ([`crate::profile::devices`]).
    pub fn new() -> Self {
        let mut r = Self {
            leaves: BTreeMap::new(),
            selectors: BTreeMap::new(),
            sensor_kinds: BTreeMap::new(),
            actuator_kinds: BTreeMap::new(),
        };
        for (kind, check) in crate::profile::devices::builtin_sensor_kinds() {
            r.register_sensor_kind(kind, check);
        }
        for (kind, check) in crate::profile::devices::builtin_actuator_kinds() {
            r.register_actuator_kind(kind, check);
        }
        r
    }

    /// Registers (or replaces) a sensor kind a profile's `[[sensors]]` may declare, with
    /// the check of its `params`.
    pub fn register_sensor_kind(
        &mut self,
        kind: impl Into<String>,
        check: impl Fn(&toml::Table) -> Result<(), String> + Send + Sync + 'static,
    ) -> &mut Self {
        self.sensor_kinds.insert(kind.into(), Box::new(check));
        self
    }

    /// Registers (or replaces) an actuator kind a profile's `[[actuators]]` may declare,
    /// with the check of its `params`.
    pub fn register_actuator_kind(
        &mut self,
        kind: impl Into<String>,
        check: impl Fn(&toml::Table) -> Result<(), String> + Send + Sync + 'static,
    ) -> &mut Self {
        self.actuator_kinds.insert(kind.into(), Box::new(check));
        self
    }

    /// Registers (or replaces) the schema `name`.
    pub fn register(
        &mut self,
        name: impl Into<String>,
        factory: impl Fn(&M, &LeafArgs<'_>) -> Result<Box<dyn Behavior<M>>, String> + Send + Sync + 'static,
    ) -> &mut Self {
        self.leaves.insert(name.into(), Box::new(factory));
        self
    }

    /// Registers (or replaces) the sequencer selector `name` (a sequencer names it in
    /// its `selector` field).
    pub fn register_selector(
        &mut self,
        name: impl Into<String>,
        factory: impl Fn(&M, &SelectorArgs<'_>) -> Result<Box<dyn Selector<M>>, String> + Send + Sync + 'static,
    ) -> &mut Self {
        self.selectors.insert(name.into(), Box::new(factory));
        self
    }

    /// The registered names, sorted.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.leaves.keys().map(String::as_str)
    }

    /// Builds the profile's `[behavior.tree]`, its factories reading `memory` (the memory
    /// the tree will be ticked with).
    ///
    /// # Errors
    /// [`ConfigError::Invalid`] naming the profile's line for an absent tree, an unknown
    /// schema, or params a schema refuses. (The tree's structure was checked when the
    /// profile loaded.)
    pub fn build(&self, profile: &Profile, memory: &M) -> Result<Box<dyn Behavior<M>>, ConfigError> {
        let Some(tree) = &profile.behavior.tree else {
            return Err(profile.problems(vec![(
                "behavior".into(),
                "this robot's behavior needs a [behavior.tree] table".into(),
            )]));
        };
        let mut problems = Vec::new();
        let sensors = profile.sensors.iter().map(|d| (&d.kind, &d.params));
        check_devices("sensors", "sensor", sensors, &self.sensor_kinds, &mut problems);
        let actuators = profile.actuators.iter().map(|d| (&d.kind, &d.params));
        check_devices("actuators", "actuator", actuators, &self.actuator_kinds, &mut problems);
        let root = self.node(tree, Site::top(&tree.root), profile, memory, &mut problems);
        match root {
            Some(r) if problems.is_empty() => Ok(r),
            _ => Err(profile.problems(problems)),
        }
    }

    /// Builds the node `name` of the profile's `[behavior.tree]` and everything under
    /// it, as [`Registry::build`] builds the root: one phase of a shipped robot, with the
    /// profile's own params, to drive on its own (tests, tools).
    ///
    /// # Errors
    /// As [`Registry::build`].
    pub fn build_node(&self, profile: &Profile, name: &str, memory: &M) -> Result<Box<dyn Behavior<M>>, ConfigError> {
        let mut problems = Vec::new();
        let built = match &profile.behavior.tree {
            Some(tree) => self.node(tree, Site::top(name), profile, memory, &mut problems),
            None => {
                problems.push((
                    "behavior".into(),
                    "this robot's behavior needs a [behavior.tree] table".into(),
                ));
                None
            }
        };
        match built {
            Some(b) if problems.is_empty() => Ok(b),
            _ => Err(profile.problems(problems)),
        }
    }

    fn node(
        &self,
        tree: &TreeSpec,
        at: Site<'_>,
        profile: &Profile,
        memory: &M,
        problems: &mut Vec<(String, String)>,
    ) -> Option<Box<dyn Behavior<M>>> {
        let Site { name, parent, depth } = at;
        let path = format!("behavior.tree.nodes.{name}");
        let Some(spec) = tree.nodes.get(name) else {
            problems.push((path, format!("no node named `{name}`")));
            return None;
        };
        if depth > tree.nodes.len() {
            problems.push((path, format!("`{name}` contains itself")));
            return None;
        }
        let children = |problems: &mut Vec<(String, String)>| -> Vec<Option<Box<dyn Behavior<M>>>> {
            spec.children()
                .iter()
                .map(|c| {
                    let at = Site {
                        name: c,
                        parent: Some(name),
                        depth: depth + 1,
                    };
                    self.node(tree, at, profile, memory, problems)
                })
                .collect()
        };
        match spec {
            NodeSpec::Leaf { schema, params, .. } => {
                let Some(factory) = self.leaves.get(schema) else {
                    let known: Vec<&str> = self.names().collect();
                    problems.push((
                        format!("{path}.schema"),
                        format!("unknown schema `{schema}` (registered: {})", known.join(", ")),
                    ));
                    return None;
                };
                let args = LeafArgs {
                    node: name,
                    parent,
                    params,
                    profile,
                };
                match factory(memory, &args) {
                    Ok(leaf) => Some(Box::new(Named {
                        name: name.to_owned(),
                        leaf,
                    })),
                    Err(e) => {
                        let at = if e.starts_with("params") && !params.is_empty() {
                            format!("{path}.params")
                        } else {
                            format!("{path}.schema")
                        };
                        problems.push((at, format!("`{schema}`: {e}")));
                        None
                    }
                }
            }
            NodeSpec::Priority { .. } => {
                let built: Option<Vec<_>> = children(problems).into_iter().collect();
                Some(Box::new(Priority::new(name, built?)))
            }
            NodeSpec::VectorSum {
                gains,
                max_speed_mps,
                k_theta,
                lead,
                ..
            } => {
                let built: Option<Vec<_>> = children(problems).into_iter().collect();
                let pairs = gains.iter().copied().zip(built?).collect();
                let sum = VectorSum::new(name, pairs, *max_speed_mps, *k_theta);
                Some(Box::new(match lead {
                    Lead::Front => sum,
                    Lead::Rear => sum.rear_first(),
                }))
            }
            NodeSpec::Sequencer {
                states,
                state_timeout_s,
                selector,
                ..
            } => {
                let built: Option<Vec<_>> = children(problems).into_iter().collect();
                let mut seq = Sequencer::new(name);
                if let Some(sel) = selector {
                    let args = SelectorArgs {
                        node: name,
                        states,
                        profile,
                    };
                    match self.selectors.get(sel).map(|f| f(memory, &args)) {
                        Some(Ok(s)) => seq.set_selector(s),
                        Some(Err(e)) => problems.push((format!("{path}.selector"), format!("`{sel}`: {e}"))),
                        None => {
                            let known: Vec<&str> = self.selectors.keys().map(String::as_str).collect();
                            problems.push((
                                format!("{path}.selector"),
                                format!("unknown selector `{sel}` (registered: {})", known.join(", ")),
                            ));
                        }
                    }
                }
                for (child, state) in states.iter().zip(built?) {
                    let s = &tree.nodes[child];
                    let i = seq.state(state, s.latched());
                    // Declared trees say every way out: nothing leads on implicitly.
                    seq.transitions(i, Next::Finish, Next::Finish);
                    for (event, target) in s.transitions() {
                        let next = if target == FINISH {
                            Next::Finish
                        } else {
                            Next::Goto(states.iter().position(|x| x == target)?)
                        };
                        seq.on_event(i, event.clone(), next);
                    }
                    // The profile's `behavior.phase_timeout_s` bounds every phase that says
                    // nothing (`timeout_s = inf` lifts it).
                    let limit = s
                        .timeout_s()
                        .or(*state_timeout_s)
                        .unwrap_or(profile.behavior.phase_timeout_s);
                    if let Some(t) = Some(limit)
                        && t.is_finite()
                    {
                        seq.timeout(i, t);
                    }
                }
                Some(Box::new(seq))
            }
        }
    }
}

/// Where in the tree a node is being built: its name, the node it is a child of, and
/// how deep (a tree that contains itself is refused past its node count).
#[derive(Clone, Copy)]
struct Site<'a> {
    name: &'a str,
    parent: Option<&'a str>,
    depth: usize,
}

impl<'a> Site<'a> {
    /// The top of what is built.
    fn top(name: &'a str) -> Self {
        Self {
            name,
            parent: None,
            depth: 0,
        }
    }
}

/// A leaf as the tree holds it: named by its node (sequencers find their states, and
/// traces name them, by it), everything else the leaf's own.
struct Named<M: 'static> {
    name: String,
    leaf: Box<dyn Behavior<M>>,
}

impl<M: 'static> Behavior<M> for Named<M> {
    fn name(&self) -> &str {
        &self.name
    }
    fn tick(&mut self, mem: &mut M, inputs: &Inputs<'_>) -> Option<Step> {
        self.leaf.tick(mem, inputs)
    }
    fn reset(&mut self) {
        self.leaf.reset()
    }
    fn enter(&mut self, mem: &mut M, inputs: &Inputs<'_>) {
        self.leaf.enter(mem, inputs)
    }
    fn start(&mut self, state: &str) -> bool {
        self.leaf.start(state)
    }
    fn explain(&self, out: &mut Vec<crate::arbiter::NodeTrace>) {
        self.leaf.explain(out)
    }
}

/// Checks a profile's `[[sensors]]` or `[[actuators]]` (`table`) against the registered
/// kinds: an unknown kind at `table[i].kind`, params the kind refuses at `table[i].params`.
fn check_devices<'p>(
    table: &str,
    what: &str,
    devices: impl Iterator<Item = (&'p String, &'p toml::Table)>,
    kinds: &BTreeMap<String, Box<KindCheck>>,
    problems: &mut Vec<(String, String)>,
) {
    for (i, (kind, params)) in devices.enumerate() {
        match kinds.get(kind.as_str()) {
            None => {
                let known: Vec<&str> = kinds.keys().map(String::as_str).collect();
                problems.push((
                    format!("{table}[{i}].kind"),
                    format!("unknown {what} kind `{kind}` (registered: {})", known.join(", ")),
                ));
            }
            Some(check) => {
                if let Err(e) = check(params) {
                    problems.push((format!("{table}[{i}].params"), e));
                }
            }
        }
    }
}
