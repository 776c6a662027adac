//! `raposa.probe` (ours, not in the paper): inside the dead zone the robot sees the ball
//! and no pair, so nothing tells it which side of the pyramid's axis it is on; the paper's
//! points 1 and 3 (0.33 m, ±70°) drove in and never docked. The probe moves the robot
//! around the ball, keeping its distance, and looks again: once the pair is in view the
//! servo's own states (region II) align it. The selector probes only while no pair has
//! been seen this docking ([`super::states::probe_due`]): a lone ball after a pair is a
//! pair lost to the light, and the robot already knows its side.
//!
//! The move is a rotation of the robot's position about the ball, so it needs no α: it is
//! planned in a ball frame that puts the robot on the +x axis (where it would be if α
//! were 0) and run by the region-II manoeuvre's leaves (`region_2`: rotate, travel,
//! rotate to face the ball, then `look`). Probe k (from 0) turns (−1)ᵏ·(k+1) steps around
//! the ball at the dead zone's exit distance (`dead_zone_exit_m` from the socket), so
//! successive probes look from +1, −1, +2, −2 steps of the start; a pair seen resets the
//! count. Ends at once with event `planned`, like `align`.

use super::memory::Memory;
use super::params::ProbeParams;
use super::region2::{plan_to, robot_in_ball_frame};
use crate::schemas::{Behavior, Inputs, Step};

/// See the module docs.
pub struct Probe {
    params: ProbeParams,
}

impl Probe {
    /// The leaf with `params`.
    pub fn new(params: ProbeParams) -> Self {
        Self { params }
    }
}

/// The angle around the ball of probe `k` (from 0), rad, for a step of `step` rad.
pub fn probe_angle(k: u32, step: f64) -> f64 {
    let sign = if k.is_multiple_of(2) { 1.0 } else { -1.0 };
    sign * f64::from(k + 1) * step
}

impl Behavior<Memory> for Probe {
    fn enter(&mut self, _mem: &mut Memory, _inputs: &Inputs<'_>) {}

    fn tick(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) -> Option<Step> {
        let Some(view) = m.percept.view else {
            return Some(m.hold("probe"));
        };
        let start = robot_in_ball_frame(&view, 0.0, m.camera_x);
        let radius = m.gains.dead_zone_exit_m + m.half_length;
        let angle = probe_angle(m.probes, self.params.step_deg.to_radians());
        let target = (radius * angle.cos(), radius * angle.sin());
        // Facing the ball from the target: the body's heading points away from it.
        let pl = plan_to(start, target, angle);
        tracing::debug!(
            target: "marsupial::behavior",
            now = m.now,
            probe = m.probes,
            around_deg = angle.to_degrees(),
            d_m = pl.distance,
            "probe: around the ball, side unknown"
        );
        m.probes += 1;
        Some(m.start_manoeuvre(pl))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn probes_alternate_and_grow() {
        let s = 35f64.to_radians();
        let ends: Vec<f64> = (0..4)
            .scan(0.0, |at, k| {
                *at += probe_angle(k, s);
                Some((*at / s).round())
            })
            .collect();
        assert_eq!(ends, [1.0, -1.0, 2.0, -2.0]);
    }
}
