//! What a [`Registry`](super::registry::Registry)'s factories get to build one node of a
//! profile's tree: the node's name and `params`, the whole profile, and the helpers every
//! factory needs (typed params read strictly, the devices the leaf uses, the phase its
//! feedback names).

use crate::profile::Profile;
use serde::de::DeserializeOwned;

/// What a factory gets to build one leaf.
pub struct LeafArgs<'a> {
    /// The node's name in the tree. The tree names the leaf by it (its
    /// [`Behavior::name`](crate::schemas::Behavior::name): sequencers find their states,
    /// and traces name them, by it), so a factory need not hand it to the leaf; a leaf
    /// whose feedback names its node takes [`LeafArgs::phase`].
    pub node: &'a str,
    /// The name of the node this leaf is a child of (the sequencer or arbiter it is a
    /// state or child of); `None` at the top of what is built.
    pub parent: Option<&'a str>,
    /// The node's `params` table.
    pub params: &'a toml::Table,
    /// The whole profile (geometry, limits, perception).
    pub profile: &'a Profile,
}

impl LeafArgs<'_> {
    /// Index of the profile's first `[[sensors]]` entry of kind `kind` (the leaf reads it
    /// as [`Inputs::sensor`](crate::schemas::Inputs::sensor)).
    ///
    /// # Errors
    /// A message saying the leaf needs such a sensor and the profile declares none.
    pub fn sensor(&self, kind: &str) -> Result<usize, String> {
        self.profile
            .sensors
            .iter()
            .position(|s| s.kind == kind)
            .ok_or_else(|| format!("needs a [[sensors]] entry of kind `{kind}`, and the profile declares none"))
    }

    /// Index of the profile's first `[[actuators]]` entry of kind `kind` (the leaf
    /// commands its kind through [`Auxiliary::set`](crate::schemas::Auxiliary::set)).
    ///
    /// # Errors
    /// A message saying the leaf needs such an actuator and the profile declares none.
    pub fn actuator(&self, kind: &str) -> Result<usize, String> {
        self.profile
            .actuators
            .iter()
            .position(|a| a.kind == kind)
            .ok_or_else(|| format!("needs an [[actuators]] entry of kind `{kind}`, and the profile declares none"))
    }

    /// Deserializes the node's params into the schema's own tuning struct (use
    /// `#[serde(deny_unknown_fields, default)]` so a misspelt field is refused and an
    /// absent one keeps its default).
    ///
    /// # Errors
    /// The deserializer's message, naming the field.
    pub fn params<T: DeserializeOwned>(&self) -> Result<T, String> {
        toml::Value::Table(self.params.clone())
            .try_into()
            .map_err(|e: toml::de::Error| format!("params: {}", e.message().trim()))
    }

    /// The node's name as a phase for [`Feedback`](crate::schemas::Feedback): interned,
    /// one copy per distinct name in the process, so a leaf shared by several phases
    /// (the legs of a manoeuvre) reports the node it runs as.
    pub fn phase(&self) -> &'static str {
        intern(self.node)
    }

    /// The phase a leg of a larger manoeuvre reports: its parent's name, interned as
    /// [`LeafArgs::phase`] is (the node's own name at the top of what is built). Axel's
    /// settle, look and step legs all report the sensing phase they are the cycle of.
    pub fn parent_phase(&self) -> &'static str {
        intern(self.parent.unwrap_or(self.node))
    }

    /// Refuses params for a schema that takes none.
    ///
    /// # Errors
    /// A message naming the first param given.
    pub fn no_params(&self) -> Result<(), String> {
        match self.params.keys().next() {
            None => Ok(()),
            Some(k) => Err(format!("params: unknown field `{k}`: this schema takes no params")),
        }
    }
}

/// What a factory gets to build a sequencer's selector.
pub struct SelectorArgs<'a> {
    /// The sequencer's name in the tree.
    pub node: &'a str,
    /// Its states, in order: the selector returns indices into this list.
    pub states: &'a [String],
    /// The whole profile.
    pub profile: &'a Profile,
}

impl SelectorArgs<'_> {
    /// Index of the state named `name`.
    ///
    /// # Errors
    /// A message naming the missing state (the selector needs it).
    pub fn state(&self, name: &str) -> Result<usize, String> {
        self.states
            .iter()
            .position(|s| s == name)
            .ok_or_else(|| format!("needs a state named `{name}` (states: {})", self.states.join(", ")))
    }
}

/// One `&'static` copy of `name` per distinct name (node names are few and built once).
fn intern(name: &str) -> &'static str {
    use std::collections::BTreeSet;
    use std::sync::{Mutex, OnceLock};
    static NAMES: OnceLock<Mutex<BTreeSet<&'static str>>> = OnceLock::new();
    let mut names = NAMES
        .get_or_init(|| Mutex::new(BTreeSet::new()))
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner);
    if let Some(n) = names.get(name) {
        return n;
    }
    let n: &'static str = Box::leak(name.to_owned().into_boxed_str());
    names.insert(n);
    n
}
