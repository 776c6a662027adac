//! A tick's arbitration decision as a value: who was active, what each proposed, who won.

use crate::schemas::{MotorOutput, Step};
use serde::Serialize;

/// Which coordination strategy made a decision.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Strategy {
    /// Highest-priority active behavior wins (subsumption).
    Priority,
    /// Gain-weighted sum of the active behaviors' outputs.
    VectorSum,
    /// One state of a state machine runs at a time.
    Sequencer,
}

/// One candidate's part in a decision.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Candidate {
    /// Index of the behavior in its arbiter (profile order).
    pub index: usize,
    /// What it proposed, or `None` when it was not released this tick.
    pub proposal: Option<MotorOutput>,
}

/// The decision of one arbiter in one tick. Arbiters keep one `Decision` and refill it
/// every tick, so recording costs no allocation in steady state.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Decision {
    /// Strategy used.
    pub strategy: Strategy,
    /// Candidates in profile order.
    pub candidates: Vec<Candidate>,
    /// Index of the winning behavior (priority, sequencer), or `None` for a sum or when no
    /// behavior was active.
    pub winner: Option<usize>,
    /// The output the arbiter returned.
    pub output: Option<MotorOutput>,
}

impl Decision {
    /// An empty decision for `strategy`.
    pub fn new(strategy: Strategy) -> Self {
        Self {
            strategy,
            candidates: Vec::new(),
            winner: None,
            output: None,
        }
    }

    /// Clears the record for a new tick (keeps capacity).
    pub fn clear(&mut self) {
        self.candidates.clear();
        self.winner = None;
        self.output = None;
    }

    /// Records one candidate.
    pub fn push(&mut self, index: usize, step: Option<&Step>) {
        self.candidates.push(Candidate {
            index,
            proposal: step.map(|s| s.output),
        });
    }

    /// Indices of the active (released) candidates.
    pub fn active(&self) -> impl Iterator<Item = usize> + '_ {
        self.candidates.iter().filter(|c| c.proposal.is_some()).map(|c| c.index)
    }

    /// Emits the decision as a `tracing` event at DEBUG level under target
    /// `marsupial::arbiter`, naming behaviors with `names`.
    pub fn trace(&self, arbiter: &str, names: &dyn Fn(usize) -> String) {
        if tracing::enabled!(target: "marsupial::arbiter", tracing::Level::DEBUG) {
            let active: Vec<String> = self.active().map(names).collect();
            let proposals: Vec<String> = self
                .candidates
                .iter()
                .filter_map(|c| c.proposal.map(|p| format!("{}={:?}", names(c.index), p.drive)))
                .collect();
            tracing::debug!(
                target: "marsupial::arbiter",
                arbiter,
                strategy = ?self.strategy,
                active = ?active,
                proposals = ?proposals,
                winner = self.winner.map(names).as_deref().unwrap_or("-"),
                output = ?self.output.map(|o| o.drive),
                "decision"
            );
        }
    }
}
