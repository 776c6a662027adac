//! Driving sequences for the AutoKrawler's state estimator (seed 003 §VI, Table I): the
//! true [`KrawlerState`] at every camera frame of a run that mixes driving, turning,
//! crabbing, steering sweeps over ±30° and articulation over rough ground, with the
//! commanded steering beside it, and the error sources the paper names as knobs.
//!
//! A sequence is a TOML file ([`SequenceSpec`], validated with field-named errors) or one
//! of the built-ins (`dataset1`, `dataset2`, `dataset3`: the paper's three datasets'
//! lengths, 82, 170 and 257 s, shipped as `sequences/*.toml` and compiled in). Its
//! segments are listed in the file or, where the list ends before the duration, drawn
//! from the seed, so the same file and seed give the same states bit for bit.
//!
//! **The motion model** (ours; the paper describes its datasets only as teleoperated
//! drives). Each segment commands a speed and the two axles' steering. The true steering
//! follows the command through a first-order lag with a rate limit and a constant offset
//! per axle (a servo's trim), plus a small compliance noise while rolling, and is clamped
//! to the profile's ±30°: that is what separates commanded from true steering, which the
//! odometry comparison measures. The body moves by the double-Ackermann kinematics
//! ([`crate::kinematics::ackermann`]); each wheel turns by its own contact point's speed
//! along its heading over the radius, with a slowly wandering slip of a few per cent.
//! Axle roll and drop follow a terrain profile under each axle (the rear axle meets it a
//! wheelbase later), a sum of sines in the distance travelled, whose amplitude an
//! `articulate` segment doubles; a stationary `articulate` segment rocks the axles on
//! their own (the rover lifted by hand, as in a lab).
//!
//! **Error sources** ([`ErrorKnobs`], all off by default): frame-rate drops, mount
//! vibration, a marker under mud for a while, a step change in the light (its level and
//! its colour), the body's shadow sweeping over the gear (markers lost in it, and its
//! edge crossing the treads), the camera mount's thin plates in view, and the floor
//! moving under the rover (fixed to the world instead of riding with the body).

use super::rng::Rng;
use crate::config::{self, ConfigError, Validate, Validator};
use crate::kinematics::DriveModel;
use crate::kinematics::ackermann::DoubleAckermann;
use crate::profile::Profile;
use crate::sim::krawler::{KrawlerState, SelfShadow};
use crate::sim::lighting::{Illuminant, LightState, Lighting, LightingRun};
use crate::sim::render::CameraPose;
use nalgebra::{Rotation3, Vector3};
use serde::Deserialize;
use std::path::Path;

/// The built-in sequences: name and TOML text.
pub const BUILTIN: [(&str, &str); 3] = [
    ("dataset1", include_str!("../../sequences/dataset1.toml")),
    ("dataset2", include_str!("../../sequences/dataset2.toml")),
    ("dataset3", include_str!("../../sequences/dataset3.toml")),
];

/// What a segment does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SegmentKind {
    /// Straight at cruise speed (backwards with a negative `speed_scale`).
    Drive,
    /// A symmetric turn: λ_R = −λ_F = −`steer_deg`.
    Turn,
    /// Crab motion: λ_R = λ_F = `steer_deg`.
    Crab,
    /// Standing still, both axles swept 0 → +`steer_deg` → 0 → −`steer_deg` → 0 (the rear
    /// opposite to the front).
    Sweep,
    /// Articulation: rolling slowly over ground twice as rough, or, at zero speed, the
    /// axles rocked in roll and drop on their own.
    Articulate,
}

/// One segment of a sequence.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Segment {
    /// What it does.
    pub kind: SegmentKind,
    /// How long, s.
    pub duration_s: f64,
    /// Steering amplitude, degrees (turn, crab: the angle; sweep: the peak).
    #[serde(default)]
    pub steer_deg: f64,
    /// Speed as a fraction of `motion.speed_mps` (negative: backwards).
    #[serde(default = "one")]
    pub speed_scale: f64,
}

fn one() -> f64 {
    1.0
}

