//! A tether from the dock to the robot's rear, with slack, pay-out and reeling.
//!
//! Paying out (or driving away with the reel passive) lengthens the tether. Reeling in
//! shortens it; once taut it pulls. With the wheels in free rotation the pull drags the
//! rover's rear toward the anchor and swings its body in line with the tether, as a
//! caster arm leading into a cone would (seed 000 §IV): so reeling aligns a nearly aligned
//! rover, and cannot rescue a badly misaligned one (the pull point must lead).

use crate::geometry::{Pose2, wrap_angle};
use crate::schemas::{TetherCommand, TetherReading};

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
    /// Attachment point behind the robot's centre, m.
    pub attach_back: f64,
    tension: f64,
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
            tension: 0.0,
        }
    }

    fn attach(&self, pose: &Pose2) -> (f64, f64) {
        pose.to_world(-self.attach_back, 0.0)
    }

    /// Distance from the anchor to the attachment point.
    pub fn distance(&self, pose: &Pose2) -> f64 {
        let a = self.attach(pose);
        (a.0 - self.anchor.0).hypot(a.1 - self.anchor.1)
    }

    /// Sensor reading.
    pub fn reading(&self) -> TetherReading {
        TetherReading {
            length: self.length,
            tension: self.tension,
        }
    }

    /// Advances `dt` with reel command `cmd`; returns the robot's pose after the tether's
    /// pull (unchanged unless taut with the wheels free).
    pub fn step(&mut self, dt: f64, pose: &Pose2, cmd: Option<TetherCommand>) -> Pose2 {
        let rate = cmd.map_or(0.0, |c| c.reel_rate.clamp(-self.max_rate, self.max_rate));
        let free = cmd.is_some_and(|c| c.free_wheel);
        let dist = self.distance(pose);
        if rate > 0.0 {
            self.length = (self.length - rate * dt).max(0.0);
        } else {
            self.length = (self.length - rate * dt).min(self.max_length);
            if dist > self.length {
                self.length = dist.min(self.max_length); // passive pay-out
            }
        }
        let stretch = dist - self.length;
        self.tension = (stretch * 500.0).max(0.0);
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
        assert!(t.reading().tension > 0.0);
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
        assert!(t.reading().tension > 0.0);
        // Driving away pays out passively.
        let mut t = Tether::new((0.0, 0.0), 0.5, 10.0, 0.05, 0.2);
        t.step(0.1, &Pose2::new(2.0, 0.0, 0.0), None);
        assert!((t.length - 1.8).abs() < 1e-9);
    }
}
