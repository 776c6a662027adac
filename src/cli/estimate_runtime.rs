//! `marsupial estimate --runtime`: Table I through the robot's loop. The sequence's
//! frames are the `krawler` robot's belly camera (`cli::estimate_frames`, the same pixels as
//! the offline run), its encoders report the sequence's true speed, and [`Lockstep`]
//! ticks the robot built from the profile (its memory's perceptual schema, the
//! estimator, and its tree) once per frame at the frame's time. Each estimate is taken
//! from the memory as the loop made it, and measured as the offline run's are.
//!
//! Two changes to the profile's robot, both for a scripted gear: the slip monitor's
//! reference is the encoders, not the traverse's command (the gear moves as the sequence
//! says, whatever the tree commands, so a command reference would be a slip every
//! window), and when the monitor halts the robot a new mission starts at once (the gear
//! goes on moving); the halts are counted, a false alarm each, as the gear never slips.
//! The RANSAC draws come from the offline run's generator, so the two paths can be
//! compared frame for frame.
//!
//! On the threaded runtime (`--runtime threads`, [`estimate_threads`]) the camera thread
//! delivers the next frame once the loop has estimated the last, so that every frame
//! reaches the estimator in order at up to the loop's rate, in real time; the encoders
//! report the speed of the frame last delivered. The loop's clock is the wall's there,
//! not the sequence's, so the slip monitor is not judged (its threshold is raised out of
//! reach): only the estimates are measured.

use super::estimate::{EstimateRun, Record, measure};
use super::estimate_frames::SequenceFrames;
use crate::arbiter::{Lockstep, LoopStatus, ReactiveLoop};
use crate::geometry::{Pose2, Twist};
use crate::perception::{KrawlerEstimate, KrawlerParams, RgbImage};
use crate::profile::{NodeSpec, Profile};
use crate::robot::{Camera, Drive, Exposure, HardwareError, Odometer, Robot};
use crate::schemas::{DriveCommand, Mission, OdometryReading};
use crate::sim::krawler_sequence::{SequenceSpec, TruthFrame, generate};
use crate::sim::rng::Rng;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Which loop `estimate --runtime` drives the robot with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum RuntimePath {
    /// [`Lockstep`], one tick per frame at the frame's time ([`estimate_runtime`]).
    Lockstep,
    /// The threaded runtime, in real time ([`estimate_threads`]).
    Threads,
}

/// What the slip monitor made of a sequence through the loop.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SlipFigures {
    /// Windows judged.
    pub windows: u64,
    /// Windows judged a slip (each halted the robot): false alarms, the gear never slips.
    pub alarms: u64,
    /// Largest |optical − encoder| rotation over one judged window, rad.
    pub max_disagreement_rad: f64,
}

/// The belly camera: the sequence's next frame at each capture (`NotReady` for a lost one).
struct SequenceCamera {
    frames: SequenceFrames,
    size: (usize, usize),
    next: usize,
}

impl Camera for SequenceCamera {
    fn resolution(&self) -> (usize, usize) {
        self.size
    }
    fn capture(&mut self, frame: &mut RgbImage) -> Result<Exposure, HardwareError> {
        let i = self.next;
        if i >= self.frames.len() {
            return Err(HardwareError::NotReady);
        }
        self.next += 1;
        match self.frames.render(i, frame) {
            Ok(true) => Ok(Exposure::NOW),
            Ok(false) => Err(HardwareError::NotReady),
            Err(detail) => Err(HardwareError::Fault {
                device: "belly camera".into(),
                detail,
            }),
        }
    }
}

/// The encoders: the sequence's true speed at each read (one read per tick).
struct SequenceEncoders {
    speed: Vec<f64>,
    t: Vec<f64>,
    next: usize,
    x: f64,
}

impl Odometer for SequenceEncoders {
    fn read(&mut self) -> Result<OdometryReading, HardwareError> {
        let i = self.next.min(self.speed.len() - 1);
        if i > 0 {
            self.x += self.speed[i - 1] * (self.t[i] - self.t[i - 1]);
        }
        self.next += 1;
        Ok(OdometryReading {
            pose: Pose2::new(self.x, 0.0, 0.0),
            twist: Twist::new(self.speed[i], 0.0),
        })
    }
}

