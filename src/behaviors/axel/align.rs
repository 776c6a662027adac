//! `axel.align`: the alignment and mating regions (seed 000 §IV). Each cycle stops,
//! looks and plans the two-arc manoeuvre to the **look pose**: on the module's axis,
//! facing it, the arm's tip `look_m` from the cone's mouth, the penultimate step from
//! which the paper's stereo pose was trusted to end the docking (§IV). It drives one
//! step of at most `step_m`, then looks again. At the look pose (within `arrive_m`) it
//! checks the alignment: the heading within `robot.two_arc.heading_tolerance_deg`
//! (±5°, §V-B) and the gate of `[success]` (the tip's lateral offset and the arm's angle
//! to the cone's axis); aligned, it commits to mating (event `aligned`, the pose kept in
//! [`Memory::commit`]). A plan is finished before it is judged: one step drives one arc,
//! and a plan whose first arc runs nearly straight to the look pose leaves its turn to a
//! short second arc, so the rover can stand inside the arrival circle with the turn still
//! to make. Misaligned there, it plans again from where it stands and drives that (at
//! most `finish_steps` times per arrival) before it reverses. With no plan farther out
//! than `spiral_beyond_m` beyond the look pose it spirals in toward the axis (the
//! approach's spiral). Misaligned at the look
//! pose, past it (also when only an untrusted pose says so: nearer than the look pose one
//! camera loses the marks), or with no plan within the turn limit closer in, it reverses `reverse_m` (paying the tether out) and retries; after
//! `behavior.max_retries` realignments (our choice: the paper had no limit and saw one
//! oscillation) the docking fails with `retries_exhausted`. Beyond the alignment radius
//! (after slipping or reversing) it hands back to the approach (event `far`); with no
//! trusted pose for `lost_looks` looks, to the acquisition (event `lost`).

use super::approach::{one_step, spiral};
use super::look::{Decision, Look};
use super::memory::{Memory, Sighting, Trust, ViewLimits};
use crate::geometry::{Pose2, wrap_angle};
use crate::kinematics::two_arc::{Arc, Polar, plan};
use crate::schemas::{Behavior, FailureReason, Inputs, Outcome, Step};
use serde::Deserialize;
use std::f64::consts::PI;

/// `axel.align`'s params.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AlignParams {
    /// The arm's tip this far from the cone's mouth at the look pose, m.
    pub look_m: f64,
    /// At the look pose within this distance, m.
    pub arrive_m: f64,
    /// Longest step between looks, m.
    pub step_m: f64,
    /// Reverse this far to realign, m.
    pub reverse_m: f64,
    /// Beyond the alignment radius by this much, hand back to the approach, m.
    pub far_margin_m: f64,
    /// Looks without a trusted pose before the module counts as lost.
    pub lost_looks: u32,
    /// Longest look for a trusted pose, s.
    pub look_s: f64,
    /// What a pose must be to be planned on.
    pub trust: Trust,
    /// Where every plan must keep the module: inside the view by a margin, within the
    /// detection range.
    pub view: ViewLimits,
    /// With no plan farther than this beyond the look pose, spiral in toward the axis
    /// (the approach's `approach::spiral`) rather than reverse, m.
    pub spiral_beyond_m: f64,
    /// The module's bearing the spiral holds, degrees.
    pub spiral_deg: f64,
    /// Misaligned inside the arrival circle, plan again and drive at most this many steps
    /// before reversing (0: reverse at once). Replayed: axel-field run 3 and
    /// axel-lighting run 5 stood 5–6 cm from the look pose, 5–8° off, with the plan's
    /// turning arc not yet driven, and reversed three times straight back (keeping the
    /// error) until the retries ran out.
    pub finish_steps: u32,
}

impl Default for AlignParams {
    fn default() -> Self {
        Self {
            look_m: 0.5,
            arrive_m: 0.08,
            step_m: 0.6,
            reverse_m: 0.6,
            far_margin_m: 0.3,
            lost_looks: 3,
            look_s: 1.2,
            trust: Trust::default(),
            view: ViewLimits::default(),
            spiral_beyond_m: 0.5,
            spiral_deg: 30.0,
            finish_steps: 2,
        }
    }
}

/// See the module docs.
///
/// The steps driven to finish a plan inside the arrival circle since the rover last
/// arrived there are the phase's [`Looks::steps`](super::look::Looks::steps).
pub struct Align {
    phase: &'static str,
    params: AlignParams,
    look: Look,
}

impl Align {
    /// A leaf in phase `phase`.
    pub fn new(phase: &'static str, params: AlignParams) -> Self {
        Self {
            phase,
            params,
            look: Look::new(params.look_s, params.trust),
        }
    }
}

