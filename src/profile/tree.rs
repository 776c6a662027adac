//! `[behavior.tree]`: a robot's docking behavior declared as a tree.
//!
//! Leaves name a registered schema (a perceptual and a motor schema paired under a
//! releaser, see [`crate::behaviors::registry`]) with its tuning in `params`; inner nodes
//! are the three arbiters. A node that is a state of a sequencer also says where each of
//! its events leads (`on`), how long it may run (`timeout_s`) and whether the sequencer's
//! selector may interrupt it (`latched`).
//!
//! ```toml
//! [behavior.tree]
//! root = "docking"
//! docking = "search"               # the state docking starts in
//!
//! [behavior.tree.nodes.docking]
//! kind = "sequencer"
//! states = ["search", "approach"]
//!
//! [behavior.tree.nodes.search]
//! kind = "leaf"
//! schema = "bujold.search"
//! on = { acquired = "approach" }
//! ```
//!
//! Validation checks the structure (every name resolves, each node has one parent, no
//! node contains itself, transitions lead to states of the same sequencer or `finish`);
//! the registry checks the schema names and their params when the tree is built.

use crate::config::Validator;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

pub use crate::arbiter::sequencer::FINISH;

/// The `[behavior.tree]` table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TreeSpec {
    /// The node the loop runs.
    pub root: String,
    /// The state a departure (undock, imprint) starts in; none when the robot has no
    /// departure.
    #[serde(default)]
    pub departure: Option<String>,
    /// The state docking starts in.
    pub docking: String,
    /// The state docking starts in when the dock's pose is known a priori (the
    /// ballistic region); `docking` when absent.
    #[serde(default)]
    pub ballistic: Option<String>,
    /// Every node, by name.
    pub nodes: BTreeMap<String, NodeSpec>,
}

/// Which end of the robot leads along a summed motion vector.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Lead {
    /// Drive forward along it.
    #[default]
    Front,
    /// Back along it.
    Rear,
}

impl Lead {
    /// +1 for the front, −1 for the rear: the sign of the body-frame x of the lead's
    /// direction of travel.
    pub fn sign(self) -> f64 {
        match self {
            Lead::Front => 1.0,
            Lead::Rear => -1.0,
        }
    }
}

/// Where a state's events lead: event name → state name (or [`FINISH`]).
pub type Transitions = BTreeMap<String, String>;

/// One node of the tree.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum NodeSpec {
    /// A registered schema.
    Leaf {
        /// Registered name, e.g. `bujold.search`.
        schema: String,
        /// The schema's tuning (its own fields; unknown ones are refused when built).
        #[serde(default)]
        params: toml::Table,
        /// As a sequencer state: where its events lead.
        #[serde(default)]
        on: Transitions,
        /// As a sequencer state: longest time in it, s (`inf`: none).
        #[serde(default)]
        timeout_s: Option<f64>,
        /// As a sequencer state: exempt from the selector until it ends.
        #[serde(default)]
        latched: bool,
    },
    /// One state at a time, with typed transitions.
    Sequencer {
        /// The states, in order (the first runs when the sequencer starts).
        states: Vec<String>,
        /// Timeout of every state that does not set its own, s (default: the profile's
        /// `behavior.phase_timeout_s`).
        #[serde(default)]
        state_timeout_s: Option<f64>,
        /// A registered selector that picks the state to run each tick while the current
        /// one is not latched (RAPOSA's seven-state selection); none: transitions only.
        #[serde(default)]
        selector: Option<String>,
        /// As a sequencer state: where its events lead.
        #[serde(default)]
        on: Transitions,
        /// As a sequencer state: longest time in it, s.
        #[serde(default)]
        timeout_s: Option<f64>,
        /// As a sequencer state: exempt from the selector until it ends.
        #[serde(default)]
        latched: bool,
    },
    /// Subsumption: the first active child wins.
    Priority {
        /// Children, highest priority first.
        children: Vec<String>,
        /// As a sequencer state: where its events lead.
        #[serde(default)]
        on: Transitions,
        /// As a sequencer state: longest time in it, s.
        #[serde(default)]
        timeout_s: Option<f64>,
        /// As a sequencer state: exempt from the selector until it ends.
        #[serde(default)]
        latched: bool,
    },
    /// Gain-weighted sum of the active children's outputs.
    VectorSum {
        /// Children.
        children: Vec<String>,
        /// One gain per child.
        gains: Vec<f64>,
        /// Speed cap of the summed vector, m/s.
        max_speed_mps: f64,
        /// Heading gain turning the summed vector into a twist, 1/s.
        k_theta: f64,
        /// Which end follows the summed vector: `front`, or `rear` for a robot that
        /// backs along it (Bujold backs into her mother).
        #[serde(default)]
        lead: Lead,
        /// As a sequencer state: where its events lead.
        #[serde(default)]
        on: Transitions,
        /// As a sequencer state: longest time in it, s.
        #[serde(default)]
        timeout_s: Option<f64>,
        /// As a sequencer state: exempt from the selector until it ends.
        #[serde(default)]
        latched: bool,
    },
}

