//! The look of Axel's sense-plan-act cycle (seed 000 §II, §V-B: "stop, take images,
//! plan, take one step"), which the three sensing leaves (`axel.acquire`,
//! `axel.approach`, `axel.align`) share.
//!
//! The cycle itself is a sequence in the profile: each sensing phase is a sequencer of
//! `axel.settle` (stand still until the base's lag and the tether's swing settle; the
//! phase's first settle starts its counts, [`Looks`]) → the phase's look leaf (look until
//! a trusted pose arrives or `look_s` passes, then decide) → `axel.step` (drive the ONE
//! motion decided, by odometry) → `axel.settle` again ([`super::legs`]). A rover that
//! kept moving while it looked would plan on frames blurred by its own motion and a pose
//! already out of date by the time it plans; the paper stopped, and so do we. Standing
//! or turning in place, the reel takes up slack until its current says the tether is
//! taut ([`Memory::take_up`]).
//!
//! A look ends with the decision's first command and the event that leads on: `step`
//! (the decided motion waits in [`Memory::step`] for `axel.step`), `settle` (nothing to
//! drive: settle and look again), or the decision's own event, which leaves the phase.

use super::legs::Motion;
use super::memory::{Memory, Sighting, Trust};
use crate::geometry::{Pose2, Twist};
use crate::kinematics::two_arc::{Arc, Polar};
use crate::schemas::{DriveCommand, Outcome, Step};

/// What a sensing leaf decides once it looked.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Decision {
    /// Drive this arc (module frame start `from`), then look again.
    Arc {
        /// The arc.
        arc: Arc,
        /// Where it starts, module frame (for the tether's change of length).
        from: Pose2,
    },
    /// Turn in place by this much, rad (counter-clockwise positive), then look again.
    Turn(f64),
    /// Wheels in free rotation, reel in this much tether, m, by the reel's own length
    /// reading, then look again: the tether drags the rover toward the module and turns
    /// its leading arm (and the cameras) to face it (the paper's pure reeling, §V-C, as a
    /// step).
    Reel(f64),
    /// Leave the phase with the event.
    Event(&'static str),
    /// End the docking with this outcome.
    Done(Outcome),
}

/// What the running phase's looks have counted, kept across its cycles and started over
/// by its first `axel.settle` ([`super::legs::Settle`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Looks {
    /// When the phase's clock started, s: its entry, or the last step that counts as
    /// progress (a reel step of the search).
    pub began: f64,
    /// The phase fails after this long on its clock, s (the search's
    /// `behavior.search_timeout_s`; infinite for the others): checked on every tick of
    /// its cycle ([`Memory::gave_up`]).
    pub limit: f64,
    /// Looks in a row without a trusted pose ([`Look::tick_seeing`]).
    pub unseen: u32,
    /// Steps of the leaf's own kind: the search's recovery steps, the alignment's
    /// finishing steps.
    pub steps: u32,
}

impl Looks {
    /// A phase entered at `now`, failing after `limit` s.
    pub fn new(now: f64, limit: f64) -> Self {
        Self {
            began: now,
            limit,
            unseen: 0,
            steps: 0,
        }
    }
}

/// One look: perception runs from the leaf's entry until a trusted pose arrives or
/// `look_s` passes (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Look {
    look_s: f64,
    trust: Trust,
    since: f64,
}

impl Look {
    /// A look of at most `look_s` s, trusting sightings by `trust`.
    pub fn new(look_s: f64, trust: Trust) -> Self {
        Self {
            look_s,
            trust,
            since: 0.0,
        }
    }

    /// Starts looking at `now`: perception runs on the next ticks' frames.
    pub fn enter(&mut self, m: &mut Memory, now: f64) {
        self.since = now;
        m.sighting = None;
        m.looking = true;
    }

    /// One tick: hold while looking; then ask `decide` (with the trusted sighting, or
    /// `None` when the look found none) and start what it decided. Feedback names `phase`.
    pub fn tick(
        &mut self,
        m: &mut Memory,
        phase: &'static str,
        decide: impl FnOnce(&mut Memory, Option<Sighting>) -> Decision,
    ) -> Step {
        let since = self.since;
        let trusted = m.sighting.filter(|s| s.t >= since && self.trust.accepts(s));
        if trusted.is_none() && m.now - since < self.look_s {
            return m.hold(phase);
        }
        m.looking = false;
        if let Some(s) = &trusted {
            m.fix(s);
        }
        let untrusted = m.sighting.filter(|s| s.t >= since);
        let decision = decide(m, trusted);
        tracing::debug!(
            target: "marsupial::behavior",
            phase,
            t = m.now,
            pose = ?untrusted.map(|s| (s.pose.x, s.pose.y, s.pose.theta.to_degrees())),
            source = ?untrusted.map(|s| s.source),
            marks = untrusted.map_or(0, |s| s.marks),
            reprojection_px = untrusted.map_or(f64::NAN, |s| s.reprojection_px),
            trusted = trusted.is_some(),
            ?decision,
            "axel looked"
        );
        start(m, decision, phase)
    }

