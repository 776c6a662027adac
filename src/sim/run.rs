//! One run of a campaign: the robot departs from the dock (imprinting on the way), the
//! proctor places it at the run's start, and it docks.
//!
//! The robot is a [`SimRobot`] behind the hardware traits, stepped in lockstep with a
//! [`ReactiveLoop`] over the profile's composed behavior ([`Lockstep`]): each tick its
//! cameras render, the loop decides, the commands reach the simulated motors, then the
//! physics advance. Both missions are started the way a real robot's are
//! ([`ReactiveLoop::begin`]); only the proctor's placement between them is the
//! simulator's.

use super::SimError;
use super::campaign::{AgentFactory, Prepared, RunRecord};
use super::engine::{PhaseEnd, Sim};
use super::lighting::LightingRun;
use super::lighting_random::LightingDraw;
use super::motion::Motion;
use super::record::{McapRecorder, RecordOptions, TickSample};
use super::render::SensorParams;
use super::rng::Rng;
use super::robot::SimRobot;
use super::scenario::{RunSpec, Scenario};
use crate::arbiter::{Lockstep, LoopStatus, NodeTrace, ReactiveLoop, TickOutput};
use crate::geometry::Pose2;
use crate::perception::RgbImage;
use crate::robot::Robot;
use crate::schemas::{Agent, Mission, Outcome};
use serde::Serialize;
use std::io::Write;
use std::path::Path;
use std::sync::Arc;

/// What a run records besides its `runs.jsonl` line.
#[derive(Default)]
pub struct Recording<'a> {
    /// Save every Nth camera frame as `DIR/{depart,frame}-{tick:05}-cam{i}.png` (N > 0).
    pub frames: Option<(&'a Path, u32)>,
    /// Write the decision trace here, one JSON object per tick ([`TraceLine`]).
    pub trace: Option<&'a mut dyn Write>,
    /// Record the run to this MCAP file ([`super::record`]): frames, percepts, commands,
    /// decision trace, poses and log.
    pub mcap: Option<(&'a Path, RecordOptions)>,
}

/// One line of a decision trace (`marsupial dock --trace`).
#[derive(Debug, Clone, Serialize)]
pub struct TraceLine<'a> {
    /// The mission running: `departure` or `docking`.
    pub mission: &'static str,
    /// Loop time, s (each mission's clock starts at 0 when the proctor places the robot).
    pub t: f64,
    /// The loop's status: running (with the phase's feedback), safe stop, finished...
    pub status: &'a LoopStatus,
    /// The command sent to the robot.
    pub command: &'a crate::schemas::MotorOutput,
    /// Every arbiter that ran this tick, outermost first: active children, proposals,
    /// winner, transitions and the events that fired them.
    pub nodes: &'a [NodeTrace],
}

