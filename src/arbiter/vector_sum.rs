//! Weighted vector summation (Arkin's motor-schema coordination).

use super::decision::{Decision, Strategy};
use crate::geometry::Twist;
use crate::schemas::{Behavior, DriveCommand, Feedback, Inputs, MotionVector, MotorOutput, Status, Step};

/// Sums the active children's drive outputs, each scaled by its gain.
///
/// `Vector` outputs (body-frame velocities, Arkin's motion vectors) are summed as vectors,
/// clipped to `max_speed` and turned into a twist by the heading controller with gain
/// `k_theta`, for a robot that leads with its front or, with [`VectorSum::rear_first`],
/// its rear (a robot backing into its dock follows the vector rear first instead of
/// turning round). Every other drive command is summed as a twist. Auxiliary commands
/// merge in list order (earlier children win). The first child (in list order) to end
/// with an outcome or an event ends the sum with it, so a sum can be a sequencer's state
/// whose leaf decides when it is over. With no active child the arbiter is inactive.
/// `M` is the tree's memory, passed to each child in turn.
pub struct VectorSum<M: ?Sized = ()> {
    name: String,
    children: Vec<(f64, Box<dyn Behavior<M>>)>,
    max_speed: f64,
    k_theta: f64,
    /// −1 when the robot follows the summed vector rear first, +1 front first.
    lead: f64,
    decision: Decision,
}

impl<M: ?Sized> VectorSum<M> {
    /// Builds the arbiter from `(gain, behavior)` pairs.
    pub fn new(
        name: impl Into<String>,
        children: Vec<(f64, Box<dyn Behavior<M>>)>,
        max_speed: f64,
        k_theta: f64,
    ) -> Self {
        Self {
            name: name.into(),
            decision: Decision::new(Strategy::VectorSum),
            children,
            max_speed,
            k_theta,
            lead: 1.0,
        }
    }

    /// Follows the summed vector rear first (the robot drives backwards along it).
    pub fn rear_first(mut self) -> Self {
        self.lead = -1.0;
        self
    }

    /// The last tick's decision.
    pub fn decision(&self) -> &Decision {
        &self.decision
    }
}

impl<M: ?Sized> Behavior<M> for VectorSum<M> {
    fn name(&self) -> &str {
        &self.name
    }

    fn tick(&mut self, mem: &mut M, inputs: &Inputs<'_>) -> Option<Step> {
        self.decision.clear();
        let mut vec_sum = MotionVector::ZERO;
        let mut any_vec = false;
        let mut tw = Twist::ZERO;
        let mut aux = crate::schemas::Auxiliary::default();
        let mut feedback: Option<Feedback> = None;
        let mut status = Status::Running;
        let mut any = false;
        for (i, (gain, child)) in self.children.iter_mut().enumerate() {
            let gain = *gain;
            let step = child.tick(mem, inputs);
            self.decision.push(i, step.as_ref());
            let Some(step) = step else { continue };
            any = true;
            match step.output.drive {
                DriveCommand::Vector(v) => {
                    vec_sum = vec_sum + v.scale(gain);
                    any_vec = true;
                }
                other => {
                    let t = other.to_twist();
                    tw.v += gain * t.v;
                    tw.omega += gain * t.omega;
                }
            }
            aux = aux.or(step.output.aux);
            feedback.get_or_insert(step.feedback);
            if status == Status::Running {
                status = step.status;
            }
        }
        if !any {
            self.decision
                .trace(&self.name, &|i| self.children[i].1.name().to_string());
            return None;
        }
        if any_vec {
            // In the lead's frame (rotated half a turn when leading with the rear), the
            // heading controller steers the leading end along the vector.
            let t = vec_sum.clip(self.max_speed).scale(self.lead).to_twist(self.k_theta);
            tw.v += self.lead * t.v;
            tw.omega += t.omega;
        }
        let output = MotorOutput {
            drive: DriveCommand::Twist(tw),
            aux,
        };
        self.decision.output = Some(output);
        let children = &self.children;
        self.decision.trace(&self.name, &|i| children[i].1.name().to_string());
        Some(Step {
            output,
            feedback: feedback.unwrap_or(Feedback::new("sum", 0.0)),
            status,
        })
    }

    fn reset(&mut self) {
        self.children.iter_mut().for_each(|(_, c)| c.reset());
    }

    fn explain(&self, out: &mut Vec<super::NodeTrace>) {
        out.push(super::trace::node_trace(&self.name, &self.decision, &|i| {
            self.children[i].1.name()
        }));
        for c in self.decision.active() {
            self.children[c].1.explain(out);
        }
    }

    fn start(&mut self, state: &str) -> bool {
        self.children
            .iter_mut()
            .fold(false, |any, (_, c)| c.start(state) || any)
    }
}
