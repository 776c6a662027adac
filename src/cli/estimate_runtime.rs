//! `marsupial estimate --runtime`: Table I through the robot's loop. The sequence's
//! frames are the `krawler` robot's belly camera ([`SequenceFrames`], the same pixels as
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
use std::sync::{Arc, Mutex};

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

/// `profile` with the mount compensation `on` and the slip monitor on the encoders.
fn in_the_loop(profile: &Profile, on: bool) -> Profile {
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
    let p = in_the_loop(profile, params.mount.enabled);
    let mut krawler = crate::behaviors::krawler::agent(&p).map_err(|e| e.to_string())?;
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
