//! Repositioning (`reposition`) and the ballistic region (`ballistic`): turn, drive and
//! turn by odometry to a staging pose on the dock axis, facing along it. Each is a
//! sequencer in the profile whose states are the common manoeuvre legs
//! ([`crate::behaviors::common::motion`]), registered here over Bujold's memory:
//!
//! * `bujold.clear`: beside the gate, where the body's corners sweep a circle of half
//!   the diagonal, drive straight out first, front first (event `cleared`);
//! * `bujold.face`: turn so that the end leading toward the staging point faces it
//!   (`faced`, or `arrived` when already there);
//! * `bujold.drive`: drive until the staging point is abeam (`abeam` or `arrived`);
//! * `bujold.align`: turn to the staging heading; event `aligned`, with the viewing-angle
//!   memory cleared, so the approach starts afresh.
//!
//! The sequencer's selector ([`Staging`], `bujold.reposition` or `bujold.ballistic`)
//! sets the staging pose on entry and picks the first leg: the reposition takes the plan
//! the approach or the decision left in memory (and starts with `bujold.clear` when the
//! plan says so); the ballistic region (seed 004 Fig. 1) plans from the a-priori dock
//! pose instead, `ballistic_staging_m` out on the dock axis.

use super::memory::{Memory, RepositionPlan};
use crate::arbiter::Selector;
use crate::behaviors::common::motion::{
    Aim, AimFn, BackOff, BackOffParams, Distance, DriveAbeam, DriveParams, End, FaceParams, Hooks, TurnParams, TurnTo,
    face,
};
use crate::behaviors::registry::{LeafArgs, Registry, SelectorArgs};
use crate::geometry::Pose2;
use crate::schemas::Inputs;

/// Where the staging pose comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlanFrom {
    /// The plan the previous phase left in memory.
    Memory,
    /// The a-priori dock pose ([`Mission::Docking`](crate::schemas::Mission)).
    DockHint,
}

/// The selector of a repositioning sequencer (see the module docs).
pub struct Staging {
    from: PlanFrom,
    /// The `bujold.clear` state, if the sequence has one.
    clear: Option<usize>,
}

impl Staging {
    /// The selector of the sequencer `args` describes, planning `from`.
    pub fn new(args: &SelectorArgs<'_>, from: PlanFrom) -> Self {
        let schema = |state: &String| {
            let tree = args.profile.behavior.tree.as_ref()?;
            match tree.nodes.get(state)? {
                crate::profile::tree::NodeSpec::Leaf { schema, .. } => Some(schema.clone()),
                _ => None,
            }
        };
        let clear = args
            .states
            .iter()
            .position(|s| schema(s).as_deref() == Some("bujold.clear"));
        Self { from, clear }
    }
}

impl Selector<Memory> for Staging {
    fn select(&mut self, _m: &mut Memory, _inputs: &Inputs<'_>, _current: usize) -> Option<usize> {
        None
    }

    fn entry(&mut self, m: &mut Memory, _inputs: &Inputs<'_>) -> Option<usize> {
        let plan = match self.from {
            PlanFrom::Memory => m.plan.take(),
            PlanFrom::DockHint => m.dock_hint.map(|dock| RepositionPlan {
                target: dock.compose(&Pose2::new(m.tuning.ballistic_staging_m, 0.0, 0.0)),
                clear_first: false,
            }),
        };
        // With no plan (none was left, or no hint), stage where the robot stands.
        let plan = plan.unwrap_or(RepositionPlan {
            target: m.odo,
            clear_first: false,
        });
        m.staging = Some(plan.target);
        match self.clear {
            Some(c) if plan.clear_first => Some(c),
            Some(c) => Some(c + 1),
            None => Some(0),
        }
    }
}

/// Registers the legs and the two selectors in `registry`.
pub fn register(registry: &mut Registry<Memory>) {
    registry
        .register_selector("bujold.reposition", |_: &Memory, a: &SelectorArgs<'_>| {
            Ok(Box::new(Staging::new(a, PlanFrom::Memory)))
        })
        .register_selector("bujold.ballistic", |_: &Memory, a: &SelectorArgs<'_>| {
            Ok(Box::new(Staging::new(a, PlanFrom::DockHint)))
        })
        .register("bujold.clear", |m: &Memory, a: &LeafArgs<'_>| {
            let p: BackOffParams = a.params()?;
            let speed = m.approach.steering.speed;
            let leg = BackOff::new(a.phase(), Distance::Fixed(p.distance_m), speed, End::Event("cleared"));
            Ok(Box::new(leg.timeout(p.timeout_s.unwrap_or(f64::INFINITY))))
        })
        .register("bujold.face", |_: &Memory, a: &LeafArgs<'_>| {
            let p: FaceParams = a.params()?;
            let aim: AimFn<Memory> = Box::new(move |m| m.staging.map_or(Aim::Hold, |s| face(&m.odo, &s, p.arrive_m)));
            let tol = Some(p.heading_tolerance_deg.to_radians());
            Ok(Box::new(TurnTo::new(a.phase(), aim, tol, "faced")))
        })
        .register("bujold.drive", |m: &Memory, a: &LeafArgs<'_>| {
            let d: DriveParams = a.params()?;
            let s = &m.approach.steering;
            let target = Box::new(|m: &Memory| m.staging);
            let leg = DriveAbeam::new(a.phase(), target, s.speed, s.tick_s, d.arrive_m, d.abeam_m);
            Ok(Box::new(leg))
        })
        .register("bujold.align", |_: &Memory, a: &LeafArgs<'_>| {
            let t: TurnParams = a.params()?;
            let aim: AimFn<Memory> = Box::new(|m| m.staging.map_or(Aim::Hold, |s| Aim::Heading(s.theta)));
            let forget = Hooks {
                end: |m: &mut Memory| {
                    m.alpha_filtered = None;
                    m.alpha_window.clear();
                    m.ratio_gate.reset();
                },
                ..Hooks::default()
            };
            let tol = Some(t.heading_tolerance_deg.to_radians());
            Ok(Box::new(
                TurnTo::new(a.phase(), aim, tol, "aligned")
                    .timeout(t.timeout_s)
                    .hooks(forget),
            ))
        });
}
