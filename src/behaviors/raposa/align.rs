//! `raposa.align`, state 2 (region II, seed 001 §II.C.2): a pair seen more than
//! `angle_threshold_deg` off the axis beyond the dead zone. Plans the alignment manoeuvre
//! ([`super::region2`]: rotate −β, travel d, rotate φ) from this tick's pair, stores it in
//! memory and ends with event `planned` (the `region_2` sequence runs it), already turning
//! toward −β at the vision-tracked rate. Without a pair it stands still.

use super::memory::Memory;
use super::region2::{plan, robot_in_ball_frame};
use crate::schemas::{Behavior, Inputs, Step};

/// See the module docs.
#[derive(Debug, Clone, Copy, Default)]
pub struct Align;

impl Behavior<Memory> for Align {
    fn enter(&mut self, _mem: &mut Memory, _inputs: &Inputs<'_>) {}

    fn tick(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) -> Option<Step> {
        let view = m.percept.view;
        let (Some(view), Some(alpha)) = (view, view.and_then(|v| v.alpha)) else {
            return Some(m.hold("state_2"));
        };
        let start = robot_in_ball_frame(&view, alpha, m.camera_x);
        let pl = plan(start, m.gains.region2_distance_m, m.half_length);
        tracing::debug!(
            target: "marsupial::behavior",
            now = m.now,
            alpha_deg = alpha.to_degrees(),
            beta_deg = -pl.rotation.to_degrees(),
            d_m = pl.distance,
            phi_deg = pl.final_rotation.to_degrees(),
            reverse = pl.reverse,
            "region II: rotate −β, travel d, rotate φ"
        );
        Some(m.start_manoeuvre(pl))
    }
}
