//! The simulated range finder (`[[sensors]]` kind `range`): a planar fan of beams cast
//! from the sensor's mount against the world's obstacles and the dock's body
//! ([`Obstacles`](super::obstacles::Obstacles)), each reading the distance to the first
//! wall (or the maximum range), with Gaussian range noise of `noise_m` from the sensor's
//! own random stream (so adding a range finder changes no other draw of a run).

use super::rng::Rng;
use super::robot::SimRobot;
use crate::profile::RangeParams;
use crate::robot::{HardwareError, Sensor};

/// See the module docs.
pub struct SimRange {
    sim: SimRobot,
    params: RangeParams,
    rng: Rng,
}

impl SimRange {
    /// A range finder with `params` on the robot of `sim`, its noise drawn from `rng`.
    pub fn new(sim: SimRobot, params: RangeParams, rng: Rng) -> Self {
        Self { sim, params, rng }
    }
}

impl Sensor for SimRange {
    fn read(&mut self, values: &mut Vec<f64>) -> Result<(), HardwareError> {
        let p = self.params;
        let (pose, rng) = (self.sim.with(|s| s.pose()), &mut self.rng);
        let (x, y) = pose.to_world(p.x_m, p.y_m);
        self.sim.with(|s| {
            let o = &s.world().obstacles;
            for i in 0..p.beams {
                let r = o.ray(x, y, pose.theta + p.beam_angle(i), p.max_range_m);
                let noisy = if r < p.max_range_m {
                    (r + rng.normal() * p.noise_m).clamp(0.0, p.max_range_m)
                } else {
                    r
                };
                values.push(noisy);
            }
        });
        Ok(())
    }
}
