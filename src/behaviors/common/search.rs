//! Search, written once: turn in place until the target is acquired, with the
//! [`SearchRotation`] motor schema (one way at a constant rate, as Bujold's "rotate until
//! it is acquired", seed 004 §V; or alternating sides and doubling the sweep below a full
//! turn, as RAPOSA's "rotate slowly until it finds it again", seed 001 §II.E).
//!
//! The robot's memory supplies, through [`Searching`], what differs between robots: how
//! it knows the target is acquired (Bujold hands over to its approach in the same tick;
//! RAPOSA's selector leaves the search instead), which side to turn first, what a timeout
//! means, and how it commands a turn. The leaf's [`SearchParams`] and the robot's rates
//! say the rest; a [`SearchWatch`] adds a reason to stop turning (Bujold: a turn that
//! leaves the view still is caught on the body).

use super::motion::Motion;
use crate::schemas::{Behavior, DriveCommand, FailureReason, Inputs, Outcome, SearchRotation, Step};

/// What the search needs of a robot's shared memory, beside its [`Motion`].
pub trait Searching: Motion {
    /// The step that ends the search with the target acquired this tick, if it is (the
    /// robot's next phase may already command its motion in it); `None` when a selector
    /// above the search leaves it instead.
    fn acquired(&mut self, phase: &'static str) -> Option<Step>;
    /// Which way to turn first, asked as the search is entered: +1 counter-clockwise, −1
    /// clockwise (toward where the target was last seen, or away from the last turn).
    fn search_side(&self) -> f64;
    /// Why the docking fails when the search times out.
    fn lost_reason(&self) -> FailureReason;
    /// Commands the search turn.
    fn search_turn(&mut self, turn: DriveCommand, phase: &'static str) -> Step;
    /// Counts one more tick with nothing seen and returns the count (the robot resets it
    /// when it sees anything): for [`SearchParams::grace_frames`].
    fn count_unseen(&mut self) -> u32 {
        0
    }
    /// The search clock the robot keeps across re-entries of its search (RAPOSA's
    /// selector may leave the search for a glimpse and return; the clock restarts only
    /// when the target is seen), for [`SearchParams::resume_clock`]. `None`: none kept.
    fn search_clock(&mut self) -> Option<&mut Option<f64>> {
        None
    }
}

/// A reason beside the target's acquisition to stop a search turn.
pub trait SearchWatch<M>: Send + 'static {
    /// The search is entered.
    fn enter(&mut self) {}
    /// Every tick, first: observe this tick's inputs.
    fn observe(&mut self, _m: &mut M, _inputs: &Inputs<'_>) {}
    /// After the acquisition and timeout checks: the step that ends the search, if the
    /// watch says it must end.
    fn stop(&mut self, _m: &mut M) -> Option<Step> {
        None
    }
}

/// No watch.
impl<M> SearchWatch<M> for () {}

/// A search's params (node `params` for those a profile may set).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SearchParams {
    /// Turn rate, rad/s.
    pub rate: f64,
    /// First sweep of a doubling search, rad.
    pub first_sweep: f64,
    /// Alternate sides and double the sweep.
    pub doubling: bool,
    /// Ticks in a row with nothing seen before turning (a single dropped frame must not
    /// start a rotation); 0: none.
    pub grace_frames: u32,
    /// Stand still this long after entering before turning, s (the image settles after
    /// a manoeuvre stops).
    pub settle_s: f64,
    /// Time the search by the robot's kept clock ([`Searching::search_clock`]) instead
    /// of from this entry.
    pub resume_clock: bool,
    /// Fail the docking after this long searching, s.
    pub timeout_s: f64,
}

/// The search leaf (see the module docs).
pub struct Search<M, W = ()> {
    phase: &'static str,
    params: SearchParams,
    watch: W,
    on_enter: fn(&mut M),
    entered: f64,
    side: f64,
    _memory: std::marker::PhantomData<fn(&mut M)>,
}

impl<M: Searching, W: SearchWatch<M>> Search<M, W> {
    /// A leaf (feedback `phase`) searching by `params`, stopped early by `watch`.
    pub fn new(phase: &'static str, params: SearchParams, watch: W) -> Self {
        Self {
            phase,
            params,
            watch,
            on_enter: |_| {},
            entered: 0.0,
            side: 1.0,
            _memory: std::marker::PhantomData,
        }
    }

    /// Runs `f` on the memory each time the search is entered (RAPOSA's look after the
    /// blind manoeuvre: the perception may look again).
    pub fn on_enter(mut self, f: fn(&mut M)) -> Self {
        self.on_enter = f;
        self
    }
}

impl<M: Searching, W: SearchWatch<M>> Behavior<M> for Search<M, W> {
    fn enter(&mut self, m: &mut M, inputs: &Inputs<'_>) {
        (self.on_enter)(m);
        self.entered = inputs.now;
        self.side = m.search_side();
        self.watch.enter();
    }

    fn tick(&mut self, m: &mut M, inputs: &Inputs<'_>) -> Option<Step> {
        let p = self.params;
        self.watch.observe(m, inputs);
        if let Some(step) = m.acquired(self.phase) {
            return Some(step);
        }
        if p.grace_frames > 0 && m.count_unseen() <= p.grace_frames {
            return Some(m.hold(self.phase));
        }
        let now = m.now();
        let start = match m.search_clock().filter(|_| p.resume_clock) {
            Some(clock) => *clock.get_or_insert(now),
            None => self.entered,
        };
        let t = now - start;
        if t < p.settle_s {
            return Some(m.hold(self.phase));
        }
        if t > p.timeout_s {
            let reason = m.lost_reason();
            return Some(m.hold(self.phase).finishing(Outcome::Failed(reason)));
        }
        if let Some(step) = self.watch.stop(m) {
            return Some(step);
        }
        let rotation = SearchRotation {
            rate: p.rate * self.side,
            first_sweep: p.first_sweep,
            doubling: p.doubling,
        };
        Some(m.search_turn(rotation.command(t - p.settle_s), self.phase))
    }
}
