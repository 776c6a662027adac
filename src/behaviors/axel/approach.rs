//! `axel.approach`: the approach region (seed 000 §IV). Each cycle stops, looks, plans
//! the two-arc manoeuvre from the measured pose to the alignment region's entry on the
//! module's axis (facing the module, `inside_m` within the alignment radius), and drives
//! ONE step of it: the first arc, cut at `step_m`, reeling by the tether's change of
//! length along it. In the alignment region it hands over (event `near`); with no trusted
//! pose for `lost_looks` looks in a row it goes back to acquiring (event `lost`). From
//! far to the side, where no S within the turn limit reaches the entry, it aims at the
//! mating radius on the axis instead; when no plan keeps the module in view it spirals in
//! toward the axis (the private `spiral`): the module held at a fixed bearing, straight steps.

use super::look::{Decision, Look};
use super::memory::{Memory, Trust, ViewLimits};
use crate::geometry::{Pose2, wrap_angle};
use crate::kinematics::two_arc::{Arc, PlanParams, Polar, Region, TwoArc, keeps_in_view, plan};
use crate::schemas::{Behavior, Inputs, Step};
use serde::Deserialize;
use std::f64::consts::PI;

/// `axel.approach`'s params.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ApproachParams {
    /// Longest step between looks, m.
    pub step_m: f64,
    /// The goal lies this far inside the alignment radius, m.
    pub inside_m: f64,
    /// Looks without a trusted pose before the module counts as lost.
    pub lost_looks: u32,
    /// Longest look for a trusted pose, s.
    pub look_s: f64,
    /// What a pose must be to be planned on.
    pub trust: Trust,
    /// Where every plan must keep the module: inside the view by a margin, within the
    /// detection range.
    pub view: ViewLimits,
    /// The module's bearing the spiral in toward the axis holds, degrees (see the module docs).
    pub spiral_deg: f64,
}

impl Default for ApproachParams {
    fn default() -> Self {
        Self {
            step_m: 1.5,
            inside_m: 0.5,
            lost_looks: 3,
            look_s: 1.2,
            trust: Trust::default(),
            view: ViewLimits::default(),
            spiral_deg: 30.0,
        }
    }
}

/// The first arc of a plan cut at `step` m; when the first arc is negligible, the second.
pub(super) fn one_step(arcs: &[Arc; 2], step: f64) -> Arc {
    let a = if arcs[0].length.abs() >= 0.02 { arcs[0] } else { arcs[1] };
    Arc {
        curvature: a.curvature,
        length: a.length.signum() * a.length.abs().min(step),
    }
}

/// The single arc from `pose` through the axis point (`x`, 0), cut at `step` m: `None`
/// when the point is not ahead, or when the whole arc to it turns by more than the
/// planner's per-arc cap (`params`): the fallback obeys the cap the two-arc plans obey,
/// judged like them on the whole arc rather than the step cut from it, so a capped
/// campaign never drives an arc planned sharper than the cap.
fn toward(pose: &Pose2, x: f64, step: f64, params: &PlanParams) -> Option<Arc> {
    let (lx, ly) = pose.to_local(x, 0.0);
    if lx <= 0.0 {
        return None;
    }
    let d2 = lx * lx + ly * ly;
    let curvature = 2.0 * ly / d2;
    let turn = 2.0 * ly.atan2(lx);
    if !params.turn_within_cap(turn) {
        return None;
    }
    let length = if curvature.abs() < 1e-9 {
        d2.sqrt()
    } else {
        turn / curvature
    };
    Some(Arc {
        curvature,
        length: length.min(step),
    })
}

