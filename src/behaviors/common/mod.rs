//! Schemas any robot's tree can use. [`register`] adds those that read only the tick's
//! inputs and their own params (`avoid_obstacles`) to a robot's registry under their plain
//! names. The others reach the robot through small traits its memory implements, and each
//! robot registers them under its own names with its own settings:
//! * [`docking`]: `imprint` and `dock_switch`, over [`docking::DockingMemory`];
//! * [`motion`]: the legs of a manoeuvre by odometry (turn to a heading, back off, drive
//!   until abeam), over [`motion::Motion`], which a robot's profile sequences into its
//!   manoeuvres;
//! * [`search`]: the search turn until the target is acquired, over
//!   [`search::Searching`].
//!
//! [`retries`] counts a docking's retries against `behavior.max_retries`, the same way
//! for every robot; [`median`] is the median window both robots smooth their viewing-angle estimates with.

pub mod avoid;
pub mod docking;
pub mod median;
pub mod motion;
pub mod retries;
pub mod search;

use super::registry::{LeafArgs, Registry};

/// Registers the common schemas (`avoid_obstacles`) in `registry`.
pub fn register<M: 'static>(registry: &mut Registry<M>) {
    registry.register("avoid_obstacles", |_: &M, a: &LeafArgs<'_>| {
        Ok(Box::new(avoid::AvoidLeaf::from_args(a)?))
    });
}
