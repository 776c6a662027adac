//! Axel's planning geometry (seed 000 §IV): polar coordinates about the central module,
//! the approach / alignment / mating regions, and the two-arc manoeuvre.
//!
//! Everything here is in the **module frame**: the module's face at x = 0 looking along
//! +x, the cone's mouth at the origin. A rover pose there is (x, y, θ); its polar form is
//! r (distance from the mouth), α (its angle about the module's axis) and h, its heading
//! measured **from the module's axis** (h = 0: heading −x, parallel to the axis, whatever
//! α; so at α = 40°, h = 0 the module sits 40° off the rover's heading, at the edge of
//! the view).
//!
//! A two-arc manoeuvre is two constant-curvature arcs (a straight is the zero-curvature
//! arc) that take the rover from its pose to a goal (x, y, h). Two arcs are the fewest
//! that control position and heading; the problem is under-constrained, so the planner
//! enumerates the family and keeps the one minimising distance travelled plus turning,
//! rejecting those whose intermediate headings lose the module from the cameras' view
//! (seed 000 §IV-A-1). The family is parametrised by the heading φ at the junction:
//! given φ, each arc's heading change is fixed, and an arc of length s turning by Δ
//! moves the rover by the chord s·sinc(Δ/2) along θ + Δ/2, so the two lengths solve a
//! 2×2 linear system. A negative length drives the arc in reverse (a cusp between two
//! arcs is allowed). Pure functions, no allocation.

use crate::geometry::{Pose2, wrap_angle};
use std::f64::consts::PI;
use thiserror::Error;

/// A rover pose in polar form about the module (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Polar {
    /// Distance from the cone's mouth to the rover's axle, m.
    pub r: f64,
    /// The axle's angle about the module's axis, rad (counter-clockwise from +x).
    pub alpha: f64,
    /// The rover's heading from the module's axis, rad (0: heading −x).
    pub h: f64,
}

impl Polar {
    /// The polar form of a module-frame pose.
    pub fn from_pose(pose: &Pose2) -> Self {
        Self {
            r: pose.x.hypot(pose.y),
            alpha: pose.y.atan2(pose.x),
            h: wrap_angle(pose.theta - PI),
        }
    }

    /// The module-frame pose of this polar form.
    pub fn to_pose(&self) -> Pose2 {
        Pose2::new(
            self.r * self.alpha.cos(),
            self.r * self.alpha.sin(),
            wrap_angle(self.h + PI),
        )
    }

    /// The module's bearing from the rover's heading, rad: 0 dead ahead, α − h in the
    /// paper's terms (what the cameras' field of view bounds).
    pub fn bearing(&self) -> f64 {
        wrap_angle(self.alpha - self.h)
    }
}

/// Which of the docking regions a rover is in (seed 000 §IV, Fig. 7).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Region {
    /// Within the mating radius: precise, slow, recheck then reel.
    Mating,
    /// Within the alignment radius: refine the alignment on the way in.
    Alignment,
    /// Within the approach radius and angle: approach, reverse and realign freely.
    Approach,
    /// Beyond the approach radius or angle: the workspace the paper did not test.
    Outside,
}

/// The regions' radii and the approach angle (profile `[robot.two_arc]` radii,
/// `[dock]` `approach_radius_m` and `approach_half_angle_deg`). The paper gives no
/// region radii: the profile's are ours.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Regions {
    /// Radius of the mating region, m.
    pub mating_radius: f64,
    /// Radius of the alignment region, m.
    pub alignment_radius: f64,
    /// Radius of the approach region (the workspace), m.
    pub approach_radius: f64,
    /// Largest |α| of the approach region, rad.
    pub approach_half_angle: f64,
}

impl Regions {
    /// The region of polar pose `p`: by radius inside the approach region; outside it
    /// beyond the approach radius or angle.
    pub fn classify(&self, p: &Polar) -> Region {
        if p.r <= self.mating_radius {
            Region::Mating
        } else if p.r <= self.alignment_radius {
            Region::Alignment
        } else if p.r <= self.approach_radius && p.alpha.abs() <= self.approach_half_angle {
            Region::Approach
        } else {
            Region::Outside
        }
    }
}

/// A constant-curvature arc: `length` m along the rover's heading (negative reverses)
/// with `curvature` 1/m (positive turns left when driving forward; 0 is straight).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Arc {
    /// Signed curvature, 1/m.
    pub curvature: f64,
    /// Signed length, m (negative: driven in reverse).
    pub length: f64,
}

