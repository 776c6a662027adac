//! Building the robot a profile describes.

use crate::profile::{ApproachKind, Profile};
use crate::schemas::Agent;
use thiserror::Error;

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

/// Builds the agent a profile selects: Bujold's for ratio steering or a potential field on
/// a two-block flap; RAPOSA's for the seven-state servo, on a pyramid or, through the
/// two-block adapter ([`super::raposa::source`]), on a two-block flap; Axel's for the
/// two-arc approach on circle fiducials.
///
/// # Errors
/// [`BuildError`] when the profile's approach has no implementation or lacks what it needs.
pub fn agent_for(profile: &Profile) -> Result<Box<dyn Agent>, BuildError> {
    match profile.behavior.approach {
        ApproachKind::RatioSteering | ApproachKind::PotentialField if profile.fiducial.two_block.is_some() => {
            Ok(Box::new(super::bujold::agent(profile)?))
        }
        ApproachKind::SevenState if profile.fiducial.pyramid.is_some() || profile.fiducial.two_block.is_some() => {
            Ok(Box::new(super::raposa::agent(profile)?))
        }
        ApproachKind::TwoArc if profile.fiducial.circles.is_some() => Ok(Box::new(super::axel::agent(profile)?)),
        approach => Err(BuildError::NoBehavior {
            profile: profile.name.clone(),
            approach,
        }),
    }
}
