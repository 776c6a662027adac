//! Search rotation and dead-reckoning back-in: the two open-loop motor schemas of docking.

use super::motor_output::DriveCommand;

/// Rotate in place to (re)acquire the target. With `doubling`, the sweep alternates sides
/// and doubles after each switch (RAPOSA, seed 001 §II.E); otherwise it keeps turning one
/// way (Bujold, seed 004 §V: "rotate until it is acquired").
///
/// # Example
///
/// A doubling search at 0.5 rad/s from a 0.5 rad sweep: 1 s counter-clockwise, then 2 s
/// clockwise, then 4 s counter-clockwise…
///
/// ```
/// use marsupial::schemas::{DriveCommand, SearchRotation};
///
/// let s = SearchRotation { rate: 0.5, first_sweep: 0.5, doubling: true };
/// assert_eq!(s.command(0.5), DriveCommand::Turn { omega: 0.5 });
/// assert_eq!(s.command(1.5), DriveCommand::Turn { omega: -0.5 });
/// assert_eq!(s.command(3.1), DriveCommand::Turn { omega: 0.5 });
/// // Without doubling it keeps turning one way.
/// let plain = SearchRotation { doubling: false, ..s };
/// assert_eq!(plain.command(100.0), DriveCommand::Turn { omega: 0.5 });
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SearchRotation {
    /// Turn rate, rad/s (sign: first direction).
    pub rate: f64,
    /// First sweep, rad (for doubling search).
    pub first_sweep: f64,
    /// Alternate and double.
    pub doubling: bool,
}

impl SearchRotation {
    /// Command after `elapsed` seconds of searching (what [`MotorSchema::act`] proposes
    /// for [`Elapsed`]`(elapsed)`; a leaf that adds its own auxiliary commands reads it
    /// here).
    ///
    /// [`MotorSchema::act`]: super::MotorSchema::act
    /// [`Elapsed`]: super::Elapsed
    pub fn command(&self, elapsed: f64) -> DriveCommand {
        if !self.doubling || self.first_sweep <= 0.0 {
            return DriveCommand::Turn { omega: self.rate };
        }
        // Sweep k (k = 0, 1, 2 …) turns through first·2^k, alternating direction; the turn
        // back to the start is included in the doubled sweep. A sweep never reaches a
        // full turn (seed 001 §II.E: "a certain angle lower than 360°"): it is capped at
        // 350°.
        let rate = self.rate.abs().max(1e-6);
        let mut t = elapsed.max(0.0);
        let mut k = 0;
        loop {
            let sweep = (self.first_sweep * 2f64.powi(k)).min(MAX_SWEEP_DEG.to_radians());
            let dur = sweep / rate;
            if t < dur || k > 30 {
                let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
                return DriveCommand::Turn {
                    omega: self.rate * sign,
                };
            }
            t -= dur;
            k += 1;
        }
    }
}

/// Largest sweep of the doubling search, degrees.
pub const MAX_SWEEP_DEG: f64 = 350.0;

/// Drive straight a set distance by odometry (the paper's blind back-in).
///
/// # Example
///
/// ```
/// use marsupial::schemas::{DeadReckoning, DriveCommand};
///
/// let back_in = DeadReckoning { speed: -0.03, distance: 0.5 };
/// assert_eq!(back_in.command(0.2), Some(DriveCommand::Straight { v: -0.03 }));
/// assert_eq!(back_in.command(0.5), None, "50 cm covered");
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DeadReckoning {
    /// Signed speed, m/s (negative backs up).
    pub speed: f64,
    /// Distance to cover, m.
    pub distance: f64,
}

impl DeadReckoning {
    /// Command after covering `travelled` metres; `None` once the distance is done (the
    /// trait's [`act`](super::MotorSchema::act) proposes a stop then; a leaf that must
    /// tell "done" from "stopped" reads this).
    pub fn command(&self, travelled: f64) -> Option<DriveCommand> {
        (travelled < self.distance).then_some(DriveCommand::Straight { v: self.speed })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn doubling_sweep_alternates() {
        let s = SearchRotation {
            rate: 0.5,
            first_sweep: 0.5,
            doubling: true,
        };
        // Sweep 0 lasts 1 s, sweep 1 lasts 2 s, sweep 2 lasts 4 s.
        assert_eq!(s.command(0.5), DriveCommand::Turn { omega: 0.5 });
        assert_eq!(s.command(1.5), DriveCommand::Turn { omega: -0.5 });
        assert_eq!(s.command(2.9), DriveCommand::Turn { omega: -0.5 });
        assert_eq!(s.command(3.1), DriveCommand::Turn { omega: 0.5 });
        assert_eq!(s.command(7.1), DriveCommand::Turn { omega: -0.5 });
        // Sweeps cap below a full turn: with a 200° first sweep the second lasts 350°.
        let big = SearchRotation {
            rate: 1.0,
            first_sweep: 200f64.to_radians(),
            doubling: true,
        };
        let t1 = 200f64.to_radians();
        let t2 = t1 + 350f64.to_radians();
        assert_eq!(big.command(t2 - 0.01), DriveCommand::Turn { omega: -1.0 });
        assert_eq!(big.command(t2 + 0.01), DriveCommand::Turn { omega: 1.0 });
        let plain = SearchRotation {
            rate: -0.3,
            first_sweep: 0.0,
            doubling: false,
        };
        assert_eq!(plain.command(100.0), DriveCommand::Turn { omega: -0.3 });
    }

    #[test]
    fn dead_reckoning_stops_at_distance() {
        let d = DeadReckoning {
            speed: -0.03,
            distance: 0.5,
        };
        assert_eq!(d.command(0.2), Some(DriveCommand::Straight { v: -0.03 }));
        assert_eq!(d.command(0.5), None);
    }
}
