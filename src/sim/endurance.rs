//! Endurance outings: one robot, `cycles` departure → dock cycles in one continuous
//! simulation, nothing reset between them (a scenario's `[endurance]`,
//! [`EnduranceSpec`]).
//!
//! A campaign's runs each build a fresh robot and have the proctor place it; an outing
//! builds one [`Sim`], one agent and one [`ReactiveLoop`](crate::arbiter::ReactiveLoop) and
//! keeps them. Odometry integrates from the docked pose the outing began at, with its slip
//! error, for the whole outing; the agent keeps whatever it keeps across missions (the
//! colour model's adaptation, the behavior's memory); the simulation's clock runs on, and
//! the light drifts with it through the `[endurance] lighting` programmes
//! ([`LightingRun::drifting`]). Each mission is started the way a real robot's is,
//! [`ReactiveLoop::begin`](crate::arbiter::ReactiveLoop::begin). Each cycle:
//!
//! 1. **Departure**: the dock lets go ([`Sim::release`]) and the robot undocks and
//!    imprints, as a campaign run's departure does.
//! 2. **Excursion**: the robot drives itself to the cycle's start (drawn from `[starts]`,
//!    with the proctor's jitter as the spread of where the excursion ends). The driver
//!    here ([`excursion`]) is a simple waypoint follower through the motion model: turn
//!    toward the start, drive to it, turn to its heading. It stands in for the daughter's
//!    own mission away from the mother (exploring, inspecting), steers by the simulator's
//!    true pose, and is not part of the behavior under test; what matters is that the
//!    robot gets there by driving, so odometry's error grows as on a real outing.
//! 3. **Docking** from there, judged as a campaign run is (`time_s` counts from its
//!    start).
//!
//! A cycle that does not dock (a typed failure, a timeout, the entrance edge caught, or
//! an excursion that ended against something) does not end the outing: the proctor
//! carries the robot back into the dock ([`Sim::carry`]: odometry, which saw no wheel
//! turn, keeps reading where the robot was) and the next cycle departs from there; the
//! record says `carried_back`.
//!
//! An outing is one unit: `trials` runs it on one thread, it cannot be sharded, and
//! `--resume` refuses it (resuming midway would need the robot's whole state; run it
//! again, which restarts the outing). `dock --index N` runs the outing through cycle N
//! and records or traces cycle N only. The same scenario and seed give the same
//! `runs.jsonl`, byte for byte.

use super::SimError;
use super::campaign::{self, AgentFactory, CampaignOptions, Prepared, RunRecord, Summary};
use super::engine::{PhaseEnd, Sim};
use super::lighting::LightingRun;
use super::record::{McapRecorder, RecordOptions};
use super::run::{Recording, Rig, docked_pose, jittered_start, motion_for, record};
use super::scenario::{EnduranceSpec, RunSpec};
use crate::geometry::{Pose2, Twist, wrap_angle};
use crate::schemas::{DriveCommand, Mission, Outcome, TetherCommand};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;
use std::sync::Arc;

/// Success and drift over an endurance outing (`summary.json`'s `endurance`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EnduranceSummary {
    /// Cycles run.
    pub cycles: usize,
    /// Cycles that docked.
    pub docked: usize,
    /// Cycles after which the proctor carried the robot back into the dock.
    pub carried_back: usize,
    /// Excursions that did not reach their start in time (the robot docked from where it
    /// was).
    pub excursions_short: usize,
    /// The outing's clock when its last cycle began, h.
    pub last_cycle_at_h: f64,
    /// Cycles in each quarter compared below (a quarter of the outing, at least 1).
    pub quarter: usize,
    /// Mean time to dock over the docked cycles of the first quarter, s.
    pub first_quarter_mean_s: Option<f64>,
    /// Mean time to dock over the docked cycles of the last quarter, s.
    pub last_quarter_mean_s: Option<f64>,
    /// Least-squares slope of time to dock against the cycle index over the docked
    /// cycles, s per cycle (positive: docking slows as the outing goes on).
    pub slope_s_per_cycle: Option<f64>,
    /// The same slope within starts: each docked cycle's time and index less the means
    /// of the docked cycles from its start (starts docked from only once are left out),
    /// so the drift is not confounded with which starts the later cycles drew, s per
    /// cycle.
    #[serde(default)]
    pub slope_within_starts_s_per_cycle: Option<f64>,
    /// Odometry's position error at the start of docking: [first cycle, last cycle,
    /// largest], m.
    pub odometry_error_m: [f64; 3],
}

