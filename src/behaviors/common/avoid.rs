//! `avoid_obstacles`: Arkin's avoid-static-obstacle motor schema
//! ([`AvoidObstacles`]) paired with a range finder (the profile's first `[[sensors]]` of
//! kind `range`) under the releaser "some return inside the sphere of influence".
//!
//! It proposes a body-frame motion vector: put it under a vector-sum node with the
//! robot's approach. Inactive (not released) when nothing is near or the sensor has not
//! read yet, so a decision trace shows when it acted.

use crate::behaviors::registry::LeafArgs;
use crate::profile::tree::Lead;
use crate::profile::{RANGE_KIND, RangeParams};
use crate::schemas::{AvoidObstacles, Behavior, DriveCommand, Feedback, Inputs, MotorOutput, Step};
use serde::{Deserialize, Serialize};

/// The leaf's `params`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AvoidParams {
    /// Sphere of influence S, m.
    pub sphere_m: f64,
    /// Safety radius R, m.
    pub safety_m: f64,
    /// Gain G, m/s at the safety radius.
    pub gain_mps: f64,
    /// Multiple of G inside R (Arkin's "infinite").
    pub cap: f64,
    /// Share of each repulsion turned to the obstacle's tangent, 0 to 1 (see
    /// [`AvoidObstacles`]): 0 is Arkin's pure repulsion.
    pub swirl: f64,
    /// The end the robot travels with, which the swirl carries on toward: `front`, or
    /// `rear` for a robot that backs (as the vector-sum node's `lead`).
    pub lead: Lead,
}

impl Default for AvoidParams {
    /// TeamBots' form at a small robot's scale: S = 0.5 m, R = 0.1 m, G = 0.05 m/s, ×3
    /// inside R.
    fn default() -> Self {
        Self {
            sphere_m: 0.5,
            safety_m: 0.1,
            gain_mps: 0.05,
            cap: 3.0,
            swirl: 0.0,
            lead: Lead::Front,
        }
    }
}

/// See the module docs.
pub struct AvoidLeaf {
    sensor: usize,
    beams: RangeParams,
    schema: AvoidObstacles,
    /// The side chosen to slide round the obstacle in range (kept until nothing is).
    side: Option<f64>,
}

impl AvoidLeaf {
    /// A leaf reading sensor `sensor` (a range finder with `beams`).
    pub fn new(sensor: usize, beams: RangeParams, params: AvoidParams) -> Self {
        Self {
            sensor,
            beams,
            schema: AvoidObstacles {
                sphere: params.sphere_m,
                safety: params.safety_m,
                gain: params.gain_mps,
                cap: params.cap,
                swirl: params.swirl,
                lead: params.lead.sign(),
            },
            side: None,
        }
    }

    /// Builds the leaf from its node: its params and the profile's range finder.
    ///
    /// # Errors
    /// A message when the params are malformed or out of range, or the profile has no
    /// `range` sensor.
    pub fn from_args(a: &LeafArgs<'_>) -> Result<Self, String> {
        let p: AvoidParams = a.params()?;
        if !(p.safety_m >= 0.0 && p.sphere_m > p.safety_m && p.sphere_m.is_finite()) {
            return Err(format!(
                "params: expected 0 ≤ safety_m < sphere_m, got {} and {}",
                p.safety_m, p.sphere_m
            ));
        }
        if !(0.0..=1.0).contains(&p.swirl) {
            return Err(format!("params.swirl: expected 0 to 1, got {}", p.swirl));
        }
        if !(p.gain_mps >= 0.0 && p.gain_mps.is_finite() && p.cap >= 1.0 && p.cap.is_finite()) {
            return Err(format!(
                "params: expected gain_mps ≥ 0 and cap ≥ 1, got {} and {}",
                p.gain_mps, p.cap
            ));
        }
        let i = a.sensor(RANGE_KIND)?;
        let beams = RangeParams::from_table(&a.profile.sensors[i].params)?;
        Ok(Self::new(i, beams, p))
    }
}

/// Reads no tree memory: it fits in any robot's tree.
impl<M: ?Sized> Behavior<M> for AvoidLeaf {
    fn reset(&mut self) {
        self.side = None;
    }

    fn tick(&mut self, _mem: &mut M, inputs: &Inputs<'_>) -> Option<Step> {
        let Some(reading) = inputs.sensor(self.sensor) else {
            self.side = None;
            return None;
        };
        let b = self.beams;
        let beams = || {
            reading
                .values
                .iter()
                .enumerate()
                .map(move |(i, &r)| (b.beam_angle(i), r))
        };
        let side = *self.side.get_or_insert_with(|| self.schema.side(beams()));
        let Some(v) = self.schema.vector(beams(), side) else {
            self.side = None;
            return None;
        };
        Some(Step::running(
            MotorOutput::drive(DriveCommand::Vector(v)),
            Feedback::new("avoid", inputs.now),
        ))
    }
}
