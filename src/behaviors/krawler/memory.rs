//! The AutoKrawler's shared memory: the state estimator, run once per tick on the belly
//! camera, and what its leaves share (the commanded wheel rotation, the slip figures).

use super::slip::SlipReading;
use crate::behaviors::SharedMemory;
use crate::schemas::{
    Inputs, KrawlerPercept, KrawlerSchema, Mission, MissionError, Observation, ObservedPercept, PerceptualSchema,
};

/// Called with each fresh estimate (for a consumer off the tree: a log, a table).
pub type Observer = Box<dyn FnMut(&KrawlerPercept) + Send>;

/// What the `krawler` kind's leaves share (see the module docs).
pub struct KrawlerMemory {
    schema: KrawlerSchema,
    observer: Option<Observer>,
    /// This tick's estimate.
    pub percept: KrawlerPercept,
    /// The wheels' tread radius, m.
    pub wheel_radius: f64,
    /// The wheel rotation rate the drive leaf commanded on the last tick, rad/s (its
    /// speed over the radius): what the wheels turn by until the next tick.
    pub commanded_rate: f64,
    /// The slip monitor's last judged window.
    pub slip: SlipReading,
}

impl KrawlerMemory {
    /// A memory running `schema`, for wheels of `wheel_radius`.
    pub fn new(schema: KrawlerSchema, wheel_radius: f64) -> Self {
        Self {
            schema,
            observer: None,
            percept: KrawlerPercept::default(),
            wheel_radius,
            commanded_rate: 0.0,
            slip: SlipReading::default(),
        }
    }

    /// The estimator's schema (to install another RANSAC generator).
    pub fn schema_mut(&mut self) -> &mut KrawlerSchema {
        &mut self.schema
    }

    /// Calls `observer` with every fresh estimate, after the tick's perception.
    pub fn on_estimate(&mut self, observer: Observer) {
        self.observer = Some(observer);
    }
}

impl SharedMemory for KrawlerMemory {
    /// Estimates the belly camera's new frame, if any (a frame is estimated once: the
    /// wheel stage measures rotation between consecutive frames).
    fn perceive(&mut self, inputs: &Inputs<'_>) {
        self.percept = self.schema.perceive(inputs);
        if self.percept.fresh
            && let Some(o) = self.observer.as_mut()
        {
            o(&self.percept);
        }
    }

    /// The estimate, for recorders and replays.
    fn observe(&self) -> Option<Observation> {
        Some(Observation {
            camera: 0,
            percept: ObservedPercept::Krawler(self.percept.observation()),
            ranges: None,
        })
    }

    /// A new mission starts with nothing commanded and no slip judged; the estimate goes
    /// on (the gear's state does not change between missions).
    fn begin(&mut self, _mission: &Mission) -> Result<(), MissionError> {
        self.commanded_rate = 0.0;
        self.slip = SlipReading::default();
        Ok(())
    }
}