/// The endurance summary of a campaign's records, when they are an outing's cycles.
pub fn summarise(records: &[RunRecord]) -> Option<EnduranceSummary> {
    let cycles: Vec<&RunRecord> = records.iter().filter(|r| r.cycle.is_some()).collect();
    if cycles.is_empty() {
        return None;
    }
    let n = cycles.len();
    let quarter = (n / 4).max(1);
    let mean_docked = |rs: &[&RunRecord]| {
        let ok: Vec<f64> = rs.iter().filter(|r| r.success).map(|r| r.time_s).collect();
        (!ok.is_empty()).then(|| ok.iter().sum::<f64>() / ok.len() as f64)
    };
    let docked: Vec<&&RunRecord> = cycles.iter().filter(|r| r.success).collect();
    let point = |r: &RunRecord| (r.cycle.unwrap_or(r.index) as f64, r.time_s);
    let pts: Vec<(f64, f64)> = docked.iter().map(|r| point(r)).collect();
    let slope = least_squares(&pts, (mean(pts.iter().map(|p| p.0)), mean(pts.iter().map(|p| p.1))));
    // Within starts: centred on each start's own means.
    let mut starts: Vec<&str> = docked.iter().map(|r| r.start.as_str()).collect();
    starts.sort_unstable();
    starts.dedup();
    let mut centred = Vec::new();
    for s in starts {
        let g: Vec<(f64, f64)> = docked.iter().filter(|r| r.start == s).map(|r| point(r)).collect();
        if g.len() >= 2 {
            let (mx, my) = (mean(g.iter().map(|p| p.0)), mean(g.iter().map(|p| p.1)));
            centred.extend(g.iter().map(|p| (p.0 - mx, p.1 - my)));
        }
    }
    let within = least_squares(&centred, (0.0, 0.0));
    let odo: Vec<f64> = cycles.iter().map(|r| r.odometry_error_m.unwrap_or(0.0)).collect();
    Some(EnduranceSummary {
        cycles: n,
        docked: cycles.iter().filter(|r| r.success).count(),
        carried_back: cycles.iter().filter(|r| r.carried_back == Some(true)).count(),
        excursions_short: cycles.iter().filter(|r| r.excursion_reached == Some(false)).count(),
        last_cycle_at_h: cycles.last().and_then(|r| r.outing_clock_s).unwrap_or(0.0) / 3600.0,
        quarter,
        first_quarter_mean_s: mean_docked(&cycles[..quarter]),
        last_quarter_mean_s: mean_docked(&cycles[n - quarter..]),
        slope_s_per_cycle: slope,
        slope_within_starts_s_per_cycle: within,
        odometry_error_m: [odo[0], odo[n - 1], odo.iter().copied().fold(0.0, f64::max)],
    })
}

fn mean(xs: impl Iterator<Item = f64>) -> f64 {
    let (mut sum, mut n) = (0.0, 0usize);
    for x in xs {
        sum += x;
        n += 1;
    }
    if n == 0 { 0.0 } else { sum / n as f64 }
}

/// The least-squares slope of `pts` about the centre `(mx, my)`; `None` for fewer than
/// two points or no spread in x.
fn least_squares(pts: &[(f64, f64)], (mx, my): (f64, f64)) -> Option<f64> {
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (pts.len() >= 2 && sxx > 0.0).then(|| sxy / sxx)
}

/// How an outing records its cycles besides their records.
pub struct OutingRecording<'a, 'b> {
    /// The cycle whose frames and decision trace are written to `recording` (none: no
    /// cycle's).
    pub traced: Option<usize>,
    /// Frames and trace of the traced cycle (its `mcap` is not used: see `mcap_for`).
    pub recording: &'a mut Recording<'b>,
    /// Where each cycle's MCAP recording goes, if anywhere.
    pub mcap_for: &'a dyn Fn(usize) -> Option<(PathBuf, RecordOptions)>,
}

/// Where the excursion's driver stops: within 3 cm and 2° of its goal.
const ARRIVED_M: f64 = 0.03;
const ARRIVED_RAD: f64 = 2.0 * std::f64::consts::PI / 180.0;