/// One step of the spiral in toward the axis, for where no two-arc plan keeps the
/// module in view (far to the side, close in): hold the module at bearing `spiral` on
/// the side that carries the rover toward the axis, and drive straight. Sense-plan-act,
/// each look one motion: turn in place until the module sits within 5° of that bearing,
/// else a straight step, at most `step` m and no longer than keeps the module in view
/// (`params`); with no room even for 5 cm, face the module. Holding the bearing at B
/// sweeps α by tan B · ln(r₀/r₁) (a log spiral), so the rover reaches the axis's
/// neighbourhood at a radius from which an S to the axis keeps the view. Its straights
/// turn by nothing and its turns are pivots in place, not arcs, so a per-arc turn cap
/// ([`PlanParams::max_arc_turn`]) never binds it.
pub(super) fn spiral(pose: &Pose2, spiral: f64, step: f64, params: &PlanParams) -> Decision {
    let polar = Polar::from_pose(pose);
    let want = -polar.alpha.signum() * spiral.min(params.fov_half_angle - params.view_margin_rad);
    let off = wrap_angle(polar.bearing() - want);
    if off.abs() > 5f64.to_radians() {
        return Decision::Turn(off);
    }
    let mut length = step.min(polar.r - 0.5).max(0.0);
    while length >= 0.05 {
        let arc = Arc { curvature: 0.0, length };
        if keeps_in_view(
            &TwoArc {
                arcs: [arc, Arc::default()],
            },
            pose,
            params,
        ) {
            return Decision::Arc { arc, from: *pose };
        }
        length *= 0.5;
    }
    Decision::Turn(polar.bearing())
}

/// See the module docs.
pub struct Approach {
    phase: &'static str,
    params: ApproachParams,
    look: Look,
}

impl Approach {
    /// A leaf in phase `phase`.
    pub fn new(phase: &'static str, params: ApproachParams) -> Self {
        Self {
            phase,
            params,
            look: Look::new(params.look_s, params.trust),
        }
    }
}

impl Behavior<Memory> for Approach {
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
            |m, s| {
                let g = m.geometry;
                let params = p.view.plan_params(&g.plan);
                let polar = Polar::from_pose(&s.pose);
                if matches!(g.regions.classify(&polar), Region::Alignment | Region::Mating) {
                    return Decision::Event("near");
                }
                // The alignment region's entry on the axis; from far to the side, where no
                // S within the turn limit reaches it, a goal farther in along the axis.
                let entry = (g.regions.alignment_radius - p.inside_m).max(g.regions.mating_radius);
                let planned = [entry, g.regions.mating_radius]
                    .into_iter()
                    .find_map(|x| plan(&s.pose, &Pose2::new(x, 0.0, PI), &params).ok());
                match planned {
                    Some(pl) => Decision::Arc {
                        arc: one_step(&pl.arcs, p.step_m),
                        from: s.pose,
                    },
                    // No two-arc plan keeps the module in view (square to the axis far to
                    // the side, the S would turn it out): one arc toward the entry point,
                    // whatever the heading it ends in, if that keeps it and turns within the
                    // cap; otherwise face the module and look again.
                    None => match toward(&s.pose, entry, p.step_m, &params) {
                        Some(arc)
                            if keeps_in_view(
                                &TwoArc {
                                    arcs: [arc, Arc::default()],
                                },
                                &s.pose,
                                &params,
                            ) =>
                        {
                            Decision::Arc { arc, from: s.pose }
                        }
                        _ => spiral(&s.pose, p.spiral_deg.to_radians(), p.step_m, &params),
                    },
                }
            },
            |_, _| None,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_single_arc_fallback_obeys_the_turn_cap() {
        // Heading −y, 1 m off the axis at 4 m: the entry (2.5 m on the axis) lies 1 m
        // ahead and 1.5 m to the right, and the arc through it turns by
        // 2·atan2(1.5, 1) ≈ 113°, beyond a 30° cap.
        let pose = Pose2::new(4.0, 1.0, -PI / 2.0);
        let open = PlanParams::default();
        let arc = toward(&pose, 2.5, 1.5, &open).expect("the point is ahead");
        assert!((arc.length - 1.5).abs() < 1e-12 && arc.curvature < 0.0, "{arc:?}");
        let capped = PlanParams {
            max_arc_turn: 30f64.to_radians(),
            ..open
        };
        assert_eq!(toward(&pose, 2.5, 1.5, &capped), None);
        // 2 m off the axis at 3 m, the same heading: the entry lies 2 m ahead and 0.5 m
        // to the right, a turn of 2·atan2(0.5, 2) ≈ 28°, within the cap.
        let near = Pose2::new(3.0, 2.0, -PI / 2.0);
        assert_eq!(toward(&near, 2.5, 1.5, &capped), toward(&near, 2.5, 1.5, &open));
        assert!(toward(&near, 2.5, 1.5, &capped).is_some());
    }
}
