//! What the simulator must know of a crate's own kinds to run its robot: how to draw the
//! dock of each fiducial kind ([`DockPainters`]) and how to simulate each device kind
//! ([`SimDevices`]). [`SimKinds::default`] knows the crate's own; a crate whose robot has
//! a fiducial or a sensor of its own registers them here, beside its robot kind in the
//! [`Catalog`](crate::behaviors::Catalog), and hands both to
//! [`campaign::prepare_with`](super::campaign::prepare_with) or to its own `marsupial`
//! command (`marsupial::cli::run_with`).

use super::robot::SimDevices;
use super::world::DockPainters;

/// See the module docs.
#[derive(Clone, Default)]
pub struct SimKinds {
    /// Dock painters by fiducial kind.
    pub painters: DockPainters,
    /// Device simulations by sensor kind.
    pub devices: SimDevices,
}