/// The motion model's parameters (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MotionSpec {
    /// Cruise speed, m/s.
    pub speed_mps: f64,
    /// Largest acceleration, m/s².
    pub accel_mps2: f64,
    /// Steering lag time constant, s.
    pub steer_lag_s: f64,
    /// Steering rate limit, deg/s.
    pub steer_rate_dps: f64,
    /// Constant steering offset (front, rear), degrees: the true angle minus the command.
    pub steer_offset_deg: [f64; 2],
    /// Steering compliance while rolling: SD of a slowly wandering disturbance, degrees.
    pub steer_compliance_deg: f64,
    /// Terrain roll amplitude, degrees (doubled in `articulate` segments).
    pub terrain_roll_deg: f64,
    /// Terrain drop amplitude, m (doubled in `articulate` segments).
    pub terrain_drop_m: f64,
    /// Wheel slip: SD of each wheel's slowly wandering slip, as a fraction of its rolling.
    pub slip: f64,
}

impl Default for MotionSpec {
    /// Walking-pace teleoperation on a rough lab floor (our estimates): 8 cm/s, a
    /// 0.2 s steering lag at up to 60°/s with trims of +1.0° and −0.7°, ±0.5° compliance,
    /// terrain rolling the axles by up to ~4° and bobbing them by ~1 cm, 2 % slip.
    fn default() -> Self {
        Self {
            speed_mps: 0.08,
            accel_mps2: 0.2,
            steer_lag_s: 0.2,
            steer_rate_dps: 60.0,
            steer_offset_deg: [1.0, -0.7],
            steer_compliance_deg: 0.5,
            terrain_roll_deg: 4.0,
            terrain_drop_m: 0.01,
            slip: 0.02,
        }
    }
}

/// A marker under mud for a while.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MudSpec {
    /// Which marker (0–7: front plate left, right, front rod left, right, then the rear).
    pub marker: usize,
    /// From, s.
    pub start_s: f64,
    /// For how long, s.
    #[serde(default = "ten")]
    pub duration_s: f64,
}

fn ten() -> f64 {
    10.0
}

/// A step change of the light: its level, and optionally its colour.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightChange {
    /// When, s.
    pub at_s: f64,
    /// The new level (1 is the starting light).
    #[serde(default = "one")]
    pub level: f64,
    /// The new light's colour (the starting light is neutral daylight); none keeps it.
    #[serde(default)]
    pub illuminant: Option<Illuminant>,
}

impl LightChange {
    /// The light at time `t` (s): uniform neutral light of level 1 before the change,
    /// then the new level in the new colour.
    pub fn light_at(change: Option<&Self>, t: f64) -> LightState {
        match change {
            Some(l) if t >= l.at_s => match l.illuminant {
                None => LightState::uniform(l.level as f32),
                Some(illuminant) => {
                    let mut state = LightState::uniform(l.level as f32);
                    let lighting = Lighting::ambient_only(l.level, illuminant);
                    LightingRun::new(lighting, &mut Rng::new(0), 0.0).fill(t, &mut state);
                    state
                }
            },
            _ => LightState::uniform(1.0),
        }
    }
}

/// The body's shadow sweeping across the gear (a band, [`SelfShadow`]): its edge turned
/// `angle_deg` from the body's x axis, crossing from the left (+y) side to the right at a
/// steady rate over `duration_s` from `start_s`, as when the rover turns under a low sun.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SelfShadowSpec {
    /// From, s.
    pub start_s: f64,
    /// For how long, s (the band crosses the whole gear, 1.4 m, in this time).
    #[serde(default = "ten")]
    pub duration_s: f64,
    /// Light removed in the shadow (0–1).
    #[serde(default = "shadow_strength")]
    pub strength: f64,
    /// The band's width, m.
    #[serde(default = "shadow_width")]
    pub width_m: f64,
    /// The band's edges' angle from the body's x axis, degrees.
    #[serde(default = "shadow_angle")]
    pub angle_deg: f64,
}

fn shadow_strength() -> f64 {
    0.7
}

fn shadow_width() -> f64 {
    0.25
}

fn shadow_angle() -> f64 {
    20.0
}

