//! The legs of a manoeuvre by odometry, written once for every robot: turn to a heading
//! ([`TurnTo`]), back off a distance ([`BackOff`]) and drive straight until a point is
//! abeam ([`DriveAbeam`]). A multi-step manoeuvre (Bujold's turn–drive–turn to a staging
//! pose, its unjamming, RAPOSA's region-II rotations) is a sequencer of these legs in the
//! robot's profile, each leg a state that ends with an event; no leaf keeps a stage
//! counter.
//!
//! The legs reach the robot through its memory's [`Motion`]: the tick's clock and
//! odometry pose, and the robot's own way to stand, turn and drive (its posture or
//! guides, its turn controller, its feedback). What a leg aims at (a heading, a point,
//! a distance) is a function of the memory that the robot's registration supplies, so
//! a leg reads the plan another phase left there.

use crate::geometry::{Pose2, wrap_angle};
use crate::schemas::{Behavior, FailureReason, Inputs, Outcome, Step};
use serde::Deserialize;

/// A turn leg's node params.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TurnParams {
    /// Close enough to the heading, degrees.
    pub heading_tolerance_deg: f64,
    /// Longest turn, s (then the leg ends with its event anyway).
    pub timeout_s: f64,
}

impl Default for TurnParams {
    fn default() -> Self {
        Self {
            heading_tolerance_deg: 3.0,
            timeout_s: f64::INFINITY,
        }
    }
}

/// A face leg's node params ([`face`]).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FaceParams {
    /// Close enough to the heading, degrees.
    pub heading_tolerance_deg: f64,
    /// Close enough to the point to need no turn, m.
    pub arrive_m: f64,
}

impl Default for FaceParams {
    fn default() -> Self {
        Self {
            heading_tolerance_deg: 3.0,
            arrive_m: 0.03,
        }
    }
}

/// A back-off leg's node params.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BackOffParams {
    /// How far, m.
    pub distance_m: f64,
    /// Speed, m/s.
    pub speed_mps: f64,
    /// Longest time, s (a blocked robot still ends the leg); unset, the leg's own
    /// default (none, or twice the time the distance needs).
    pub timeout_s: Option<f64>,
}

impl Default for BackOffParams {
    fn default() -> Self {
        Self {
            distance_m: 0.35,
            speed_mps: 0.06,
            timeout_s: None,
        }
    }
}

/// A drive leg's node params ([`DriveAbeam`]).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DriveParams {
    /// Close enough to the point to end, m.
    pub arrive_m: f64,
    /// The drive ends when the point is this close to abeam, m.
    pub abeam_m: f64,
}

impl Default for DriveParams {
    fn default() -> Self {
        Self {
            arrive_m: 0.03,
            abeam_m: 0.02,
        }
    }
}