impl Recording<'_> {
    /// A last trace line when the simulator, not the behavior, ended the mission: the
    /// plates closed (`docked`), the robot caught the entrance (`stuck_contact`), or time
    /// ran out (`timeout`), or it drove into an obstacle (`collision`).
    pub(super) fn end(&mut self, mission: &'static str, t: f64, end: &PhaseEnd, mcap: &mut Option<McapRecorder>) {
        let what = match end {
            PhaseEnd::Docked => "docked",
            PhaseEnd::Stuck { .. } => "stuck_contact",
            PhaseEnd::Collision { .. } => "collision",
            PhaseEnd::Timeout => "timeout",
            PhaseEnd::Finished(_) => return,
        };
        if let Some(m) = mcap.as_mut() {
            m.log(t, 2, &format!("{mission}: the world ended it: {what}"));
        }
        let Some(w) = self.trace.as_mut() else { return };
        let line = serde_json::json!({ "mission": mission, "t": t, "world": what });
        let _ = writeln!(w, "{line}");
    }

    fn frame(&mut self, prefix: &str, n: u64, frames: &[RgbImage]) {
        if let Some((dir, every)) = self.frames
            && every > 0
            && n.is_multiple_of(every as u64)
        {
            for (i, f) in frames.iter().enumerate() {
                let path = dir.join(format!("{prefix}-{n:05}-cam{i}.png"));
                if let Err(e) = crate::image_io::save_png(&path, f) {
                    tracing::warn!(target: "marsupial::sim", path = %path.display(), %e, "frame not saved");
                }
            }
        }
    }

    fn tick(&mut self, mission: &'static str, t: f64, root: &dyn Agent, out: &TickOutput, nodes: &mut Vec<NodeTrace>) {
        let Some(w) = self.trace.as_mut() else { return };
        nodes.clear();
        root.explain(nodes);
        let line = TraceLine {
            mission,
            t,
            status: &out.status,
            command: &out.command,
            nodes,
        };
        if let Ok(json) = serde_json::to_string(&line) {
            let _ = writeln!(w, "{json}");
        }
    }

    /// Records the tick to the MCAP file (after [`Recording::tick`], whose `nodes` it
    /// reuses when a trace is written too).
    fn mcap_tick(
        &mut self,
        mcap: &mut Option<McapRecorder>,
        mission: &'static str,
        t: f64,
        rig: &Rig,
        out: &TickOutput,
        nodes: &mut Vec<NodeTrace>,
    ) {
        let Some(m) = mcap.as_mut() else { return };
        let root = rig.lp.root();
        if self.trace.is_none() {
            nodes.clear();
            root.explain(nodes);
        }
        let trace = TraceLine {
            mission,
            t,
            status: &out.status,
            command: &out.command,
            nodes,
        };
        let (truth, odometry) = rig.sim.with(|s| (s.pose(), s.odometry().pose));
        m.tick(&TickSample {
            t,
            frames: rig.step.frames(),
            command: &out.command,
            trace: &trace,
            observation: root.observe(),
            truth,
            odometry,
        });
    }
}

/// The simulated robot and the loop that drives it through one run.
pub(super) struct Rig {
    pub(super) sim: SimRobot,
    pub(super) robot: Robot,
    pub(super) lp: ReactiveLoop<dyn Agent>,
    pub(super) step: Lockstep,
}

impl Rig {
    /// The simulated robot behind the scenario's devices, driven by `agent` in a loop
    /// of `config`, ticked in lockstep.
    ///
    /// # Errors
    /// [`SimError::Unsupported`] when a device kind cannot be simulated.
    pub(super) fn new(
        sim: Sim,
        p: &Prepared,
        agent: Box<dyn Agent>,
        config: crate::arbiter::LoopConfig,
    ) -> Result<Self, SimError> {
        let sim = SimRobot::new(sim);
        let robot = sim.robot(&p.devices).map_err(SimError::Unsupported)?;
        Ok(Self {
            step: Lockstep::new(&robot, &config),
            lp: ReactiveLoop::new(agent, config),
            sim,
            robot,
        })
    }

    /// Runs the mission just begun until the behavior reports an outcome, the robot docks
    /// or catches the entrance edge, or `max_s` of simulated time pass.
    pub(super) fn run(
        &mut self,
        mission: &'static str,
        max_s: f64,
        rec: &mut Recording<'_>,
        mcap: &mut Option<McapRecorder>,
    ) -> PhaseEnd {
        let t_end = self.sim.with(|s| s.time()) + max_s;
        let prefix = if mission == "departure" { "depart" } else { "frame" };
        let mut nodes = Vec::new();
        if let Some(m) = mcap.as_mut() {
            m.begin_mission(mission);
        }
        loop {
            let now = self.sim.with(|s| s.time());
            if now >= t_end - 1e-9 {
                rec.end(mission, now, &PhaseEnd::Timeout, mcap);
                return PhaseEnd::Timeout;
            }
            let out = self.step.tick(&mut self.robot, &mut self.lp, now);
            for (t, device, e) in self.step.take_errors() {
                tracing::warn!(target: "marsupial::sim", t, device, %e, "device fault");
                if let Some(m) = mcap.as_mut() {
                    m.log(t, 3, &format!("device fault: {device}: {e}"));
                }
            }
            rec.frame(prefix, self.sim.with(|s| s.frame_count()), self.step.frames());
            rec.tick(mission, now, self.lp.root(), &out, &mut nodes);
            rec.mcap_tick(mcap, mission, now, self, &out, &mut nodes);
            let moving = !out.command.drive.is_stop();
            let (limits, period) = (&self.lp.config().staleness, 1.0 / self.lp.config().rate_hz);
            self.sim.with(|s| {
                if moving && s.fault().is_some_and(|f| f.inputs_invalid(now, limits, period)) {
                    s.stale_motion_ticks += 1;
                }
            });
            match out.status {
                LoopStatus::SafeStop { .. } => self.sim.with(|s| s.safe_stops += 1),
                LoopStatus::Finished { outcome } => return PhaseEnd::Finished(outcome),
                _ => {}
            }
            if let Some(end) = self.sim.advance() {
                rec.end(mission, self.sim.with(|s| s.time()), &end, mcap);
                return end;
            }
        }
    }
}