impl SelfShadowSpec {
    /// The band at time `t`, s (`None` outside the knob's interval).
    pub fn at(&self, t: f64) -> Option<SelfShadow> {
        let f = (t - self.start_s) / self.duration_s;
        if !(0.0..1.0).contains(&f) {
            return None;
        }
        let a = self.angle_deg.to_radians();
        Some(SelfShadow {
            normal: [-a.sin(), a.cos()],
            offset: 0.7 - 1.4 * f,
            width: self.width_m,
            strength: self.strength as f32,
        })
    }
}

/// The error sources the paper names, as knobs (all off by default).
#[derive(Debug, Clone, Copy, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ErrorKnobs {
    /// Probability that a frame is lost (the estimator gets the next one, with twice
    /// the motion in between).
    pub frame_drop: f64,
    /// Mount vibration: SD of the camera's rotation per frame, degrees (the estimator
    /// assumes the nominal mount).
    pub vibration_deg: f64,
    /// Mount vibration: SD of the camera's displacement per frame, mm.
    pub vibration_mm: f64,
    /// A marker under mud.
    pub mud: Option<MudSpec>,
    /// A light change.
    pub light: Option<LightChange>,
    /// The body's shadow sweeping over the gear.
    pub self_shadow: Option<SelfShadowSpec>,
    /// The camera mount's four thin plates in view.
    pub mount_plates: bool,
    /// The floor fixed to the world, moving under the rover as it drives (off: the
    /// floor rides with the body, as it did before this knob).
    pub moving_ground: bool,
}

impl ErrorKnobs {
    /// The knobs that are on, by name (for reports).
    pub fn active(&self) -> Vec<String> {
        let mut out = Vec::new();
        if self.frame_drop > 0.0 {
            out.push(format!("frame drops {:.0} %", self.frame_drop * 100.0));
        }
        if self.vibration_deg > 0.0 || self.vibration_mm > 0.0 {
            out.push(format!(
                "vibration {:.2}° / {:.1} mm",
                self.vibration_deg, self.vibration_mm
            ));
        }
        if let Some(m) = self.mud {
            out.push(format!(
                "mud on marker {} {:.0}–{:.0} s",
                m.marker,
                m.start_s,
                m.start_s + m.duration_s
            ));
        }
        if let Some(l) = self.light {
            match l.illuminant {
                Some(i) => out.push(format!("light ×{} {i:?} at {:.0} s", l.level, l.at_s)),
                None => out.push(format!("light ×{} at {:.0} s", l.level, l.at_s)),
            }
        }
        if let Some(s) = self.self_shadow {
            out.push(format!(
                "self-shadow {:.0} % {:.0}–{:.0} s",
                s.strength * 100.0,
                s.start_s,
                s.start_s + s.duration_s
            ));
        }
        if self.mount_plates {
            out.push("mount plates in view".into());
        }
        if self.moving_ground {
            out.push("ground moving under the rover".into());
        }
        out
    }
}

/// A sequence file.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SequenceSpec {
    /// Its name.
    pub name: String,
    /// What it is for.
    #[serde(default)]
    pub description: String,
    /// Length, s.
    pub duration_s: f64,
    /// Seed of the segments drawn, the motion's noise, the sensor noise and the RANSAC.
    #[serde(default)]
    pub seed: u64,
    /// Camera rate, frames/s (default: the profile camera's).
    #[serde(default)]
    pub fps: Option<f64>,
    /// Which of the paper's Table I rows (1–3) this sequence stands beside, if any.
    #[serde(default)]
    pub paper_dataset: Option<usize>,
    /// The motion model.
    #[serde(default)]
    pub motion: MotionSpec,
    /// Segments played first, in order; the rest of the duration is drawn from the seed.
    #[serde(default)]
    pub segments: Vec<Segment>,
    /// Error sources.
    #[serde(default)]
    pub errors: ErrorKnobs,
}

