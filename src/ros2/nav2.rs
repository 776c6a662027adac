//! Nav2's docking vocabulary and how the robot's behaviors map onto it: the feedback
//! states a `DockRobot` goal reports, derived from the running phase, and the error code
//! a result carries, derived from the typed outcome.
//!
//! Nav2's docking server runs fixed stages (drive to the staging pose, detect the dock,
//! control onto it, wait for charge, retry); our robots run composed behaviors whose
//! leaves have their own names (`search`, `approach`, `back_in` …). [`PHASE_STATES`] is
//! the one table between the two, written from the shipped profiles' phase names.

use crate::schemas::FailureReason;

/// `nav2_msgs/action/DockRobot_Feedback`'s state constants.
pub mod state {
    /// No docking stage: idle, a safe stop (inputs stale, the base stopped), or a phase
    /// the table does not know.
    pub const NONE: u16 = 0;
    /// Driving to the staging pose: an odometry leg towards the dock's approach zone or
    /// back onto its axis.
    pub const NAV_TO_STAGING_POSE: u16 = 1;
    /// Looking for the dock before controlling onto it.
    pub const INITIAL_PERCEPTION: u16 = 2;
    /// Servoing onto the dock by what the camera sees, or the blind final entry.
    pub const CONTROLLING: u16 = 3;
    /// On the dock, waiting for the contact (or charge) that ends the docking.
    pub const WAIT_FOR_CHARGE: u16 = 4;
    /// Backing off to try again.
    pub const RETRY: u16 = 5;
}

/// `nav2_msgs/action/DockRobot_Result`'s (and `UndockRobot_Result`'s) error codes.
pub mod error {
    /// Success.
    pub const NONE: u16 = 0;
    /// The `dock_id` is not in the dock database.
    pub const DOCK_NOT_IN_DB: u16 = 901;
    /// The dock (its pose, frame or type) or another goal field is unusable.
    pub const DOCK_NOT_VALID: u16 = 902;
    /// The drive to the staging pose failed or took longer than `max_staging_time`.
    pub const FAILED_TO_STAGE: u16 = 903;
    /// The dock was never seen, or lost.
    pub const FAILED_TO_DETECT_DOCK: u16 = 904;
    /// The controller could not bring the robot onto the dock.
    pub const FAILED_TO_CONTROL: u16 = 905;
    /// On the dock, but the contact (or charge) never came.
    pub const FAILED_TO_CHARGE: u16 = 906;
    /// A time limit ran out.
    pub const TIMEOUT: u16 = 907;
    /// Anything else (the runtime aborted: a device failed).
    pub const UNKNOWN: u16 = 999;
}

/// The feedback state of each docking phase of the shipped profiles (`bujold`,
/// `bujold-avoid`, `bujold-raposa`, `raposa`, `axel`), by the phase's leaf name, which is
/// what [`crate::schemas::Feedback::phase`] reports:
/// * ballistic legs and repositioning onto the axis (Bujold's `ballistic*` and
///   `reposition*`, RAPOSA's region-II plan `region_2`, `rotate_7`, `rotate_odo`,
///   `travel`, `rotate_phi`): `NAV_TO_STAGING_POSE`;
/// * searching and looking (`search`, `unjam*`, `look`, `probe`, `leave_dead_zone`,
///   Axel's `acquire`, whose cycle's legs `acquire_start`, `_look`, `_step` and
///   `_settle` report it) and Bujold's `decide` (a look at the fiducial before backing in):
///   `INITIAL_PERCEPTION`;
/// * servoing and the final entry (`approach*`, `avoid`, `back_in`, `servo`, `align*`,
///   `far_ellipse`, `blue_only`, `final`, Axel's `mate*`): `CONTROLLING`;
/// * the dock contact that subsumes every phase (`dock_switch`; Axel's `stall` guard):
///   `WAIT_FOR_CHARGE`;
/// * backing off to try again (`move_away`, `retreat`, `give_up`): `RETRY`. A rise in
///   the behavior's retry count is reported as one `RETRY` message as well.
///
/// A phase not listed is `NONE`; so is a departure's phase (undocking has no feedback in
/// Nav2's interface).
pub const PHASE_STATES: &[(&str, u16)] = &[
    ("ballistic", state::NAV_TO_STAGING_POSE),
    ("ballistic_face", state::NAV_TO_STAGING_POSE),
    ("ballistic_drive", state::NAV_TO_STAGING_POSE),
    ("ballistic_align", state::NAV_TO_STAGING_POSE),
    ("reposition", state::NAV_TO_STAGING_POSE),
    ("reposition_clear", state::NAV_TO_STAGING_POSE),
    ("reposition_face", state::NAV_TO_STAGING_POSE),
    ("reposition_drive", state::NAV_TO_STAGING_POSE),
    ("reposition_align", state::NAV_TO_STAGING_POSE),
    ("region_2", state::NAV_TO_STAGING_POSE),
    ("rotate_7", state::NAV_TO_STAGING_POSE),
    ("rotate_odo", state::NAV_TO_STAGING_POSE),
    ("travel", state::NAV_TO_STAGING_POSE),
    ("rotate_phi", state::NAV_TO_STAGING_POSE),
    ("search", state::INITIAL_PERCEPTION),
    ("unjam", state::INITIAL_PERCEPTION),
    ("unjam_turn", state::INITIAL_PERCEPTION),
    ("unjam_out", state::INITIAL_PERCEPTION),
    ("look", state::INITIAL_PERCEPTION),
    ("probe", state::INITIAL_PERCEPTION),
    ("leave_dead_zone", state::INITIAL_PERCEPTION),
    ("acquire", state::INITIAL_PERCEPTION),
    ("acquire_start", state::INITIAL_PERCEPTION),
    ("acquire_look", state::INITIAL_PERCEPTION),
    ("acquire_step", state::INITIAL_PERCEPTION),
    ("acquire_settle", state::INITIAL_PERCEPTION),
    ("decide", state::INITIAL_PERCEPTION),
    ("approach", state::CONTROLLING),
    ("approach_start", state::CONTROLLING),
    ("approach_look", state::CONTROLLING),
    ("approach_step", state::CONTROLLING),
    ("approach_settle", state::CONTROLLING),
    ("approach_field", state::CONTROLLING),
    ("approach_near", state::CONTROLLING),
    ("avoid", state::CONTROLLING),
    ("back_in", state::CONTROLLING),
    ("servo", state::CONTROLLING),
    ("align", state::CONTROLLING),
    ("align_start", state::CONTROLLING),
    ("align_look", state::CONTROLLING),
    ("align_step", state::CONTROLLING),
    ("align_settle", state::CONTROLLING),
    ("far_ellipse", state::CONTROLLING),
    ("blue_only", state::CONTROLLING),
    ("final", state::CONTROLLING),
    ("mate", state::CONTROLLING),
    ("mate_close", state::CONTROLLING),
    ("mate_reel", state::CONTROLLING),
    ("dock_switch", state::WAIT_FOR_CHARGE),
    ("stall", state::WAIT_FOR_CHARGE),
    ("move_away", state::RETRY),
    ("retreat", state::RETRY),
    ("give_up", state::RETRY),
];