/// Whether the rover at module-frame `pose` may commit to mating: its heading within
/// `heading_tolerance` of the axis, the arm within `gate_heading` of it, and the arm's
/// tip within `gate_lateral` of the axis **where it will meet the mouth**: mating drives
/// blind and straight, so the tip's offset is carried along the heading to the mouth's
/// plane (x = 0). Judged at the look pose alone, a tip 4 cm aside and 5° off (both
/// within) meets the mouth 9 cm aside, outside the cone's capture: axel-field run 31
/// committed so and stalled at the cone (`stuck_contact`).
pub fn aligned(pose: &Pose2, arm: f64, heading_tolerance: f64, gate_lateral: f64, gate_heading: f64) -> bool {
    let h = wrap_angle(pose.theta - PI).abs();
    h <= heading_tolerance && h <= gate_heading && tip_at_mouth(pose, arm).abs() <= gate_lateral
}

/// The arm's tip's lateral offset from the axis (module frame y) once a straight drive
/// along `pose`'s heading brings it to the mouth's plane; the tip's own offset when it is
/// already there or the rover does not face the module.
fn tip_at_mouth(pose: &Pose2, arm: f64) -> f64 {
    let (tx, ty) = pose.to_world(arm, 0.0);
    let (c, s) = (pose.theta.cos(), pose.theta.sin());
    if tx <= 0.0 || c >= -1e-6 {
        return ty;
    }
    // Along (c, s) until x = 0: t = tx / −c.
    ty + tx / -c * s
}

fn decide(m: &mut Memory, p: &AlignParams, s: Sighting) -> Decision {
    let g = m.geometry;
    let polar = Polar::from_pose(&s.pose);
    if polar.r > g.regions.alignment_radius + p.far_margin_m {
        return Decision::Event("far");
    }
    let look = Pose2::new(g.tether.arm + p.look_m, 0.0, PI);
    let at_look = s.pose.distance(&look) <= p.arrive_m;
    let past = s.pose.x < look.x - p.arrive_m;
    if at_look
        && aligned(
            &s.pose,
            g.tether.arm,
            g.heading_tolerance,
            g.gate_lateral,
            g.gate_heading,
        )
    {
        m.commit = Some(s.pose);
        return Decision::Event("aligned");
    }
    let params = p.view.plan_params(&g.plan);
    // Inside the arrival circle a plan is driven only to finish a turn (bounded); outside
    // it, the count starts over.
    let may_plan = if at_look {
        m.looks.steps += 1;
        m.looks.steps <= p.finish_steps
    } else {
        m.looks.steps = 0;
        !past
    };
    let planned = if may_plan {
        plan(&s.pose, &look, &params).ok()
    } else {
        None
    };
    match planned {
        Some(pl) => Decision::Arc {
            arc: one_step(&pl.arcs, p.step_m),
            from: s.pose,
        },
        // Far from the look pose and to the side: no S keeps the view, so spiral in
        // toward the axis first; reversing would only bring the rover back here.
        None if !at_look && !past && polar.r > look.x + p.spiral_beyond_m => {
            spiral(&s.pose, p.spiral_deg.to_radians(), p.step_m, &params)
        }
        None => {
            // Reverse and realign (seed 000 §II, §V-B), a bounded number of times.
            if !m.retries.spend() {
                return Decision::Done(Outcome::Failed(FailureReason::RetriesExhausted));
            }
            Decision::Arc {
                arc: Arc {
                    curvature: 0.0,
                    length: -p.reverse_m,
                },
                from: s.pose,
            }
        }
    }
}

/// A centred look whose pose is untrusted (one camera lost the marks, or too few were
/// matched in both) while that pose puts the rover past the look pose: nearer than
/// the look pose, the module leaves one camera's view, so looking again from here
/// never gives the stereo pose the commitment needs. Reverse and realign, as `decide`
/// does past the look pose (a bounded retry). Replayed: axel-field run 22 (i11, loose
/// sand) stood 12 cm past the look pose, square to the axis, seen by camera 1 only, and
/// went align → acquire → approach → align for 600 s.
fn past_unseen(m: &mut Memory, p: &AlignParams, s: Sighting) -> Option<Decision> {
    let look_x = m.geometry.tether.arm + p.look_m;
    if s.pose.x >= look_x - p.arrive_m {
        return None;
    }
    if !m.retries.spend() {
        return Some(Decision::Done(Outcome::Failed(FailureReason::RetriesExhausted)));
    }
    Some(Decision::Arc {
        arc: Arc {
            curvature: 0.0,
            length: -p.reverse_m,
        },
        from: s.pose,
    })
}

impl Behavior<Memory> for Align {
    fn enter(&mut self, m: &mut Memory, inputs: &Inputs<'_>) {
        self.look.enter(m, inputs.now);
    }