impl Validate for SequenceSpec {
    fn validate(&self, v: &mut Validator<'_>) {
        v.require(!self.name.trim().is_empty(), "name", || {
            "expected a non-empty name".into()
        });
        v.range("duration_s", self.duration_s, 0.1, 3600.0);
        if let Some(f) = self.fps {
            v.range("fps", f, 1.0, 240.0);
        }
        if let Some(d) = self.paper_dataset {
            v.require((1..=3).contains(&d), "paper_dataset", || {
                format!("expected 1, 2 or 3 (the paper's Table I rows), got {d}")
            });
        }
        let m = &self.motion;
        v.range("motion.speed_mps", m.speed_mps, 0.0, 1.0);
        v.positive("motion.accel_mps2", m.accel_mps2);
        v.range("motion.steer_lag_s", m.steer_lag_s, 0.0, 5.0);
        v.positive("motion.steer_rate_dps", m.steer_rate_dps);
        for (i, o) in m.steer_offset_deg.iter().enumerate() {
            v.range(&format!("motion.steer_offset_deg[{i}]"), *o, -10.0, 10.0);
        }
        v.range("motion.steer_compliance_deg", m.steer_compliance_deg, 0.0, 10.0);
        v.range("motion.terrain_roll_deg", m.terrain_roll_deg, 0.0, 15.0);
        v.range("motion.terrain_drop_m", m.terrain_drop_m, 0.0, 0.03);
        v.range("motion.slip", m.slip, 0.0, 0.5);
        for (i, s) in self.segments.iter().enumerate() {
            let p = |f: &str| format!("segments[{i}].{f}");
            v.range(&p("duration_s"), s.duration_s, 0.1, 3600.0);
            v.range(&p("steer_deg"), s.steer_deg, -30.0, 30.0);
            v.range(&p("speed_scale"), s.speed_scale, -2.0, 2.0);
        }
        let e = &self.errors;
        v.range("errors.frame_drop", e.frame_drop, 0.0, 0.9);
        v.range("errors.vibration_deg", e.vibration_deg, 0.0, 5.0);
        v.range("errors.vibration_mm", e.vibration_mm, 0.0, 20.0);
        if let Some(mud) = &e.mud {
            v.require(mud.marker < 8, "errors.mud.marker", || {
                format!("expected a marker index 0–7, got {}", mud.marker)
            });
            v.non_negative("errors.mud.start_s", mud.start_s);
            v.positive("errors.mud.duration_s", mud.duration_s);
        }
        if let Some(l) = &e.light {
            v.non_negative("errors.light.at_s", l.at_s);
            v.range("errors.light.level", l.level, 0.01, 10.0);
        }
        if let Some(s) = &e.self_shadow {
            v.non_negative("errors.self_shadow.start_s", s.start_s);
            v.positive("errors.self_shadow.duration_s", s.duration_s);
            v.range("errors.self_shadow.strength", s.strength, 0.0, 1.0);
            v.range("errors.self_shadow.width_m", s.width_m, 0.01, 2.0);
            v.range("errors.self_shadow.angle_deg", s.angle_deg, -90.0, 90.0);
        }
    }
}

impl SequenceSpec {
    /// A built-in sequence by name, or a sequence file.
    ///
    /// # Errors
    /// [`ConfigError`] naming the file (or the built-in), the field and the line.
    pub fn load(name_or_file: &str) -> Result<Self, ConfigError> {
        match BUILTIN.iter().find(|(n, _)| *n == name_or_file) {
            Some((n, text)) => config::parse_str(text, Path::new(&format!("<built-in {n}>"))),
            None => config::load(Path::new(name_or_file)),
        }
    }

    /// Parses `text` (the contents of `file`, named in errors).
    ///
    /// # Errors
    /// As [`SequenceSpec::load`].
    pub fn parse(text: &str, file: &Path) -> Result<Self, ConfigError> {
        config::parse_str(text, file)
    }
}

/// One camera frame's truth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TruthFrame {
    /// Time, s.
    pub t: f64,
    /// The gear's state.
    pub state: KrawlerState,
    /// The commanded steering (front, rear), rad.
    pub steer_cmd: [f64; 2],
    /// Body speed, m/s (what an odometry takes from the wheel encoders).
    pub speed: f64,
}

/// The segments actually played (listed first, then drawn), each with its start time.
pub fn plan(spec: &SequenceSpec, seed: u64) -> Vec<(f64, Segment)> {
    let mut rng = Rng::named(seed, "krawler-segments");
    let mut out = Vec::new();
    let mut t = 0.0;
    let mut listed = spec.segments.iter();
    while t < spec.duration_s {
        let s = match listed.next() {
            Some(s) => *s,
            None => draw_segment(&mut rng),
        };
        out.push((t, s));
        t += s.duration_s;
    }
    out
}