/// What the manoeuvre legs need of a robot's shared memory.
pub trait Motion: Send + 'static {
    /// Loop time of this tick, s.
    fn now(&self) -> f64;
    /// Odometry pose of this tick.
    fn odo(&self) -> Pose2;
    /// Stand still (with the robot's auxiliary commands), feedback naming `phase`.
    fn hold(&mut self, phase: &'static str) -> Step;
    /// Turn in place toward `heading` (odometry frame, rad); `None` once within
    /// `tolerance` rad of it (`None`: the robot's own turn controller's tolerance).
    fn turn_toward(&mut self, heading: f64, tolerance: Option<f64>, phase: &'static str) -> Option<Step>;
    /// Drive straight at `v` m/s, positive along the body's forward axis.
    fn straight(&mut self, v: f64, phase: &'static str) -> Step;
    /// Drive away from the dock at `speed` m/s, the robot's way (Bujold front first,
    /// RAPOSA keeping the ellipse centred in its backward camera).
    fn back_off(&mut self, speed: f64, phase: &'static str) -> Step;
}

/// What a turn aims at this tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Aim {
    /// This heading, odometry frame, rad.
    Heading(f64),
    /// Nothing to aim at yet: stand still.
    Hold,
    /// The leg has nothing left to do: end with this event.
    Reached(&'static str),
}

/// Robot-specific work a leg does beside its motion: plain functions, so a leg stays
/// `Send` and a registration states them at a glance.
pub struct Hooks<M> {
    /// On entry (RAPOSA: the region-II manoeuvre looks away from the pyramid on purpose).
    pub enter: fn(&mut M),
    /// Every tick, before the leg decides (Bujold: keep the frame-change cue running).
    pub each: fn(&mut M, &Inputs<'_>),
    /// When the leg ends with its event (Bujold: forget the viewing angle once aligned).
    pub end: fn(&mut M),
}

impl<M> Default for Hooks<M> {
    fn default() -> Self {
        Self {
            enter: |_| {},
            each: |_, _| {},
            end: |_| {},
        }
    }
}

/// The heading a [`TurnTo`] aims at, read from the memory each tick.
pub type AimFn<M> = Box<dyn Fn(&M) -> Aim + Send>;

/// The point a [`DriveAbeam`] drives to, read from the memory each tick (`None`: none yet).
pub type TargetFn<M> = Box<dyn Fn(&M) -> Option<Pose2> + Send>;

/// What every leg keeps: its feedback phase, time limit, hooks, and when it was
/// entered.
struct Leg<M> {
    phase: &'static str,
    timeout_s: f64,
    hooks: Hooks<M>,
    started: f64,
}

impl<M: Motion> Leg<M> {
    fn new(phase: &'static str) -> Self {
        Self {
            phase,
            timeout_s: f64::INFINITY,
            hooks: Hooks::default(),
            started: 0.0,
        }
    }

    fn enter(&mut self, m: &mut M, inputs: &Inputs<'_>) {
        (self.hooks.enter)(m);
        self.started = inputs.now;
    }

    /// The leg has run longer than its time limit.
    fn overran(&self, m: &M) -> bool {
        m.now() - self.started > self.timeout_s
    }

    /// Runs the end hook and holds with `event`.
    fn end(&self, m: &mut M, event: &'static str) -> Step {
        (self.hooks.end)(m);
        m.hold(self.phase).with_event(event)
    }
}

/// The builder methods every leg shares.
macro_rules! leg_builders {
    () => {
        /// Ends the leg with its event after `seconds` in it, done or not (a leg that
        /// cannot finish must not hold the manoeuvre forever).
        pub fn timeout(mut self, seconds: f64) -> Self {
            self.leg.timeout_s = seconds;
            self
        }

        /// With `hooks`.
        pub fn hooks(mut self, hooks: Hooks<M>) -> Self {
            self.leg.hooks = hooks;
            self
        }
    };
}

/// Turn in place to the heading `aim` gives, then end with `event`; after `timeout_s`
/// in the leg it ends with `event` too (a turn that cannot finish must not hold the
/// manoeuvre forever).
pub struct TurnTo<M> {
    leg: Leg<M>,
    aim: AimFn<M>,
    tolerance: Option<f64>,
    event: &'static str,
}

impl<M: Motion> TurnTo<M> {
    /// A leaf (feedback `phase`) turning to `aim` within `tolerance` rad (`None`: the
    /// robot's controller decides), ending with `event`.
    pub fn new(phase: &'static str, aim: AimFn<M>, tolerance: Option<f64>, event: &'static str) -> Self {
        Self {
            leg: Leg::new(phase),
            aim,
            tolerance,
            event,
        }
    }

    leg_builders!();
}

impl<M: Motion> Behavior<M> for TurnTo<M> {
    fn enter(&mut self, m: &mut M, inputs: &Inputs<'_>) {
        self.leg.enter(m, inputs);
    }

    fn tick(&mut self, m: &mut M, inputs: &Inputs<'_>) -> Option<Step> {
        let leg = &self.leg;
        (leg.hooks.each)(m, inputs);
        Some(match (self.aim)(m) {
            Aim::Hold => m.hold(leg.phase),
            Aim::Reached(e) => leg.end(m, e),
            Aim::Heading(_) if leg.overran(m) => leg.end(m, self.event),
            Aim::Heading(h) => match m.turn_toward(h, self.tolerance, leg.phase) {
                Some(step) => step,
                None => leg.end(m, self.event),
            },
        })
    }
}

/// How far a [`BackOff`] goes.
pub enum Distance<M> {
    /// A set distance, m.
    Fixed(f64),
    /// Measured on entry from the memory (RAPOSA: out of the dead zone from the view).
    AtEntry(Box<dyn Fn(&M) -> f64 + Send>),
}

/// How a [`BackOff`] ends.
#[derive(Debug, Clone, Copy)]
pub enum End<M> {
    /// With this event (retry, search again).
    Event(&'static str),
    /// The docking failed, for the reason the memory gives (Bujold's give-up: the
    /// reason the phase that gave up left).
    Fail(fn(&M) -> FailureReason),
}

/// Back off from the dock at `speed_mps` until `distance` is covered by odometry (the
/// straight-line distance from where the leg began) or `timeout_s` has passed, then end
/// as `end` says: Bujold's move-away, give-up and unjam drive-out, RAPOSA's retreat and
/// its way out of the dead zone.
pub struct BackOff<M> {
    leg: Leg<M>,
    distance: Distance<M>,
    speed_mps: f64,
    end: End<M>,
    mark: Pose2,
    goal: f64,
}

impl<M: Motion> BackOff<M> {
    /// A leaf (feedback `phase`) backing off `distance` at `speed_mps`, with no time
    /// limit.
    pub fn new(phase: &'static str, distance: Distance<M>, speed_mps: f64, end: End<M>) -> Self {
        Self {
            leg: Leg::new(phase),
            distance,
            speed_mps,
            end,
            mark: Pose2::default(),
            goal: 0.0,
        }
    }

    leg_builders!();
}

impl<M: Motion> Behavior<M> for BackOff<M> {
    fn enter(&mut self, m: &mut M, inputs: &Inputs<'_>) {
        self.leg.enter(m, inputs);
        self.mark = m.odo();
        self.goal = match &self.distance {
            Distance::Fixed(d) => *d,
            Distance::AtEntry(f) => f(m),
        };
    }

    fn tick(&mut self, m: &mut M, inputs: &Inputs<'_>) -> Option<Step> {
        let leg = &self.leg;
        (leg.hooks.each)(m, inputs);
        if m.odo().distance(&self.mark) < self.goal && !leg.overran(m) {
            return Some(m.back_off(self.speed_mps, leg.phase));
        }
        Some(match self.end {
            End::Event(e) => leg.end(m, e),
            End::Fail(why) => {
                (leg.hooks.end)(m);
                let reason = why(m);
                m.hold(leg.phase).finishing(Outcome::Failed(reason))
            }
        })
    }
}

/// The drive leg of a turn–drive–turn: with the heading already facing the target
/// point (either end leading), drive straight until it is abeam (the signed distance to
/// it along the heading under `abeam_m`: a point off the line of travel is never
/// reached exactly), slowing so as not to overshoot in one tick. Ends with `abeam`, or
/// with `arrived` once within `arrive_m` of the point.
pub struct DriveAbeam<M> {
    phase: &'static str,
    target: TargetFn<M>,
    speed_mps: f64,
    tick_s: f64,
    arrive_m: f64,
    abeam_m: f64,
}

impl<M: Motion> DriveAbeam<M> {
    /// A leaf (feedback `phase`) driving at up to `speed_mps` (the loop ticks every
    /// `tick_s`) toward the point `target` reads (`None`: stand still).
    pub fn new(
        phase: &'static str,
        target: TargetFn<M>,
        speed_mps: f64,
        tick_s: f64,
        arrive_m: f64,
        abeam_m: f64,
    ) -> Self {
        Self {
            phase,
            target,
            speed_mps,
            tick_s,
            arrive_m,
            abeam_m,
        }
    }
}

impl<M: Motion> Behavior<M> for DriveAbeam<M> {
    fn tick(&mut self, m: &mut M, _inputs: &Inputs<'_>) -> Option<Step> {
        let Some(target) = (self.target)(m) else {
            return Some(m.hold(self.phase));
        };
        let odo = m.odo();
        let (dx, dy) = (target.x - odo.x, target.y - odo.y);
        if dx.hypot(dy) < self.arrive_m {
            return Some(m.hold(self.phase).with_event("arrived"));
        }
        let along = dx * odo.theta.cos() + dy * odo.theta.sin();
        if along.abs() < self.abeam_m {
            return Some(m.hold(self.phase).with_event("abeam"));
        }
        let v = self.speed_mps.min(along.abs() / self.tick_s).copysign(along);
        Some(m.straight(v, self.phase))
    }
}

/// The heading that faces `target` from `odo` with whichever end of the robot turns
/// less to lead toward it; [`Aim::Reached`]`("arrived")` within `arrive_m` of it.
pub fn face(odo: &Pose2, target: &Pose2, arrive_m: f64) -> Aim {
    let (dx, dy) = (target.x - odo.x, target.y - odo.y);
    if dx.hypot(dy) < arrive_m {
        return Aim::Reached("arrived");
    }
    let bearing = dy.atan2(dx);
    let forward = wrap_angle(bearing - odo.theta).abs() <= std::f64::consts::FRAC_PI_2;
    Aim::Heading(if forward {
        bearing
    } else {
        bearing + std::f64::consts::PI
    })
}
