//! `marsupial replay`: run a profile's perception, or its whole behavior open-loop, on the
//! frames of a real log (see [`crate::replay`]), printing one line per frame.

use super::json_line;
use crate::config::ConfigError;
use crate::msgs::rescale::Rescaler;
use crate::perception::RgbImage;
use crate::profile::CameraSpec;
use crate::replay::decode::{self, DecodeError};
use crate::replay::log::Log;
use crate::replay::session::{FrameOutput, Session};
use crate::replay::topics::{TopicKind, choose};
use crate::replay::{ReplayError, topics::TopicError};
use crate::schemas::{Observation, ObservedPercept, OdometryReading, Stamped};
use crate::sim::record::{McapRecorder, RecordError, RecordOptions};
use serde::Serialize;
use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Options of `marsupial replay` (also its command-line arguments).
#[derive(Debug, Clone, PartialEq, clap::Args)]
pub struct ReplayOptions {
    /// The log: a ROS 2 bag in MCAP (a file, or a rosbag2 directory with its
    /// metadata.yaml), or a Foxglove-schema MCAP file.
    #[arg(value_name = "LOG.mcap|BAG_DIR")]
    pub log: PathBuf,
    /// Profile whose camera 0 took the frames (e.g. profiles/bujold.toml).
    #[arg(long, value_name = "PROFILE")]
    pub profile: PathBuf,
    /// Image topic (default: the log's only image topic).
    #[arg(long, value_name = "TOPIC")]
    pub image_topic: Option<String>,
    /// Odometry topic (default: the log's only odometry topic, if any).
    #[arg(long, value_name = "TOPIC")]
    pub odom_topic: Option<String>,
    /// Run the profile's whole behavior open-loop (a docking mission) and print the
    /// command it would have sent, not the perceptual schema alone.
    #[arg(long)]
    pub behavior: bool,
    /// One JSON object per line: `frame`, `skipped` and a final `summary`.
    #[arg(long)]
    pub json: bool,
    /// Write the frames, percepts (and commands) to this MCAP file, for Foxglove.
    #[arg(long, value_name = "OUT.mcap")]
    pub record: Option<PathBuf>,
}

/// Why `replay` failed.
#[derive(Debug, Error)]
pub enum ReplayCliError {
    /// Bad profile.
    #[error(transparent)]
    Profile(#[from] ConfigError),
    /// The log, its topics or the profile cannot be replayed.
    #[error(transparent)]
    Replay(#[from] ReplayError),
    /// The recording could not be written.
    #[error(transparent)]
    Record(#[from] RecordError),
    /// Writing the output failed.
    #[error("cannot write output: {0}")]
    Output(#[from] std::io::Error),
}

/// Messages of one topic that were skipped for one reason.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Skipped {
    /// The topic.
    pub topic: String,
    /// The reason's short name ([`DecodeError::reason`]).
    pub reason: &'static str,
    /// How many.
    pub count: u64,
    /// The first one's index in the topic.
    pub first_index: u64,
    /// The first one's error.
    pub first_why: String,
}

/// The last line of the output: what was read and what was skipped.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    /// The image topic.
    pub image_topic: String,
    /// Its kind.
    pub image_kind: TopicKind,
    /// The odometry topic, if any.
    pub odom_topic: Option<String>,
    /// Frames run.
    pub frames: u64,
    /// Frames in which the fiducial was found.
    pub found: u64,
    /// Odometry messages used.
    pub odometry: u64,
    /// Skipped messages by topic and reason.
    pub skipped: Vec<Skipped>,
}

#[derive(Serialize)]
struct FrameLine<'a> {
    kind: &'static str,
    topic: &'a str,
    index: u64,
    t: f64,
    stamp_ns: u64,
    width: usize,
    height: usize,
    found: bool,
    percept: Option<&'a ObservedPercept>,
    #[serde(skip_serializing_if = "Option::is_none")]
    v: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    omega: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    command: Option<&'a crate::schemas::MotorOutput>,
    #[serde(skip_serializing_if = "Option::is_none")]
    status: Option<&'a crate::arbiter::LoopStatus>,
}

#[derive(Serialize)]
struct SkippedLine<'a> {
    kind: &'static str,
    topic: &'a str,
    index: u64,
    reason: &'static str,
    why: String,
}