/// The base's motion model on `terrain`: the profile's drive and limits, with the
/// scenario's slip, latency and acceleration limits.
pub(super) fn motion_for(sc: &Scenario, profile: &crate::profile::Profile, terrain: super::motion::Terrain) -> Motion {
    Motion::new(
        profile.drive.model(),
        profile.drive.limits(),
        sc.slip(terrain),
        sc.motion.latency_s,
        sc.motion.accel_mps2,
        sc.motion.yaw_accel_dps2.to_radians(),
    )
}

/// Where the robot really starts for `spec`: the nominal start plus the proctor's
/// placement error (position and heading jitter drawn from `draws`), slid clear of the
/// dock's body if the jitter pushed it in.
pub(super) fn jittered_start(
    sc: &Scenario,
    spec: &RunSpec,
    draws: &mut Rng,
    dock: &super::world::DockGeometry,
    (length, width): (f64, f64),
) -> Pose2 {
    let s = &spec.start;
    let jx = draws.normal() * sc.starts.position_jitter_m;
    let jy = draws.normal() * sc.starts.position_jitter_m;
    let jt = draws.normal() * sc.starts.heading_jitter_deg.to_radians();
    super::dock::slid_clear(
        dock,
        Pose2::new(s.pose.x + jx, s.pose.y + jy, s.pose.theta + jt),
        length,
        width,
    )
}

/// The simulated world of run `spec`: its lighting (drawn from `pair`, the stream paired
/// runs share), sensor, terrain, paints and seed, with the run's profile (its
/// segmentation mode and paints).
/// Returns the run's lighting and sensor too (the departure may run under others), and
/// the lighting's draw when the run's lighting is a distribution.
fn simulation(p: &Prepared, spec: &RunSpec, pair: &mut Rng) -> (Sim, LightingRun, SensorParams, Option<LightingDraw>) {
    let sc: &Scenario = &p.loaded.scenario;
    let profile = p.profile_for(spec);
    let (lighting, draw) = sc.lighting_for_run(&spec.lighting, spec.pair_seed);
    let run_light = LightingRun::new(lighting.clone(), pair, sc.timeout_s + 120.0);
    let sensor = sc.sensor_params(&lighting);
    let motion = motion_for(sc, &profile, spec.terrain);
    let sim = Sim::new(
        Arc::new(profile),
        Arc::clone(p.world_for(spec)),
        run_light.clone(),
        sensor,
        motion,
        sc.dt_s,
        spec.seed,
    );
    (sim, run_light, sensor, draw)
}

/// Puts the robot where a departure starts: in the dock, or, for an open dock (a target
/// on the ground), 1 cm outside the socket's mouth zone, where the dock judge would count
/// it as docked again.
/// Where a robot sits docked, and whether that is inside a closed dock's pouch: in the
/// dock, or, for an open dock (a target on the ground), 1 cm outside the socket's mouth
/// zone, where the dock judge would count it as docked again; for a cone, with its arm's
/// tip in the throat.
pub(super) fn docked_pose(s: &Sim) -> (Pose2, bool) {
    let dock = s.world().dock;
    let length = s.profile().body.length_m;
    if let Some(c) = &dock.cone {
        // The arm's tip seated in the cone's throat, the rover facing the module.
        return (Pose2::new(c.arm - c.depth, 0.0, std::f64::consts::PI), false);
    }
    let at = if dock.open {
        Pose2::new(length / 2.0 + dock.mouth_reach(0.0) + 0.01, 0.0, 0.0)
    } else {
        Pose2::new(-dock.depth + length / 2.0, 0.0, 0.0)
    };
    (at, !dock.open)
}

