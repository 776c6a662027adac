//! Building the robot a profile describes.

use crate::profile::Profile;
use crate::schemas::Agent;
use thiserror::Error;

/// Why no agent could be built for a profile.
#[derive(Debug, Clone, Error)]
pub enum BuildError {
    /// The profile's `[behavior.tree]` does not build: an unknown schema, params a schema
    /// refuses (the error names the profile's line).
    #[error("{0}")]
    Tree(crate::config::ConfigError),
    /// The profile's `[robot]` table is not one the catalog can build: an unknown robot
    /// kind, or tuning the kind refuses (the error names the profile's line).
    #[error("{0}")]
    Invalid(crate::config::ConfigError),
    /// The profile lacks something the behavior needs.
    #[error("profile `{profile}`: {what}")]
    Profile {
        /// The profile.
        profile: String,
        /// What is missing.
        what: String,
    },
}

/// Builds the robot `profile`'s `[robot] kind` names, with the crate's catalog
/// ([`super::catalog::shipped`]); a crate with robot kinds of its own uses its
/// [`Catalog`](super::catalog::Catalog) instead.
///
/// # Errors
/// As [`Catalog::agent`](super::catalog::Catalog::agent).
pub fn agent_for(profile: &Profile) -> Result<Box<dyn Agent>, BuildError> {
    super::catalog::shipped().agent(profile)
}
