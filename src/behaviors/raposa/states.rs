//! The seven states and their selection rules (seed 001 §II.D).
//!
//! After the best pair is chosen:
//!
//! * a pair: state 6 when the ball is at or inside the final distance; state 1 inside
//!   the dead zone (socket to ball under `distance_threshold_m`: α is unreliable there);
//!   state 2 (region II) when α exceeds the angle threshold; state 1 otherwise;
//! * no pair, an ellipse: state 6 near, state 3 far (beyond `far_distance_m`), state 1
//!   between;
//! * no ellipse, a blue region: state 4;
//! * nothing: state 5.
//!
//! States 6 and 7 latch: the caller does not select again until their manoeuvre ends.
//!
//! The paper writes the region-II rule as "angles bigger than 15° and/or distances bigger
//! than 34 cm". We read it as both: an "or" would send every start beyond 34 cm, aligned
//! or not, into the alignment manoeuvre, and the paper's dead zone (its points 1 and 3, at
//! 0.33 m) is exactly the pairs closer than 34 cm. Right after a region-II manoeuvre the
//! angle threshold is widened by `settle_tolerance_deg`, the paper's tolerance for
//! odometry error at the region boundary.

use super::tuning::SevenStateGains;
use crate::perception::PyramidPercept;
use serde::Serialize;

/// The seven states of seed 001, plus our dead-zone exit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum ServoState {
    /// Region I approach: servo on the ellipse.
    S1Approach,
    /// Region II: plan the alignment manoeuvre.
    S2Align,
    /// A lone ellipse far away: approach it (the paper does not say how; we run the
    /// state-1 law at its constant far speed until the blue edges join it).
    S3FarEllipse,
    /// Blue edges, no ellipse: turn toward them and creep once centred (the guide may be
    /// hidden by glare or the pyramid's own body).
    S4BlueOnly,
    /// Nothing: slow search, alternating and doubling its sweep.
    S5Nothing,
    /// Final approach at constant low speed for a set time, then close the guides.
    S6Final,
    /// Vision-tracked rotation of the region-II manoeuvre.
    S7Rotate,
    /// Ours: misaligned inside the dead zone, back away before choosing again.
    LeaveDeadZone,
    /// Ours: only the ball, no pair this docking, inside the dead zone for `lost_frames`
    /// frames: the side is unknown, so move around the ball and look again
    /// (`raposa.probe`, [`probe_due`]).
    Probe,
}

impl ServoState {
    /// Name for feedback and logs.
    pub fn name(&self) -> &'static str {
        match self {
            ServoState::S1Approach => "state_1",
            ServoState::S2Align => "state_2",
            ServoState::S3FarEllipse => "state_3",
            ServoState::S4BlueOnly => "state_4",
            ServoState::S5Nothing => "state_5",
            ServoState::S6Final => "state_6",
            ServoState::S7Rotate => "state_7",
            ServoState::LeaveDeadZone => "leave_dead_zone",
            ServoState::Probe => "probe",
        }
    }

    /// States 6 and 7 hold until their manoeuvre ends.
    pub fn latched(&self) -> bool {
        matches!(self, ServoState::S6Final | ServoState::S7Rotate)
    }
}

/// Selects the state for a percept. `socket_inset` is the camera's distance in front of
/// the socket (camera-to-ball minus socket-to-ball), `settling` widens the angle
/// threshold right after a region-II manoeuvre.
pub fn select_state(p: &PyramidPercept, g: &SevenStateGains, socket_inset: f64, settling: bool) -> ServoState {
    let Some(v) = p.view else {
        return if p.detection.blue.is_some() {
            ServoState::S4BlueOnly
        } else {
            ServoState::S5Nothing
        };
    };
    if v.ball_distance_m <= g.final_distance_m {
        return ServoState::S6Final;
    }
    match v.alpha {
        Some(alpha) => {
            let threshold = g.angle_threshold_deg + if settling { g.settle_tolerance_deg } else { 0.0 };
            let misaligned = alpha.abs().to_degrees() > threshold;
            let socket_distance = v.ball_distance_m - socket_inset;
            if socket_distance < g.distance_threshold_m {
                if misaligned && g.leave_dead_zone {
                    ServoState::LeaveDeadZone
                } else {
                    ServoState::S1Approach
                }
            } else if misaligned {
                ServoState::S2Align
            } else {
                ServoState::S1Approach
            }
        }
        None if v.ball_distance_m >= g.far_distance_m => ServoState::S3FarEllipse,
        None => ServoState::S1Approach,
    }
}

/// Probes before the servo gives up probing and approaches the lone ball as state 1
/// does: two each way, alternating and growing, cover ±2 probe steps around the start.
pub const MAX_PROBES: u32 = 4;