/// The feedback state of the docking phase `phase` ([`PHASE_STATES`]; `NONE` when not
/// listed).
pub fn state_of(phase: &str) -> u16 {
    PHASE_STATES
        .iter()
        .find(|(p, _)| *p == phase)
        .map_or(state::NONE, |(_, s)| *s)
}

/// Nav2's error code for a docking (`dock`) or undocking that failed with `reason` while
/// its last reported state was `last_state`:
/// * `target_never_detected`, `target_lost` → `FAILED_TO_DETECT_DOCK`;
/// * `timeout` → `FAILED_TO_STAGE` when it ran out while driving to the staging pose,
///   otherwise `TIMEOUT`;
/// * `failed_to_control`, `stuck_contact`, `retries_exhausted` → `FAILED_TO_CHARGE` when
///   it failed waiting for the contact, `FAILED_TO_STAGE` while staging, otherwise
///   `FAILED_TO_CONTROL` (Nav2 also ends on the last retry's error).
///
/// An undocking has only `TIMEOUT` and `FAILED_TO_CONTROL` (`UndockRobot`'s codes).
pub fn error_code(reason: FailureReason, last_state: u16, dock: bool) -> u16 {
    use FailureReason as F;
    match (reason, dock) {
        (F::Timeout, false) => error::TIMEOUT,
        (_, false) => error::FAILED_TO_CONTROL,
        (F::TargetNeverDetected | F::TargetLost, true) => error::FAILED_TO_DETECT_DOCK,
        (F::Timeout, true) if last_state == state::NAV_TO_STAGING_POSE => error::FAILED_TO_STAGE,
        (F::Timeout, true) => error::TIMEOUT,
        (F::FailedToControl | F::StuckContact | F::RetriesExhausted, true) => match last_state {
            state::WAIT_FOR_CHARGE => error::FAILED_TO_CHARGE,
            state::NAV_TO_STAGING_POSE => error::FAILED_TO_STAGE,
            _ => error::FAILED_TO_CONTROL,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every docking phase of every shipped profile is in the table: a new phase name
    /// must be given its Nav2 state here, or it would report `NONE`.
    #[test]
    fn every_shipped_docking_phase_has_a_state() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles");
        // Composite nodes (the behavior's root, its two missions and their sequencers) and
        // the departure's phases report no docking state.
        let not_docking = [
            "bujold",
            "raposa",
            "axel",
            "krawler",
            "departure",
            "docking",
            "close_dock",
            "dock",
            "undock",
            "drive_out",
            "imprint",
            "depart",
            "drive",
            "slip_monitor",
            "traverse",
            "halt",
        ];
        for entry in std::fs::read_dir(&root).unwrap() {
            let path = entry.unwrap().path();
            let text = std::fs::read_to_string(&path).unwrap();
            for line in text.lines() {
                let Some(name) = line
                    .strip_prefix("[behavior.tree.nodes.")
                    .and_then(|l| l.strip_suffix(']'))
                else {
                    continue;
                };
                if !not_docking.contains(&name) {
                    assert_ne!(state_of(name), state::NONE, "{}: phase `{name}`", path.display());
                }
            }
        }
        assert_eq!(state_of("safe_stop"), state::NONE);
    }

    #[test]
    fn failures_get_the_code_of_the_stage_they_failed_in() {
        use FailureReason as F;
        assert_eq!(error_code(F::TargetLost, state::CONTROLLING, true), 904);
        assert_eq!(error_code(F::TargetNeverDetected, state::INITIAL_PERCEPTION, true), 904);
        assert_eq!(error_code(F::Timeout, state::NAV_TO_STAGING_POSE, true), 903);
        assert_eq!(error_code(F::Timeout, state::CONTROLLING, true), 907);
        assert_eq!(error_code(F::FailedToControl, state::CONTROLLING, true), 905);
        assert_eq!(error_code(F::StuckContact, state::WAIT_FOR_CHARGE, true), 906);
        assert_eq!(error_code(F::RetriesExhausted, state::RETRY, true), 905);
        assert_eq!(error_code(F::TargetLost, state::NONE, false), 905);
        assert_eq!(error_code(F::Timeout, state::NONE, false), 907);
    }
}