/// The wheel motors of a scripted gear: commands go nowhere.
struct Scripted;

impl Drive for Scripted {
    fn apply(&mut self, _c: &DriveCommand) -> Result<(), HardwareError> {
        Ok(())
    }
}

/// `profile` with the mount compensation `on` and the slip monitor on the encoders (and
/// with `judged` false, its threshold out of reach).
fn in_the_loop(profile: &Profile, on: bool, judged: bool) -> Profile {
    let mut p = profile.clone();
    if let Some(r) = p.robot.as_mut() {
        r.tuning.insert("mount_compensation".into(), toml::Value::Boolean(on));
    }
    if let Some(tree) = p.behavior.tree.as_mut() {
        for node in tree.nodes.values_mut() {
            if let NodeSpec::Leaf { schema, params, .. } = node
                && schema == "krawler.slip_monitor"
            {
                params.insert("reference".into(), toml::Value::String("odometry".into()));
                if !judged {
                    params.insert("threshold_rad".into(), toml::Value::Float(1e9));
                }
            }
        }
    }
    p
}

/// Generates the sequence and estimates every frame through the robot's loop (see the
/// module docs), then measures.
///
/// # Errors
/// As [`super::estimate::estimate`], and when the profile's robot does not build or a
/// mission cannot start.
pub fn estimate_runtime(
    spec: &SequenceSpec,
    profile: &Profile,
    seed: u64,
    params: KrawlerParams,
) -> Result<(EstimateRun, SlipFigures), String> {
    let truth = generate(spec, profile, seed)?;
    let p = in_the_loop(profile, params.mount.enabled, true);
    let mut krawler = crate::behaviors::catalog::shipped()
        .compose(&crate::behaviors::krawler::Krawler, &p)
        .map_err(|e| e.to_string())?;
    let mut ransac = Rng::named(seed, "krawler-ransac");
    let m = krawler.memory_mut();
    m.schema_mut()
        .set_draw(Box::new(move |n| (ransac.next_u64() % n as u64) as usize));
    let seen: Arc<Mutex<Vec<(f64, KrawlerEstimate)>>> = Arc::new(Mutex::new(Vec::with_capacity(truth.len())));
    let log = Arc::clone(&seen);
    m.on_estimate(Box::new(move |e| {
        if let Ok(mut v) = log.lock() {
            v.push((e.stamp, e.estimate));
        }
    }));
    let cam = p.cameras.first().ok_or("the profile has no camera")?;
    let camera = SequenceCamera {
        frames: SequenceFrames::new(spec, &p, &truth, seed)?,
        size: (cam.width_px, cam.height_px),
        next: 0,
    };
    let mut robot = Robot::new(vec![Box::new(camera)], Box::new(Scripted));
    robot.odometer = Some(Box::new(SequenceEncoders {
        speed: truth.iter().map(|f| f.speed).collect(),
        t: truth.iter().map(|f| f.t).collect(),
        next: 0,
        x: 0.0,
    }));
    let mut lp = ReactiveLoop::new(Box::new(krawler), p.loop_config());
    lp.begin(&Mission::docking()).map_err(|e| e.to_string())?;
    let mut step = Lockstep::new(&robot, lp.config());
    let mut slip = SlipFigures::default();
    let mut judged = f64::NEG_INFINITY;
    for f in &truth {
        let out = step.tick(&mut robot, &mut lp, f.t);
        if let Some((_, device, e)) = step.take_errors().next() {
            return Err(format!("t {:.3} s: {device}: {e}", f.t));
        }
        let s = lp.root().memory().slip;
        if s.t > judged {
            judged = s.t;
            slip.windows += 1;
            slip.max_disagreement_rad = slip.max_disagreement_rad.max((s.optical_rad - s.reference_rad).abs());
        }
        if let LoopStatus::Finished { .. } = out.status {
            slip.alarms += 1;
            lp.begin(&Mission::docking()).map_err(|e| e.to_string())?;
        }
    }
    let seen = std::mem::take(&mut *seen.lock().map_err(|_| "the estimate log was poisoned")?);
    let records = match_frames(&truth, seen)?;
    Ok((measure(spec, profile, seed, params, truth, records, "lockstep")?, slip))
}

