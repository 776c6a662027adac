//! `bujold.approach`: the approach zone (seed 004 §V). Steer on the fiducial with the
//! approach motor schema the profile selects (ratio steering, or the potential field
//! realised through ratio steering's dead band, understeer and turn-or-drive
//! alternation), speed falling with the summed pixel count.
//!
//! Events: `at_dock` when the summed pixel count reaches `dock_total_px`; `off_axis` when
//! the median viewing angle of the last reliable frames puts the robot more than
//! `reposition_lateral_m` off the axis (retries left: creeping in would only arrive
//! misaligned); `lost` when the fiducial has been out of sight for `lost_after_s`; with
//! `near_m`, `near` once the fiducial is that close.
//!
//! With `output = "vector"` the leaf proposes the potential field's motion vector instead
//! of a steering command, so a vector-sum node can add other motor schemas to it (an
//! avoid-obstacle schema in `profiles/bujold-avoid.toml`); while the fiducial is out of
//! sight (for up to `lost_after_s`) it follows the field toward the dock pose remembered
//! from the last sighting and carried on by odometry.

use super::memory::Memory;
use super::memory::raised;
use super::params::{ApproachOutput, ApproachParams};
use crate::perception::two_block_pose::FiducialView;
use crate::schemas::{Behavior, DriveCommand, Inputs, MotionVector, MotorOutput, Step};

/// See the module docs.
pub struct Approach {
    params: ApproachParams,
    dock_total_px: f64,
}

impl Approach {
    /// The leaf of a tree over `mem` (read here for its approach); at the dock
    /// at `dock_total_px`, repositioning while the docking has retries left.
    ///
    /// # Errors
    /// A message when `output = "vector"` but the memory's approach has no potential
    /// field.
    pub fn new(mem: &Memory, params: ApproachParams, dock_total_px: f64) -> Result<Self, String> {
        if params.output == ApproachOutput::Vector && mem.approach.field.is_none() {
            return Err(
                "params.output: `vector` needs robot.approach = \"potential_field\" (ratio steering has no vector)"
                    .into(),
            );
        }
        Ok(Self { params, dock_total_px })
    }

    /// This tick's proposal for a view.
    fn propose(&self, m: &Memory, v: &FiducialView) -> MotorOutput {
        // The field's vector only when the leaf proposes vectors: a steering approach
        // does not compute it every tick to throw it away.
        let vector = match self.params.output {
            ApproachOutput::Vector => m.approach.vector(v),
            ApproachOutput::Steer => None,
        };
        match vector {
            Some(vec) => vector_output(vec),
            None => m.approach.act(v),
        }
    }

    /// The planning view with the median viewing angle of the alpha window, when that
    /// window is full, the blocks are tall enough to trust and the robot is more than
    /// `reposition_lateral_m` off the axis; `None` otherwise.
    fn off_axis(&self, m: &Memory, planning: &FiducialView) -> Option<FiducialView> {
        if planning.height_px < m.tuning.reliable_height_px {
            return None;
        }
        let alpha = m.alpha_window.full_median()?;
        ((planning.distance * alpha.sin()).abs() > self.params.reposition_lateral_m).then(|| planning.with_alpha(alpha))
    }
}

impl Behavior<Memory> for Approach {
    fn enter(&mut self, _mem: &mut Memory, _inputs: &Inputs<'_>) {}

    fn tick(&mut self, m: &mut Memory, inputs: &Inputs<'_>) -> Option<Step> {
        m.observe_change(inputs);
        // Repositioning is decided on the median viewing angle, not the filtered one.
        let off_axis = match &m.planning {
            Some(p) if m.retries.left() => self.off_axis(m, p),
            _ => None,
        };
        let step = match (m.view, off_axis) {
            (Some(v), _) if v.total_px as f64 >= self.dock_total_px => m.hold("approach").with_event("at_dock"),
            (Some(_), Some(off)) => {
                m.retries.spend();
                m.plan = Some(m.plan_reposition(&off));
                m.hold("approach").with_event("off_axis")
            }
            (Some(v), _) if self.params.near_m.is_some_and(|near| v.distance < near) => {
                Step::event("near", self.propose(m, &v), m.feedback("approach"))
            }
            (Some(v), _) => Step::running(self.propose(m, &v), m.feedback("approach")),
            (None, _) => {
                let lost = m.last_seen.is_none_or(|t| m.now - t > self.params.lost_after_s);
                // Out of sight for a moment: a vector approach follows the field toward
                // where odometry says the dock is (Murphy: the remembered dock
                // direction); a steering approach stands still and waits.
                let remembered = match self.params.output {
                    ApproachOutput::Vector => m.remembered_pose().and_then(|p| m.approach.vector_at(&p)),
                    ApproachOutput::Steer => None,
                };
                let hold = match remembered {
                    Some(vec) => Step::running(vector_output(vec), m.feedback("approach")),
                    None => m.hold("approach"),
                };
                if lost { hold.with_event("lost") } else { hold }
            }
        };
        Some(step)
    }
}

/// A motion vector proposed raised (as the approach drives).
fn vector_output(vec: MotionVector) -> MotorOutput {
    MotorOutput::drive(DriveCommand::Vector(vec)).with_aux(raised())
}
