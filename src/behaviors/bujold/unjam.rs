//! `bujold.unjam`: the search turn is jammed against the body. Turn back to the heading
//! the close dock began with (turning back over the ground just swept is free), then
//! drive out front first; event `cleared` (the search then turns the other way, which
//! swings the caught corner off the body).

use super::memory::Memory;
use super::params::UnjamParams;
use crate::geometry::{Pose2, wrap_angle};
use crate::schemas::{Behavior, Inputs, Step};

/// See the module docs.
pub struct Unjam {
    name: String,
    params: UnjamParams,
    /// 0: turning back; 1: driving out.
    stage: u8,
    stage_start: f64,
    mark: Pose2,
}

impl Unjam {
    /// A leaf named `name`.
    pub fn new(name: &str, params: UnjamParams) -> Self {
        Self {
            name: name.into(),
            params,
            stage: 0,
            stage_start: 0.0,
            mark: Pose2::default(),
        }
    }
}

impl Behavior<Memory> for Unjam {
    fn name(&self) -> &str {
        &self.name
    }

    fn enter(&mut self, m: &mut Memory, inputs: &Inputs<'_>) {
        self.stage = 0;
        self.stage_start = inputs.now;
        self.mark = m.odo;
    }

    fn tick(&mut self, m: &mut Memory, inputs: &Inputs<'_>) -> Option<Step> {
        // The frame-change cue keeps running so the search that follows compares its
        // first frame with the one just before it.
        m.observe_change(inputs);
        let in_stage = m.now - self.stage_start;
        let p = self.params;
        if self.stage == 0 {
            let err = wrap_angle(m.start_heading.unwrap_or(m.odo.theta) - m.odo.theta);
            if err.abs() < p.heading_tolerance_deg.to_radians() || in_stage > p.turn_timeout_s {
                self.stage = 1;
                self.stage_start = m.now;
                self.mark = m.odo;
                return Some(m.hold("unjam"));
            }
            return Some(m.turn_by(err, "unjam"));
        }
        if m.travelled(&self.mark) >= p.distance_m || in_stage > 2.0 * p.distance_m / p.speed_mps {
            return Some(m.hold("unjam").with_event("cleared"));
        }
        Some(m.drive_away(p.speed_mps, "unjam"))
    }
}
