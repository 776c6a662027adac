//! The servo states that run while the selector keeps choosing them (seed 001 §II.E):
//! `raposa.approach` (state 1), `raposa.far_ellipse` (state 3) and `raposa.blue_only`
//! (state 4). They never end by themselves: the `servo` sequencer's selector
//! ([`super::selector`]) leaves them when the percept calls for another state.

use super::memory::Memory;
use super::params::BlueOnlyParams;
use crate::schemas::{Behavior, Inputs, Step};

/// `raposa.approach`, state 1 (region I): the servo law on the ellipse, constant speed
/// beyond `far_distance_m`, v = K_lin·√(A₁/A) closer, ω = −K_ang·x_dev.
#[derive(Debug, Clone, Copy, Default)]
pub struct Approach;

impl Behavior<Memory> for Approach {
    fn enter(&mut self, _mem: &mut Memory, _inputs: &Inputs<'_>) {}

    fn tick(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) -> Option<Step> {
        Some(m.approach(false, "state_1"))
    }
}

/// `raposa.far_ellipse`, state 3: a lone ellipse far away, approached at the constant far
/// speed until the blue edges join it (the paper does not say how).
#[derive(Debug, Clone, Copy, Default)]
pub struct FarEllipse;

impl Behavior<Memory> for FarEllipse {
    fn enter(&mut self, _mem: &mut Memory, _inputs: &Inputs<'_>) {}

    fn tick(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) -> Option<Step> {
        Some(m.approach(true, "state_3"))
    }
}

/// `raposa.blue_only`, state 4: blue edges without the ellipse (hidden by glare or the
/// pyramid's own body): turn toward them, and creep at the final speed once they are
/// within `centred_px` of the image centre.
pub struct BlueOnly {
    params: BlueOnlyParams,
}

impl BlueOnly {
    /// The leaf with `params`.
    pub fn new(params: BlueOnlyParams) -> Self {
        Self { params }
    }
}

impl Behavior<Memory> for BlueOnly {
    fn enter(&mut self, _mem: &mut Memory, _inputs: &Inputs<'_>) {}

    fn tick(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) -> Option<Step> {
        let Some(b) = m.percept.detection.blue else {
            return Some(m.hold("state_4"));
        };
        let dev = b.centre()[0] + 0.5 - m.half_width_px;
        let omega = m.law.turn(dev);
        let creep = if dev.abs() < self.params.centred_px {
            m.gains.final_speed_mps
        } else {
            0.0
        };
        Some(m.drive(m.law.twist(creep, omega), "state_4"))
    }
}
