//! `axel.acquire`: find the module. The module may start outside the cameras' view, so
//! the rover turns in place in steps, stopping to look after each (sense-plan-act), until
//! a trusted pose arrives (event `acquired`). When the module was seen before this
//! docking lost it, the rover first recovers from its last fix, dead-reckoned by
//! odometry ([`Memory::reckoned`]): it turns back to face where the module should be,
//! then backs away when nearer than `near_m` (the marks leave the view's top), or,
//! beyond the marks' detection range (`view.range_m`), drives straight toward it into
//! range; at most `recover_steps` such steps per entry. Then it sweeps toward the
//! side the module was last seen on, counter-clockwise when it was never seen. After
//! `behavior.search_timeout_s` without a trusted pose the docking fails: `target_lost`
//! if the module was seen this docking, `target_never_detected` otherwise.
//!
//! **Reeling closer** (`reel_beyond_range`, ours). With no recovery step to take, the
//! reel's length reading still bounds the range
//! ([`TetherGeometry::farthest_from_mouth`](crate::kinematics::tether_length::TetherGeometry::farthest_from_mouth)).
//! When that bound lies beyond the detection range (`view.range_m`), turning cannot
//! help: the module may be dead ahead with its marks too small to resolve (the paper's
//! marks were "designed to be discernable from 5 m", §V-B). The rover then reels in one
//! step (at most `step_m`, to 0.3 m inside the range) with its wheels free, as in the
//! paper's pure reeling (§V-C): the tether drags it toward the module and turns its
//! leading arm, and with it the cameras, to face the module. Then it looks again. The
//! paper suggests combining tether-based and vision-based docking "for significantly
//! improved docking range and heading capability" (§V-C); this is that combination, only
//! while nothing is seen and only far from the cone, where reeling cannot push the arm
//! into it. A reel step restarts the search's clock: it is progress, and the steps
//! end once the tether is within range.

use super::look::{Decision, Look};
use super::memory::{Memory, Trust, ViewLimits};
use crate::geometry::Pose2;
use crate::kinematics::two_arc::{Arc, Polar};
use crate::schemas::{Behavior, Inputs, Step};
use serde::Deserialize;

/// `axel.acquire`'s params.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AcquireParams {
    /// Each turn between looks, degrees (below the cameras' 90° view, so views overlap).
    pub turn_deg: f64,
    /// Longest look for a trusted pose, s.
    pub look_s: f64,
    /// What a pose must be to count as found.
    pub trust: Trust,
    /// Recovery steps (turn back, close in) from the last fix before sweeping.
    pub recover_steps: u32,
    /// Longest straight step toward a module beyond the detection range, or away from
    /// one too near, m.
    pub step_m: f64,
    /// Nearer than this (axle to mouth) the recovery backs away first, m: the marks
    /// leave the view's top.
    pub near_m: f64,
    /// The detection range the recovery closes into (`range_m`; the margin is unused).
    pub view: ViewLimits,
    /// With nothing seen and no recovery step to take, reel in closer while the reel's
    /// length puts the module possibly beyond `view.range_m` (module docs). Off: the
    /// paper's vision-only search, which turns in place.
    pub reel_beyond_range: bool,
}

impl Default for AcquireParams {
    fn default() -> Self {
        Self {
            turn_deg: 30.0,
            look_s: 1.2,
            trust: Trust::default(),
            recover_steps: 3,
            step_m: 1.0,
            near_m: 1.3,
            view: ViewLimits::default(),
            reel_beyond_range: false,
        }
    }
}

/// How much to reel in (wheels free) before looking again, m, when the module may lie
/// farther than `range` m from the mouth: `farthest` m by the reel's length (at most
/// `step` m, to 0.3 m inside the range). `None` when it cannot be beyond the range.
pub fn reel_closer(farthest: f64, range: f64, step: f64) -> Option<f64> {
    (farthest > range).then(|| (farthest - range + 0.3).min(step))
}

/// One recovery step from the dead-reckoned module-frame pose `at`: turn to face the
/// module when it lies more than 3° off the heading; else back straight away (at most
/// `step` m, to 0.3 m beyond `near` m) when it is nearer than `near` m, where the upper
/// marks leave the cameras' vertical view; else drive straight toward it (at most `step`
/// m) when it is beyond `range` m (to 0.3 m inside); else nothing.
pub fn recovery(at: &Pose2, near: f64, range: f64, step: f64) -> Option<Decision> {
    let polar = Polar::from_pose(at);
    let bearing = polar.bearing();
    if bearing.abs() > 3f64.to_radians() {
        return Some(Decision::Turn(bearing));
    }
    if polar.r < near {
        let length = (near - polar.r + 0.3).min(step);
        return Some(Decision::Arc {
            arc: Arc {
                curvature: 0.0,
                length: -length,
            },
            from: *at,
        });
    }
    if polar.r > range {
        let length = (polar.r - range + 0.3).min(step);
        return Some(Decision::Arc {
            arc: Arc { curvature: 0.0, length },
            from: *at,
        });
    }
    None
}