/// sin(x)/x, continuous at 0.
fn sinc(x: f64) -> f64 {
    if x.abs() < 1e-6 { 1.0 - x * x / 6.0 } else { x.sin() / x }
}

impl Arc {
    /// The heading change along the whole arc, rad.
    pub fn turn(&self) -> f64 {
        self.curvature * self.length
    }

    /// The pose `s` m (signed, same sign as the length) along the arc from `from`.
    pub fn at(&self, from: &Pose2, s: f64) -> Pose2 {
        let d = self.curvature * s;
        let chord = s * sinc(d / 2.0);
        let dir = from.theta + d / 2.0;
        Pose2::new(from.x + chord * dir.cos(), from.y + chord * dir.sin(), from.theta + d)
    }

    /// The pose at the arc's end.
    pub fn end(&self, from: &Pose2) -> Pose2 {
        self.at(from, self.length)
    }
}

/// Two arcs, driven one after the other.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TwoArc {
    /// The arcs, in driving order.
    pub arcs: [Arc; 2],
}

impl TwoArc {
    /// The pose at the manoeuvre's end.
    pub fn end(&self, from: &Pose2) -> Pose2 {
        self.arcs[1].end(&self.arcs[0].end(from))
    }

    /// Distance travelled, m.
    pub fn distance(&self) -> f64 {
        self.arcs[0].length.abs() + self.arcs[1].length.abs()
    }

    /// Total turning, rad.
    pub fn turning(&self) -> f64 {
        self.arcs[0].turn().abs() + self.arcs[1].turn().abs()
    }
}

/// What the planner optimises and must respect.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlanParams {
    /// Tightest turn, m (a differential base can pivot about one wheel: half its track).
    pub min_radius_m: f64,
    /// Cost of turning, m per rad, added to the distance travelled.
    pub turn_weight_m_per_rad: f64,
    /// The cameras' half field of view, rad: the module must stay within it.
    pub fov_half_angle: f64,
    /// Margin kept inside the half field of view, rad: the module's centre must stay
    /// this far from the view's edge, where the fish-eye compresses the marks and the
    /// off-centre camera of the stereo pair and the module's own width lose them first.
    pub view_margin_rad: f64,
    /// Farthest the rover may drive from the module along a plan, m (the marks'
    /// detection range); a start already beyond it may not drive farther out.
    pub max_range_m: f64,
    /// Junction headings tried, evenly over the full turn; as many first-arc curvatures
    /// are tried, evenly within the limit (see [`plan`]).
    pub headings: usize,
    /// Allow arcs driven in reverse.
    pub allow_reverse: bool,
    /// Spacing of the view check along the arcs, m.
    pub check_step_m: f64,
    /// Largest heading change either arc may make, rad (`f64::INFINITY`: no cap). The
    /// reel pays out at a constant rate along an arc (the paper's linear approximation
    /// of the tether's length), and that approximation holds only for small turns: the
    /// paper found it sufficient below 30° (seed 000 §V-F). A cap makes plans with a
    /// sharper arc infeasible, so the approximation's error can be bounded by the plan
    /// rather than by the turn weight alone (the tether ablation).
    pub max_arc_turn: f64,
}

impl Default for PlanParams {
    fn default() -> Self {
        Self {
            min_radius_m: 0.5,
            turn_weight_m_per_rad: 0.5,
            fov_half_angle: 45f64.to_radians(),
            view_margin_rad: 0.0,
            max_range_m: f64::INFINITY,
            headings: 720,
            allow_reverse: true,
            check_step_m: 0.05,
            max_arc_turn: f64::INFINITY,
        }
    }
}

impl PlanParams {
    /// True when an arc turning by `turn` rad is within [`PlanParams::max_arc_turn`]
    /// (the schemas' single-arc fallbacks check their arcs by it too).
    pub fn turn_within_cap(&self, turn: f64) -> bool {
        turn.abs() <= self.max_arc_turn + 1e-9
    }
}

/// Why no manoeuvre was planned.
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum PlanError {
    /// A pose or parameter is not finite, `headings` is 0, or the turn cap is not
    /// positive.
    #[error("the start, goal or planner parameters are not finite (or the turn cap is not positive)")]
    NonFinite,
    /// No two-arc manoeuvre within the curvature limit keeps the module in view.
    #[error("no two-arc manoeuvre within the turn limit keeps the module in view")]
    Infeasible,
}

