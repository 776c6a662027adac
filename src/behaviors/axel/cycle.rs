//! The sense-plan-act cycle Axel's sensing schemas share (seed 000 §II, §V-B: "stop,
//! take images, plan, take one step"): settle stopped, look until a trusted pose arrives
//! (or give up looking), let the schema decide, then execute ONE motion by odometry (an
//! arc, reeling to the tether's exposed length at its end, or a turn in place) and start
//! over. Standing or turning in place, the reel takes up slack until its current says the
//! tether is taut ([`Memory::take_up`]). A rover that kept moving while it looked would
//! plan on frames blurred by its own motion and a pose already out of date by the time
//! it plans; the paper stopped, and so do we.

use super::memory::{Memory, Sighting, Trust};
use crate::geometry::{Pose2, Twist, wrap_angle};
use crate::kinematics::two_arc::{Arc, Polar};
use crate::schemas::{DriveCommand, Outcome, Step};
use serde::Deserialize;

/// Timing of the cycle (node params).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CycleParams {
    /// Standing still before looking, s (the base's lag and the tether's swing settle).
    pub settle_s: f64,
    /// Longest look for a trusted pose, s.
    pub look_s: f64,
}

impl Default for CycleParams {
    fn default() -> Self {
        Self {
            settle_s: 0.6,
            look_s: 1.2,
        }
    }
}

/// What a schema decides once it looked.
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
    /// End this state with the event.
    Event(&'static str),
    /// End the docking with this outcome.
    Done(Outcome),
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum State {
    Settle {
        since: f64,
    },
    Look {
        since: f64,
    },
    Arc {
        twist: Twist,
        reel: f64,
        left: f64,
        last: Pose2,
    },
    Turn {
        omega: f64,
        left: f64,
        last: f64,
    },
    Reel {
        until: f64,
        deadline: f64,
    },
}

/// The cycle's state (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cycle {
    state: State,
    params: CycleParams,
    trust: Trust,
    /// Looks in a row without a trusted pose ([`Cycle::tick_seeing`]).
    unseen: u32,
}

impl Cycle {
    /// A cycle with `params`, trusting sightings by `trust`.
    pub fn new(params: CycleParams, trust: Trust) -> Self {
        Self {
            state: State::Settle { since: 0.0 },
            params,
            trust,
            unseen: 0,
        }
    }

    /// Begins a state at `now`: settle, then look, with no looks counted yet.
    pub fn begin(&mut self, now: f64) {
        self.unseen = 0;
        self.restart(now);
    }

    /// Starts over at `now`: settle, then look.
    pub fn restart(&mut self, now: f64) {
        self.state = State::Settle { since: now };
    }

    /// One tick: settle, look, ask `decide` (with the trusted sighting, or `None` when the
    /// look found none), then drive what it decided. Feedback names `phase`.
    pub fn tick(
        &mut self,
        m: &mut Memory,
        phase: &'static str,
        decide: impl FnOnce(&mut Memory, Option<Sighting>) -> Decision,
    ) -> Step {
        let now = m.now;
        match self.state {
            State::Settle { since } => {
                if now - since >= self.params.settle_s {
                    self.state = State::Look { since: now };
                    m.sighting = None;
                    m.looking = true;
                }
                m.hold(phase)
            }
            State::Look { since } => {
                let trusted = m.sighting.filter(|s| s.t >= since && self.trust.accepts(s));
                if trusted.is_none() && now - since < self.params.look_s {
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
                    t = now,
                    pose = ?untrusted.map(|s| (s.pose.x, s.pose.y, s.pose.theta.to_degrees())),
                    source = ?untrusted.map(|s| s.source),
                    marks = untrusted.map_or(0, |s| s.marks),
                    reprojection_px = untrusted.map_or(f64::NAN, |s| s.reprojection_px),
                    trusted = trusted.is_some(),
                    ?decision,
                    "axel looked"
                );
                match decision {
                    Decision::Arc { arc, from } => self.begin_arc(m, arc, &from, phase),
                    Decision::Turn(angle) => {
                        let omega = 0.5 * m.geometry.max_turn_rate * angle.signum();
                        self.state = State::Turn {
                            omega,
                            left: angle.abs(),
                            last: m.odo.theta,
                        };
                        m.drive(DriveCommand::Turn { omega }, m.take_up(), phase)
                    }
                    Decision::Reel(length) => self.begin_reel(m, length, phase),
                    Decision::Event(e) => {
                        self.restart(now);
                        m.hold(phase).with_event(e)
                    }
                    Decision::Done(o) => m.hold(phase).finishing(o),
                }
            }
            State::Arc {
                twist,
                reel,
                left,
                last,
            } => {
                let left = left - m.odo.distance(&last);
                if left <= 0.0 {
                    self.restart(now);
                    return m.hold(phase);
                }
                self.state = State::Arc {
                    twist,
                    reel,
                    left,
                    last: m.odo,
                };
                m.drive(DriveCommand::Twist(twist), reel, phase)
            }
            State::Turn { omega, left, last } => {
                let left = left - wrap_angle(m.odo.theta - last).abs();
                if left <= 0.0 {
                    self.restart(now);
                    return m.hold(phase);
                }
                self.state = State::Turn {
                    omega,
                    left,
                    last: m.odo.theta,
                };
                m.drive(DriveCommand::Turn { omega }, m.take_up(), phase)
            }
            State::Reel { until, deadline } => {
                if now >= deadline || m.reel.is_none_or(|r| r.length <= until) {
                    self.restart(now);
                    return m.hold(phase);
                }
                m.free_reel(phase)
            }
        }
    }