/// Puts the robot where a departure starts ([`docked_pose`]).
pub(super) fn place_docked(s: &mut Sim) {
    let (at, inside) = docked_pose(s);
    s.place(at, inside);
}

/// The simulated robot of run `spec` (its lighting, sensor, terrain and seed), docked and
/// ready to depart: to drive it with the threaded runtime or your own loop.
pub fn docked_robot(p: &Prepared, spec: &RunSpec) -> SimRobot {
    let (mut sim, _, _, _) = simulation(p, spec, &mut Rng::new(spec.pair_seed));
    place_docked(&mut sim);
    SimRobot::new(sim)
}

/// Runs one run of a prepared campaign (see the module docs).
///
/// # Errors
/// [`SimError::Unsupported`] when no agent can be built, the robot refuses to dock, or a
/// `[[sensors]]` kind cannot be simulated.
pub fn run_one(
    p: &Prepared,
    spec: &RunSpec,
    make_agent: &AgentFactory,
    rec: &mut Recording<'_>,
) -> Result<RunRecord, SimError> {
    let sc: &Scenario = &p.loaded.scenario;
    let profile = p.profile_for(spec);
    let agent = make_agent(&profile).map_err(|e| SimError::Unsupported(e.to_string()))?;
    let mut pair = Rng::new(spec.pair_seed);
    let (sim, run_light, sensor, draw) = simulation(p, spec, &mut pair);
    let (length, width) = (profile.body.length_m, profile.body.width_m);
    let mut rig = Rig::new(sim, p, agent, profile.loop_config())?;
    let dock = p.world_for(spec).dock;
    let mut mcap = match rec.mcap {
        Some((path, opts)) => {
            let mut m = McapRecorder::create(path, &profile.cameras, opts)?;
            m.log(
                0.0,
                2,
                &format!(
                    "run {} of {}: start {} ({:.2} m, {:+.0}°), trial {}, lighting {}, segmentation {}, terrain {}, seed {}",
                    spec.index,
                    sc.name,
                    spec.start.label,
                    spec.start.distance,
                    spec.start.angle_deg,
                    spec.trial,
                    spec.lighting,
                    spec.segmentation.as_str(),
                    spec.terrain.as_str(),
                    spec.seed
                ),
            );
            Some(m)
        }
        None => None,
    };
    // The run's `tracing` events go to the recording's `/log` too, until the run returns.
    let _tracing = mcap.as_ref().map(McapRecorder::capture_tracing);
    // Departure: undock and imprint (paired runs share it through `pair`).
    let mut imprinted = None;
    if sc.imprint.enabled && rig.lp.begin(&Mission::Departure).is_ok() {
        let (dep_light, dep_sensor) = match &sc.imprint.lighting {
            Some(name) => {
                let l = sc.lighting_named(name);
                (
                    LightingRun::new(l.clone(), &mut Rng::new(spec.pair_seed ^ 0xD0), 120.0),
                    sc.sensor_params(&l),
                )
            }
            None => (run_light.clone(), sensor),
        };
        rig.sim.with(|s| {
            s.set_lighting(dep_light, dep_sensor);
            place_docked(s);
        });
        let end = rig.run("departure", 90.0, rec, &mut mcap);
        imprinted = Some(matches!(end, PhaseEnd::Finished(Outcome::Completed)));
        let mut light = run_light;
        light.advance_session(sc.imprint.sleep_s);
        rig.sim.with(|s| s.set_lighting(light, sensor));
    }
    // Placement with the proctor's error.
    // `prepare` refused nominal starts inside the body; the jitter may still push one in.
    let start = jittered_start(sc, spec, &mut pair, &dock, (length, width));
    rig.sim.with(|sim| {
        sim.place(start, false);
        sim.set_fault(spec.fault.and_then(|i| sc.faults.get(i)).cloned());
    });
    let dock_hint = sc.ballistic.enabled.then(|| {
        // Odometry restarts at the placed pose: the dock's origin seen from there, with
        // the a-priori error (its own stream, so the other draws stay as they were).
        let mut r = Rng::new(spec.seed ^ 0xBA11_1571C);
        let exact = start.relative(&Pose2::default());
        let b = &sc.ballistic;
        Pose2::new(
            exact.x + r.normal() * b.error_m,
            exact.y + r.normal() * b.error_m,
            exact.theta + r.normal() * b.heading_error_deg.to_radians(),
        )
    });
    rig.lp
        .begin(&Mission::Docking { dock_hint, stage: true })
        .map_err(|e| SimError::Unsupported(e.to_string()))?;
    let end = rig.run("docking", sc.timeout_s, rec, &mut mcap);
    let manoeuvres = rig.lp.root().stats().manoeuvres;
    let mut record = rig.sim.with(|sim| record(spec, sim, end, imprinted, manoeuvres));
    if let Some(f) = spec.fault.and_then(|i| sc.faults.get(i)) {
        record.fault = Some(f.name.clone());
        record.fault_as_expected = Some(f.expect.accepts(&record.outcome));
        record.stale_motion_ticks = Some(rig.sim.with(|s| s.stale_motion_ticks));
        record.safe_stop_s = Some(record.safe_stops as f64 / profile.loop_.rate_hz);
    }
    record.lighting_draw = draw;
    if let Some(mut m) = mcap {
        let t = record.time_s;
        m.log(
            t,
            if record.success { 2 } else { 4 },
            &format!(
                "run {} ends: {} after {:.1} s, {:.2} m driven{}",
                record.index,
                record.outcome,
                record.time_s,
                record.path_m,
                if record.success { "" } else { " (failed)" }
            ),
        );
        m.finish()?;
    }
    Ok(record)
}

