//! `raposa.leave_dead_zone` and `raposa.retreat` (latched): back away from the pyramid by
//! odometry, body forward for the backward camera, at the far speed, keeping the ellipse
//! centred when it is seen; then event `cleared` (the servo selects again).
//!
//! * leave the dead zone (ours, `[robot.seven_state] leave_dead_zone`): a pair closer
//!   than `distance_threshold_m` shows misalignment, where α is unreliable and region II
//!   cannot run: back off until the socket is `dead_zone_exit_m` from the ball (at least
//!   `min_distance_m`), measured from the view on entry;
//! * retreat: a final approach ended without the dock switch: back off `distance_m`.

use super::memory::Memory;
use super::params::{LeaveDeadZoneParams, RetreatParams};
use crate::geometry::Pose2;
use crate::schemas::{Behavior, Inputs, Step};

/// How far a back-away goes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Distance {
    /// Out of the dead zone, from the view on entry.
    DeadZone(LeaveDeadZoneParams),
    /// A fixed distance.
    Retreat(RetreatParams),
}

/// See the module docs.
pub struct BackAway {
    name: String,
    rule: Distance,
    mark: Pose2,
    distance: f64,
}

impl BackAway {
    /// A leaf named `name` backing away by `rule`.
    pub fn new(name: &str, rule: Distance) -> Self {
        Self {
            name: name.into(),
            rule,
            mark: Pose2::default(),
            distance: 0.0,
        }
    }

    fn phase(&self) -> &'static str {
        match self.rule {
            Distance::DeadZone(_) => "leave_dead_zone",
            Distance::Retreat(_) => "retreat",
        }
    }
}

impl Behavior<Memory> for BackAway {
    fn name(&self) -> &str {
        &self.name
    }

    fn enter(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) {
        self.mark = m.odo;
        self.distance = match self.rule {
            Distance::DeadZone(p) => {
                let socket = m.percept.view.map_or(0.0, |v| v.ball_distance_m - m.socket_inset);
                (m.gains.dead_zone_exit_m - socket).max(p.min_distance_m)
            }
            Distance::Retreat(p) => p.distance_m,
        };
    }

    fn tick(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) -> Option<Step> {
        let phase = self.phase();
        if m.travelled(&self.mark) >= self.distance {
            m.source.reset();
            return Some(m.hold(phase).with_event("cleared"));
        }
        let omega = m.percept.view.map_or(0.0, |v| m.law.turn(v.dev_px[0]));
        let speed = m.gains.far_speed_mps;
        Some(m.drive(m.law.twist(-speed, omega), phase))
    }
}
