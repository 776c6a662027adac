//! `bujold.reposition` and `bujold.ballistic`: turn, drive and turn by odometry to a
//! staging pose on the dock axis, facing along it; event `aligned` (then the approach
//! starts afresh, its viewing-angle memory cleared).
//!
//! The reposition phase takes the plan the approach or the decision left in memory
//! (beside the gate, where the body's corners sweep a circle of half the diagonal, it
//! first drives straight out, front first). The ballistic phase (the ballistic region,
//! seed 004 Fig. 1) plans from the a-priori dock pose instead: `ballistic_staging_m` out
//! on the dock axis.

use super::memory::{Memory, RepositionPlan, raised};
use super::params::RepositionParams;
use crate::geometry::{Pose2, wrap_angle};
use crate::schemas::{Behavior, DriveCommand, Inputs, MotorOutput, Step};
use std::f64::consts::FRAC_PI_2;

/// Where the staging pose comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlanFrom {
    /// The plan the previous phase left in memory.
    Memory,
    /// The a-priori dock pose ([`Mission::Docking`](crate::schemas::Mission)).
    DockHint,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Stage {
    /// Drive straight out, front first.
    Clear,
    /// Face the staging point with the end that leads toward it.
    Face,
    /// Drive until the staging point is abeam.
    Drive,
    /// Turn to the staging heading.
    Align,
}

/// See the module docs.
pub struct Reposition {
    name: String,
    params: RepositionParams,
    from: PlanFrom,
    stage: Stage,
    target: Pose2,
    mark: Pose2,
}

impl Reposition {
    /// A leaf named `name` taking its plan `from` memory or the dock hint.
    pub fn new(name: &str, params: RepositionParams, from: PlanFrom) -> Self {
        Self {
            name: name.into(),
            params,
            from,
            stage: Stage::Face,
            target: Pose2::default(),
            mark: Pose2::default(),
        }
    }

    fn phase(&self) -> &'static str {
        match self.from {
            PlanFrom::Memory => "reposition",
            PlanFrom::DockHint => "ballistic",
        }
    }
}

impl Behavior<Memory> for Reposition {
    fn name(&self) -> &str {
        &self.name
    }

    fn enter(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) {
        self.mark = m.odo;
        let plan = match self.from {
            PlanFrom::Memory => m.plan.take(),
            PlanFrom::DockHint => m.dock_hint.map(|dock| RepositionPlan {
                target: dock.compose(&Pose2::new(m.tuning.ballistic_staging_m, 0.0, 0.0)),
                clear_first: false,
            }),
        };
        // With no plan (none was left, or no hint), stage where the robot stands.
        let plan = plan.unwrap_or(RepositionPlan {
            target: m.odo,
            clear_first: false,
        });
        self.target = plan.target;
        self.stage = if plan.clear_first { Stage::Clear } else { Stage::Face };
    }

    fn tick(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) -> Option<Step> {
        let phase = self.phase();
        let p = self.params;
        let odo = m.odo;
        let target = self.target;
        let (dx, dy) = (target.x - odo.x, target.y - odo.y);
        let dist = dx.hypot(dy);
        let tol = p.heading_tolerance_deg.to_radians();
        let speed = m.approach.steering.speed;
        let step = match self.stage {
            Stage::Clear => {
                if m.travelled(&self.mark) >= p.clear_m {
                    self.stage = Stage::Face;
                    m.hold(phase)
                } else {
                    let v = -m.geometry.drive_dir * speed;
                    Step::running(
                        MotorOutput::drive(DriveCommand::Straight { v }).with_aux(raised()),
                        m.feedback(phase),
                    )
                }
            }
            Stage::Face | Stage::Drive if dist < p.arrive_m => {
                self.stage = Stage::Align;
                m.hold(phase)
            }
            Stage::Face => {
                let bearing = dy.atan2(dx);
                let forward = wrap_angle(bearing - odo.theta).abs() <= FRAC_PI_2;
                let want = if forward {
                    bearing
                } else {
                    bearing + std::f64::consts::PI
                };
                let err = wrap_angle(want - odo.theta);
                if err.abs() < tol {
                    self.stage = Stage::Drive;
                    m.hold(phase)
                } else {
                    m.turn_by(err, phase)
                }
            }
            Stage::Drive => {
                // Drive along the heading until the target is abeam: the signed distance
                // to it along the heading crosses zero (a target off the line of travel
                // is never reached exactly).
                let along = dx * odo.theta.cos() + dy * odo.theta.sin();
                if along.abs() < p.abeam_m {
                    self.stage = Stage::Align;
                    m.hold(phase)
                } else {
                    let tick_s = m.approach.steering.tick_s;
                    let v = speed.min(along.abs() / tick_s).copysign(along);
                    Step::running(
                        MotorOutput::drive(DriveCommand::Straight { v }).with_aux(raised()),
                        m.feedback(phase),
                    )
                }
            }
            Stage::Align => {
                let err = wrap_angle(target.theta - odo.theta);
                if err.abs() < tol {
                    m.alpha_filtered = None;
                    m.alpha_window.clear();
                    m.ratio_gate.reset();
                    m.hold(phase).with_event("aligned")
                } else {
                    m.turn_by(err, phase)
                }
            }
        };
        Some(step)
    }
}