/// The run's `runs.jsonl` line, from the simulator's ground truth.
pub(super) fn record(spec: &RunSpec, sim: &Sim, end: PhaseEnd, imprinted: Option<bool>, manoeuvres: u32) -> RunRecord {
    let s = &spec.start;
    let success = sim.docked();
    let outcome = match end {
        PhaseEnd::Docked => "docked".to_string(),
        PhaseEnd::Finished(Outcome::Docked) if success => "docked".to_string(),
        PhaseEnd::Finished(Outcome::Docked | Outcome::Completed) => "false_dock".to_string(),
        PhaseEnd::Finished(Outcome::Failed(r)) => r.as_str().to_string(),
        PhaseEnd::Stuck { .. } => "stuck_contact".to_string(),
        PhaseEnd::Collision { .. } => "collision".to_string(),
        PhaseEnd::Timeout => "timeout".to_string(),
    };
    let time_s = sim.mission_time();
    let path_m = sim.path_m;
    RunRecord {
        index: spec.index,
        start: s.label.clone(),
        lighting: spec.lighting.clone(),
        segmentation: spec.segmentation.as_str().into(),
        terrain: spec.terrain.as_str().into(),
        fiducial_colors: spec.fiducial_colors,
        trial: spec.trial,
        seed: spec.seed,
        distance_m: s.distance,
        angle_deg: s.angle_deg,
        success,
        outcome,
        time_s,
        path_m,
        v_eff_cmps: if success && time_s > 0.0 {
            s.distance / time_s * 100.0
        } else {
            0.0
        },
        commands_per_m: if path_m > 0.01 {
            sim.drive_changes as f64 / path_m
        } else {
            0.0
        },
        entrance_lateral_m: sim.entrance.map(|e| e.0),
        entrance_heading_deg: sim.entrance.map(|e| e.1.to_degrees()),
        safe_stops: sim.safe_stops,
        imprinted,
        manoeuvres,
        tether: sim.tether_tally(),
        track: sim
            .track
            .iter()
            .map(|t| [(t[1] * 1000.0).round() as i32, (t[2] * 1000.0).round() as i32])
            .collect(),
        // The fault's, the draw's and the outing's figures are added by those stages.
        ..RunRecord::default()
    }
}
