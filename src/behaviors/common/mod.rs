//! Schemas any robot's tree can use, whatever its shared memory: they read only the
//! tick's inputs and their own params. [`register`] adds them to a robot's registry under
//! their plain names (no robot prefix).

pub mod avoid;

use super::registry::{LeafArgs, Registry};

/// Registers the common schemas (`avoid_obstacles`) in `registry`.
pub fn register<C>(registry: &mut Registry<C>) {
    registry.register("avoid_obstacles", |_: &C, a: &LeafArgs<'_>| {
        Ok(Box::new(avoid::AvoidLeaf::from_args(a)?))
    });
}