/// Each estimate's frame, by its stamp (the frame's time: the camera exposes at the tick).
fn match_frames(truth: &[TruthFrame], seen: Vec<(f64, KrawlerEstimate)>) -> Result<Vec<Record>, String> {
    let mut index = 0;
    let mut out = Vec::with_capacity(seen.len());
    for (stamp, estimate) in seen {
        while index < truth.len() && truth[index].t < stamp {
            index += 1;
        }
        if index == truth.len() || truth[index].t != stamp {
            return Err(format!(
                "an estimate stamped {stamp} s matches no frame of the sequence"
            ));
        }
        out.push(Record { index, estimate });
    }
    Ok(out)
}

/// The belly camera on the threaded runtime: the next frame once the loop has estimated
/// the one before (see the module docs).
struct PacedCamera {
    frames: SequenceFrames,
    size: (usize, usize),
    next: usize,
    /// Frames delivered, by index; how many the loop has estimated.
    delivered: Arc<Mutex<Vec<usize>>>,
    estimated: Arc<AtomicU64>,
    /// The index of the frame last delivered (the encoders' speed).
    current: Arc<AtomicUsize>,
}

impl Camera for PacedCamera {
    fn resolution(&self) -> (usize, usize) {
        self.size
    }
    fn capture(&mut self, frame: &mut RgbImage) -> Result<Exposure, HardwareError> {
        let waited = Instant::now();
        let fault = |detail: String| HardwareError::Fault {
            device: "belly camera".into(),
            detail,
        };
        let delivered = self.delivered.lock().map_err(|_| fault("poisoned".into()))?.len() as u64;
        while self.estimated.load(Ordering::Acquire) < delivered {
            if waited.elapsed() > Duration::from_millis(30) {
                return Err(HardwareError::NotReady);
            }
            std::thread::sleep(Duration::from_millis(1));
        }
        while self.next < self.frames.len() {
            let i = self.next;
            self.next += 1;
            if self.frames.render(i, frame).map_err(fault)? {
                self.current.store(i, Ordering::Release);
                self.delivered.lock().map_err(|_| fault("poisoned".into()))?.push(i);
                return Ok(Exposure::NOW);
            }
        }
        std::thread::sleep(Duration::from_millis(30));
        Err(HardwareError::NotReady)
    }
}

/// The encoders on the threaded runtime: the speed of the frame last delivered.
struct PacedEncoders {
    speed: Vec<f64>,
    current: Arc<AtomicUsize>,
}

impl Odometer for PacedEncoders {
    fn read(&mut self) -> Result<OdometryReading, HardwareError> {
        let i = self.current.load(Ordering::Acquire).min(self.speed.len() - 1);
        Ok(OdometryReading {
            pose: Pose2::default(),
            twist: Twist::new(self.speed[i], 0.0),
        })
    }
}

