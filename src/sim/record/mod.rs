//! MCAP recordings of runs, to open in Foxglove (`marsupial dock --record FILE.mcap`,
//! `marsupial trials --record-dir DIR`).
//!
//! One file per run holds, on the simulation clock (nanoseconds from the run's start:
//! the departure from 0, the docking mission 0.1 s after the departure's last message,
//! so a recording is the same file byte for byte for the same seed):
//!
//! | topic | schema | what |
//! | --- | --- | --- |
//! | `/camI/image` | `sensor_msgs/msg/Image` (`rgb8`, ROS 2 CDR), or `foxglove.CompressedImage` (JPEG, JSON) with [`RecordOptions::jpeg`] | every frame camera I delivered |
//! | `/camI/calibration` | `foxglove.CameraCalibration` | its pin-hole intrinsics, with each frame (pin-hole cameras only) |
//! | `/camI/annotations` | `foxglove.ImageAnnotations` | the percept drawn over the frame: block boxes, centroids, pair box ([`annotations`]) |
//! | `/percept` | `marsupial.Percept` (JSON) | the percept ([`Observation`]) |
//! | `/colour_ranges` | `marsupial.ColourRanges` (JSON) | the colour model's segmentation ranges |
//! | `/command` | `marsupial.MotorCommand` (JSON) | the command sent, with its twist `v`, `omega` |
//! | `/trace` | `marsupial.TraceLine` (JSON) | the decision trace ([`TraceLine`]) |
//! | `/odometry` | `foxglove.PoseInFrame` | the odometry pose, frame `odom` |
//! | `/ground_truth` | `foxglove.PoseInFrame` | the true pose, frame `dock` |
//! | `/tf` | `foxglove.FrameTransform` | `dock`→`base_link` (truth) each tick; `dock`→`odom` and `base_link`→`camI` when a mission starts |
//! | `/log` | `foxglove.Log` | the run's start, missions, the world's verdicts, device faults and the outcome; and, while [`McapRecorder::capture_tracing`]'s guard lives, every `tracing` event at debug level or above on the run's thread ([`tracing_log`]), at the time of the tick it happened in |
//!
//! The `dock` frame is the dock's: origin at the entrance, +x out of it. The percept and
//! colour ranges are recorded only when the agent exposes them ([`Agent::observe`]).
//!
//! Recording never changes a run: it reads the frames, the command and the poses after
//! the loop decided, and the simulator draws no random number for it.
//!
//! [`Agent::observe`]: crate::schemas::Agent::observe

pub mod annotations;
pub mod base64;
pub mod messages;
pub mod schemas;
pub mod tracing_log;
mod uncached;

use super::run::TraceLine;
use crate::geometry::Pose2;
use crate::msgs::cdr::CdrWriter;
use crate::perception::RgbImage;
use crate::profile::CameraSpec;
use crate::schemas::{MotorOutput, Observation};
use messages::{CameraCalibration, FrameTransform, Log, PoseInFrame, Quaternion, Time, Vector3};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use thiserror::Error;
use uncached::UncachedFile;

/// How a recording is made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RecordOptions {
    /// Frames as JPEG (`foxglove.CompressedImage`) instead of raw RGB.
    pub jpeg: bool,
    /// JPEG quality, 1–100.
    pub jpeg_quality: u8,
}

impl Default for RecordOptions {
    fn default() -> Self {
        Self {
            jpeg: false,
            jpeg_quality: 85,
        }
    }
}

/// Why a recording could not be written.
#[derive(Debug, Error)]
pub enum RecordError {
    /// The file could not be created or written.
    #[error("{}: cannot write the recording: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The MCAP writer refused (an I/O error underneath, or a bad record).
    #[error("{}: cannot write the recording: {why}", path.display())]
    Mcap {
        /// The file.
        path: PathBuf,
        /// The writer's message.
        why: String,
    },
    /// A frame could not be encoded as JPEG.
    #[error("{}: cannot encode a frame as JPEG: {why}", path.display())]
    Jpeg {
        /// The file.
        path: PathBuf,
        /// The encoder's message.
        why: String,
    },
}

/// What the recorder is given each tick.
pub struct TickSample<'a> {
    /// Loop time of the mission, s.
    pub t: f64,
    /// The frames the loop saw, one per camera.
    pub frames: &'a [RgbImage],
    /// The command sent.
    pub command: &'a MotorOutput,
    /// The decision trace of the tick.
    pub trace: &'a TraceLine<'a>,
    /// The percept and colour ranges, when the agent exposes them.
    pub observation: Option<Observation>,
    /// The true pose, dock frame.
    pub truth: Pose2,
    /// The odometry pose, odometry frame (its origin is where the mission began).
    pub odometry: Pose2,
}