/// Drives the robot to `goal` by the motion model (see the module docs): out of the
/// pouch if it is in one, turn toward the goal (driving forward or in reverse, whichever
/// faces it), drive there steering onto it, turn to the goal's heading, stop. Steers by
/// the true pose; commands reach the motors as the behavior's do (latency, acceleration
/// limits, slip), so odometry integrates the excursion with its error.
///
/// Returns whether it arrived within `max_s`, or how the world ended it (an obstacle,
/// the dock's entrance edge).
pub fn excursion(sim: &mut Sim, goal: Pose2, speed: f64, max_s: f64) -> Result<bool, PhaseEnd> {
    let (t0, tick) = (sim.time(), 1.0 / sim.profile().loop_.rate_hz);
    let max_w = 0.8;
    if sim.tether_reading().is_some() {
        // The reel passive: the tether pays out as the robot drives away.
        sim.command_reel(TetherCommand {
            reel_rate: 0.0,
            free_wheel: false,
        });
    }
    let mut at_position = false;
    let mut arrived = false;
    let mut settle = 0.0;
    loop {
        if sim.time() - t0 >= max_s - 1e-9 {
            sim.command_drive(DriveCommand::Stop);
            break;
        }
        let pose = sim.pose();
        let (lx, ly) = pose.to_local(goal.x, goal.y);
        let d = lx.hypot(ly);
        if d > 2.5 * ARRIVED_M {
            at_position = false;
        } else if d < ARRIVED_M {
            at_position = true;
        }
        let cmd = if arrived {
            settle += tick;
            if settle >= 1.0 {
                break;
            }
            DriveCommand::Stop
        } else if sim.inside() {
            // Straight out of the pouch, whichever end leads.
            DriveCommand::Straight {
                v: speed * pose.theta.cos().signum(),
            }
        } else if !at_position {
            let a = ly.atan2(lx);
            let reverse = a.abs() > std::f64::consts::FRAC_PI_2;
            let e = if reverse {
                wrap_angle(a - std::f64::consts::PI)
            } else {
                a
            };
            if e.abs() > 0.35 {
                DriveCommand::Turn {
                    omega: (2.0 * e).clamp(-max_w, max_w),
                }
            } else {
                let v = speed * (d / 0.25).clamp(0.2, 1.0);
                DriveCommand::Twist(Twist::new(if reverse { -v } else { v }, (2.0 * e).clamp(-max_w, max_w)))
            }
        } else {
            let e = wrap_angle(goal.theta - pose.theta);
            if e.abs() > ARRIVED_RAD {
                let w = (2.0 * e).clamp(-max_w, max_w);
                DriveCommand::Turn {
                    omega: if w.abs() < 0.15 { 0.15 * w.signum() } else { w },
                }
            } else {
                arrived = true;
                DriveCommand::Stop
            }
        };
        sim.command_drive(cmd);
        if let Some(end) = sim.advance() {
            return Err(end);
        }
    }
    Ok(arrived)
}

/// The outing's odometry error: odometry's pose against the true pose expressed in the
/// frame odometry began in (`origin`, the docked pose at the outing's start). Metres and
/// degrees.
fn odometry_error(sim: &Sim, origin: &Pose2) -> (f64, f64) {
    let truth = origin.relative(&sim.pose());
    let odo = sim.odometry().pose;
    (truth.distance(&odo), wrap_angle(odo.theta - truth.theta).to_degrees())
}

