//! `raposa.rotate_7`, state 7 (seed 001 §II.E): the part of the region-II rotation −β that
//! keeps the ellipse in view, measured by vision. The rotation is the change of the
//! ball's bearing from frame to frame; a one-frame predictor (the last frame's change, the
//! control delay) ends it before the goal is passed (event `rotated`: travel next) or the
//! ellipse leaves the image (event `edge`: finish −β by odometry). Either way the
//! odometry frame of the manoeuvre ([`Memory::map`]) is reset with the angle vision
//! measured. The ellipse lost for `lost_frames` frames ends it with event `lost`.

use super::memory::Memory;
use crate::geometry::Pose2;
use crate::schemas::{Behavior, Inputs, Step};

/// See the module docs.
#[derive(Debug, Clone, Copy, Default)]
pub struct Rotate7 {
    /// Angle turned so far toward −β, rad.
    rotated: f64,
    /// The ball's bearing in the last frame it was seen, rad.
    last_bearing: f64,
    /// The last frame-to-frame change of the bearing, rad.
    last_step: f64,
    /// Consecutive frames without the ellipse.
    lost: u32,
}

impl Behavior<Memory> for Rotate7 {
    /// Starts from this tick's view (the one the plan was made from).
    fn enter(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) {
        m.blind = false;
        self.rotated = 0.0;
        self.last_bearing = m.percept.view.map_or(0.0, |v| v.bearing);
        self.last_step = 0.0;
        self.lost = 0;
    }

    fn tick(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) -> Option<Step> {
        let Some(pl) = m.plan else {
            return Some(m.hold("state_7").with_event("lost"));
        };
        let dir = pl.rotation.signum();
        let want = pl.rotation.abs();
        let Some(v) = m.percept.view else {
            // Lost: stop; give up on the vision part after too many frames.
            if self.lost + 1 >= m.gains.lost_frames {
                return Some(m.hold("state_7").with_event("lost"));
            }
            self.last_step = 0.0;
            self.lost += 1;
            return Some(m.hold("state_7"));
        };
        // Turning the camera by +Δ moves the ball's bearing by −Δ.
        let step = self.last_bearing - v.bearing;
        let rotated = self.rotated + step * dir;
        // Predict the next frame from the frame-to-frame change (the control delay), and
        // stop before the goal or the image edge is passed. Turning the camera in `dir`
        // moves the ellipse toward the image side `dir` (+1: right).
        let per_frame = step.abs().max(self.last_step.abs());
        let predicted_rot = rotated + per_frame;
        let x_next = v.dev_px[0] + dir * per_frame * m.source.f_px();
        let near_edge = x_next * dir > m.half_width_px - m.gains.fov_margin_px;
        let done = predicted_rot >= want - m.ctrl.rotation_tolerance;
        if done || near_edge {
            // Reset the odometry origin with the angle rotated by vision.
            let start = Pose2::new(pl.start.x, pl.start.y, pl.start.theta + rotated * dir);
            m.map = m.odo.compose(&start.relative(&Pose2::default()));
            return Some(m.hold("state_7").with_event(if done { "rotated" } else { "edge" }));
        }
        self.rotated = rotated;
        self.last_bearing = v.bearing;
        self.last_step = step;
        self.lost = 0;
        let omega = m.vision_turn * dir;
        Some(m.turn(omega, "state_7"))
    }
}
