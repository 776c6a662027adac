//! A tether from the dock to the robot, with slack, pay-out and reeling.
//!
//! Paying out (or driving away with the reel passive) lengthens the tether. Reeling in
//! shortens it; once taut it pulls. Where it pulls depends on the robot:
//!
//! * **Rear** (RAPOSA, no arm): the tether leaves the body's rear. With the wheels in free
//!   rotation the pull drags the rear toward the anchor and swings the body in line.
//! * **Leading arm** (Axel, seed 000): the tether leaves the tip of an arm `arm` ahead of
//!   the axle, and is anchored inside the dock. With the wheels free the rover is a
//!   towed caster: its two wheels roll along its heading (and turn it freely about the
//!   axle, rolling opposite ways) but do not slide sideways, so the tip goes straight
//!   toward the anchor along the tether while the axle follows it. The rover's heading
//!   thus turns toward the tether's line, by the pull's sideways share at the tip over the
//!   arm's length: a heading error up to 90° aligns as it is reeled in (seed 000 §V-C),
//!   but the tether's line, not the dock's axis, is what it aligns with. Past about 90°
//!   the tether from the tip runs back across the rover's own wheels and fouls there
//!   ([`Tether::fouled`]). The reel stalls at [`STALL_CURRENT_A`]; the sensor reports the
//!   reel motor's current, not tension (the paper had no tension sensor, §IV-A).

use crate::geometry::{Pose2, wrap_angle};
use crate::schemas::{TetherCommand, TetherReading};
use serde::{Deserialize, Serialize};

/// Tether stiffness, N per metre stretched (our estimate).
const STIFFNESS_N_PER_M: f64 = 500.0;

/// Reel motor current while turning with no load, A (our estimate).
pub const REEL_IDLE_A: f64 = 0.4;

/// Reel motor current per newton of tether tension, A/N (our estimate): about 1 A at
/// 10 N, in the 0.5–1.0 A the paper saw in vision-guided docks and the 1.5–2.0 A when
/// pure reeling pushed the arm against the cone (seed 000 §V-C).
pub const AMPS_PER_NEWTON: f64 = 0.06;

/// The reel motor stalls at this current, A (our estimate): a leading-arm tether cannot be
/// stretched further, so a caught arm holds the pull at the stall.
pub const STALL_CURRENT_A: f64 = 2.0;

/// Tether state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tether {
    /// Anchor in the world, m.
    pub anchor: (f64, f64),
    /// Length paid out, m.
    pub length: f64,
    /// Total length on the reel, m.
    pub max_length: f64,
    /// Largest reel rate, m/s.
    pub max_rate: f64,
    /// Attachment point behind the robot's centre, m (rear tethers).
    pub attach_back: f64,
    /// The leading arm, from the axle to its tip where the tether leaves, m; 0 for a
    /// rear tether.
    pub arm: f64,
    tension: f64,
    /// The reel turned in the last step (its motor draws idle current).
    reeling: bool,
}

impl Tether {
    /// A tether anchored at `anchor`, currently `length` paid out.
    pub fn new(anchor: (f64, f64), length: f64, max_length: f64, max_rate: f64, attach_back: f64) -> Self {
        Self {
            anchor,
            length,
            max_length,
            max_rate,
            attach_back,
            arm: 0.0,
            tension: 0.0,
            reeling: false,
        }
    }

    /// A tether anchored at `anchor` that leaves the tip of a leading arm `arm` ahead of
    /// the robot's centre (Axel), currently `length` paid out.
    pub fn with_arm(anchor: (f64, f64), length: f64, max_length: f64, max_rate: f64, arm: f64) -> Self {
        Self {
            arm,
            ..Self::new(anchor, length, max_length, max_rate, 0.0)
        }
    }

    /// The tether leaves a leading arm's tip.
    pub fn arm_leads(&self) -> bool {
        self.arm > 0.0
    }

    /// Where the tether leaves the robot, in the world.
    pub fn attach(&self, pose: &Pose2) -> (f64, f64) {
        if self.arm_leads() {
            pose.to_world(self.arm, 0.0)
        } else {
            pose.to_world(-self.attach_back, 0.0)
        }
    }

    /// Distance from the anchor to the attachment point.
    pub fn distance(&self, pose: &Pose2) -> f64 {
        let a = self.attach(pose);
        (a.0 - self.anchor.0).hypot(a.1 - self.anchor.1)
    }

    /// Sensor reading: length paid out and the reel motor's current (tension itself is
    /// not sensed).
    pub fn reading(&self) -> TetherReading {
        let idle = if self.reeling { REEL_IDLE_A } else { 0.0 };
        TetherReading {
            length: self.length,
            motor_current_a: (idle + AMPS_PER_NEWTON * self.tension).min(STALL_CURRENT_A.max(idle)),
        }
    }

