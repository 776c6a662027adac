//! Priority / subsumption coordination.

use super::decision::{Decision, Strategy};
use crate::schemas::{Behavior, Inputs, Step};

/// Ticks every child each tick (so their perceptual schemas keep adapting) and returns
/// the proposal of the first active child in list order: earlier children subsume later
/// ones. When no child is active the arbiter is itself inactive (`None`), and the
/// reactive loop commands a stop. `M` is the tree's memory, passed to each child in turn.
pub struct Priority<M: ?Sized = ()> {
    name: String,
    children: Vec<Box<dyn Behavior<M>>>,
    decision: Decision,
}

impl<M: ?Sized> Priority<M> {
    /// Builds the arbiter; `children` are in priority order, highest first.
    pub fn new(name: impl Into<String>, children: Vec<Box<dyn Behavior<M>>>) -> Self {
        let n = children.len();
        let mut decision = Decision::new(Strategy::Priority);
        decision.candidates.reserve(n);
        Self {
            name: name.into(),
            children,
            decision,
        }
    }

    /// The last tick's decision.
    pub fn decision(&self) -> &Decision {
        &self.decision
    }
}

impl<M: ?Sized> Behavior<M> for Priority<M> {
    fn name(&self) -> &str {
        &self.name
    }

    fn tick(&mut self, mem: &mut M, inputs: &Inputs<'_>) -> Option<Step> {
        self.decision.clear();
        let mut winner: Option<Step> = None;
        for (i, child) in self.children.iter_mut().enumerate() {
            let step = child.tick(mem, inputs);
            self.decision.push(i, step.as_ref());
            if winner.is_none() && step.is_some() {
                winner = step;
                self.decision.winner = Some(i);
            }
        }
        self.decision.output = winner.map(|s| s.output);
        let children = &self.children;
        self.decision.trace(&self.name, &|i| children[i].name().to_string());
        winner
    }

    fn reset(&mut self) {
        self.children.iter_mut().for_each(|c| c.reset());
    }

    fn explain(&self, out: &mut Vec<super::NodeTrace>) {
        out.push(super::trace::node_trace(&self.name, &self.decision, &|i| {
            self.children[i].name()
        }));
        for c in self.decision.active() {
            self.children[c].explain(out);
        }
    }

    /// Every child that has the state starts there (a priority node usually holds one
    /// sequence under its overrides).
    fn start(&mut self, state: &str) -> bool {
        let mut any = false;
        for c in self.children.iter_mut() {
            any |= c.start(state);
        }
        any
    }
}