/// See the module docs: the look of the search's cycle (event `acquired` with a trusted
/// pose). Its phase's clock ([`Memory::gave_up`]) is started by the phase's first
/// `axel.settle` with `search = true`, and restarted here by each reel step.
pub struct Acquire {
    phase: &'static str,
    params: AcquireParams,
    look: Look,
}

impl Acquire {
    /// A leaf in phase `phase`.
    pub fn new(phase: &'static str, params: AcquireParams) -> Self {
        Self {
            phase,
            params,
            look: Look::new(params.look_s, params.trust),
        }
    }
}

impl Behavior<Memory> for Acquire {
    fn enter(&mut self, m: &mut Memory, inputs: &Inputs<'_>) {
        self.look.enter(m, inputs.now);
    }

    fn tick(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) -> Option<Step> {
        if let Some(end) = m.gave_up(self.phase) {
            return Some(end);
        }
        let p = self.params;
        Some(self.look.tick(m, self.phase, |m, seen| match seen {
            Some(s) => {
                m.search_sign = Polar::from_pose(&s.pose).bearing().signum();
                Decision::Event("acquired")
            }
            None => {
                let back = m.reckoned().filter(|_| m.looks.steps < p.recover_steps).and_then(|at| {
                    // Sweep on toward the side the module should lie on.
                    let b = Polar::from_pose(&at).bearing();
                    if b.abs() > 1e-3 {
                        m.search_sign = b.signum();
                    }
                    recovery(&at, p.near_m, p.view.range_m, p.step_m)
                });
                let farthest = m.reel.map(|r| m.geometry.tether.farthest_from_mouth(r.length));
                let reel = farthest
                    .filter(|_| p.reel_beyond_range)
                    .and_then(|f| reel_closer(f, p.view.range_m, p.step_m));
                match (back, reel) {
                    (Some(d), _) => {
                        m.looks.steps += 1;
                        d
                    }
                    // A reel step is progress, not search: the search's clock restarts
                    // with it (the steps are bounded: each shortens the tether until it
                    // is within range).
                    (None, Some(length)) => {
                        m.looks.began = m.now;
                        Decision::Reel(length)
                    }
                    (None, None) => Decision::Turn(p.turn_deg.to_radians() * m.search_sign),
                }
            }
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn recovery_turns_back_then_closes_into_range() {
        // 3 m out on the axis, turned 50° away: turn back by 50° toward the module.
        let turned = Pose2::new(3.0, 0.0, PI + 50f64.to_radians());
        match recovery(&turned, 1.3, 4.0, 1.0) {
            Some(Decision::Turn(a)) => assert!((a + 50f64.to_radians()).abs() < 1e-9, "{a}"),
            d => panic!("{d:?}"),
        }
        // Facing it from 5.2 m with a 4 m range: one straight step of at most 1 m in.
        let far = Pose2::new(5.2, 0.0, PI);
        match recovery(&far, 1.3, 4.0, 1.0) {
            Some(Decision::Arc { arc, from }) => {
                assert!(arc.curvature == 0.0 && (arc.length - 1.0).abs() < 1e-9, "{arc:?}");
                assert_eq!(from, far);
            }
            d => panic!("{d:?}"),
        }
        // 4.2 m: in to 0.3 m inside the range.
        match recovery(&Pose2::new(4.2, 0.0, PI), 1.3, 4.0, 1.0) {
            Some(Decision::Arc { arc, .. }) => assert!((arc.length - 0.5).abs() < 1e-9, "{arc:?}"),
            d => panic!("{d:?}"),
        }
        // Facing it 0.85 m out: back away to 0.3 m beyond 1.3 m.
        match recovery(&Pose2::new(0.85, 0.0, PI), 1.3, 4.0, 1.0) {
            Some(Decision::Arc { arc, .. }) => assert!((arc.length + 0.75).abs() < 1e-9, "{arc:?}"),
            d => panic!("{d:?}"),
        }
        // Facing it within range: nothing to recover, the sweep takes over.
        assert_eq!(recovery(&Pose2::new(3.0, 0.1, PI), 1.3, 4.0, 1.0), None);
    }

    #[test]
    fn reels_closer_only_beyond_the_range() {
        // 6 m by the reel with a 4 m range: a full 1 m step; 4.4 m: to 0.3 m inside.
        assert_eq!(reel_closer(6.0, 4.0, 1.0), Some(1.0));
        assert!((reel_closer(4.4, 4.0, 1.0).unwrap() - 0.7).abs() < 1e-12);
        // Within the range the sweep takes over.
        assert_eq!(reel_closer(4.0, 4.0, 1.0), None);
        assert_eq!(reel_closer(2.5, 4.0, 1.0), None);
    }
}