    /// The tether's true tension, N (the simulator's and tests' business; no sensor
    /// reports it).
    pub fn tension(&self) -> f64 {
        self.tension
    }

    /// Tether paid out beyond the straight line from its attachment to the anchor with
    /// the robot at `pose`, m: what lies slack on the ground (0 when taut).
    pub fn slack(&self, pose: &Pose2) -> f64 {
        (self.length - self.distance(pose)).max(0.0)
    }

    /// True when a leading arm's taut tether, on its way from the tip to the anchor, runs
    /// across the rover's body (`length × width` about its centre: the wheels): it is
    /// caught by the grousers of the free wheels and wound up, the entanglement the
    /// leading arm exists to avoid (seed 000 §IV-A).
    pub fn fouled(&self, pose: &Pose2, length: f64, width: f64) -> bool {
        if !self.arm_leads() || self.tension <= 0.0 {
            return false;
        }
        let (ax, ay) = pose.to_local(self.anchor.0, self.anchor.1);
        segment_hits_box((self.arm, 0.0), (ax, ay), length / 2.0, width / 2.0)
    }

    /// Advances `dt` with reel command `cmd`; returns the robot's pose after the tether's
    /// pull (unchanged unless taut with the wheels free).
    pub fn step(&mut self, dt: f64, pose: &Pose2, cmd: Option<TetherCommand>) -> Pose2 {
        let rate = cmd.map_or(0.0, |c| c.reel_rate.clamp(-self.max_rate, self.max_rate));
        let free = cmd.is_some_and(|c| c.free_wheel);
        if self.arm_leads() {
            return self.step_arm(dt, pose, rate, free);
        }
        let dist = self.distance(pose);
        self.reel(dt, rate, dist);
        let stretch = dist - self.length;
        self.tension = (stretch * STIFFNESS_N_PER_M).max(0.0);
        if stretch <= 0.0 || !free {
            return *pose;
        }
        // Pulled: the attachment point moves toward the anchor by the stretch, and the body
        // swings so the rear points along the tether.
        let a = self.attach(pose);
        let (dx, dy) = (self.anchor.0 - a.0, self.anchor.1 - a.1);
        let d = dx.hypot(dy).max(1e-9);
        let (mx, my) = (dx / d * stretch, dy / d * stretch);
        let want = (-dy).atan2(-dx); // heading with the rear toward the anchor
        let err = wrap_angle(want - pose.theta);
        let turn = err * (stretch / (stretch + 0.05)).min(1.0) * 0.5;
        let moved = Pose2::new(pose.x + mx, pose.y + my, pose.theta + turn);
        // Keep the attachment point where the pull put it.
        let a2 = moved.to_world(-self.attach_back, 0.0);
        let want_attach = (a.0 + mx, a.1 + my);
        Pose2::new(
            moved.x + want_attach.0 - a2.0,
            moved.y + want_attach.1 - a2.1,
            moved.theta,
        )
    }
}

impl Tether {
    /// The reel's part of a step, whichever end the tether pulls: reeling in at `rate`
    /// (m/s, positive in) shortens the tether; paying out lengthens it up to its length,
    /// and a robot `dist` from the anchor that has moved beyond the tether draws it out
    /// passively.
    fn reel(&mut self, dt: f64, rate: f64, dist: f64) {
        self.reeling = rate != 0.0;
        if rate > 0.0 {
            self.length = (self.length - rate * dt).max(0.0);
        } else {
            self.length = (self.length - rate * dt).min(self.max_length);
            if dist > self.length {
                self.length = dist.min(self.max_length); // passive pay-out
            }
        }
    }

    /// A leading arm's step: the reel shortens (or passively pays out) the tether, up to
    /// its stall; a taut tether with the wheels free drags the tip toward the anchor by
    /// the stretch, the rover following as a towed caster.
    fn step_arm(&mut self, dt: f64, pose: &Pose2, rate: f64, free: bool) -> Pose2 {
        let dist = self.distance(pose);
        self.reel(dt, rate, dist);
        let stall = (STALL_CURRENT_A - REEL_IDLE_A) / AMPS_PER_NEWTON / STIFFNESS_N_PER_M;
        if dist - self.length > stall {
            self.length = dist - stall; // the stalled reel slips back
        }
        let stretch = dist - self.length;
        self.tension = (stretch * STIFFNESS_N_PER_M).max(0.0);
        if stretch <= 0.0 || !free {
            return *pose;
        }
        // Drag in steps of at most 5 mm, so the caster's turn follows the tip.
        let n = (stretch / 0.005).ceil().max(1.0);
        let step = stretch / n;
        let mut p = *pose;
        for _ in 0..n as usize {
            let tip = p.to_world(self.arm, 0.0);
            let (dx, dy) = (self.anchor.0 - tip.0, self.anchor.1 - tip.1);
            let d = dx.hypot(dy);
            if d < 1e-9 {
                break;
            }
            let (mx, my) = (dx / d * step.min(d), dy / d * step.min(d));
            p = caster_drag(&p, self.arm, mx, my);
        }
        p
    }
}