/// The module's bearing from `pose`'s heading, rad (the module at the origin).
fn module_bearing(pose: &Pose2) -> f64 {
    wrap_angle((-pose.y).atan2(-pose.x) - pose.theta)
}

/// True when the module stays within the view along `plan` from `from`: at every check
/// point its bearing is within the half field of view less the margin
/// ([`PlanParams::view_margin_rad`]), or, where the start already had it beyond (at the
/// edge of the view), no farther out than at the start; and the rover stays within the
/// detection range ([`PlanParams::max_range_m`]), or no farther than the start where it
/// began beyond. A rover that sees the module keeps it; one at the edge does not lose it
/// further.
pub fn keeps_in_view(plan: &TwoArc, from: &Pose2, params: &PlanParams) -> bool {
    let limit = (params.fov_half_angle - params.view_margin_rad.max(0.0)).max(module_bearing(from).abs()) + 1e-9;
    let range = params.max_range_m.max(from.x.hypot(from.y)) + 1e-9;
    let step_m = params.check_step_m.max(1e-3);
    let mut p = *from;
    for arc in &plan.arcs {
        let n = (arc.length.abs() / step_m).ceil().max(1.0) as usize;
        for k in 1..=n {
            let q = arc.at(&p, arc.length * k as f64 / n as f64);
            if module_bearing(&q).abs() > limit || q.x.hypot(q.y) > range {
                return false;
            }
        }
        p = arc.end(&p);
    }
    true
}

/// The two arcs through junction heading `phi` from `from` to `goal`, if any: the lengths
/// solve s₁·c₁ + s₂·c₂ = goal − from, with cᵢ each arc's unit-length chord.
fn through(from: &Pose2, goal: &Pose2, phi: f64) -> Option<TwoArc> {
    let d1 = wrap_angle(phi - from.theta);
    let d2 = wrap_angle(goal.theta - phi);
    let (k1, k2) = (sinc(d1 / 2.0), sinc(d2 / 2.0));
    let (a1, a2) = (from.theta + d1 / 2.0, phi + d2 / 2.0);
    let c1 = (k1 * a1.cos(), k1 * a1.sin());
    let c2 = (k2 * a2.cos(), k2 * a2.sin());
    let (dx, dy) = (goal.x - from.x, goal.y - from.y);
    let det = c1.0 * c2.1 - c1.1 * c2.0;
    let (s1, s2) = if det.abs() < 1e-9 {
        // Parallel chords (the start and goal headings are equal): only a goal along them
        // is reachable. An S (turn, then turn back) shares the length out evenly, the
        // widest arcs; a heading change of 0 on either side leaves one arc.
        let n1 = c1.0.hypot(c1.1);
        let n2 = c2.0.hypot(c2.1);
        let u = (c1.0 / n1, c1.1 / n1);
        let along = dx * u.0 + dy * u.1;
        if (dx - along * u.0).hypot(dy - along * u.1) > 1e-6 {
            return None;
        }
        let sigma = (c2.0 * u.0 + c2.1 * u.1).signum();
        match (d1.abs() < 1e-12, d2.abs() < 1e-12) {
            (_, true) => (along / n1, 0.0),
            (true, false) => (0.0, along / (sigma * n2)),
            (false, false) => (along / (2.0 * n1), along / (2.0 * sigma * n2)),
        }
    } else {
        ((dx * c2.1 - dy * c2.0) / det, (c1.0 * dy - c1.1 * dx) / det)
    };
    let arc = |d: f64, s: f64| Arc {
        curvature: if s.abs() < 1e-12 { 0.0 } else { d / s },
        length: s,
    };
    // A heading change with no length is a pivot in place: not an arc.
    if (s1.abs() < 1e-9 && d1.abs() > 1e-9) || (s2.abs() < 1e-9 && d2.abs() > 1e-9) {
        return None;
    }
    Some(TwoArc {
        arcs: [arc(d1, s1), arc(d2, s2)],
    })
}