/// Ours: whether to probe instead of approaching a lone ball (state 1 without α). Inside
/// the dead zone the pair cannot be seen from beyond about 60° off the axis, so nothing
/// tells the robot which side it is on and driving in catches the entrance (the paper's
/// points 1 and 3). When no pair has been seen this docking (`pair_seen`: one seen
/// earlier gave the side, and a lone ball now is a pair lost to the light), after
/// `lost_frames` such frames in a row (`lone`), and while fewer than [`MAX_PROBES`]
/// probes have been made, it probes.
pub fn probe_due(
    p: &PyramidPercept,
    g: &SevenStateGains,
    socket_inset: f64,
    lone: u32,
    probes: u32,
    pair_seen: bool,
) -> bool {
    let Some(v) = p.view else {
        return false;
    };
    !pair_seen
        && v.alpha.is_none()
        && v.ball_distance_m > g.final_distance_m
        && v.ball_distance_m - socket_inset < g.distance_threshold_m
        && lone >= g.lost_frames
        && probes < MAX_PROBES
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::perception::pyramid::{BlueRegion, Ellipse, PyramidDetection};
    use crate::perception::pyramid_pose::PyramidView;
    use crate::profile::Profile;

    fn gains() -> SevenStateGains {
        let p = Profile::load("profiles/raposa.toml".as_ref()).unwrap();
        crate::behaviors::catalog::tuning::<super::super::Raposa>(&p)
            .unwrap()
            .seven_state
    }

    fn percept(ellipse: bool, blue: bool, pair: bool, d: f64, alpha_deg: f64) -> PyramidPercept {
        let e = Ellipse {
            centre: [80.0, 60.0],
            semi_major: 5.0,
            semi_minor: 5.0,
            angle: 0.0,
            count: 80,
            bbox: [75, 55, 85, 65],
        };
        let b = BlueRegion {
            bbox: [70, 50, 90, 70],
            count: 100,
        };
        let mut p = PyramidPercept::not_found(0.0, (160, 120));
        p.detection = PyramidDetection {
            pair: None,
            ellipse: ellipse.then_some(e),
            blue: blue.then_some(b),
            candidates: 0,
        };
        if ellipse {
            p.view = Some(PyramidView {
                blue_distance_m: pair.then_some(d + 0.16),
                ball_distance_m: d,
                alpha: pair.then_some(alpha_deg.to_radians()),
                alpha_saturated: false,
                bearing: 0.0,
                dev_px: [0.0, 0.0],
                area_px: 80,
            });
        }
        p
    }

    #[test]
    fn pair_rules_thresholds_and_dead_zone() {
        let g = gains();
        let inset = 0.1;
        let s = |d, a| select_state(&percept(true, true, true, d, a), &g, inset, false);
        assert_eq!(s(1.5, 10.0), ServoState::S1Approach);
        assert_eq!(s(1.5, -14.9), ServoState::S1Approach);
        assert_eq!(s(1.5, 15.1), ServoState::S2Align, "beyond 15°");
        assert_eq!(s(1.5, -40.0), ServoState::S2Align);
        // Socket to ball 0.33 m (< 0.34): the dead zone; misaligned → leave it (ours).
        assert_eq!(s(0.43, 60.0), ServoState::LeaveDeadZone);
        assert_eq!(s(0.43, 5.0), ServoState::S1Approach);
        let paper = SevenStateGains {
            leave_dead_zone: false,
            ..g
        };
        assert_eq!(
            select_state(&percept(true, true, true, 0.43, 60.0), &paper, inset, false),
            ServoState::S1Approach,
            "the paper approaches anyway"
        );
        assert_eq!(s(0.29, 40.0), ServoState::S6Final, "area beyond the 0.3 m threshold");
        // Settling widens the threshold by settle_tolerance_deg.
        assert_eq!(
            select_state(&percept(true, true, true, 1.0, 18.0), &g, inset, true),
            ServoState::S1Approach
        );
    }

    #[test]
    fn lone_ellipse_blue_and_nothing() {
        let g = gains();
        let s = |e, b, d| select_state(&percept(e, b, false, d, 0.0), &g, 0.1, false);
        assert_eq!(s(true, false, 2.0), ServoState::S3FarEllipse);
        assert_eq!(s(true, true, 0.6), ServoState::S1Approach);
        assert_eq!(s(true, false, 0.25), ServoState::S6Final);
        assert_eq!(s(false, true, 0.0), ServoState::S4BlueOnly);
        assert_eq!(s(false, false, 0.0), ServoState::S5Nothing);
    }

    #[test]
    fn only_six_and_seven_latch() {
        use ServoState::*;
        for st in [S1Approach, S2Align, S3FarEllipse, S4BlueOnly, S5Nothing, LeaveDeadZone] {
            assert!(!st.latched());
        }
        assert!(S6Final.latched() && S7Rotate.latched());
    }
}