/// Whether a percept found its target.
fn found(p: &ObservedPercept) -> bool {
    match p {
        ObservedPercept::TwoBlock(p) => p.found,
        ObservedPercept::Pyramid(p) => p.view.is_some(),
        ObservedPercept::Krawler(k) => k.fresh && k.markers.iter().all(Option::is_some),
    }
}

/// Skip counts, by (topic, reason).
#[derive(Default)]
struct Skips(BTreeMap<(String, &'static str), Skipped>);

impl Skips {
    fn add(&mut self, topic: &str, index: u64, e: &DecodeError) {
        self.0
            .entry((topic.to_string(), e.reason()))
            .and_modify(|s| s.count += 1)
            .or_insert_with(|| Skipped {
                topic: topic.to_string(),
                reason: e.reason(),
                count: 1,
                first_index: index,
                first_why: e.to_string(),
            });
    }
}

/// Per-topic bookkeeping: messages seen, used, and the first failure.
#[derive(Default)]
struct TopicCount {
    seen: u64,
    used: u64,
    first_error: Option<(u64, DecodeError)>,
}

impl TopicCount {
    fn check(&self, path: &Path, topic: &str) -> Result<(), ReplayError> {
        match &self.first_error {
            Some((first_index, why)) if self.used == 0 => Err(ReplayError::Unreadable {
                path: path.to_path_buf(),
                topic: topic.to_string(),
                count: self.seen,
                first_index: *first_index,
                why: Box::new(why.clone()),
            }),
            _ => Ok(()),
        }
    }
}

/// The replay clock: seconds since the first message used.
struct Clock(Option<u64>);

impl Clock {
    fn t(&mut self, ns: u64) -> f64 {
        let t0 = *self.0.get_or_insert(ns);
        (ns as i128 - t0 as i128) as f64 / 1e9
    }
}

/// The camera spec to record frames of `size` under: the profile's, or without
/// intrinsics when the log's frames are another size (their calibration is unknown).
fn record_spec(spec: &CameraSpec, size: (usize, usize)) -> CameraSpec {
    let mut s = spec.clone();
    if (s.width_px, s.height_px) != size {
        s.width_px = size.0;
        s.height_px = size.1;
        s.intrinsics = None;
        s.hfov_deg = None;
    }
    s
}

/// Runs `replay`, writing one line per frame (and per skipped message) to `out`, then a
/// summary.
///
/// # Errors
/// [`ReplayCliError`]: a bad profile, log or topic, a topic with no usable message, a
/// frame the behavior cannot take, or output that cannot be written. Lines for the frames
/// before a fault in the file (a truncated log) are written before the error, and so is
/// the summary.
pub fn run(opts: &ReplayOptions, out: &mut dyn Write) -> Result<Summary, ReplayCliError> {
    run_with(opts, crate::behaviors::catalog::shipped(), out)
}

/// [`run`] with the robot built from `catalog` (a crate's own robot kinds).
///
/// # Errors
/// As [`run`].
pub fn run_with(
    opts: &ReplayOptions,
    catalog: &crate::behaviors::Catalog,
    out: &mut dyn Write,
) -> Result<Summary, ReplayCliError> {
    let profile = catalog.load_profile(&opts.profile)?;
    let log = Log::open(&opts.log)?;
    let topic_err = |error: TopicError| ReplayError::Topic {
        path: opts.log.clone(),
        error,
    };
    let Some((image_topic, image_kind)) =
        choose(log.topics(), opts.image_topic.as_deref(), false, false).map_err(topic_err)?
    else {
        return Err(ReplayError::Setup("no image topic".into()).into());
    };
    let odom = choose(log.topics(), opts.odom_topic.as_deref(), true, true).map_err(topic_err)?;
    let mut session = Session::new_with(&profile, catalog, opts.behavior, odom.is_some())?;

    let mut wanted = vec![image_topic.as_str()];
    if let Some((t, _)) = &odom {
        wanted.push(t.as_str());
    }
    let mut summary = Summary {
        image_topic: image_topic.clone(),
        image_kind,
        odom_topic: odom.as_ref().map(|(t, _)| t.clone()),
        frames: 0,
        found: 0,
        odometry: 0,
        skipped: Vec::new(),
    };
    let mut skips = Skips::default();
    let mut counts: BTreeMap<&str, TopicCount> = BTreeMap::new();
    let mut clock = Clock(None);
    let mut latest_odom: Option<Stamped<OdometryReading>> = None;
    let mut recorder: Option<McapRecorder> = None;
    let mut fault = None;
    // Frames of another size than the camera's, with its aspect ratio, rescaled to it.
    let mut rescaler = Rescaler::new();
    let mut scaled = RgbImage::default();

    for msg in log.messages(&wanted) {
        let msg = match msg {
            Ok(m) => m,
            Err(e) => {
                fault = Some(e);
                break;
            }
        };
        let count = counts.entry(msg.topic).or_default();
        count.seen += 1;
        let is_image = msg.topic == image_topic;
        let decoded = if is_image {
            decode::frame(image_kind, &msg.data).map(Ok)
        } else {
            let kind = odom.as_ref().map_or(TopicKind::RosOdometry, |(_, k)| *k);
            decode::odometry(kind, &msg.data).map(Err)
        };
        let item = match decoded {
            Ok(item) => item,
            Err(e) => {
                if opts.json {
                    json_line(
                        out,
                        &SkippedLine {
                            kind: "skipped",
                            topic: msg.topic,
                            index: msg.index,
                            reason: e.reason(),
                            why: e.to_string(),
                        },
                    )?;
                } else {
                    writeln!(out, "skip {} #{}: {e}", msg.topic, msg.index)?;
                }
                skips.add(msg.topic, msg.index, &e);
                count.first_error.get_or_insert((msg.index, e));
                continue;
            }
        };
        count.used += 1;
        match item {
            Err(o) => {
                let ns = o.stamp_ns.unwrap_or(msg.log_time);
                let t = clock.t(ns);
                latest_odom = Some(Stamped {
                    stamp: t,
                    value: o.reading,
                });
                summary.odometry += 1;
                if let Some(r) = recorder.as_mut() {
                    r.odometry(t, &o.reading.pose);
                }
            }
            Ok(frame) => {
                let size = (frame.image.width(), frame.image.height());
                let image = if session.accepts(size) {
                    &frame.image
                } else {
                    let camera = session.camera_size();
                    scaled.resize(camera.0, camera.1);
                    if rescaler.fill(&frame.image.view(), &mut scaled).is_err() {
                        return Err(ReplayError::FrameSize {
                            topic: image_topic.clone(),
                            index: msg.index,
                            got: size,
                            expected: camera,
                        }
                        .into());
                    }
                    &scaled
                };
                let ns = frame.stamp_ns.unwrap_or(msg.log_time);
                let t = clock.t(ns);
                let res = session.frame(t, image, latest_odom)?;
                summary.frames += 1;
                if res.percept.as_ref().is_some_and(found) {
                    summary.found += 1;
                }
                if let Some(path) = &opts.record {
                    if recorder.is_none() {
                        let spec = record_spec(&profile.cameras[0], (image.width(), image.height()));
                        let mut r = McapRecorder::create(path, &[spec], RecordOptions::default())?;
                        r.begin_mission("replay");
                        recorder = Some(r);
                    }
                    if let Some(r) = recorder.as_mut() {
                        record_frame(r, t, image, &res);
                    }
                }
                write_frame(out, opts.json, &image_topic, msg.index, t, ns, size, &res)?;
            }
        }
    }

    summary.skipped = skips.0.into_values().collect();
    if opts.json {
        #[derive(Serialize)]
        struct Line<'a> {
            kind: &'static str,
            #[serde(flatten)]
            summary: &'a Summary,
        }
        json_line(
            out,
            &Line {
                kind: "summary",
                summary: &summary,
            },
        )?;
    } else {
        write_summary(out, &summary)?;
    }
    if let Some(r) = recorder {
        r.finish()?;
    }
    if let Some(e) = fault {
        return Err(e.into());
    }
    let image_count = counts.get(image_topic.as_str());
    if image_count.is_none_or(|c| c.seen == 0) {
        return Err(ReplayError::Empty {
            path: opts.log.clone(),
            topic: image_topic,
        }
        .into());
    }
    for (topic, c) in &counts {
        c.check(&opts.log, topic)?;
    }
    Ok(summary)
}

fn record_frame(r: &mut McapRecorder, t: f64, image: &RgbImage, res: &FrameOutput) {
    let obs = res.percept.map(|percept| Observation {
        camera: 0,
        percept,
        ranges: res.ranges,
    });
    r.perception(t, std::slice::from_ref(image), obs.as_ref());
    if let Some((cmd, _)) = &res.command {
        r.command(t, cmd);
    }
}

#[allow(clippy::too_many_arguments)]
fn write_frame(
    out: &mut dyn Write,
    json: bool,
    topic: &str,
    index: u64,
    t: f64,
    ns: u64,
    size: (usize, usize),
    res: &FrameOutput,
) -> std::io::Result<()> {
    let twist = res.command.as_ref().map(|(c, _)| c.drive.to_twist());
    if json {
        return json_line(
            out,
            &FrameLine {
                kind: "frame",
                topic,
                index,
                t,
                stamp_ns: ns,
                width: size.0,
                height: size.1,
                found: res.percept.as_ref().is_some_and(found),
                percept: res.percept.as_ref(),
                v: twist.map(|w| w.v),
                omega: twist.map(|w| w.omega),
                command: res.command.as_ref().map(|(c, _)| c),
                status: res.command.as_ref().map(|(_, s)| s),
            },
        );
    }
    write!(out, "{topic} #{index:<4} t {t:8.3} s  {}×{}  ", size.0, size.1)?;
    match &res.percept {
        Some(ObservedPercept::TwoBlock(p)) if p.found => write!(
            out,
            "found  left {} px  right {} px  ratio {:.3}  offset {:+.1} px  [{}]",
            p.left_px, p.right_px, p.ratio, p.offset_px, p.mode
        )?,
        Some(ObservedPercept::TwoBlock(p)) => write!(out, "not found  [{}]", p.mode)?,
        Some(ObservedPercept::Pyramid(p)) => match &p.view {
            Some(v) => write!(
                out,
                "found  ball {:.2} m  bearing {:+.1}°",
                v.ball_distance_m,
                v.bearing.to_degrees()
            )?,
            None => write!(out, "not found")?,
        },
        Some(ObservedPercept::Krawler(k)) => write!(
            out,
            "markers {}/8  roll {:+.1}° {:+.1}°  steer {:+.1}° {:+.1}°  θ {:.2} {:.2} {:.2} {:.2} rad",
            k.markers.iter().flatten().count(),
            k.roll_rad[0].to_degrees(),
            k.roll_rad[1].to_degrees(),
            k.steer_rad[0].to_degrees(),
            k.steer_rad[1].to_degrees(),
            k.wheel_rad[0],
            k.wheel_rad[1],
            k.wheel_rad[2],
            k.wheel_rad[3]
        )?,
        None => write!(out, "no percept")?,
    }
    if let (Some(w), Some((_, status))) = (twist, &res.command) {
        let state = match status {
            crate::arbiter::LoopStatus::Running { feedback } => feedback.phase.to_string(),
            crate::arbiter::LoopStatus::Idle => "idle".into(),
            crate::arbiter::LoopStatus::SafeStop { reason } => format!("safe stop: {reason}"),
            crate::arbiter::LoopStatus::Finished { outcome } => format!("finished: {outcome:?}"),
        };
        write!(out, "  →  v {:+.3} m/s  ω {:+.3} rad/s  ({state})", w.v, w.omega)?;
    }
    writeln!(out)
}

fn write_summary(out: &mut dyn Write, s: &Summary) -> std::io::Result<()> {
    write!(
        out,
        "{} frames from {} (found in {}), {} odometry messages",
        s.frames, s.image_topic, s.found, s.odometry
    )?;
    if let Some(t) = &s.odom_topic {
        write!(out, " from {t}")?;
    }
    writeln!(out)?;
    for k in &s.skipped {
        writeln!(
            out,
            "skipped {} messages of {} ({}), first #{}: {}",
            k.count, k.topic, k.reason, k.first_index, k.first_why
        )?;
    }
    Ok(())
}
