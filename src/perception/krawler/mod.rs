//! The AutoKrawler's running-gear state from its belly fisheye (seed 003, DESIGN §2.4).
//!
//! The paper's pipeline, one stage per module: [`markers`], the perceptual step that
//! finds the eight magenta markers (HSV segmentation, a 3×3 opening, connected
//! components, blob centres) and gives each its identity; [`mount`], the camera's own
//! shake on its mount from the plate markers (ours, not the paper's); [`axle`], axle roll ψ and drop
//! d from each plate-marker pair by ray-plane intersection; [`steering`], λ from the
//! tie-rod markers' distance ratio through a calibrated polynomial; [`wheel`], the
//! geometry and statistics of wheel rotation from tracked tread features; [`rotation`],
//! the wheel stage on whole frames (observation windows, Shi–Tomasi and Lucas–Kanade
//! from [`crate::perception::flow`], RANSAC, the once-per-turn correction); and
//! [`schema`], [`KrawlerStateSchema`], which runs them all on each frame and reports the
//! ten degrees of freedom with validity flags. [`gear`] is the gear's geometry (from the
//! profile) and the estimator's own model of it: the rest state and its first marker
//! predictions.

pub mod axle;
pub mod gear;
pub mod markers;
pub mod mount;
pub mod rotation;
pub mod schema;
pub mod steering;
pub mod wheel;

pub use axle::{AxleGeometry, AxlePose};
pub use gear::{GearGeometry, GearSpec};
pub use markers::{Blob, ExpectedMarker, MarkerFinder, MarkerParams, Markers};
pub use mount::{MountOffset, MountParams, fit_mount};
pub use rotation::{AxleState, GearLayout, WheelParams, WheelStep, WheelTracker};
pub use schema::{Dof, KrawlerEstimate, KrawlerParams, KrawlerStateSchema};
pub use steering::{SteeringFit, SteeringFitError, SteeringPoly, fit_steering};
pub use wheel::{TurnCounter, WheelCylinder, ransac_angle};