    /// [`Look::tick`] for a leaf that plans only on a trusted pose: `decide` gets the
    /// sighting; a look without one turns to recentre the module (toward the look's
    /// untrusted pose, else the dead-reckoned last fix) when it lies more than 5° off,
    /// and looks again; `lost_looks` of them in a row ([`Looks::unseen`]) leave the phase
    /// with event `lost`. When the module is centred but the look's pose is untrusted,
    /// `untrusted` may decide from that pose instead (`None`: look again): recentring
    /// cannot help a view that one camera lost because the module is too near.
    pub fn tick_seeing(
        &mut self,
        m: &mut Memory,
        phase: &'static str,
        lost_looks: u32,
        decide: impl FnOnce(&mut Memory, Sighting) -> Decision,
        untrusted: impl FnOnce(&mut Memory, Sighting) -> Option<Decision>,
    ) -> Step {
        self.tick(m, phase, |m, seen| match seen {
            Some(s) => {
                m.looks.unseen = 0;
                decide(m, s)
            }
            None => {
                m.looks.unseen += 1;
                // Recentre before looking again: toward this look's untrusted pose
                // (the module at the fish-eye's edge, seen by one camera or by too
                // few marks), else toward where the last fix puts it.
                let seen = m.sighting.filter(|s| s.t >= m.now - 3.0);
                let bearing = seen
                    .map(|s| s.pose)
                    .or_else(|| m.reckoned())
                    .map_or(0.0, |p| Polar::from_pose(&p).bearing());
                let off_centre = bearing.abs() > 5f64.to_radians();
                if !off_centre && let Some(d) = seen.and_then(|s| untrusted(m, s)) {
                    m.looks.unseen = 0;
                    return d;
                }
                if m.looks.unseen >= lost_looks {
                    Decision::Event("lost")
                } else {
                    Decision::Turn(if off_centre { bearing } else { 0.0 })
                }
            }
        })
    }
}

/// The step that starts `decision`: its first command, with the decided motion left in
/// [`Memory::step`] for `axel.step` (event `step`), or the decision's own ending.
fn start(m: &mut Memory, decision: Decision, phase: &'static str) -> Step {
    match decision {
        Decision::Arc { arc, from } => start_arc(m, arc, &from, phase),
        Decision::Turn(angle) => {
            let omega = 0.5 * m.geometry.max_turn_rate * angle.signum();
            m.step = Some(Motion::Turn {
                omega,
                left: angle.abs(),
                last: m.odo.theta,
            });
            m.drive(DriveCommand::Turn { omega }, m.take_up(), phase)
                .with_event("step")
        }
        Decision::Reel(length) => start_reel(m, length, phase),
        Decision::Event(e) => m.hold(phase).with_event(e),
        Decision::Done(o) => m.hold(phase).finishing(o),
    }
}

/// Starts reeling in `length` m with the wheels free. The reel's length reading ends
/// it; so does twice the time the reel needs at its top rate, plus 2 s (a reel pulling
/// against a caught arm is the `axel.stall` leaf's to judge, by its current). Without a
/// reel reading there is nothing to measure by: hold, settle and look again.
fn start_reel(m: &mut Memory, length: f64, phase: &'static str) -> Step {
    let Some(r) = m.reel.filter(|_| length > 0.0) else {
        return m.hold(phase).with_event("settle");
    };
    m.step = Some(Motion::Reel {
        until: r.length - length,
        deadline: m.now + 2.0 * length / m.geometry.max_reel_rate.max(1e-6) + 2.0,
    });
    m.free_reel(phase).with_event("step")
}

/// Starts driving `arc` from module-frame `from`: at the arc speed, slower where the
/// turn-rate limit needs it or where the reel could not keep up, reeling at the rate that
/// brings the reel's paid-out length to the exposed length at the arc's end
/// ([`crate::kinematics::tether_length::TetherGeometry::pay_out_along`]).
fn start_arc(m: &mut Memory, arc: Arc, from: &Pose2, phase: &'static str) -> Step {
    let g = &m.geometry;
    let mut speed = if arc.curvature.abs() > 1e-9 {
        g.arc_speed.min(0.9 * g.max_turn_rate / arc.curvature.abs())
    } else {
        g.arc_speed
    };
    // The reel pays out |ΔL| over |s| (the change along the arc, and the slack its
    // reading shows now): at `speed` it must turn at speed·|ΔL|/|s|, no faster than it
    // can.
    let paid_out = m.reel.map(|r| r.length);
    let per_m = g.tether.pay_out_along(paid_out, from, &arc).abs() / arc.length.abs().max(1e-9);
    if per_m * speed > g.max_reel_rate {
        speed = g.max_reel_rate / per_m;
    }
    let v = speed * arc.length.signum();
    let twist = Twist::new(v, v * arc.curvature);
    let reel = g.tether.reel_rate(paid_out, from, &arc, speed);
    m.arcs += 1;
    m.step = Some(Motion::Arc {
        twist,
        reel,
        left: arc.length.abs(),
        last: m.odo,
    });
    m.drive(DriveCommand::Twist(twist), reel, phase).with_event("step")
}
