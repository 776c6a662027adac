//! The two leaves every docking robot has, whatever its fiducial: `imprint` (stand still
//! and learn the fiducial's colours from a few frames, seed 004 §IV.C) and `dock_switch`
//! (the dock's contact sensor closed: docked, whatever phase was running; under a
//! priority node it subsumes them). They reach the robot's perceptual schema and its
//! auxiliary commands through [`DockingMemory`], which each robot's shared memory
//! implements: each leaf is a [`Behavior<M>`] for every `M: DockingMemory`, handed the
//! memory by its tree at each tick.

use crate::perception::RgbView;
use crate::schemas::{Auxiliary, Behavior, FailureReason, Feedback, Inputs, MotorOutput, Outcome, Status, Step};

/// What the common docking leaves need of a robot's shared memory.
pub trait DockingMemory: Send + 'static {
    /// Feeds one frame to the perceptual schema's imprinter.
    fn imprint_frame(&mut self, image: &RgbView<'_>);
    /// Ends the imprint: learns the colours from the frames fed, remembers whether it
    /// worked, and says so.
    fn finish_imprint(&mut self) -> bool;
    /// The auxiliary commands while standing still (posture, lights, guides as they are).
    fn holding(&self) -> Auxiliary;
    /// The auxiliary commands once docked (the posture or guides the dock wants).
    fn docked(&mut self) -> Auxiliary;
    /// This tick's feedback in `phase`.
    fn feedback(&self, phase: &'static str) -> Feedback;
}

/// How an imprint ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImprintEnd {
    /// With this event either way (the tree goes on; the memory says whether it worked).
    Event(&'static str),
    /// With the departure's outcome: completed when the colours were learned, failed
    /// (target never detected) otherwise.
    Outcome,
}

/// `imprint`: see the module docs. Stands still for `settle` ticks without sampling (the
/// first frames after stopping may still be blurred by the motion), then feeds `frames`
/// ticks' camera frames to the imprinter, and ends as `end` says.
pub struct Imprint {
    settle: u32,
    frames: u32,
    end: ImprintEnd,
    ticks: u32,
}

impl Imprint {
    /// A leaf settling `settle` ticks, sampling `frames`, ending as `end` says.
    pub fn new(settle: u32, frames: u32, end: ImprintEnd) -> Self {
        Self {
            settle,
            frames,
            end,
            ticks: 0,
        }
    }
}

impl<M: DockingMemory> Behavior<M> for Imprint {
    fn enter(&mut self, _mem: &mut M, _inputs: &Inputs<'_>) {
        self.ticks = 0;
    }

    fn tick(&mut self, m: &mut M, inputs: &Inputs<'_>) -> Option<Step> {
        if self.ticks >= self.settle
            && let Some(cam) = inputs.camera(0)
        {
            m.imprint_frame(&cam.image);
        }
        self.ticks += 1;
        let out = MotorOutput::stop().with_aux(m.holding());
        let status = if self.ticks >= self.settle + self.frames {
            let learned = m.finish_imprint();
            match self.end {
                ImprintEnd::Event(e) => Status::Event(e),
                ImprintEnd::Outcome if learned => Status::Done(Outcome::Completed),
                ImprintEnd::Outcome => Status::Done(Outcome::Failed(FailureReason::TargetNeverDetected)),
            }
        } else {
            Status::Running
        };
        Some(Step {
            status,
            output: out,
            feedback: m.feedback("imprint"),
        })
    }
}

/// `dock_switch`: see the module docs. Released only when the dock's contact sensor reads
/// closed.
#[derive(Debug, Clone, Copy, Default)]
pub struct DockSwitch;

impl<M: DockingMemory> Behavior<M> for DockSwitch {
    fn tick(&mut self, m: &mut M, inputs: &Inputs<'_>) -> Option<Step> {
        inputs.docked_contact().then(|| {
            let aux = m.docked();
            Step::done(Outcome::Docked, MotorOutput::stop().with_aux(aux), m.feedback("docked"))
        })
    }
}