/// One camera's channels.
struct CameraChannels {
    frame_id: String,
    image: u16,
    calibration: u16,
    annotations: u16,
    spec: CameraSpec,
}

/// The channels of a recording.
struct Channels {
    cameras: Vec<CameraChannels>,
    percept: u16,
    colour_ranges: u16,
    command: u16,
    trace: u16,
    odometry: u16,
    ground_truth: u16,
    tf: u16,
    log: u16,
}

/// Gap between the departure's last message and the docking mission's clock, ns.
const MISSION_GAP_NS: u64 = 100_000_000;

/// A run being recorded to an MCAP file (see the module docs).
///
/// Writing stops at the first error, which [`McapRecorder::finish`] returns; a run is
/// never stopped by its recording.
pub struct McapRecorder {
    path: PathBuf,
    writer: Option<mcap::Writer<UncachedFile>>,
    opts: RecordOptions,
    ch: Channels,
    sequence: u32,
    /// Start of the current mission's clock, ns.
    base_ns: u64,
    /// Latest time written, ns.
    last_ns: u64,
    /// A tick was recorded.
    started: bool,
    /// The next tick is a mission's first.
    mission_start: bool,
    mission: &'static str,
    buf: Vec<u8>,
    jpeg: Vec<u8>,
    /// `tracing` events not yet written ([`McapRecorder::capture_tracing`]).
    captured: tracing_log::Captures,
    error: Option<RecordError>,
}

/// The MCAP writer's error, named by file.
fn mcap_err(path: &Path) -> impl Fn(mcap::McapError) -> RecordError + '_ {
    move |e| RecordError::Mcap {
        path: path.to_path_buf(),
        why: e.to_string(),
    }
}

