//! `bujold.decide`: the at-dock decision (seed 004 §V: "if the ratio of left to right
//! pixel counts is close to one and the fiducial is centred, back in; otherwise move away
//! and retry"), made metric by [`at_dock_decision`].
//!
//! Stops and averages `frames` views. Events: `aligned` (back in), `misaligned`
//! (reposition, counting a retry), `retries_exhausted` (give up), `lost` (too few views
//! within `lost_after_s`: back off and look again, counting a retry).

use super::memory::{Memory, lowered};
use super::params::DecideParams;
use crate::perception::two_block_pose::FiducialView;
use crate::schemas::{Behavior, FailureReason, Inputs, MotorOutput, Step};

/// The at-dock decision: average the views, predict the lateral error where the rear
/// will reach the entrance, and back in only if that and the heading are within
/// `fraction` of the profile's tolerances, and the heading also at least `heading_margin`
/// inside its tolerance. The heading is the viewing angle α, from the blocks' pixel ratio,
/// less the fiducial's bearing; the bearing is a centroid and sharp, but α carries the
/// ratio's error, which partial shadows and flashes bias by up to 2–4° at the gate. The
/// back-in is blind, so that error must fit inside the tolerance. The rear sits `rear_behind_camera` behind the
/// camera along the heading θ and backs a further `to_go` to the entrance, so its lateral
/// error there is the camera's, d·sin α, less (rear_behind_camera + to_go)·sin θ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Decision {
    /// Back in now.
    pub back_in: bool,
    /// Mean viewing angle, rad.
    pub alpha: f64,
    /// Mean heading, rad.
    pub heading: f64,
    /// Mean camera distance, m.
    pub distance: f64,
    /// Predicted lateral error at the entrance, m.
    pub lateral_at_entrance: f64,
}

/// See [`Decision`]. An empty `samples` decides "no".
pub fn at_dock_decision(
    samples: &[FiducialView],
    rear_behind_camera: f64,
    tol_lateral: f64,
    tol_heading: f64,
    fraction: f64,
    heading_margin: f64,
) -> Decision {
    let n = samples.len().max(1) as f64;
    let alpha = samples.iter().map(|s| s.alpha).sum::<f64>() / n;
    let heading = samples.iter().map(|s| s.heading).sum::<f64>() / n;
    let distance = samples.iter().map(|s| s.distance).sum::<f64>() / n;
    let to_go = (distance - rear_behind_camera).max(0.0);
    let lateral_at_entrance = distance * alpha.sin() - (rear_behind_camera + to_go) * heading.sin();
    Decision {
        back_in: !samples.is_empty()
            && lateral_at_entrance.abs() <= fraction * tol_lateral
            && heading.abs() <= (fraction * tol_heading).min(tol_heading - heading_margin),
        alpha,
        heading,
        distance,
        lateral_at_entrance,
    }
}

/// The heading margin for a decision: the margin is insurance for a robot that can
/// still retry, so the last decision (`last`: a "no" would end the mission in a certain
/// failure) backs in within the tolerance fraction alone.
fn heading_margin(margin: f64, last: bool) -> f64 {
    if last { 0.0 } else { margin }
}

/// See the module docs.
pub struct Decide {
    params: DecideParams,
    tol_lateral: f64,
    tol_heading: f64,
    started: f64,
    samples: Vec<FiducialView>,
}

impl Decide {
    /// The leaf, with the profile's success tolerances (m, rad).
    pub fn new(params: DecideParams, tol_lateral: f64, tol_heading: f64) -> Self {
        Self {
            samples: Vec::with_capacity(params.frames.max(1)),
            params,
            tol_lateral,
            tol_heading,
            started: 0.0,
        }
    }
}

impl Behavior<Memory> for Decide {
    fn enter(&mut self, _mem: &mut Memory, inputs: &Inputs<'_>) {
        self.started = inputs.now;
        self.samples.clear();
    }

