//! Decision traces: each tick's decision as a value a campaign can save.
//!
//! After a tick, [`Behavior::explain`](crate::schemas::Behavior::explain) on the root
//! walks the nodes that ran and lists, for each arbiter, which children were active, what
//! each proposed, which won, and, for a sequencer, which state ran and why a transition
//! fired (the event's name). `marsupial dock --trace FILE.jsonl` writes one line per
//! tick. Explaining allocates (names are copied), so the loop never does it by itself:
//! only a caller that wants a trace pays for it.

use super::decision::Strategy;
use crate::schemas::MotorOutput;
use serde::Serialize;

/// A sequencer's change of state.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Transition {
    /// State left.
    pub from: String,
    /// State entered.
    pub to: String,
    /// Why: the event's name (`"acquired"`, `"timeout"`), `"selected"` for a selector's
    /// switch, `"started"` for a start.
    pub event: String,
}

/// One arbiter's part in a tick's decision.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct NodeTrace {
    /// The node's name (as in the profile's tree).
    pub node: String,
    /// Its strategy.
    pub strategy: Strategy,
    /// Children that were active (released), in order.
    pub active: Vec<String>,
    /// What each active child proposed.
    pub proposals: Vec<(String, MotorOutput)>,
    /// The child whose proposal won (priority, sequencer); none for a sum.
    pub winner: Option<String>,
    /// Transitions this tick (a sequencer's; at most a start and an event's).
    pub transitions: Vec<Transition>,
}

/// The trace of one arbiter's recorded decision, naming children with `name`.
pub(crate) fn node_trace<'a>(node: &str, d: &super::Decision, name: &dyn Fn(usize) -> &'a str) -> NodeTrace {
    NodeTrace {
        node: node.to_string(),
        strategy: d.strategy,
        active: d.active().map(|i| name(i).to_string()).collect(),
        proposals: d
            .candidates
            .iter()
            .filter_map(|c| c.proposal.map(|p| (name(c.index).to_string(), p)))
            .collect(),
        winner: d.winner.map(|i| name(i).to_string()),
        transitions: Vec::new(),
    }
}
