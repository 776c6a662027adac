//! The agent abstraction and its construction from a profile.

use crate::profile::{ApproachKind, Profile};
use crate::schemas::Behavior;
use thiserror::Error;

/// A robot's behaviors for one docking experiment.
pub trait Agent: Behavior {
    /// Switches to the departure phase (leave the dock, imprint on the way). Returns false
    /// when the agent has none, in which case it stays ready to dock.
    fn begin_departure(&mut self) -> bool;
    /// Switches to the docking phase; the robot may have been moved since departure.
    fn begin_docking(&mut self);
    /// An a-priori estimate of the dock's pose (entrance, +x out along its axis) in the
    /// odometry frame the next docking starts in: from GPS, or remembered from the
    /// departure. With one, docking starts with a ballistic drive to the dock's approach
    /// zone; without (`None`, the default), the robot is taken to be placed within sight
    /// of the dock. Agents that cannot use it ignore it.
    fn set_dock_hint(&mut self, _hint: Option<crate::geometry::Pose2>) {}
    /// Counters of the current docking run (for campaign records).
    fn stats(&self) -> AgentStats {
        AgentStats::default()
    }
}

/// Counters an agent keeps per docking run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct AgentStats {
    /// Alignment manoeuvres started (RAPOSA's region-II iterations).
    pub manoeuvres: u32,
}

/// Why no agent could be built for a profile.
#[derive(Debug, Clone, Error)]
pub enum BuildError {
    /// The profile's approach has no behavior implementation.
    #[error("profile `{profile}`: approach `{approach:?}` has no docking behavior in this build")]
    NoBehavior {
        /// The profile.
        profile: String,
        /// Its approach.
        approach: ApproachKind,
    },
    /// The profile's `[behavior.tree]` does not build: an unknown schema, params a schema
    /// refuses (the error names the profile's line).
    #[error("{0}")]
    Tree(crate::config::ConfigError),
    /// The profile lacks something the behavior needs.
    #[error("profile `{profile}`: {what}")]
    Profile {
        /// The profile.
        profile: String,
        /// What is missing.
        what: String,
    },
}

/// Builds the agent a profile selects.
///
/// # Errors
/// [`BuildError`] when the profile's approach has no implementation or lacks what it needs.
pub fn agent_for(profile: &Profile) -> Result<Box<dyn Agent>, BuildError> {
    match profile.behavior.approach {
        ApproachKind::RatioSteering | ApproachKind::PotentialField if profile.fiducial.two_block.is_some() => {
            Ok(Box::new(super::bujold::BujoldAgent::new(profile)?))
        }
        ApproachKind::SevenState if profile.fiducial.pyramid.is_some() => {
            Ok(Box::new(super::raposa::RaposaAgent::new(profile)?))
        }
        approach => Err(BuildError::NoBehavior {
            profile: profile.name.clone(),
            approach,
        }),
    }
}
