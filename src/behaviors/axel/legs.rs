//! `axel.settle` and `axel.step`, the legs of Axel's sense-plan-act cycle around each
//! phase's look ([`super::look`]): stand still until the base settles, and drive the one
//! motion a look decided, by odometry. Both report the phase they are part of (the
//! sequencer they are states of) in their feedback, and both end the docking when the
//! phase's clock runs out ([`Memory::gave_up`]).

use super::memory::Memory;
use crate::geometry::{Pose2, Twist, wrap_angle};
use crate::schemas::{Behavior, DriveCommand, Inputs, Step};
use serde::Deserialize;

/// One motion a look decided, as `axel.step` drives it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Motion {
    /// Drive `twist` reeling at `reel` m/s for `left` m more, measured from odometry
    /// pose `last`.
    Arc {
        /// The base's command.
        twist: Twist,
        /// The reel's rate, m/s (positive in).
        reel: f64,
        /// Path left, m.
        left: f64,
        /// Odometry pose `left` was measured at.
        last: Pose2,
    },
    /// Turn in place at `omega` rad/s for `left` rad more, from odometry heading `last`.
    Turn {
        /// Turn rate, rad/s.
        omega: f64,
        /// Angle left, rad.
        left: f64,
        /// Odometry heading `left` was measured at, rad.
        last: f64,
    },
    /// Wheels free, reel in until the reel reads `until` m paid out, or until loop time
    /// `deadline`.
    Reel {
        /// Paid-out length that ends it, m.
        until: f64,
        /// Loop time that ends it, s.
        deadline: f64,
    },
}

/// `axel.settle`'s params.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SettleParams {
    /// Standing still before looking, s (the base's lag and the tether's swing settle).
    pub settle_s: f64,
    /// This settle starts the phase: its looks' counts start over ([`super::look::Looks`]).
    pub starts_phase: bool,
    /// The phase is a search: it fails after `behavior.search_timeout_s` without a
    /// trusted pose (`target_lost` when the module was seen this docking,
    /// `target_never_detected` otherwise). Read only where `starts_phase` is set.
    pub search: bool,
}

impl Default for SettleParams {
    fn default() -> Self {
        Self {
            settle_s: 0.6,
            starts_phase: false,
            search: false,
        }
    }
}

/// `axel.settle`: the base stopped, the reel taking up slack, for `settle_s`; then event
/// `settled`.
pub struct Settle {
    phase: &'static str,
    settle_s: f64,
    /// The phase's time limit, s, set as it starts (`starts_phase`).
    limit: Option<f64>,
    since: f64,
}

impl Settle {
    /// A leaf in phase `phase`, giving up after `search_timeout_s` when
    /// `params` make it a search.
    pub fn new(phase: &'static str, params: SettleParams, search_timeout_s: f64) -> Self {
        let limit = if params.search { search_timeout_s } else { f64::INFINITY };
        Self {
            phase,
            settle_s: params.settle_s,
            limit: params.starts_phase.then_some(limit),
            since: 0.0,
        }
    }
}

impl Behavior<Memory> for Settle {
    fn enter(&mut self, m: &mut Memory, inputs: &Inputs<'_>) {
        self.since = inputs.now;
        if let Some(limit) = self.limit {
            m.looks = super::look::Looks::new(inputs.now, limit);
        }
    }

    fn tick(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) -> Option<Step> {
        if let Some(end) = m.gave_up(self.phase) {
            return Some(end);
        }
        let step = m.hold(self.phase);
        Some(if m.now - self.since >= self.settle_s {
            step.with_event("settled")
        } else {
            step
        })
    }
}

/// `axel.step`: drives the motion the phase's look decided ([`Memory::step`], taken as
/// it is entered) until odometry or the reel's reading says it is done; then event
/// `done`, stopped. Entered with no motion decided, it ends at once.
pub struct StepLeg {
    phase: &'static str,
    motion: Option<Motion>,
}

impl StepLeg {
    /// A leaf in phase `phase`.
    pub fn new(phase: &'static str) -> Self {
        Self { phase, motion: None }
    }
}

impl Behavior<Memory> for StepLeg {
    fn enter(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) {
        self.motion = m.step.take();
    }

    fn tick(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) -> Option<Step> {
        if let Some(end) = m.gave_up(self.phase) {
            return Some(end);
        }
        let phase = self.phase;
        let done = |m: &Memory| Some(m.hold(phase).with_event("done"));
        match self.motion.as_mut() {
            None => done(m),
            Some(Motion::Arc {
                twist,
                reel,
                left,
                last,
            }) => {
                *left -= m.odo.distance(last);
                if *left <= 0.0 {
                    return done(m);
                }
                *last = m.odo;
                Some(m.drive(DriveCommand::Twist(*twist), *reel, phase))
            }
            Some(Motion::Turn { omega, left, last }) => {
                *left -= wrap_angle(m.odo.theta - *last).abs();
                if *left <= 0.0 {
                    return done(m);
                }
                *last = m.odo.theta;
                Some(m.drive(DriveCommand::Turn { omega: *omega }, m.take_up(), phase))
            }
            Some(Motion::Reel { until, deadline }) => {
                if m.now >= *deadline || m.reel.is_none_or(|r| r.length <= *until) {
                    return done(m);
                }
                Some(m.free_reel(phase))
            }
        }
    }
}
