//! Observations: what a robot's perception made of the latest frame, offered to
//! recorders and displays (`marsupial dock --record`), never to the decision.
//!
//! An [`Agent`](super::Agent) that has perception answers
//! [`Agent::observe`](super::Agent::observe) with the percept its perceptual schema
//! produced this tick and the colour ranges it will segment the next frame with. Asking
//! copies a few hundred bytes and takes the shared memory's lock, so the loop never does
//! it by itself: only a caller that records pays for it.

use crate::perception::{HsvRange, PyramidPercept, SctRange, TwoBlockPercept};
use serde::Serialize;

/// The percept of one tick, by fiducial kind.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ObservedPercept {
    /// The two-block flap's (blocks, centroids, boxes).
    TwoBlock(TwoBlockPercept),
    /// The pyramid's (blue region, ellipse, geometric view); also RAPOSA's cues read from
    /// a two-block flap.
    Pyramid(PyramidPercept),
    /// The AutoKrawler's state estimate (its markers and ten degrees of freedom).
    Krawler(super::krawler::KrawlerObservation),
}

/// The colour model's segmentation ranges for the two fiducial colours.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ColourRanges {
    /// SCT boxes (image-left colour, image-right colour).
    Sct([SctRange; 2]),
    /// HSV boxes (orange, blue).
    Hsv([HsvRange; 2]),
}

/// What a robot's perception made of the current tick (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Observation {
    /// The camera the percept was computed from (index into the profile's cameras).
    pub camera: usize,
    /// The percept.
    pub percept: ObservedPercept,
    /// The colour ranges the model holds now, when it has any.
    pub ranges: Option<ColourRanges>,
}