    fn tick(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) -> Option<Step> {
        if let Some(v) = m.planning {
            self.samples.push(v);
        }
        if self.samples.len() < self.params.frames {
            if m.now - self.started > self.params.lost_after_s {
                // Lost at the gate: back off and look again, the retry counted (the
                // next decision judges the allowance).
                m.retries.spend();
                return Some(m.hold("decide").with_event("lost"));
            }
            return Some(m.hold("decide"));
        }
        let d = at_dock_decision(
            &self.samples,
            m.rear_behind_camera,
            self.tol_lateral,
            self.tol_heading,
            self.params.tolerance_fraction,
            heading_margin(self.params.heading_margin_deg.to_radians(), !m.retries.left()),
        );
        tracing::debug!(target: "marsupial::behavior", now = m.now, back_in = d.back_in, alpha_deg = d.alpha.to_degrees(), heading_deg = d.heading.to_degrees(), distance = d.distance, lateral_m = d.lateral_at_entrance, "at-dock decision");
        if d.back_in {
            m.samples_distance = d.distance;
            return Some(Step::event(
                "aligned",
                MotorOutput::stop().with_aux(lowered()),
                m.feedback("decide"),
            ));
        }
        if !m.retries.spend() {
            m.failing = Some(FailureReason::RetriesExhausted);
            return Some(Step::event(
                "retries_exhausted",
                MotorOutput::stop(),
                m.feedback("decide"),
            ));
        }
        let mean = FiducialView {
            alpha: d.alpha,
            heading: d.heading,
            distance: d.distance,
            ..self.samples[0]
        };
        m.plan = Some(m.plan_reposition(&mean));
        Some(m.hold("decide").with_event("misaligned"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn view(alpha_deg: f64, heading_deg: f64) -> FiducialView {
        FiducialView {
            distance: 0.38,
            alpha: alpha_deg.to_radians(),
            asym: 0.0,
            offset_px: 0.0,
            bearing: 0.0,
            heading: heading_deg.to_radians(),
            total_px: 4600,
            height_px: 50.0,
        }
    }

    fn decide(samples: &[FiducialView], tol_heading: f64) -> Decision {
        at_dock_decision(samples, 0.15, 0.02, tol_heading, 0.8, 0.0)
    }

    #[test]
    fn centred_and_balanced_backs_in() {
        let d = decide(&[view(0.5, 0.5); 5], 5f64.to_radians());
        assert!(d.back_in, "{d:?}");
    }

    #[test]
    fn off_axis_or_skewed_moves_away() {
        // 3° off the axis at 0.38 m is 2 cm: beyond 80 % of the ±2 cm tolerance.
        assert!(!decide(&[view(3.0, 0.0); 5], 5f64.to_radians()).back_in);
        // On the axis but heading 4.5°: within 5° but beyond 80 % of it.
        assert!(!decide(&[view(0.0, 4.5); 5], 5f64.to_radians()).back_in);
        // A small offset cancelled by a heading that steers back onto the axis: backs in.
        let d = decide(&[view(2.0, 2.0); 5], 5f64.to_radians());
        assert!(d.lateral_at_entrance.abs() < 1e-12 && d.back_in, "{d:?}");
        // The lever arm from camera to rear counts: 1° off with the heading 4° back toward
        // the axis leaves the camera 6.6 mm off, but the rear reaches the entrance 20 mm
        // past the axis (ignoring the 0.15 m arm would predict 10 mm and back in).
        let d = decide(&[view(1.0, 4.0); 5], 5f64.to_radians());
        let expected = 0.38 * 1f64.to_radians().sin() - 0.38 * 4f64.to_radians().sin();
        assert!((d.lateral_at_entrance - expected).abs() < 1e-12, "{d:?}");
        assert!(!d.back_in, "{d:?}");
        assert!(!decide(&[], 0.1).back_in);
    }

    #[test]
    fn the_heading_margin_narrows_the_heading_gate_only() {
        let tol = 5f64.to_radians();
        let margin = 2f64.to_radians();
        // 3.5° is inside 80 % of 5° but not 2° inside 5°.
        let skewed = [view(3.5, 3.5); 5];
        assert!(decide(&skewed, tol).back_in);
        assert!(!at_dock_decision(&skewed, 0.15, 0.02, tol, 0.8, margin).back_in);
        assert!(at_dock_decision(&[view(2.9, 2.9); 5], 0.15, 0.02, tol, 0.8, margin).back_in);
        // A margin smaller than the fraction's leaves the fraction in charge.
        let small = 0.5f64.to_radians();
        assert!(!at_dock_decision(&[view(4.2, 4.2); 5], 0.15, 0.02, tol, 0.8, small).back_in);
        assert!(at_dock_decision(&[view(3.9, 3.9); 5], 0.15, 0.02, tol, 0.8, small).back_in);
    }

    #[test]
    fn the_last_decision_drops_the_margin() {
        let margin = 2f64.to_radians();
        // Whether the decision after `used` of 2 retries is the last.
        let last = |used: u32| {
            let mut r = crate::behaviors::common::retries::Retries::new(2);
            (0..used).for_each(|_| {
                r.spend();
            });
            !r.left()
        };
        assert_eq!(heading_margin(margin, last(0)), margin);
        assert_eq!(heading_margin(margin, last(1)), margin);
        assert_eq!(heading_margin(margin, last(2)), 0.0);
        // A heading of 3.4° is refused with the margin and taken without it.
        let s = [view(3.4, 3.4)];
        let tol = 5f64.to_radians();
        assert!(!at_dock_decision(&s, 0.2, 0.02, tol, 0.8, heading_margin(margin, last(1))).back_in);
        assert!(at_dock_decision(&s, 0.2, 0.02, tol, 0.8, heading_margin(margin, last(2))).back_in);
    }

    #[test]
    fn averages_the_samples() {
        let d = decide(&[view(2.0, 0.0), view(-2.0, 0.0)], 0.1);
        assert!(d.alpha.abs() < 1e-12 && d.back_in);
    }
}
