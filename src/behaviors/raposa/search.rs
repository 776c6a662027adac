//! RAPOSA's memory as the common leaves see it: its [`Motion`] (the guides, arm and
//! lights carried on every command; turns by the [`PointController`](crate::schemas::PointController)'s
//! rotation, remembering the side) and its [`Searching`] (seed 001 §II.E: "rotate slowly
//! until it finds it again", alternating sides and doubling the sweep below 360°, first
//! away from the side of the last turn). The seven-state selector leaves the search as
//! soon as anything is seen, so the search itself never reports an acquisition; the
//! search clock it keeps across the selector's glimpses restarts once the ellipse is
//! seen, and a timeout is a target lost.

use super::memory::Memory;
use crate::behaviors::common::motion::Motion;
use crate::behaviors::common::search::Searching;
use crate::geometry::{Pose2, Twist};
use crate::schemas::{DriveCommand, FailureReason, Step};

impl Motion for Memory {
    fn now(&self) -> f64 {
        self.now
    }

    fn odo(&self) -> Pose2 {
        self.odo
    }

    fn hold(&mut self, phase: &'static str) -> Step {
        Memory::hold(self, phase)
    }

    /// By the point controller's rotation, within its own `rotation_tolerance`.
    fn turn_toward(&mut self, heading: f64, _tolerance: Option<f64>, phase: &'static str) -> Option<Step> {
        let odo = self.odo;
        let t = self.ctrl.rotate(&odo, heading)?;
        Some(self.turn(t.omega, phase))
    }

    fn straight(&mut self, v: f64, phase: &'static str) -> Step {
        self.drive(Twist::new(v, 0.0), phase)
    }

    /// Body forward for the backward camera, keeping the ellipse centred when it is seen.
    fn back_off(&mut self, speed: f64, phase: &'static str) -> Step {
        let omega = self.percept.view.map_or(0.0, |v| self.law.turn(v.dev_px[0]));
        self.drive(self.law.twist(-speed, omega), phase)
    }
}

impl Searching for Memory {
    fn acquired(&mut self, _phase: &'static str) -> Option<Step> {
        None
    }

    fn search_side(&self) -> f64 {
        -self.last_turn
    }

    fn lost_reason(&self) -> FailureReason {
        FailureReason::TargetLost
    }

    fn search_turn(&mut self, turn: DriveCommand, phase: &'static str) -> Step {
        self.command(turn, phase)
    }

    fn count_unseen(&mut self) -> u32 {
        self.unseen += 1;
        self.unseen
    }

    fn search_clock(&mut self) -> Option<&mut Option<f64>> {
        Some(&mut self.search_start)
    }
}