/// The two-arc manoeuvre from `from` to `goal` (module frame) minimising distance plus
/// weighted turning among those within the curvature limit and the per-arc turn cap
/// ([`PlanParams::max_arc_turn`]), forward-only unless reverse is allowed, that keep the
/// module in view ([`keeps_in_view`]).
///
/// # Errors
/// [`PlanError::NonFinite`] for non-finite input, [`PlanError::Infeasible`] when no
/// candidate qualifies.
pub fn plan(from: &Pose2, goal: &Pose2, params: &PlanParams) -> Result<TwoArc, PlanError> {
    let finite = from.is_finite()
        && goal.is_finite()
        && params.min_radius_m.is_finite()
        && params.turn_weight_m_per_rad.is_finite()
        && params.fov_half_angle.is_finite()
        && params.view_margin_rad.is_finite()
        && !params.max_range_m.is_nan()
        && params.check_step_m.is_finite()
        && params.max_arc_turn > 0.0;
    if !finite || params.headings == 0 {
        return Err(PlanError::NonFinite);
    }
    let kmax = 1.0 / params.min_radius_m.max(1e-6);
    // A candidate's cost, before the view check (`None`: no such manoeuvre, or beyond
    // the curvature limit or the turn cap, or reversing when that is not allowed).
    let candidate = |phi: f64| -> Option<(f64, TwoArc)> {
        let cand = through(from, goal, phi)?;
        if cand
            .arcs
            .iter()
            .any(|a| a.curvature.abs() > kmax + 1e-9 || !params.turn_within_cap(a.turn()))
        {
            return None;
        }
        if !params.allow_reverse && cand.arcs.iter().any(|a| a.length < 0.0) {
            return None;
        }
        Some((cand.distance() + params.turn_weight_m_per_rad * cand.turning(), cand))
    };
    let mut best: Option<(f64, TwoArc)> = None;
    let mut consider = |phi: f64| {
        let Some((cost, cand)) = candidate(phi) else { return };
        if best.is_some_and(|(c, _)| c <= cost) {
            return;
        }
        if keeps_in_view(&cand, from, params) {
            best = Some((cost, cand));
        }
    };
    // The junction headings: the grid, plus the start's and goal's own (single arcs) and
    // the one whose chord points at the goal (the S between equal headings, which a grid
    // would only miss).
    let n = params.headings;
    let step = 2.0 * PI / n as f64;
    let at = |i: usize| -PI + step * i as f64;
    let toward = 2.0 * (goal.y - from.y).atan2(goal.x - from.x) - from.theta;
    for phi in [from.theta, goal.theta, toward] {
        consider(phi);
    }
    for i in 0..n {
        consider(at(i));
    }
    // Where the start and goal headings nearly agree the chords are nearly parallel, and
    // the lengths stay sane only in a valley of junction headings narrower than any grid
    // of them. So the family is also walked by the first arc's curvature, which is well
    // conditioned there: for each k₁ on a grid within the limit, the junction heading of
    // the two-arc manoeuvre whose first arc has that curvature.
    for i in 0..n {
        let k1 = kmax * (2.0 * (i as f64 + 0.5) / n as f64 - 1.0);
        if let Some(phi) = junction_for_curvature(from, goal, k1) {
            consider(phi);
        }
    }
    best.map(|(_, p)| p).ok_or(PlanError::Infeasible)
}

