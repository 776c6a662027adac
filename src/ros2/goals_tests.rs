//! Results: the typed outcome and Nav2's code for it, without a network.

use super::*;
use crate::schemas::FailureReason;

fn report(outcome: Option<Outcome>) -> RuntimeReport {
    RuntimeReport {
        outcome,
        ..RuntimeReport::default()
    }
}

fn progress(last: u16, retries: u16) -> Progress {
    let mut p = Progress::new([0; 16], true, StopHandle::new(), Some(10.0));
    p.state = (last, 0.0);
    p.retries = retries;
    p
}

#[test]
fn results_carry_the_typed_outcome_and_nav2_codes() {
    let r = result_of(
        &report(Some(Outcome::Docked)),
        false,
        &progress(state::CONTROLLING, 1),
        true,
    );
    assert_eq!(
        (r.status, r.success, r.error_code, r.error_msg.as_str(), r.num_retries),
        (4, true, 0, "docked", 1)
    );
    let lost = report(Some(Outcome::Failed(FailureReason::TargetLost)));
    let r = result_of(&lost, false, &progress(state::CONTROLLING, 0), true);
    assert_eq!((r.status, r.error_code, r.error_msg.as_str()), (6, 904, "target_lost"));
    let stuck = report(Some(Outcome::Failed(FailureReason::StuckContact)));
    assert_eq!(
        result_of(&stuck, false, &progress(state::CONTROLLING, 0), true).error_code,
        905
    );
    assert_eq!(
        result_of(&stuck, false, &progress(state::WAIT_FOR_CHARGE, 0), true).error_code,
        906
    );
    let late = report(Some(Outcome::Failed(FailureReason::Timeout)));
    assert_eq!(
        result_of(&late, false, &progress(state::NAV_TO_STAGING_POSE, 0), true).error_code,
        903
    );
    assert_eq!(
        result_of(&lost, false, &progress(state::NONE, 0), false).error_code,
        905
    );
    let r = result_of(&report(None), true, &progress(state::NONE, 0), true);
    assert_eq!((r.status, r.error_msg.as_str()), (5, "canceled"));
    let r = result_of(&report(None), false, &progress(state::NONE, 0), true);
    assert_eq!((r.status, r.error_code, r.error_msg.as_str()), (6, 907, "timeout"));
    let mut p = progress(state::NAV_TO_STAGING_POSE, 0);
    p.staged_out = true;
    let r = result_of(&report(None), true, &p, true);
    assert_eq!(r.error_code, 903);
    assert!(r.error_msg.contains("max_staging_time"), "{}", r.error_msg);
}