/// A segment drawn from the mix: drives, turns and crabs of 5–12 s, sweeps of 8–12 s over
/// the full ±30°, articulations of 6–10 s, half of them standing still.
fn draw_segment(rng: &mut Rng) -> Segment {
    let sign = |rng: &mut Rng| if rng.uniform() < 0.5 { -1.0 } else { 1.0 };
    let u = rng.uniform();
    let (kind, duration_s, steer_deg, speed_scale) = if u < 0.2 {
        (
            SegmentKind::Drive,
            rng.range(5.0, 12.0),
            0.0,
            if rng.uniform() < 0.25 { -1.0 } else { 1.0 },
        )
    } else if u < 0.45 {
        (
            SegmentKind::Turn,
            rng.range(5.0, 12.0),
            sign(rng) * rng.range(8.0, 28.0),
            1.0,
        )
    } else if u < 0.55 {
        (
            SegmentKind::Crab,
            rng.range(5.0, 10.0),
            sign(rng) * rng.range(8.0, 20.0),
            1.0,
        )
    } else if u < 0.8 {
        (SegmentKind::Sweep, rng.range(8.0, 12.0), 30.0, 0.0)
    } else {
        let still = rng.uniform() < 0.5;
        (
            SegmentKind::Articulate,
            rng.range(6.0, 10.0),
            0.0,
            if still { 0.0 } else { 0.5 },
        )
    };
    Segment {
        kind,
        duration_s,
        steer_deg,
        speed_scale,
    }
}

/// A slowly wandering disturbance: an Ornstein–Uhlenbeck process with time constant
/// `tau` s and stationary SD `sd`.
#[derive(Debug, Clone, Copy)]
struct Wander {
    x: f64,
    tau: f64,
    sd: f64,
}

impl Wander {
    fn step(&mut self, dt: f64, rng: &mut Rng) -> f64 {
        let a = (-dt / self.tau).exp();
        self.x = a * self.x + self.sd * (1.0 - a * a).sqrt() * rng.normal();
        self.x
    }
}

/// The terrain under an axle at distance `s` along the path: (roll, drop offset) per
/// unit amplitude, sums of three sines with wavelengths 0.7–2.3 m and phases from `phase`.
fn terrain(s: f64, phase: &[f64; 6]) -> (f64, f64) {
    let w = [0.7, 1.3, 2.3];
    let mut roll = 0.0;
    let mut drop = 0.0;
    for k in 0..3 {
        let a = std::f64::consts::TAU * s / w[k];
        roll += (a + phase[k]).sin() / 1.8;
        drop += (a * 0.9 + phase[3 + k]).sin() / 1.8;
    }
    (roll, drop)
}