    fn tick(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) -> Option<Step> {
        if let Some(end) = m.gave_up(self.phase) {
            return Some(end);
        }
        let p = self.params;
        Some(self.look.tick_seeing(
            m,
            self.phase,
            p.lost_looks,
            |m, s| decide(m, &p, s),
            |m, s| past_unseen(m, &p, s),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_gate_checks_heading_and_the_tips_offset() {
        let arm = 0.55;
        let d5 = 5f64.to_radians();
        let on_axis = Pose2::new(1.05, 0.0, PI);
        assert!(aligned(&on_axis, arm, d5, 0.05, d5));
        // 6° off: refused by the ±5°.
        let turned = Pose2::new(1.05, 0.0, PI + 6f64.to_radians());
        assert!(!aligned(&turned, arm, d5, 0.05, d5));
        // Square to the axis but 8 cm to the side: the tip misses the gate.
        let beside = Pose2::new(1.05, 0.08, PI);
        assert!(!aligned(&beside, arm, d5, 0.05, d5));
        // 3° off, axle 4 cm aside, tip pointing back at the axis: within.
        let converging = Pose2::new(1.05, 0.04, PI + 3f64.to_radians());
        assert!(aligned(&converging, arm, d5, 0.05, d5));
        // axel-field run 31's commitment: 0.4 cm aside, 5.0° off, the tip 4.4 cm aside
        // and heading away from the axis: it would meet the mouth 9 cm aside.
        let diverging = Pose2::new(1.12, 0.0037, PI + 4.99f64.to_radians());
        assert!(!aligned(&diverging, arm, d5, 0.05, d5));
        assert!((tip_at_mouth(&diverging, arm) + 0.094).abs() < 0.003);
        // The same offsets mirrored, converging: the tip meets the mouth on the axis.
        let mirrored = Pose2::new(1.12, 0.094, PI + 4.99f64.to_radians());
        assert!(aligned(&mirrored, arm, d5, 0.05, d5));
    }

    fn stereo(pose: Pose2) -> Sighting {
        Sighting {
            t: 0.0,
            pose,
            source: crate::perception::circles::PoseSource::Stereo,
            marks: 8,
            reprojection_px: 0.03,
            residual_m: 0.001,
        }
    }

    #[test]
    fn a_turn_left_undone_inside_the_arrival_circle_is_finished_before_reversing() {
        // axel-field run 3: 5–6 cm short of the look pose on the axis, 7° off.
        let mut m = Memory::shipped_axel();
        let p = AlignParams::default();
        let look_x = m.geometry.tether.arm + p.look_m;
        for (dx, dy, deg) in [(0.055, 0.003, 7.0), (0.05, -0.004, -6.0), (0.06, 0.0, 8.0)] {
            let start = Pose2::new(look_x + dx, dy, PI + f64::to_radians(deg));
            assert!(!aligned(
                &start,
                m.geometry.tether.arm,
                m.geometry.heading_tolerance,
                m.geometry.gate_lateral,
                m.geometry.gate_heading
            ));
            m.looks.steps = 0;
            let mut pose = start;
            // Driving what it plans (exactly, as if no slip) brings it into the gate
            // within the budget, with no retry spent.
            let mut committed = false;
            for _ in 0..=p.finish_steps {
                match decide(&mut m, &p, stereo(pose)) {
                    Decision::Arc { arc, from } => pose = arc.end(&from),
                    Decision::Event("aligned") => {
                        committed = true;
                        break;
                    }
                    d => panic!("{start:?}: expected a finishing arc, got {d:?}"),
                }
            }
            assert!(committed, "{start:?} ended at {pose:?}");
            assert_eq!(m.retries.used(), 0);
        }
        // With the budget spent, a misaligned arrival reverses and spends a retry.
        let start = Pose2::new(look_x + 0.05, 0.0, PI + 7f64.to_radians());
        m.looks.steps = p.finish_steps;
        match decide(&mut m, &p, stereo(start)) {
            Decision::Arc { arc, .. } => assert_eq!((arc.curvature, arc.length), (0.0, -p.reverse_m)),
            d => panic!("expected a reverse, got {d:?}"),
        }
        assert_eq!(m.retries.used(), 1);
        // Leaving the arrival circle starts the count over.
        let _ = decide(&mut m, &p, stereo(Pose2::new(look_x + 0.4, 0.0, PI)));
        assert_eq!(m.looks.steps, 0);
    }

    #[test]
    fn an_untrusted_pose_past_the_look_pose_reverses_and_counts_a_retry() {
        let mut m = Memory::shipped_axel();
        let p = AlignParams::default();
        let look_x = m.geometry.tether.arm + p.look_m;
        let sighting = |x: f64| Sighting {
            t: 0.0,
            pose: Pose2::new(x, -0.02, PI),
            source: crate::perception::circles::PoseSource::Mono { camera: 1 },
            marks: 6,
            reprojection_px: 0.03,
            residual_m: 0.001,
        };
        // At or before the look pose: look again (None), no retry spent.
        assert!(past_unseen(&mut m, &p, sighting(look_x)).is_none());
        assert_eq!(m.retries.used(), 0);
        // 12 cm past it (axel-field run 22): reverse `reverse_m`, one retry.
        match past_unseen(&mut m, &p, sighting(look_x - 0.12)) {
            Some(Decision::Arc { arc, .. }) => assert_eq!((arc.curvature, arc.length), (0.0, -p.reverse_m)),
            _ => panic!("expected a reverse"),
        }
        assert_eq!(m.retries.used(), 1);
        // Retries are bounded as for any realignment.
        while m.retries.left() {
            m.retries.spend();
        }
        assert!(matches!(
            past_unseen(&mut m, &p, sighting(look_x - 0.12)),
            Some(Decision::Done(Outcome::Failed(FailureReason::RetriesExhausted)))
        ));
    }
}
