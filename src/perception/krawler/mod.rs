//! The AutoKrawler's running-gear state from its belly fisheye (seed 003, DESIGN §2.4).
//!
//! The paper's pipeline, one stage per module. So far: [`markers`], the perceptual step
//! that finds the eight magenta markers (HSV segmentation, a 3×3 opening, connected
//! components, blob centres) and gives each its identity; and [`axle`], axle roll ψ and
//! drop d from each plate-marker pair by ray-plane intersection; and [`steering`], λ from
//! the tie-rod markers' distance ratio through a calibrated polynomial; and [`wheel`],
//! the geometry and statistics of wheel rotation from tracked tread features (the
//! tracking itself is [`crate::perception::flow`]).

pub mod axle;
pub mod markers;
pub mod steering;
pub mod wheel;

pub use axle::{AxleGeometry, AxlePose};
pub use markers::{Blob, ExpectedMarker, MarkerFinder, MarkerParams, Markers};
pub use steering::{SteeringFit, SteeringFitError, SteeringPoly, fit_steering};
pub use wheel::{TurnCounter, WheelCylinder, ransac_angle};