/// Runs an endurance outing's cycles `0..=last` (see the module docs), handing each
/// cycle's record to `emit` as it ends.
///
/// # Errors
/// [`SimError::Unsupported`] when the scenario has no `[endurance]`, no agent can be
/// built or the robot refuses to dock; [`SimError`] from `emit` or a recording.
pub fn run_outing(
    p: &Prepared,
    make_agent: &AgentFactory,
    last: usize,
    rec: OutingRecording<'_, '_>,
    emit: &mut dyn FnMut(RunRecord) -> Result<(), SimError>,
) -> Result<(), SimError> {
    let sc = &p.loaded.scenario;
    let e: &EnduranceSpec = sc
        .endurance
        .as_ref()
        .ok_or_else(|| SimError::Unsupported(format!("scenario `{}` has no [endurance] table", sc.name)))?;
    let Some(first) = p.runs.first() else {
        return Ok(());
    };
    let profile = p.profile_for(first);
    let agent = make_agent(&profile).map_err(|e| SimError::Unsupported(e.to_string()))?;
    let keys: Vec<_> = e.lighting.iter().map(|n| sc.lighting_named(n)).collect();
    let sensor = sc.sensor_params(&keys[0]);
    let light = LightingRun::drifting(keys, e.day_s);
    let motion = motion_for(sc, &profile, first.terrain);
    let (length, width) = (profile.body.length_m, profile.body.width_m);
    let config = profile.loop_config();
    let cameras = profile.cameras.clone();
    let mut sim = Sim::new(
        Arc::new(profile),
        Arc::clone(p.world_for(first)),
        light,
        sensor,
        motion,
        sc.dt_s,
        sc.outing_seed(),
    );
    // The one placement of the outing: docked, where odometry's frame begins.
    let (home, inside) = docked_pose(&sim);
    sim.place(home, inside);
    let origin = home;
    let mut rig = Rig::new(sim, p, agent, config)?;
    let rec_all = rec.recording;
    for spec in p.runs.iter().take(last.saturating_add(1)) {
        let mut blank = Recording::default();
        let traced = rec.traced == Some(spec.index);
        let r: &mut Recording<'_> = if traced { &mut *rec_all } else { &mut blank };
        let mut mcap = match (rec.mcap_for)(spec.index) {
            Some((path, opts)) => {
                let mut m = McapRecorder::create(&path, &cameras, opts)?;
                m.log(
                    0.0,
                    2,
                    &format!(
                        "cycle {} of endurance outing {}: start {} ({:.2} m, {:+.0}°), light {}, seed {}",
                        spec.index,
                        sc.name,
                        spec.start.label,
                        spec.start.distance,
                        spec.start.angle_deg,
                        spec.lighting,
                        spec.seed
                    ),
                );
                Some(m)
            }
            None => None,
        };
        // The cycle's `tracing` events go to its recording's `/log` too.
        let _tracing = mcap.as_ref().map(McapRecorder::capture_tracing);
        let cycle = cycle(&mut rig, p, spec, e, origin, (length, width), r, &mut mcap)?;
        let mut record = cycle;
        if !record.success {
            // The proctor carries the robot back into the dock.
            rig.sim.with(|s| {
                let (at, inside) = docked_pose(s);
                s.carry(at, inside);
            });
            record.carried_back = Some(true);
        } else {
            record.carried_back = Some(false);
        }
        if let Some(mut m) = mcap {
            m.log(
                record.time_s,
                if record.success { 2 } else { 4 },
                &format!(
                    "cycle {} ends: {} after {:.1} s",
                    record.index, record.outcome, record.time_s
                ),
            );
            m.finish()?;
        }
        emit(record)?;
    }
    Ok(())
}

/// One cycle of an outing: departure, excursion, docking; its record (before the
/// proctor, if needed).
#[allow(clippy::too_many_arguments)]
fn cycle(
    rig: &mut Rig,
    p: &Prepared,
    spec: &RunSpec,
    e: &EnduranceSpec,
    origin: Pose2,
    (length, width): (f64, f64),
    rec: &mut Recording<'_>,
    mcap: &mut Option<McapRecorder>,
) -> Result<RunRecord, SimError> {
    let sc = &p.loaded.scenario;
    let clock = rig.sim.with(|s| s.time());
    // 1. Departure.
    rig.sim.with(|s| {
        s.begin_leg();
        s.release();
    });
    let imprinted = match rig.lp.begin(&Mission::Departure) {
        Ok(()) => {
            let end = rig.run("departure", 90.0, rec, mcap);
            Some(matches!(end, PhaseEnd::Finished(Outcome::Completed)))
        }
        Err(_) => None,
    };
    // 2. Excursion to the cycle's start, with the proctor's jitter as its spread.
    let mut draws = super::rng::Rng::named(spec.seed, "excursion");
    let goal = jittered_start(sc, spec, &mut draws, &p.world_for(spec).dock, (length, width));
    let went = rig
        .sim
        .with(|sim| excursion(sim, goal, e.excursion_speed_mps, e.excursion_timeout_s));
    let (odo_m, odo_deg) = rig.sim.with(|sim| odometry_error(sim, &origin));
    // 3. Docking from wherever the excursion ended.
    let mut record = match went {
        Ok(_) => {
            rig.sim.with(|sim| {
                sim.begin_leg();
                sim.set_fault(None);
            });
            rig.lp
                .begin(&Mission::docking())
                .map_err(|e| SimError::Unsupported(e.to_string()))?;
            let end = rig.run("docking", sc.timeout_s, rec, mcap);
            let manoeuvres = rig.lp.root().stats().manoeuvres;
            rig.sim.with(|sim| record(spec, sim, end, imprinted, manoeuvres))
        }
        Err(end) => {
            // The excursion ran into something: the cycle fails without docking.
            let mut r = rig.sim.with(|sim| {
                sim.begin_leg();
                record(spec, sim, end, imprinted, 0)
            });
            r.outcome = format!("excursion_{}", r.outcome);
            r.success = false;
            r
        }
    };
    record.cycle = Some(spec.index);
    record.outing_clock_s = Some(clock);
    record.odometry_error_m = Some(odo_m);
    record.odometry_error_deg = Some(odo_deg);
    record.excursion_reached = Some(matches!(went, Ok(true)));
    Ok(record)
}