/// The truth at every frame of `spec` for the AutoKrawler of `profile`, with `seed`
/// (the spec's own unless overridden).
///
/// # Errors
/// A message when the profile has no double-Ackermann drive or the gear cannot be built.
pub fn generate(spec: &SequenceSpec, profile: &Profile, seed: u64) -> Result<Vec<TruthFrame>, String> {
    let DriveModel::DoubleAckermann(drive) = profile.drive.model() else {
        return Err(format!("profile `{}` has no double-Ackermann drive", profile.name));
    };
    let rest = KrawlerState::rest(profile).map_err(|e| e.to_string())?;
    let radius = profile.drive.wheel_radius_m.unwrap_or(0.115);
    let fps = spec.fps.or(profile.cameras.first().map(|c| c.fps)).unwrap_or(30.0);
    let dt = 1.0 / fps;
    let n = (spec.duration_s * fps).round().max(1.0) as usize;
    let m = &spec.motion;
    let segments = plan(spec, seed);
    let mut rng = Rng::named(seed, "krawler-motion");
    let phases: [[f64; 6]; 2] = [0, 1].map(|_| [0; 6].map(|_| rng.range(0.0, std::f64::consts::TAU)));
    let rock_phase: [f64; 4] = [0; 4].map(|_| rng.range(0.0, std::f64::consts::TAU));
    let mut compliance = [0; 2].map(|_| Wander {
        x: 0.0,
        tau: 1.5,
        sd: m.steer_compliance_deg.to_radians(),
    });
    let mut slip = [0; 4].map(|_| Wander {
        x: 0.0,
        tau: 3.0,
        sd: m.slip,
    });
    let max_steer = drive.max_steer;
    let mut state = rest;
    state.wheel = [0; 4].map(|_| rng.range(0.0, std::f64::consts::TAU));
    let mut steer = [0.0f64; 2];
    let mut speed = 0.0f64;
    let mut travelled = 0.0f64;
    let mut rough = 1.0f64;
    let mut rock = 0.0f64;
    let mut rock_t = 0.0f64;
    let mut seg = 0;
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let t = i as f64 * dt;
        while seg + 1 < segments.len() && segments[seg + 1].0 <= t {
            seg += 1;
        }
        let (t0, s) = segments[seg];
        let tau = (t - t0) / s.duration_s;
        let a = s.steer_deg.to_radians();
        let (v_cmd, cmd, rough_cmd, rock_cmd) = match s.kind {
            SegmentKind::Drive => (s.speed_scale * m.speed_mps, [0.0, 0.0], 1.0, 0.0),
            SegmentKind::Turn => (s.speed_scale * m.speed_mps, [a, -a], 1.0, 0.0),
            SegmentKind::Crab => (s.speed_scale * m.speed_mps, [a, a], 1.0, 0.0),
            SegmentKind::Sweep => {
                let l = a * (std::f64::consts::TAU * tau).sin();
                (0.0, [l, -l], 1.0, 0.0)
            }
            SegmentKind::Articulate if s.speed_scale == 0.0 => (0.0, [0.0, 0.0], 1.0, 1.0),
            SegmentKind::Articulate => (s.speed_scale * m.speed_mps, [0.0, 0.0], 2.0, 0.0),
        };
        // The axles on the terrain under them (and rocked), then record this frame and
        // advance to the next.
        for axle in 0..2 {
            let s_axle = travelled - if axle == 0 { 0.0 } else { drive.wheelbase };
            let (r, d) = terrain(s_axle, &phases[axle]);
            let rr = (0.6 * rock_t + rock_phase[axle]).sin();
            let rd = (0.45 * rock_t + rock_phase[2 + axle]).sin();
            state.roll[axle] = m.terrain_roll_deg.to_radians() * (rough * r + 2.0 * rock * rr);
            state.drop[axle] = rest.drop[axle] + m.terrain_drop_m * (rough * d + 2.0 * rock * rd);
        }
        state.steer = steer;
        out.push(TruthFrame {
            t,
            state,
            steer_cmd: cmd,
            speed,
        });
        // Speed with an acceleration limit.
        let dv = (v_cmd - speed).clamp(-m.accel_mps2 * dt, m.accel_mps2 * dt);
        speed += dv;
        // Steering: lag toward command + trim (+ compliance while rolling), rate-limited.
        let rolling = (speed.abs() / m.speed_mps.max(1e-9)).min(1.0);
        for k in 0..2 {
            let c = compliance[k].step(dt, &mut rng) * rolling;
            let target = (cmd[k] + m.steer_offset_deg[k].to_radians() + c).clamp(-max_steer, max_steer);
            let lag = if m.steer_lag_s > 0.0 {
                (target - steer[k]) * (1.0 - (-dt / m.steer_lag_s).exp())
            } else {
                target - steer[k]
            };
            let rate = m.steer_rate_dps.to_radians() * dt;
            steer[k] += lag.clamp(-rate, rate);
        }
        // Body motion and each wheel's rolling.
        let body = drive.body_velocity(speed, steer[0], steer[1]);
        travelled += body.vx.hypot(body.vy) * dt * speed.signum();
        for (w, sl) in slip.iter_mut().enumerate() {
            let axle = w / 2;
            let x = if axle == 0 {
                drive.wheelbase / 2.0
            } else {
                -drive.wheelbase / 2.0
            };
            let y = if w % 2 == 0 {
                drive.track / 2.0
            } else {
                -drive.track / 2.0
            };
            let (vx, vy) = (body.vx - body.omega * y, body.vy + body.omega * x);
            let (sn, cs) = steer[axle].sin_cos();
            let rolling_speed = vx * cs + vy * sn;
            let s = sl.step(dt, &mut rng);
            state.wheel[w] += rolling_speed * (1.0 + s) / radius * dt;
        }
        // Roughness and rocking change smoothly (1 s).
        let g = 1.0 - (-dt).exp();
        rough += (rough_cmd - rough) * g;
        rock += (rock_cmd - rock) * g;
        rock_t += dt * rock;
    }
    Ok(out)
}