impl NodeSpec {
    /// The node's children (states of a sequencer), in order.
    pub fn children(&self) -> &[String] {
        match self {
            NodeSpec::Leaf { .. } => &[],
            NodeSpec::Sequencer { states, .. } => states,
            NodeSpec::Priority { children, .. } | NodeSpec::VectorSum { children, .. } => children,
        }
    }

    /// Where its events lead, as a sequencer state.
    pub fn transitions(&self) -> &Transitions {
        match self {
            NodeSpec::Leaf { on, .. }
            | NodeSpec::Sequencer { on, .. }
            | NodeSpec::Priority { on, .. }
            | NodeSpec::VectorSum { on, .. } => on,
        }
    }

    /// Its own timeout as a sequencer state, s.
    pub fn timeout_s(&self) -> Option<f64> {
        match self {
            NodeSpec::Leaf { timeout_s, .. }
            | NodeSpec::Sequencer { timeout_s, .. }
            | NodeSpec::Priority { timeout_s, .. }
            | NodeSpec::VectorSum { timeout_s, .. } => *timeout_s,
        }
    }

    /// Latched as a sequencer state.
    pub fn latched(&self) -> bool {
        match self {
            NodeSpec::Leaf { latched, .. }
            | NodeSpec::Sequencer { latched, .. }
            | NodeSpec::Priority { latched, .. }
            | NodeSpec::VectorSum { latched, .. } => *latched,
        }
    }

    /// The field listing its children, for messages.
    fn children_field(&self) -> &'static str {
        match self {
            NodeSpec::Sequencer { .. } => "states",
            _ => "children",
        }
    }
}

impl TreeSpec {
    /// The sequencer holding state `name`, with the state's index.
    pub fn sequencer_of(&self, name: &str) -> Option<(&str, usize)> {
        self.nodes.iter().find_map(|(seq, n)| match n {
            NodeSpec::Sequencer { states, .. } => states.iter().position(|s| s == name).map(|i| (seq.as_str(), i)),
            _ => None,
        })
    }
}

