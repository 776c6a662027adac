//! How the loop learns that a device thread is stuck, panicked, or that the actuators keep
//! rejecting commands, without the device threads allocating or the loop blocking.

use crate::robot::DeviceId;
use std::sync::Mutex;

/// The call a device thread is inside, if any: which device and since when (run time, s).
/// The thread marks each call; the loop reads it every tick and declares the device
/// blocked once one call has lasted longer than the runtime's device timeout.
#[derive(Debug, Default)]
pub(super) struct Watch {
    call: Mutex<Option<(DeviceId, f64)>>,
}

impl Watch {
    /// The thread is about to call `device` at run time `t`.
    pub(super) fn enter(&self, device: DeviceId, t: f64) {
        *lock(&self.call) = Some((device, t));
    }

    /// The call returned.
    pub(super) fn leave(&self) {
        *lock(&self.call) = None;
    }

    /// The device whose call has lasted `timeout_s` or more at `now`, and for how long.
    pub(super) fn stuck(&self, now: f64, timeout_s: f64) -> Option<(DeviceId, f64)> {
        let (device, since) = (*lock(&self.call))?;
        (now - since >= timeout_s).then_some((device, now - since))
    }

    /// The device being called (after a panic: the one that panicked).
    pub(super) fn current(&self) -> Option<DeviceId> {
        lock(&self.call).map(|(d, _)| d)
    }
}

/// Locks, ignoring poisoning: the data is a plain value that a panic cannot leave torn.
fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// Runs a device call, turning a panic inside the driver into its message.
pub(super) fn guarded<R>(f: impl FnOnce() -> R) -> Result<R, String> {
    crate::panics::contain("a panic with no message", f)
}

/// The actuators' record of rejected commands, kept by the actuator thread and read by the
/// loop.
///
/// An *episode* starts at the first rejection after a command from the behaviors was
/// accepted, and ends only when one is accepted again: a drive that accepts the runtime's
/// stops but rejects every motion still fails, and the run ends once the episode has lasted
/// the device timeout.
#[derive(Debug, Default)]
pub(super) struct ActuatorHealth {
    state: Mutex<Health>,
}

/// See [`ActuatorHealth`].
#[derive(Debug, Default, Clone, Copy)]
pub(super) struct Health {
    /// When the current episode began, s.
    pub(super) episode_since: Option<f64>,
    /// The last device that rejected a command, and when, s.
    pub(super) last_error: Option<(DeviceId, f64)>,
}

impl ActuatorHealth {
    /// Records one applied command: `rejected_by` the first device that failed, if any;
    /// `from_behaviors` false for the runtime's own stops.
    pub(super) fn record(&self, t: f64, rejected_by: Option<DeviceId>, from_behaviors: bool) {
        let mut h = lock(&self.state);
        match rejected_by {
            Some(device) => {
                h.episode_since.get_or_insert(t);
                h.last_error = Some((device, t));
            }
            None if from_behaviors => h.episode_since = None,
            None => {}
        }
    }

    /// The record as it stands.
    pub(super) fn get(&self) -> Health {
        *lock(&self.state)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_watch_names_the_device_stuck_past_the_timeout() {
        let w = Watch::default();
        assert_eq!(w.stuck(10.0, 1.0), None);
        w.enter(DeviceId::nth("camera", 1), 2.0);
        assert_eq!(w.stuck(2.5, 1.0), None);
        assert_eq!(w.stuck(3.5, 1.0), Some((DeviceId::nth("camera", 1), 1.5)));
        w.leave();
        assert_eq!(w.stuck(9.0, 1.0), None);
    }

    #[test]
    fn guarded_turns_a_panic_into_its_message() {
        assert_eq!(guarded(|| 3), Ok(3));
        assert_eq!(guarded(|| -> i32 { panic!("usb gone") }), Err("usb gone".to_owned()));
        let n = 7;
        assert_eq!(guarded(|| -> i32 { panic!("{n} bytes") }), Err("7 bytes".to_owned()));
    }

    #[test]
    fn only_an_accepted_command_from_the_behaviors_ends_an_episode() {
        let h = ActuatorHealth::default();
        let drive = DeviceId::one("drive");
        h.record(1.0, Some(drive), true);
        h.record(1.1, None, false); // the runtime's stop went through
        assert_eq!(h.get().episode_since, Some(1.0));
        h.record(1.2, Some(drive), true);
        assert_eq!(h.get().episode_since, Some(1.0));
        assert_eq!(h.get().last_error, Some((drive, 1.2)));
        h.record(1.3, None, true);
        assert_eq!(h.get().episode_since, None);
    }
}