/// `trials` for an endurance scenario: the outing's cycles streamed to
/// `out/runs.jsonl` (one line each, in order), then `summary.json` and the plots.
///
/// # Errors
/// [`SimError::InvalidArgument`] for `--resume` (an outing cannot be resumed midway),
/// and as [`run_outing`] and for unwritable output.
pub fn run_campaign(
    p: &Prepared,
    make_agent: &AgentFactory,
    opts: &CampaignOptions,
) -> Result<(Vec<RunRecord>, Summary), SimError> {
    let io = |path: &std::path::Path| {
        let path = path.display().to_string();
        move |source| SimError::Io { path, source }
    };
    if opts.resume {
        return Err(SimError::InvalidArgument(format!(
            "--resume: `{}` is an endurance outing, one continuous run of the same robot, which cannot be resumed midway; run it again without --resume (the outing restarts)",
            p.loaded.scenario.name
        )));
    }
    make_agent(&p.loaded.profile).map_err(|e| SimError::Unsupported(e.to_string()))?;
    if let Some(r) = &opts.record {
        std::fs::create_dir_all(&r.dir).map_err(io(&r.dir))?;
    }
    let mut jsonl = None;
    if let Some(dir) = &opts.out {
        std::fs::create_dir_all(dir).map_err(io(dir))?;
        let path = dir.join("runs.jsonl");
        let f = std::fs::File::create(&path).map_err(io(&path))?;
        jsonl = Some((f, path));
    }
    let mut lines = (opts.progress != campaign::Progress::Off).then(|| campaign::ProgressLines::new(p, [].iter()));
    let mut records = Vec::with_capacity(p.runs.len());
    let mcap_for = |i: usize| opts.record.as_ref().map(|r| (r.path(i), r.options));
    let mut blank = Recording::default();
    run_outing(
        p,
        make_agent,
        p.runs.len().saturating_sub(1),
        OutingRecording {
            traced: None,
            recording: &mut blank,
            mcap_for: &mcap_for,
        },
        &mut |r: RunRecord| {
            if let (Some(record), true) = (&opts.record, r.success)
                && record.failed_only
            {
                let path = record.path(r.index);
                if let Err(e) = std::fs::remove_file(&path) {
                    tracing::warn!(target: "marsupial::sim", path = %path.display(), %e, "recording of a docked cycle not removed");
                }
            }
            if let (Some(dir), true) = (&opts.out, opts.per_run_files) {
                let d = dir.join(format!("run-{:04}", r.index));
                std::fs::create_dir_all(&d).map_err(io(&d))?;
                let csv = d.join("trajectory.csv");
                campaign::write_track_csv(&csv, &r).map_err(io(&csv))?;
            }
            if let Some((f, path)) = jsonl.as_mut() {
                let mut line = serde_json::to_vec(&r).unwrap_or_default();
                line.push(b'\n');
                std::io::Write::write_all(f, &line).map_err(io(path))?;
            }
            if let Some(l) = lines.as_mut() {
                l.record(r.success);
            }
            records.push(r);
            Ok(())
        },
    )?;
    let summary = campaign::summary(&p.loaded.scenario.name, &records);
    if let Some(dir) = &opts.out {
        let path = dir.join("summary.json");
        std::fs::write(&path, serde_json::to_string_pretty(&summary).unwrap_or_default()).map_err(io(&path))?;
    }
    Ok((records, summary))
}