/// Checks the tree's structure (see the module docs); problems are reported at `path`
/// (`behavior.tree`).
pub(crate) fn validate_tree(t: &TreeSpec, path: &str, v: &mut Validator<'_>) {
    let node_path = |n: &str| format!("{path}.nodes.{n}");
    if !t.nodes.contains_key(&t.root) {
        v.problem(
            &format!("{path}.root"),
            format!("no node named `{}` in [{path}.nodes]", t.root),
        );
    }
    if t.nodes.contains_key(FINISH) {
        v.problem(
            &node_path(FINISH),
            format!("`{FINISH}` is reserved for ending a sequence"),
        );
    }
    // Every child resolves and has one parent.
    let mut parent: BTreeMap<&str, &str> = BTreeMap::new();
    for (name, node) in &t.nodes {
        let field = node.children_field();
        if node.children().is_empty() && !matches!(node, NodeSpec::Leaf { .. }) {
            v.problem(&format!("{}.{field}", node_path(name)), "expected at least one child");
        }
        for (i, child) in node.children().iter().enumerate() {
            let at = format!("{}.{field}[{i}]", node_path(name));
            if !t.nodes.contains_key(child) {
                v.problem(&at, format!("no node named `{child}` in [{path}.nodes]"));
            } else if let Some(first) = parent.insert(child, name) {
                v.problem(
                    &at,
                    format!("`{child}` is already a child of `{first}`: a node has one parent (declare a second node)"),
                );
            }
        }
        if let NodeSpec::VectorSum { gains, children, .. } = node {
            v.require(
                gains.len() == children.len(),
                &format!("{}.gains", node_path(name)),
                || format!("expected one gain per child ({}), got {}", children.len(), gains.len()),
            );
        }
        let timeout = node.timeout_s().or(match node {
            NodeSpec::Sequencer { state_timeout_s, .. } => *state_timeout_s,
            _ => None,
        });
        if let Some(s) = timeout {
            v.require(s > 0.0, &format!("{}.timeout_s", node_path(name)), || {
                format!("expected a positive number of seconds (or inf), got {s}")
            });
        }
    }
    for name in t.nodes.keys() {
        if *name != t.root && !parent.contains_key(name.as_str()) {
            v.problem(
                &node_path(name),
                format!("`{name}` is not part of the tree (no node lists it)"),
            );
        }
    }
    if parent.contains_key(t.root.as_str()) {
        v.problem(
            &format!("{path}.root"),
            format!("the root `{}` is a child of `{}`", t.root, parent[t.root.as_str()]),
        );
    }
    // No node contains itself: walk up from each node.
    for name in t.nodes.keys() {
        let mut at = name.as_str();
        for _ in 0..=t.nodes.len() {
            match parent.get(at) {
                Some(p) if *p == name => {
                    v.problem(
                        &node_path(name),
                        format!("`{name}` contains itself (through `{at}`): a tree has no cycles"),
                    );
                    break;
                }
                Some(p) => at = p,
                None => break,
            }
        }
    }
    // Transitions lead to states of the same sequencer.
    for (name, node) in &t.nodes {
        if node.transitions().is_empty() {
            continue;
        }
        let Some(seq) = parent.get(name.as_str()).and_then(|p| t.nodes.get(*p).map(|n| (p, n))) else {
            v.problem(
                &format!("{}.on", node_path(name)),
                "only a state of a sequencer has transitions",
            );
            continue;
        };
        let NodeSpec::Sequencer { states, .. } = seq.1 else {
            v.problem(
                &format!("{}.on", node_path(name)),
                format!(
                    "only a state of a sequencer has transitions (`{}` is not a sequencer)",
                    seq.0
                ),
            );
            continue;
        };
        for (event, target) in node.transitions() {
            if target != FINISH && !states.contains(target) {
                v.problem(
                    &format!("{}.on.{event}", node_path(name)),
                    format!(
                        "`{target}` is not a state of `{}` (expected one of {states:?} or `{FINISH}`)",
                        seq.0
                    ),
                );
            }
        }
    }
    // Entry states are states of some sequencer.
    let entries = [
        ("docking", Some(&t.docking)),
        ("departure", t.departure.as_ref()),
        ("ballistic", t.ballistic.as_ref()),
    ];
    for (field, entry) in entries {
        if let Some(e) = entry
            && t.sequencer_of(e).is_none()
        {
            v.problem(
                &format!("{path}.{field}"),
                format!("`{e}` is not a state of any sequencer in the tree"),
            );
        }
    }
}