    /// Starts reeling in `length` m with the wheels free. The reel's length reading ends
    /// it; so does twice the time the reel needs at its top rate, plus 2 s (a reel
    /// pulling against a caught arm is the `axel.stall` leaf's to judge, by its current).
    /// Without a reel reading there is nothing to measure by: hold and look again.
    fn begin_reel(&mut self, m: &mut Memory, length: f64, phase: &'static str) -> Step {
        let Some(r) = m.reel.filter(|_| length > 0.0) else {
            self.restart(m.now);
            return m.hold(phase);
        };
        self.state = State::Reel {
            until: r.length - length,
            deadline: m.now + 2.0 * length / m.geometry.max_reel_rate.max(1e-6) + 2.0,
        };
        m.free_reel(phase)
    }

    /// [`Cycle::tick`] for a schema that plans only on a trusted pose: `decide` gets the
    /// sighting; a look without one turns to recentre the module (toward the look's
    /// untrusted pose, else the dead-reckoned last fix) when it lies more than 5° off,
    /// and looks again; `lost_looks` of them in a row end the state with event `lost`.
    /// When the module is centred but the look's pose is untrusted, `untrusted` may
    /// decide from that pose instead (`None`: look again): recentring cannot help a
    /// view that one camera lost because the module is too near.
    pub fn tick_seeing(
        &mut self,
        m: &mut Memory,
        phase: &'static str,
        lost_looks: u32,
        decide: impl FnOnce(&mut Memory, Sighting) -> Decision,
        untrusted: impl FnOnce(&mut Memory, Sighting) -> Option<Decision>,
    ) -> Step {
        let mut unseen = self.unseen;
        let step = self.tick(m, phase, |m, seen| match seen {
            Some(s) => {
                unseen = 0;
                decide(m, s)
            }
            None => {
                unseen += 1;
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
                    unseen = 0;
                    return d;
                }
                if unseen >= lost_looks {
                    Decision::Event("lost")
                } else {
                    Decision::Turn(if off_centre { bearing } else { 0.0 })
                }
            }
        });
        self.unseen = unseen;
        step
    }

    /// Starts driving `arc` from module-frame `from`: at the arc speed, slower where the
    /// turn-rate limit needs it or where the reel could not keep up, reeling at the rate
    /// that brings the reel's paid-out length to the exposed length at the arc's end
    /// ([`crate::kinematics::tether_length::TetherGeometry::pay_out_along`]).
    fn begin_arc(&mut self, m: &mut Memory, arc: Arc, from: &Pose2, phase: &'static str) -> Step {
        let g = &m.geometry;
        let mut speed = if arc.curvature.abs() > 1e-9 {
            g.arc_speed.min(0.9 * g.max_turn_rate / arc.curvature.abs())
        } else {
            g.arc_speed
        };
        // The reel pays out |ΔL| over |s| (the change along the arc, and the slack its
        // reading shows now): at `speed` it must turn at speed·|ΔL|/|s|, no faster than
        // it can.
        let paid_out = m.reel.map(|r| r.length);
        let per_m = g.tether.pay_out_along(paid_out, from, &arc).abs() / arc.length.abs().max(1e-9);
        if per_m * speed > g.max_reel_rate {
            speed = g.max_reel_rate / per_m;
        }
        let v = speed * arc.length.signum();
        let twist = Twist::new(v, v * arc.curvature);
        let reel = g.tether.reel_rate(paid_out, from, &arc, speed);
        m.arcs += 1;
        self.state = State::Arc {
            twist,
            reel,
            left: arc.length.abs(),
            last: m.odo,
        };
        m.drive(DriveCommand::Twist(twist), reel, phase)
    }
}