impl McapRecorder {
    /// Creates `path` and declares the channels of a robot with `cameras`.
    ///
    /// # Errors
    /// [`RecordError`] when the file cannot be created or written.
    pub fn create(path: &Path, cameras: &[CameraSpec], opts: RecordOptions) -> Result<Self, RecordError> {
        let file = UncachedFile::create(path).map_err(|source| RecordError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let e = mcap_err(path);
        // No compression, no CRCs: two passes less over every frame's bytes (readers
        // accept a zero CRC as "not computed"), to keep recording cheap. The writer
        // streams each chunk's records to the file as they come and seeks back to patch
        // the chunk's header; the file ([`uncached`]) stages the stream in aligned
        // segments that a thread writes past the page cache.
        let mut w = mcap::WriteOptions::new()
            .compression(None)
            .calculate_chunk_crcs(false)
            .calculate_data_section_crc(false)
            .profile("")
            .create(file)
            .map_err(&e)?;
        let json =
            |w: &mut mcap::Writer<_>, name: &str, schema: &str| w.add_schema(name, "jsonschema", schema.as_bytes());
        let none = BTreeMap::new();
        let channel = |w: &mut mcap::Writer<_>, topic: &str, name: &str, schema: &str| -> Result<u16, RecordError> {
            let id = json(w, name, schema).map_err(&e)?;
            w.add_channel(id, topic, "json", &none).map_err(&e)
        };
        // Raw frames as ROS 2 `sensor_msgs/msg/Image` in CDR (no base64); JPEG frames as
        // JSON `foxglove.CompressedImage`.
        let image_schema = if opts.jpeg {
            json(&mut w, "foxglove.CompressedImage", schemas::COMPRESSED_IMAGE)
        } else {
            w.add_schema("sensor_msgs/msg/Image", "ros2msg", schemas::ROS2_IMAGE.as_bytes())
        }
        .map_err(&e)?;
        let image_encoding = if opts.jpeg { "json" } else { "cdr" };
        let mut cams = Vec::with_capacity(cameras.len());
        for (i, spec) in cameras.iter().enumerate() {
            let frame_id = format!("cam{i}");
            cams.push(CameraChannels {
                image: w
                    .add_channel(image_schema, &format!("/{frame_id}/image"), image_encoding, &none)
                    .map_err(&e)?,
                calibration: channel(
                    &mut w,
                    &format!("/{frame_id}/calibration"),
                    "foxglove.CameraCalibration",
                    schemas::CAMERA_CALIBRATION,
                )?,
                annotations: channel(
                    &mut w,
                    &format!("/{frame_id}/annotations"),
                    "foxglove.ImageAnnotations",
                    schemas::IMAGE_ANNOTATIONS,
                )?,
                frame_id,
                spec: spec.clone(),
            });
        }
        let ch = Channels {
            cameras: cams,
            percept: channel(&mut w, "/percept", "marsupial.Percept", schemas::PERCEPT)?,
            colour_ranges: channel(
                &mut w,
                "/colour_ranges",
                "marsupial.ColourRanges",
                schemas::COLOUR_RANGES,
            )?,
            command: channel(&mut w, "/command", "marsupial.MotorCommand", schemas::MOTOR_COMMAND)?,
            trace: channel(&mut w, "/trace", "marsupial.TraceLine", schemas::TRACE_LINE)?,
            odometry: channel(&mut w, "/odometry", "foxglove.PoseInFrame", schemas::POSE_IN_FRAME)?,
            ground_truth: channel(&mut w, "/ground_truth", "foxglove.PoseInFrame", schemas::POSE_IN_FRAME)?,
            tf: channel(&mut w, "/tf", "foxglove.FrameTransform", schemas::FRAME_TRANSFORM)?,
            log: channel(&mut w, "/log", "foxglove.Log", schemas::LOG)?,
        };
        Ok(Self {
            path: path.to_path_buf(),
            writer: Some(w),
            opts,
            ch,
            sequence: 0,
            base_ns: 0,
            last_ns: 0,
            started: false,
            mission_start: true,
            mission: "",
            buf: Vec::with_capacity(1 << 16),
            jpeg: Vec::new(),
            captured: tracing_log::Captures::default(),
            error: None,
        })
    }

    /// Copies the `tracing` events of this thread (debug level and above) to `/log` until
    /// the guard drops, while still handing them to the subscriber that was current.
    /// Each is written at the time of the next tick recorded (or at the end).
    pub fn capture_tracing(&self) -> tracing::dispatcher::DefaultGuard {
        tracing_log::Capture::install(self.captured.clone())
    }

    /// Writes the captured `tracing` events at `ns`.
    fn flush_captured(&mut self, ns: u64) {
        let lines = std::mem::take(&mut *self.captured.lock().unwrap_or_else(|e| e.into_inner()));
        for c in &lines {
            self.put_json(
                self.ch.log,
                ns,
                &Log {
                    timestamp: Time::from_ns(ns),
                    level: c.level,
                    message: &c.message,
                    name: &c.target,
                    file: "",
                    line: 0,
                },
            );
        }
    }

    /// The file being written.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Nanoseconds on the recording's clock for mission time `t`.
    fn ns(&self, t: f64) -> u64 {
        self.base_ns + (t.max(0.0) * 1e9).round() as u64
    }

    /// Writes `self.buf` on `channel` at `ns`; notes the first error and stops writing.
    fn put(&mut self, channel: u16, ns: u64) {
        let Some(w) = self.writer.as_mut() else { return };
        self.sequence = self.sequence.wrapping_add(1);
        let header = mcap::records::MessageHeader {
            channel_id: channel,
            sequence: self.sequence,
            log_time: ns,
            publish_time: ns,
        };
        if let Err(e) = w.write_to_known_channel(&header, &self.buf) {
            self.error.get_or_insert(mcap_err(&self.path)(e));
            self.writer = None;
        }
        self.last_ns = self.last_ns.max(ns);
    }

    /// Serialises `msg` as JSON and writes it on `channel` at `ns`.
    fn put_json<T: Serialize + ?Sized>(&mut self, channel: u16, ns: u64, msg: &T) {
        self.buf.clear();
        if serde_json::to_writer(&mut self.buf, msg).is_ok() {
            self.put(channel, ns);
        }
    }

    /// A line on `/log` at mission time `t` (`level`: 2 info, 3 warning, 4 error).
    pub fn log(&mut self, t: f64, level: u8, message: &str) {
        let ns = self.ns(t);
        self.put_json(
            self.ch.log,
            ns,
            &Log {
                timestamp: Time::from_ns(ns),
                level,
                message,
                name: "marsupial::sim",
                file: "",
                line: 0,
            },
        );
    }

    /// Starts a mission's clock (`departure`, `docking`): its loop time 0 is 0.1 s after
    /// the last message (0 for the first mission recorded).
    pub fn begin_mission(&mut self, mission: &'static str) {
        if self.started {
            self.base_ns = self.last_ns + MISSION_GAP_NS;
        }
        self.mission = mission;
        self.mission_start = true;
        self.log(0.0, 2, &format!("{mission} begins"));
    }

    /// Records one tick.
    pub fn tick(&mut self, s: &TickSample<'_>) {
        let ns = self.ns(s.t);
        self.flush_captured(ns);
        let stamp = Time::from_ns(ns);
        self.started = true;
        if std::mem::take(&mut self.mission_start) {
            // The odometry frame's origin: where the mission placed the robot.
            let origin = s.truth.compose(&inverse(&s.odometry));
            self.put_json(self.ch.tf, ns, &FrameTransform::planar(stamp, "dock", "odom", &origin));
            for i in 0..self.ch.cameras.len() {
                let m = self.ch.cameras[i].spec.mount;
                let tf = FrameTransform {
                    timestamp: stamp,
                    parent_frame_id: "base_link",
                    child_frame_id: &self.ch.cameras[i].frame_id,
                    translation: Vector3 {
                        x: m.x_m,
                        y: m.y_m,
                        z: m.z_m,
                    },
                    // Body axes (x forward, z up) turned by the mount, then to the
                    // optical convention (z forward, x right, y down).
                    rotation: Quaternion::from_euler(
                        m.roll_deg.to_radians(),
                        m.pitch_deg.to_radians(),
                        m.yaw_deg.to_radians(),
                    )
                    .mul(&Quaternion {
                        x: -0.5,
                        y: 0.5,
                        z: -0.5,
                        w: 0.5,
                    }),
                };
                self.buf.clear();
                if serde_json::to_writer(&mut self.buf, &tf).is_ok() {
                    let id = self.ch.tf;
                    self.put(id, ns);
                }
            }
        }
        self.perception(s.t, s.frames, s.observation.as_ref());
        self.command(s.t, s.command);
        self.put_json(self.ch.trace, ns, s.trace);
        self.odometry(s.t, &s.odometry);
        self.put_json(
            self.ch.ground_truth,
            ns,
            &PoseInFrame {
                timestamp: stamp,
                frame_id: "dock",
                pose: (&s.truth).into(),
            },
        );
        self.put_json(
            self.ch.tf,
            ns,
            &FrameTransform::planar(stamp, "dock", "base_link", &s.truth),
        );
    }

    /// Records the frames of mission time `t` (one per camera, in the order given at
    /// [`McapRecorder::create`]) and what perception made of them: the annotations, the
    /// percept and the colour ranges. Part of [`McapRecorder::tick`]; on its own for
    /// callers without a simulated world (`marsupial replay --record`).
    pub fn perception(&mut self, t: f64, frames: &[RgbImage], observation: Option<&Observation>) {
        let ns = self.ns(t);
        let stamp = Time::from_ns(ns);
        self.started = true;
        for (i, frame) in frames.iter().enumerate().take(self.ch.cameras.len()) {
            self.image(i, ns, frame);
            self.calibration(i, ns);
        }
        if let Some(obs) = observation {
            if let Some(cam) = self.ch.cameras.get(obs.camera) {
                let id = cam.annotations;
                self.put_json(id, ns, &annotations::annotate(stamp, obs));
            }
            #[derive(Serialize)]
            struct PerceptMsg<'a> {
                camera: usize,
                percept: &'a crate::schemas::ObservedPercept,
            }
            self.put_json(
                self.ch.percept,
                ns,
                &PerceptMsg {
                    camera: obs.camera,
                    percept: &obs.percept,
                },
            );
            if let Some(r) = &obs.ranges {
                self.put_json(self.ch.colour_ranges, ns, r);
            }
        }
    }