/// A rover with a leading arm `arm`, towed at the arm's tip by `(mx, my)` (world, small):
/// its wheels roll the axle along its heading by the pull's share along the arm, and it
/// turns about the axle by the share across the arm over the arm's length. The wheels
/// do not slide sideways.
pub fn caster_drag(pose: &Pose2, arm: f64, mx: f64, my: f64) -> Pose2 {
    let (s, c) = pose.theta.sin_cos();
    let along = mx * c + my * s;
    let across = -mx * s + my * c;
    Pose2::new(pose.x + along * c, pose.y + along * s, pose.theta + across / arm)
}

/// True when the segment from `a` to `b` meets the box |x| ≤ `hx`, |y| ≤ `hy`
/// (Liang–Barsky clipping).
fn segment_hits_box(a: (f64, f64), b: (f64, f64), hx: f64, hy: f64) -> bool {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for (p, q) in [(-dx, a.0 + hx), (dx, hx - a.0), (-dy, a.1 + hy), (dy, hy - a.1)] {
        if p.abs() < 1e-12 {
            if q < 0.0 {
                return false;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
            if t0 > t1 {
                return false;
            }
        }
    }
    true
}

/// The tether's extremes over one mission, from the simulator's truth (a run's record:
/// `runs.jsonl`'s `tether`). The behavior never sees them: it reads the reel's length
/// and current alone.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct TetherTally {
    /// Largest slack, m ([`Tether::slack`]): whether the reel kept the tether off the
    /// ground.
    pub max_slack_m: f64,
    /// When the slack was largest, s from the mission's start (0 with none): where to
    /// look in a replay.
    pub max_slack_at_s: f64,
    /// Highest tension, N.
    pub peak_tension_n: f64,
    /// Highest reel motor current the sensor read, A (the stall guard's input).
    pub peak_current_a: f64,
}

