//! RAPOSA's docking (seed 001): the seven-state vision servo onto the tether pyramid.
//!
//! Every tick the [pyramid schema](crate::perception::PyramidSchema) reports the best
//! (ellipse, blue region) pair, or an ellipse or blue region alone, with distance and α.
//! The agent selects one of seven states ([`states`]) unless state 6 or 7 is latched:
//!
//! 1. **approach** (region I): the servo law of [`ServoLaw`](crate::schemas::ServoLaw)
//!    (constant speed beyond 1 m, v = K_lin·√(A₁/A) closer, ω = −K_ang·x_dev);
//! 2. **align** (region II, α > 15° beyond the dead zone): plan the manoeuvre of
//!    [`region2`] (rotate −β, travel d, rotate φ, landing on the axis at δ);
//! 3. **far ellipse** alone: approach it at the far speed;
//! 4. **blue only**: turn toward the blue region, creep once centred;
//! 5. **nothing**: slow search, alternating sides and doubling the sweep (below 360°);
//! 6. **final** (latched), from the 0.3 m area threshold: arm to −K_arm·y_dev, lights on,
//!    slow constant speed for a set time, then stop and close the guides; without the dock
//!    switch by then, back away and retry (up to `max_retries`);
//! 7. **vision-tracked rotation** (latched): the part of −β that keeps the ellipse in view,
//!    ended by a one-frame predictor before the ellipse leaves the image; the odometry
//!    origin is then reset with the angle vision measured. The rest of −β, the travel (the
//!    inverse (x_ref, y_ref) controller of [`PointController`](crate::schemas::PointController))
//!    and φ run on odometry; then the robot looks, and searches slowly if the pyramid is
//!    not in view.
//!
//! Beyond the paper (profile switch `leave_dead_zone`): a robot misaligned inside the dead
//! zone backs away to `dead_zone_exit_m` first, so that region II can align it; the paper's
//! points 1 and 3 never docked.
//!
//! Simplified relative to the paper: the simulator is planar, so the arm command and the
//! lights are issued but do not change what the camera sees.

pub mod agent;
pub mod region2;
pub mod states;

pub use agent::RaposaAgent;
pub use region2::Region2Plan;
pub use states::{ServoState, select_state};