    /// Records the command of mission time `t`, with its twist. Part of
    /// [`McapRecorder::tick`].
    pub fn command(&mut self, t: f64, command: &MotorOutput) {
        #[derive(Serialize)]
        struct CommandMsg<'a> {
            mission: &'static str,
            t: f64,
            v: f64,
            omega: f64,
            command: &'a MotorOutput,
        }
        let ns = self.ns(t);
        self.started = true;
        let twist = command.drive.to_twist();
        self.put_json(
            self.ch.command,
            ns,
            &CommandMsg {
                mission: self.mission,
                t,
                v: twist.v,
                omega: twist.omega,
                command,
            },
        );
    }

    /// Records the odometry pose of mission time `t` (frame `odom`). Part of
    /// [`McapRecorder::tick`].
    pub fn odometry(&mut self, t: f64, pose: &Pose2) {
        let ns = self.ns(t);
        self.started = true;
        self.put_json(
            self.ch.odometry,
            ns,
            &PoseInFrame {
                timestamp: Time::from_ns(ns),
                frame_id: "odom",
                pose: pose.into(),
            },
        );
    }

    /// Camera `i`'s frame as `foxglove.RawImage` or `foxglove.CompressedImage`, written
    /// by hand: the pixels go base64 straight into the reused buffer.
    fn image(&mut self, i: usize, ns: u64, frame: &RgbImage) {
        if self.opts.jpeg {
            self.jpeg_image(i, ns, frame);
        } else {
            self.raw_image(i, ns, frame);
        }
    }

    /// A raw frame as a CDR `sensor_msgs/msg/Image` (`rgb8`): the pixels are copied once,
    /// behind a header of a few dozen bytes.
    fn raw_image(&mut self, i: usize, ns: u64, frame: &RgbImage) {
        let t = Time::from_ns(ns);
        let (w, h) = (frame.width(), frame.height());
        let cam = &self.ch.cameras[i];
        let id = cam.image;
        let mut cdr = CdrWriter::new(&mut self.buf);
        cdr.u32(t.sec);
        cdr.u32(t.nsec);
        cdr.string(&cam.frame_id);
        cdr.u32(h as u32);
        cdr.u32(w as u32);
        cdr.string("rgb8");
        cdr.u8(0); // is_bigendian
        cdr.u32(3 * w as u32);
        cdr.bytes(frame.as_bytes());
        self.put(id, ns);
    }

    fn jpeg_image(&mut self, i: usize, ns: u64, frame: &RgbImage) {
        use std::io::Write as _;
        let t = Time::from_ns(ns);
        let (w, h) = (frame.width(), frame.height());
        let cam = &self.ch.cameras[i];
        let id = cam.image;
        self.buf.clear();
        self.jpeg.clear();
        let mut enc =
            image::codecs::jpeg::JpegEncoder::new_with_quality(&mut self.jpeg, self.opts.jpeg_quality.clamp(1, 100));
        if let Err(e) = enc.encode(frame.as_bytes(), w as u32, h as u32, image::ExtendedColorType::Rgb8) {
            self.error.get_or_insert(RecordError::Jpeg {
                path: self.path.clone(),
                why: e.to_string(),
            });
            self.writer = None;
            return;
        }
        let _ = write!(
            self.buf,
            r#"{{"timestamp":{{"sec":{},"nsec":{}}},"frame_id":"{}","format":"jpeg","data":""#,
            t.sec, t.nsec, cam.frame_id
        );
        let head = self.buf.len();
        let n = base64::encoded_len(self.jpeg.len());
        self.buf.resize(head + n, 0);
        let _ = base64::encode_into(&self.jpeg, &mut self.buf[head..]);
        self.buf.extend_from_slice(b"\"}");
        self.put(id, ns);
    }

    /// Camera `i`'s pin-hole calibration (none for a fisheye camera).
    fn calibration(&mut self, i: usize, ns: u64) {
        let cam = &self.ch.cameras[i];
        let Some(k) = cam.spec.pinhole_intrinsics() else {
            return;
        };
        let msg = CameraCalibration {
            timestamp: Time::from_ns(ns),
            frame_id: &cam.frame_id,
            width: cam.spec.width_px as u32,
            height: cam.spec.height_px as u32,
            distortion_model: "plumb_bob",
            D: [k.k1, k.k2, 0.0, 0.0, 0.0],
            K: [k.fx, 0.0, k.cx, 0.0, k.fy, k.cy, 0.0, 0.0, 1.0],
            R: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
            P: [k.fx, 0.0, k.cx, 0.0, 0.0, k.fy, k.cy, 0.0, 0.0, 0.0, 1.0, 0.0],
        };
        let id = cam.calibration;
        self.buf.clear();
        if serde_json::to_writer(&mut self.buf, &msg).is_ok() {
            self.put(id, ns);
        }
    }

    /// Writes the summary and closes the file.
    ///
    /// # Errors
    /// The first [`RecordError`] met while recording, or one closing the file.
    pub fn finish(mut self) -> Result<(), RecordError> {
        self.flush_captured(self.last_ns);
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        let Some(mut w) = self.writer.take() else {
            return Ok(());
        };
        w.finish().map_err(mcap_err(&self.path))?;
        let mut inner = w.into_inner();
        std::io::Write::flush(&mut inner).map_err(|source| RecordError::Io {
            path: self.path.clone(),
            source,
        })
    }
}

/// The inverse of a planar pose.
fn inverse(p: &Pose2) -> Pose2 {
    p.relative(&Pose2::default())
}
