//! Memory shared by the nodes of one composed behavior.
//!
//! A robot's phase schemas are separate behaviors under the arbiters, yet they share what
//! the robot knows: this tick's percepts, where the fiducial was last seen, how many
//! retries are left, the plan one phase hands the next. A [`Blackboard`] holds that memory
//! once; every node built for the robot keeps a clone of the handle.
//!
//! The reactive loop ticks its tree on one thread, one node at a time, so the lock is
//! never contended (it costs an uncontended atomic swap); it exists because behaviors are
//! `Send` (the threaded runtime moves the loop onto its own thread).

use std::sync::{Arc, Mutex, MutexGuard};

/// A shared, lockable memory (see the module docs).
pub struct Blackboard<T>(Arc<Mutex<T>>);

impl<T> Clone for Blackboard<T> {
    fn clone(&self) -> Self {
        Self(Arc::clone(&self.0))
    }
}

impl<T> Blackboard<T> {
    /// A blackboard holding `memory`.
    pub fn new(memory: T) -> Self {
        Self(Arc::new(Mutex::new(memory)))
    }

    /// Locks the memory. A node that panicked while holding it leaves the memory as it
    /// was; the next node still gets it (the loop decides what a panic means, not this).
    pub fn lock(&self) -> MutexGuard<'_, T> {
        self.0.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    /// Runs `f` on the memory.
    pub fn with<R>(&self, f: impl FnOnce(&mut T) -> R) -> R {
        f(&mut self.lock())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clones_share_one_memory() {
        let a = Blackboard::new(1u32);
        let b = a.clone();
        b.with(|m| *m += 41);
        assert_eq!(*a.lock(), 42);
    }
}