/// As [`estimate_runtime`], on the threaded runtime (see the module docs): real time,
/// every frame delivered to the loop in order.
///
/// # Errors
/// As [`estimate_runtime`], and when the run ends before every frame is estimated (a
/// frame the loop was given in a safe stop, say).
pub fn estimate_threads(
    spec: &SequenceSpec,
    profile: &Profile,
    seed: u64,
    params: KrawlerParams,
) -> Result<EstimateRun, String> {
    use crate::arbiter::runtime::{RuntimeConfig, StopHandle, run_missions};
    let truth = generate(spec, profile, seed)?;
    let p = in_the_loop(profile, params.mount.enabled, false);
    let mut krawler = crate::behaviors::catalog::shipped()
        .compose(&crate::behaviors::krawler::Krawler, &p)
        .map_err(|e| e.to_string())?;
    let mut ransac = Rng::named(seed, "krawler-ransac");
    let m = krawler.memory_mut();
    m.schema_mut()
        .set_draw(Box::new(move |n| (ransac.next_u64() % n as u64) as usize));
    let estimated = Arc::new(AtomicU64::new(0));
    let seen: Arc<Mutex<Vec<KrawlerEstimate>>> = Arc::new(Mutex::new(Vec::with_capacity(truth.len())));
    let (log, count) = (Arc::clone(&seen), Arc::clone(&estimated));
    m.on_estimate(Box::new(move |e| {
        if let Ok(mut v) = log.lock() {
            v.push(e.estimate);
        }
        count.fetch_add(1, Ordering::Release);
    }));
    let cam = p.cameras.first().ok_or("the profile has no camera")?;
    let delivered = Arc::new(Mutex::new(Vec::with_capacity(truth.len())));
    let current = Arc::new(AtomicUsize::new(0));
    let camera = PacedCamera {
        frames: SequenceFrames::new(spec, &p, &truth, seed)?,
        size: (cam.width_px, cam.height_px),
        next: 0,
        delivered: Arc::clone(&delivered),
        estimated: Arc::clone(&estimated),
        current: Arc::clone(&current),
    };
    let mut robot = Robot::new(vec![Box::new(camera)], Box::new(Scripted));
    robot.odometer = Some(Box::new(PacedEncoders {
        speed: truth.iter().map(|f| f.speed).collect(),
        current,
    }));
    let mut lp = ReactiveLoop::new(Box::new(krawler), p.loop_config());
    let stop = StopHandle::new();
    let frames = truth.len();
    let watch = {
        let (stop, delivered) = (stop.clone(), Arc::clone(&delivered));
        let estimated = Arc::clone(&estimated);
        std::thread::spawn(move || {
            // Ends the run once the last frame is delivered and estimated (or given up).
            let mut since: Option<Instant> = None;
            while !stop.is_stopped() {
                std::thread::sleep(Duration::from_millis(50));
                let last = delivered.lock().map(|d| d.last().copied()).unwrap_or(None);
                let done = estimated.load(Ordering::Acquire) as usize >= delivered.lock().map_or(0, |d| d.len());
                if last.is_some_and(|i| i + 1 >= frames) && done {
                    stop.stop();
                } else if last.is_some_and(|i| i + 1 >= frames) {
                    let t = *since.get_or_insert_with(Instant::now);
                    if t.elapsed() > Duration::from_secs(2) {
                        stop.stop();
                    }
                }
            }
        })
    };
    let rc = RuntimeConfig {
        max_duration: Some(Duration::from_secs_f64(spec.duration_s * 4.0 + 30.0)),
        ..RuntimeConfig::default()
    };
    let report = run_missions(&mut robot, &mut lp, &[Mission::docking()], &rc, &stop);
    stop.stop();
    let _ = watch.join();
    if let Some(why) = report.aborted {
        return Err(format!("the run was aborted: {why:?}"));
    }
    let delivered = std::mem::take(&mut *delivered.lock().map_err(|_| "poisoned")?);
    let seen = std::mem::take(&mut *seen.lock().map_err(|_| "poisoned")?);
    if delivered.last().is_none_or(|i| i + 1 < frames) {
        return Err(format!(
            "the run ended after {:.1} s with {} of {} frames delivered",
            report.elapsed_s,
            delivered.len(),
            frames
        ));
    }
    let missed = (delivered.len() - seen.len().min(delivered.len())) as u64;
    if missed > 0 {
        return Err(format!(
            "{missed} of {} frames delivered to the loop were not estimated (ticks in a safe stop: {:?})",
            delivered.len(),
            report.events.first()
        ));
    }
    let records = delivered
        .into_iter()
        .zip(seen)
        .map(|(index, estimate)| Record { index, estimate })
        .collect();
    measure(spec, profile, seed, params, truth, records, "threads")
}