/// The camera pose `base` shaken by the mount's vibration: a random small rotation about
/// the body's axes (each SD `deg` degrees) and displacement (each SD `mm` millimetres),
/// drawn from `rng`, independent frame to frame.
pub fn shaken(base: &CameraPose, deg: f64, mm: f64, rng: &mut Rng) -> CameraPose {
    let r = Vector3::new(rng.normal(), rng.normal(), rng.normal()) * deg.to_radians();
    let d = Vector3::new(rng.normal(), rng.normal(), rng.normal()) * (mm / 1000.0);
    CameraPose {
        rotation: Rotation3::new(r).matrix() * base.rotation,
        position: base.position + d,
    }
}

/// The double-Ackermann geometry of a profile, for odometry.
pub fn drive_of(profile: &Profile) -> Option<DoubleAckermann> {
    match profile.drive.model() {
        DriveModel::DoubleAckermann(d) => Some(d),
        _ => None,
    }
}

/// Dead-reckons a path (x, y, heading per step) from body speeds and steering angles at
/// `dt` intervals (midpoint rule): the double-Ackermann odometry of seed 003's use case.
pub fn odometry(drive: &DoubleAckermann, dt: &[f64], speed: &[f64], steer: &[[f64; 2]]) -> Vec<[f64; 3]> {
    let mut pose = [0.0f64; 3];
    let mut out = Vec::with_capacity(speed.len());
    for ((&dt, &v), s) in dt.iter().zip(speed).zip(steer) {
        out.push(pose);
        let b = drive.body_velocity(v, s[0], s[1]);
        // The heading half-way through the step: second order, so a constant arc stays
        // on its circle.
        let (sn, cs) = (pose[2] + b.omega * dt / 2.0).sin_cos();
        pose[0] += (b.vx * cs - b.vy * sn) * dt;
        pose[1] += (b.vx * sn + b.vy * cs) * dt;
        pose[2] += b.omega * dt;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(duration: f64) -> SequenceSpec {
        SequenceSpec::parse(
            &format!("name = \"t\"\nduration_s = {duration}\nseed = 3\n"),
            Path::new("t.toml"),
        )
        .unwrap()
    }

    #[test]
    fn built_ins_load_with_the_papers_lengths() {
        for (name, len) in [("dataset1", 82.0), ("dataset2", 170.0), ("dataset3", 257.0)] {
            let s = SequenceSpec::load(name).unwrap();
            assert_eq!(s.duration_s, len, "{name}");
        }
    }

    #[test]
    fn the_plan_covers_the_duration_and_mixes_every_kind() {
        let s = spec(257.0);
        let p = plan(&s, 3);
        let (t, last) = p.last().unwrap();
        assert!(t + last.duration_s >= 257.0);
        for kind in [
            SegmentKind::Drive,
            SegmentKind::Turn,
            SegmentKind::Sweep,
            SegmentKind::Articulate,
        ] {
            assert!(p.iter().any(|(_, s)| s.kind == kind), "{kind:?}");
        }
        assert_eq!(p, plan(&s, 3));
        assert_ne!(p, plan(&s, 4));
    }

    /// Every state moves smoothly from frame to frame (from the first), stays within the
    /// steering limit, and the sweep reaches it; the wheels turn both ways over a run.
    #[test]
    fn generated_states_are_smooth_and_within_limits() {
        let profile = Profile::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/autokrawler.toml")).unwrap();
        let s = SequenceSpec::load("dataset1").unwrap();
        let frames = generate(&s, &profile, 1).unwrap();
        assert_eq!(frames.len(), 2460);
        let max = 30f64.to_radians() + 1e-12;
        let mut peak = 0.0f64;
        for w in frames.windows(2) {
            let (a, b) = (&w[0].state, &w[1].state);
            for k in 0..2 {
                assert!(
                    (a.roll[k] - b.roll[k]).abs() < 0.5f64.to_radians(),
                    "{} s: roll",
                    w[1].t
                );
                assert!((a.drop[k] - b.drop[k]).abs() < 0.002, "{} s: drop", w[1].t);
                assert!(
                    (a.steer[k] - b.steer[k]).abs() <= 2f64.to_radians() + 1e-12,
                    "{} s",
                    w[1].t
                );
                assert!(b.steer[k].abs() <= max);
                peak = peak.max(b.steer[k].abs());
            }
            for k in 0..4 {
                assert!((a.wheel[k] - b.wheel[k]).abs() < 0.05, "{} s: wheel {k}", w[1].t);
            }
        }
        assert!(peak > 29f64.to_radians(), "the sweep reaches the limit: {peak}");
        let steps: Vec<f64> = frames
            .windows(2)
            .map(|w| w[1].state.wheel[0] - w[0].state.wheel[0])
            .collect();
        assert!(steps.iter().any(|d| *d > 0.005) && steps.iter().any(|d| *d < -0.005));
        assert_eq!(frames, generate(&s, &profile, 1).unwrap());
    }

    #[test]
    fn the_shadow_sweeps_its_band_across_the_gear_while_it_lasts() {
        let spec = SelfShadowSpec {
            start_s: 10.0,
            duration_s: 4.0,
            strength: 0.7,
            width_m: 0.25,
            angle_deg: 0.0,
        };
        assert!(spec.at(9.9).is_none() && spec.at(14.0).is_none());
        let offsets: Vec<f64> = [10.0, 12.0, 13.9].iter().map(|&t| spec.at(t).unwrap().offset).collect();
        assert!((offsets[0] - 0.7).abs() < 1e-12 && offsets[1].abs() < 1e-12 && offsets[2] < -0.6);
        assert_eq!(spec.at(11.0).unwrap().normal, [0.0, 1.0]);
    }

    #[test]
    fn a_light_change_sets_level_and_colour_from_its_time() {
        let level = LightChange {
            at_s: 2.0,
            level: 0.5,
            illuminant: None,
        };
        assert_eq!(LightChange::light_at(Some(&level), 1.9), LightState::uniform(1.0));
        assert_eq!(LightChange::light_at(Some(&level), 2.0), LightState::uniform(0.5));
        assert_eq!(LightChange::light_at(None, 5.0), LightState::uniform(1.0));
        let warm = LightChange {
            illuminant: Some(Illuminant::Tungsten),
            ..level
        };
        let e = LightChange::light_at(Some(&warm), 3.0).irradiance(&Vector3::z());
        let want = Illuminant::Tungsten.rgb().map(|c| c * 0.5);
        for c in 0..3 {
            assert!((e[c] - want[c]).abs() < 1e-6, "{e:?} against {want:?}");
        }
        let spec = SequenceSpec::parse(
            "name = \"t\"\nduration_s = 1\n[errors.light]\nat_s = 0.5\nilluminant = \"dusk\"\n",
            Path::new("t.toml"),
        )
        .unwrap();
        assert_eq!(spec.errors.light.unwrap().level, 1.0, "the level defaults to unchanged");
        assert!(
            SequenceSpec::parse(
                "name = \"t\"\nduration_s = 1\n[errors.light]\nat_s = 0.5\nilluminant = \"green\"\n",
                Path::new("t.toml"),
            )
            .unwrap_err()
            .to_string()
            .contains("illuminant")
        );
    }

    #[test]
    fn odometry_of_a_symmetric_turn_is_a_circle() {
        let d = DoubleAckermann {
            wheelbase: 0.66,
            track: 0.56,
            max_steer: 0.5,
        };
        let l = 0.2f64;
        let r = 0.33 / l.tan();
        let n = 1000;
        let dt = vec![0.01; n];
        let v = vec![0.5; n];
        let steer = vec![[l, -l]; n];
        let path = odometry(&d, &dt, &v, &steer);
        for p in &path {
            assert!((p[0].hypot(p[1] - r) - r).abs() < 1e-3, "{p:?}");
        }
    }
}