/// The junction heading of the two-arc manoeuvre from `from` to `goal` whose first arc
/// has curvature `k1` (≠ 0), if one exists. With signed radii rᵢ = 1/kᵢ and left
/// normals nᵢ, the arcs' centres are C₁ = p₀ + r₁·n₀ and C₂ = p_g + r₂·n_g, and the arcs
/// meet tangentially when |C₂ − C₁| = |r₁ − r₂|, which is linear in r₂:
/// r₂ = (r₁² − |A|²) / (2·(A·n_g + r₁)) with A = p_g − C₁. The junction lies on the line of
/// centres, J = C₁ + r₁·u with u = (C₂ − C₁)/(r₁ − r₂), and the heading there is that of
/// a circle of radius r₁ whose radius vector is r₁·u.
fn junction_for_curvature(from: &Pose2, goal: &Pose2, k1: f64) -> Option<f64> {
    if k1.abs() < 1e-12 {
        return None;
    }
    let r1 = 1.0 / k1;
    let n0 = (-from.theta.sin(), from.theta.cos());
    let ng = (-goal.theta.sin(), goal.theta.cos());
    let c1 = (from.x + r1 * n0.0, from.y + r1 * n0.1);
    let a = (goal.x - c1.0, goal.y - c1.1);
    let den = 2.0 * (a.0 * ng.0 + a.1 * ng.1 + r1);
    if den.abs() < 1e-12 {
        return None;
    }
    let r2 = (r1 * r1 - (a.0 * a.0 + a.1 * a.1)) / den;
    if (r1 - r2).abs() < 1e-12 || !r2.is_finite() {
        return None;
    }
    let c2 = (goal.x + r2 * ng.0, goal.y + r2 * ng.1);
    let u = ((c2.0 - c1.0) / (r1 - r2), (c2.1 - c1.1) / (r1 - r2));
    Some(u.0.atan2(-u.1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn close(a: &Pose2, b: &Pose2) -> bool {
        (a.x - b.x).abs() < 1e-6 && (a.y - b.y).abs() < 1e-6 && wrap_angle(a.theta - b.theta).abs() < 1e-6
    }

    #[test]
    fn polar_round_trips_and_h_is_from_the_axis() {
        let p = Polar {
            r: 4.0,
            alpha: 15f64.to_radians(),
            h: 0.0,
        };
        let pose = p.to_pose();
        assert!((pose.theta.abs() - PI).abs() < 1e-12, "h = 0 heads −x: {pose:?}");
        let q = Polar::from_pose(&pose);
        assert!((q.r - 4.0).abs() < 1e-12 && (q.alpha - p.alpha).abs() < 1e-12 && q.h.abs() < 1e-12);
        // At α 40°, h 0 the module is 40° off the heading: the edge of a 90° view.
        let edge = Polar {
            r: 6.0,
            alpha: 40f64.to_radians(),
            h: 0.0,
        };
        assert!((edge.bearing() - 40f64.to_radians()).abs() < 1e-12);
        assert!((module_bearing(&edge.to_pose()) - 40f64.to_radians()).abs() < 1e-9);
    }

    #[test]
    fn regions_by_radius_and_angle() {
        let g = Regions {
            mating_radius: 1.5,
            alignment_radius: 3.0,
            approach_radius: 7.0,
            approach_half_angle: 40f64.to_radians(),
        };
        let at = |r: f64, a: f64| {
            g.classify(&Polar {
                r,
                alpha: a.to_radians(),
                h: 0.0,
            })
        };
        assert_eq!(at(1.0, 60.0), Region::Mating);
        assert_eq!(at(2.0, 0.0), Region::Alignment);
        assert_eq!(at(6.0, 30.0), Region::Approach);
        assert_eq!(at(6.0, 45.0), Region::Outside);
        assert_eq!(at(7.5, 0.0), Region::Outside);
    }

    #[test]
    fn the_fig10_start_plans_an_s_that_keeps_the_module_in_view() {
        // Seed 000 Fig. 10: 4 m, α 15°, h 0°, to the axis 1.5 m out facing the module.
        let from = Polar {
            r: 4.0,
            alpha: 15f64.to_radians(),
            h: 0.0,
        }
        .to_pose();
        let goal = Pose2::new(1.5, 0.0, PI);
        let p = plan(&from, &goal, &PlanParams::default()).expect("a plan");
        assert!(close(&p.end(&from), &goal), "{p:?}");
        // An S: the two arcs turn opposite ways, and nothing reverses.
        assert!(p.arcs[0].turn() * p.arcs[1].turn() < 0.0, "{p:?}");
        assert!(p.arcs.iter().all(|a| a.length >= 0.0));
        let check = PlanParams {
            check_step_m: 0.01,
            ..PlanParams::default()
        };
        assert!(keeps_in_view(&p, &from, &check));
        // No longer than the straight line plus a little.
        assert!(
            p.distance() < 1.1 * from.x.hypot(from.y) - 1.5 + 0.5,
            "{}",
            p.distance()
        );
    }

    #[test]
    fn a_goal_straight_ahead_is_one_straight() {
        let from = Pose2::new(4.0, 0.0, PI);
        let goal = Pose2::new(1.5, 0.0, PI);
        let p = plan(&from, &goal, &PlanParams::default()).expect("a plan");
        assert!((p.distance() - 2.5).abs() < 1e-9 && p.turning() < 1e-9, "{p:?}");
    }

    #[test]
    fn a_view_that_cannot_be_kept_is_refused() {
        // The goal lies behind: any way there turns the module out of a 10° view.
        let from = Pose2::new(3.0, 0.0, PI);
        let goal = Pose2::new(4.0, 2.0, 0.0);
        let params = PlanParams {
            fov_half_angle: 10f64.to_radians(),
            ..PlanParams::default()
        };
        assert_eq!(plan(&from, &goal, &params), Err(PlanError::Infeasible));
        assert_eq!(
            plan(&Pose2::new(f64::NAN, 0.0, 0.0), &goal, &params),
            Err(PlanError::NonFinite)
        );
    }

    #[test]
    fn the_margin_and_the_range_bound_every_plan() {
        // 30 cm off the axis at 3.5 m, square to it, to the axis at 1.5 m: every check
        // point keeps the module's centre 10° inside the 45° half view and the rover
        // within 4 m of the module.
        let from = Pose2::new(3.5, 0.3, PI);
        let goal = Pose2::new(1.5, 0.0, PI);
        let params = PlanParams {
            view_margin_rad: 10f64.to_radians(),
            max_range_m: 4.0,
            check_step_m: 0.01,
            ..PlanParams::default()
        };
        let p = plan(&from, &goal, &params).expect("a plan");
        assert!(close(&p.end(&from), &goal), "{p:?}");
        let mut q = from;
        for arc in &p.arcs {
            for k in 1..=100 {
                let at = arc.at(&q, arc.length * f64::from(k) / 100.0);
                assert!(module_bearing(&at).abs() <= 35f64.to_radians() + 1e-6, "{at:?}");
                assert!(at.x.hypot(at.y) <= 4.0 + 1e-6, "{at:?}");
            }
            q = arc.end(&q);
        }
        // A reverse out of range is refused however cheap: straight back from 3.9 m to
        // 4.5 m on the axis.
        let ahead = Pose2::new(3.9, 0.0, PI);
        let behind = Pose2::new(4.5, 0.0, PI);
        assert_eq!(plan(&ahead, &behind, &params), Err(PlanError::Infeasible));
        // Starting beyond the range, driving in is allowed, farther out is not.
        let far = Pose2::new(5.0, 0.0, PI);
        assert!(plan(&far, &Pose2::new(3.0, 0.0, PI), &params).is_ok());
        assert_eq!(
            plan(&far, &Pose2::new(5.5, 0.0, PI), &params),
            Err(PlanError::Infeasible)
        );
        // Without the margin a plan may graze the view's edge; with it, the same start
        // 40° off (beyond 35°) may not turn the module any farther out.
        let edge = Pose2::new(3.0, 0.0, PI + 40f64.to_radians());
        let out = TwoArc {
            arcs: [
                Arc {
                    curvature: 0.5,
                    length: 0.2,
                },
                Arc::default(),
            ],
        };
        assert!(!keeps_in_view(&out, &edge, &params));
        let back = TwoArc {
            arcs: [
                Arc {
                    curvature: -0.5,
                    length: 0.2,
                },
                Arc::default(),
            ],
        };
        assert!(keeps_in_view(&back, &edge, &params));
    }

    #[test]
    fn the_turn_cap_refuses_sharper_arcs() {
        // A quarter turn: two arcs within a 30° cap change the heading by at most 60°, so
        // the goal is reachable without the cap and infeasible under it.
        let from = Pose2::new(0.0, 0.0, 0.0);
        let goal = Pose2::new(2.0, 2.0, PI / 2.0);
        let open = PlanParams {
            fov_half_angle: PI,
            ..PlanParams::default()
        };
        let p = plan(&from, &goal, &open).expect("a plan without the cap");
        assert!(close(&p.end(&from), &goal), "{p:?}");
        assert!(p.arcs.iter().any(|a| a.turn().abs() > 30f64.to_radians()), "{p:?}");
        let capped = PlanParams {
            max_arc_turn: 30f64.to_radians(),
            ..open
        };
        assert_eq!(plan(&from, &goal, &capped), Err(PlanError::Infeasible));
        // A 50° change, split by the cap: each arc within 30°, the goal reached.
        let made = TwoArc {
            arcs: [
                Arc {
                    curvature: 0.5,
                    length: 25f64.to_radians() / 0.5,
                },
                Arc {
                    curvature: 0.4,
                    length: 25f64.to_radians() / 0.4,
                },
            ],
        };
        let goal = made.end(&from);
        let p = plan(&from, &goal, &capped).expect("a plan within the cap");
        assert!(close(&p.end(&from), &goal), "{p:?}");
        assert!(
            p.arcs.iter().all(|a| a.turn().abs() <= 30f64.to_radians() + 1e-9),
            "{p:?}"
        );
        // The uncapped optimum of this goal turns one arc by more than 30° (a single arc
        // of 50°), so the cap changed the plan rather than agreeing with it.
        let free = plan(&from, &goal, &open).expect("a plan");
        assert!(
            free.arcs.iter().any(|a| a.turn().abs() > 30f64.to_radians()),
            "{free:?}"
        );
        // A cap that is not positive, or NaN, is refused as a parameter.
        for bad in [0.0, -1.0, f64::NAN] {
            let params = PlanParams {
                max_arc_turn: bad,
                ..open
            };
            assert_eq!(plan(&from, &goal, &params), Err(PlanError::NonFinite));
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Random feasible goals (the end of a random two-arc manoeuvre within the turn
        /// limit): the plan ends at the goal, within the limit, no costlier than the
        /// manoeuvre that made the goal.
        #[test]
        fn plans_reach_random_feasible_goals(
            x in -3.0f64..3.0, y in -3.0f64..3.0, th in -PI..PI,
            k1 in -1.9f64..1.9, s1 in -3.0f64..3.0, k2 in -1.9f64..1.9, s2 in -3.0f64..3.0,
        ) {
            let from = Pose2::new(x, y, th);
            let made = TwoArc { arcs: [Arc { curvature: k1, length: s1 }, Arc { curvature: k2, length: s2 }] };
            // Heading changes beyond ±180° wrap: the planner's arcs turn at most half a turn.
            prop_assume!((k1 * s1).abs() < 3.0 && (k2 * s2).abs() < 3.0);
            let goal = made.end(&from);
            let params = PlanParams { fov_half_angle: PI, headings: 720, ..PlanParams::default() };
            let p = plan(&from, &goal, &params);
            prop_assert!(p.is_ok(), "{from:?} → {goal:?}: {p:?}");
            let p = p.unwrap();
            prop_assert!(close(&p.end(&from), &goal), "{p:?} ends at {:?}", p.end(&from));
            for arc in &p.arcs {
                prop_assert!(arc.curvature.abs() <= 1.0 / params.min_radius_m + 1e-9);
            }
            let cost = |t: &TwoArc| t.distance() + params.turn_weight_m_per_rad * t.turning();
            prop_assert!(cost(&p) <= 1.05 * cost(&made) + 0.1, "{} > {}", cost(&p), cost(&made));
        }

        /// With a 30° cap every arc of every plan turns by at most 30°; goals made by two
        /// arcs of at most 25° each are still reached (the cap removes only sharper arcs).
        #[test]
        fn capped_plans_keep_every_arc_within_the_cap(
            x in -3.0f64..3.0, y in -3.0f64..3.0, th in -PI..PI,
            k1 in -1.9f64..1.9, s1 in -3.0f64..3.0, k2 in -1.9f64..1.9, s2 in -3.0f64..3.0,
        ) {
            let from = Pose2::new(x, y, th);
            let made = TwoArc { arcs: [Arc { curvature: k1, length: s1 }, Arc { curvature: k2, length: s2 }] };
            prop_assume!((k1 * s1).abs() < 3.0 && (k2 * s2).abs() < 3.0);
            let goal = made.end(&from);
            let cap = 30f64.to_radians();
            let params = PlanParams { fov_half_angle: PI, max_arc_turn: cap, ..PlanParams::default() };
            let within = made.arcs.iter().all(|a| a.turn().abs() <= 25f64.to_radians());
            match plan(&from, &goal, &params) {
                Ok(p) => {
                    prop_assert!(close(&p.end(&from), &goal), "{p:?} ends at {:?}", p.end(&from));
                    for arc in &p.arcs {
                        prop_assert!(arc.turn().abs() <= cap + 1e-9, "{p:?}");
                    }
                }
                Err(e) => {
                    prop_assert_eq!(e, PlanError::Infeasible);
                    prop_assert!(!within, "{from:?} → {goal:?} made by {made:?} within 25°");
                }
            }
        }
    }
}
