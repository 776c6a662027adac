//! `bujold.approach`: the approach zone (seed 004 §V). Steer on the fiducial with the
//! approach motor schema the profile selects (ratio steering, or the potential field
//! realised through ratio steering's dead band, understeer and turn-or-drive
//! alternation), speed falling with the summed pixel count.
//!
//! Events: `at_dock` when the summed pixel count reaches `dock_total_px`; `off_axis` when
//! the median viewing angle of the last reliable frames puts the robot more than
//! `reposition_lateral_m` off the axis (retries left: creeping in would only arrive
//! misaligned); `lost` when the fiducial has been out of sight for `lost_after_s`.

use super::memory::Memory;
use super::params::ApproachParams;
use crate::arbiter::Blackboard;
use crate::perception::two_block_pose::FiducialView;
use crate::schemas::{Behavior, Inputs, Step};

/// See the module docs.
pub struct Approach {
    name: String,
    mem: Blackboard<Memory>,
    params: ApproachParams,
    dock_total_px: f64,
    max_retries: u32,
}

impl Approach {
    /// A leaf named `name`; at the dock at `dock_total_px`, repositioning at most
    /// `max_retries` times per docking.
    pub fn new(
        name: &str,
        mem: Blackboard<Memory>,
        params: ApproachParams,
        dock_total_px: f64,
        max_retries: u32,
    ) -> Self {
        Self {
            name: name.into(),
            mem,
            params,
            dock_total_px,
            max_retries,
        }
    }

    /// The planning view with the median viewing angle of the alpha window, when that
    /// window is full, the blocks are tall enough to trust and the robot is more than
    /// `reposition_lateral_m` off the axis; `None` otherwise.
    fn off_axis(&self, m: &Memory, planning: &FiducialView) -> Option<FiducialView> {
        if !m.alpha_window.is_full() || planning.height_px < m.tuning.reliable_height_px {
            return None;
        }
        let alpha = m.alpha_window.median()?;
        ((planning.distance * alpha.sin()).abs() > self.params.reposition_lateral_m).then(|| planning.with_alpha(alpha))
    }
}

impl Behavior for Approach {
    fn name(&self) -> &str {
        &self.name
    }

    fn enter(&mut self, _inputs: &Inputs<'_>) {}

    fn tick(&mut self, inputs: &Inputs<'_>) -> Option<Step> {
        let mem = self.mem.clone();
        let mut m = mem.lock();
        m.observe_change(inputs);
        // Repositioning is decided on the median viewing angle, not the filtered one.
        let off_axis = match &m.planning {
            Some(p) if m.retries < self.max_retries => self.off_axis(&m, p),
            _ => None,
        };
        let step = match (m.view, off_axis) {
            (Some(v), _) if v.total_px as f64 >= self.dock_total_px => {
                Step::event("at_dock", m.hold("approach").output, m.feedback("approach"))
            }
            (Some(_), Some(off)) => {
                m.retries += 1;
                m.plan = Some(m.plan_reposition(&off));
                Step::event("off_axis", m.hold("approach").output, m.feedback("approach"))
            }
            (Some(v), _) => Step::running(m.approach.act(&v), m.feedback("approach")),
            (None, _) => {
                let lost = m.last_seen.is_none_or(|t| m.now - t > self.params.lost_after_s);
                let hold = m.hold("approach");
                if lost {
                    Step::event("lost", hold.output, hold.feedback)
                } else {
                    hold
                }
            }
        };
        Some(step)
    }
}