impl TetherTally {
    /// Takes in the tether's state with the robot at `pose`, `t` s into the mission.
    pub fn observe(&mut self, tether: &Tether, pose: &Pose2, t: f64) {
        let slack = tether.slack(pose);
        if slack > self.max_slack_m {
            self.max_slack_m = slack;
            self.max_slack_at_s = t;
        }
        self.peak_tension_n = self.peak_tension_n.max(tether.tension());
        self.peak_current_a = self.peak_current_a.max(tether.reading().motor_current_a);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reeling_aligns_a_nearly_aligned_rover() {
        // Rover 1 m out on the axis, heading 15° off, rear toward the anchor.
        let mut t = Tether::new((0.0, 0.0), 0.8, 10.0, 0.05, 0.2);
        let mut p = Pose2::new(1.0, 0.05, 15f64.to_radians());
        let reel = Some(TetherCommand {
            reel_rate: 0.05,
            free_wheel: true,
        });
        for _ in 0..300 {
            p = t.step(0.05, &p, reel);
        }
        assert!(t.distance(&p) < 0.1 + 1e-6, "pulled in: {}", t.distance(&p));
        let bearing = p.y.atan2(p.x);
        assert!(
            wrap_angle(p.theta - bearing).abs() < 3f64.to_radians(),
            "aligned with the tether: {p:?}"
        );
        assert!(t.tension() > 0.0 && t.reading().motor_current_a > REEL_IDLE_A);
    }

    #[test]
    fn slack_and_locked_wheels_do_not_pull() {
        let mut t = Tether::new((0.0, 0.0), 3.0, 10.0, 0.05, 0.2);
        let p = Pose2::new(1.0, 0.0, 0.0);
        assert_eq!(
            t.step(
                0.1,
                &p,
                Some(TetherCommand {
                    reel_rate: 0.05,
                    free_wheel: true
                })
            ),
            p
        );
        let mut t = Tether::new((0.0, 0.0), 0.5, 10.0, 0.05, 0.2);
        assert_eq!(
            t.step(
                0.1,
                &p,
                Some(TetherCommand {
                    reel_rate: 0.05,
                    free_wheel: false
                })
            ),
            p
        );
        assert!(t.tension() > 0.0);
        // Driving away pays out passively.
        let mut t = Tether::new((0.0, 0.0), 0.5, 10.0, 0.05, 0.2);
        t.step(0.1, &Pose2::new(2.0, 0.0, 0.0), None);
        assert!((t.length - 1.8).abs() < 1e-9);
    }

    fn reel() -> Option<TetherCommand> {
        Some(TetherCommand {
            reel_rate: 0.05,
            free_wheel: true,
        })
    }

    #[test]
    fn a_leading_arm_turns_the_rover_onto_the_tether_line() {
        // 3 m out on the axis, facing the anchor but 60° off, arm 0.5 m.
        let mut t = Tether::with_arm((-0.25, 0.0), 0.0, 50.0, 0.05, 0.5);
        let mut p = Pose2::new(3.0, 0.0, std::f64::consts::PI + 60f64.to_radians());
        t.length = t.distance(&p);
        for _ in 0..(2.5 / 0.05 / 0.02) as usize {
            p = t.step(0.02, &p, reel());
            assert!(!t.fouled(&p, 0.7, 1.1), "{p:?}");
        }
        // Reeled 2.5 m: the tip went straight along its line to the anchor; the heading came round to
        // that line (8.2° off the axis, where the tip started), not to the axis.
        let (start, tip) = (
            (3.0 + 0.5 * 240f64.to_radians().cos(), 0.5 * 240f64.to_radians().sin()),
            t.attach(&p),
        );
        let line = (start.1 - t.anchor.1).atan2(start.0 - t.anchor.0);
        let now = (tip.1 - t.anchor.1).atan2(tip.0 - t.anchor.0);
        assert!(wrap_angle(now - line).abs() < 1e-3, "{tip:?}");
        assert!(
            wrap_angle(p.theta - (line + std::f64::consts::PI)).abs() < 1f64.to_radians(),
            "{p:?}"
        );
        assert!(t.reading().motor_current_a >= REEL_IDLE_A);
    }

    #[test]
    fn a_tether_pulled_back_over_the_rover_fouls_its_wheels() {
        // Facing away from the anchor (h = 150°): the tether from the tip runs back over
        // the wheels.
        let mut t = Tether::with_arm((-0.25, 0.0), 0.0, 50.0, 0.05, 0.5);
        let p = Pose2::new(3.0, 0.0, 150f64.to_radians() + std::f64::consts::PI);
        t.length = t.distance(&p) - 0.01;
        t.step(0.02, &p, reel());
        assert!(t.fouled(&p, 0.7, 1.1));
        // At 60° it clears them.
        let p = Pose2::new(3.0, 0.0, 60f64.to_radians() + std::f64::consts::PI);
        t.length = t.distance(&p) - 0.01;
        t.step(0.02, &p, reel());
        assert!(!t.fouled(&p, 0.7, 1.1));
    }

    #[test]
    fn a_caught_arm_stalls_the_reel() {
        let mut t = Tether::with_arm((-0.25, 0.0), 0.0, 50.0, 0.05, 0.5);
        let p = Pose2::new(1.0, 0.0, std::f64::consts::PI);
        t.length = t.distance(&p);
        // Wheels locked: nothing moves, the reel winds up to its stall and holds there.
        for _ in 0..500 {
            t.step(
                0.02,
                &p,
                Some(TetherCommand {
                    reel_rate: 0.05,
                    free_wheel: false,
                }),
            );
        }
        let i = t.reading().motor_current_a;
        assert!((i - STALL_CURRENT_A).abs() < 1e-6, "{i}");
    }

    #[test]
    fn the_tally_keeps_the_largest_slack_tension_and_current() {
        let mut t = Tether::with_arm((-0.25, 0.0), 0.0, 50.0, 0.05, 0.5);
        let far = Pose2::new(2.0, 0.0, std::f64::consts::PI);
        t.length = t.distance(&far);
        let mut tally = TetherTally::default();
        tally.observe(&t, &far, 0.0);
        assert_eq!(tally, TetherTally::default(), "taut and idle: nothing to tally");
        // Driven 0.3 m in without reeling: 0.3 m lies slack.
        let near = Pose2::new(1.7, 0.0, std::f64::consts::PI);
        t.step(0.02, &near, None);
        tally.observe(&t, &near, 1.0);
        assert!((tally.max_slack_m - 0.3).abs() < 1e-9, "{tally:?}");
        // Wheels locked, reeling: the slack is taken up, then the reel pulls to its stall.
        for _ in 0..1000 {
            t.step(
                0.02,
                &near,
                Some(TetherCommand {
                    reel_rate: 0.05,
                    free_wheel: false,
                }),
            );
            tally.observe(&t, &near, 2.0);
        }
        assert!(
            (tally.max_slack_m - 0.3).abs() < 1e-9,
            "the largest slack is kept: {tally:?}"
        );
        assert!((tally.peak_current_a - STALL_CURRENT_A).abs() < 1e-6, "{tally:?}");
        assert!(tally.peak_tension_n > 0.0);
        assert_eq!(t.slack(&near), 0.0);
    }
}
