//! Scenario files: experiments as data.
//!
//! A scenario names a profile, the start poses (a built-in grid such as `paper16`, or an
//! explicit list), trials per start, a seed, the axes that vary (lighting programmes,
//! segmentation modes, terrains), sensor noise, motion, imprinting, clutter and backdrop
//! photos. `marsupial check` validates it with the same errors as profiles. Paths are
//! relative to the scenario file.

use super::lighting::{Lighting, LightingPreset, LightingSpec};
use super::lighting_random::{LightingDistribution, LightingDraw};
use super::motion::{SlipSpec, Terrain};
use super::render::{Defocus, SensorParams, WhiteBalance};
use super::rng::Rng;
use super::world::ClutterSpec;
use crate::config::{self, ConfigError, Validate, Validator};
use crate::geometry::Pose2;
use crate::profile::{FiducialKinds, NamedColor, Profile, SegmentationMode};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Built-in start grids.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Grid {
    /// The 16 positions of seed 004 Fig. 8 (DESIGN §2.1): 0.33 m at −a, 0°, +a (a =
    /// `corner_angle_deg`); 0.5 m at −30, 0, 30°; 1.33 m and 2 m at −60, −30, 0, 30, 60°.
    Paper16,
}

/// One explicit start: polar (distance, angle from the dock axis) or Cartesian.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StartPoint {
    /// Distance from the dock entrance, m.
    #[serde(default)]
    pub distance_m: Option<f64>,
    /// Angle off the dock axis, degrees (positive toward +y).
    #[serde(default)]
    pub angle_deg: Option<f64>,
    /// x, m.
    #[serde(default)]
    pub x_m: Option<f64>,
    /// y, m.
    #[serde(default)]
    pub y_m: Option<f64>,
    /// Heading, degrees; default: the camera faces the dock.
    #[serde(default)]
    pub heading_deg: Option<f64>,
    /// Label in tables (default: its 1-based position in the list).
    #[serde(default)]
    pub label: Option<String>,
}

/// `[starts]`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StartsSpec {
    /// A built-in grid.
    #[serde(default)]
    pub grid: Option<Grid>,
    /// Use only these 1-based grid positions.
    #[serde(default)]
    pub select: Option<Vec<usize>>,
    /// Angle of grid positions 1 and 3, degrees (the paper's is not recoverable).
    #[serde(default = "default_corner")]
    pub corner_angle_deg: f64,
    /// Explicit starts (instead of, or after, the grid).
    #[serde(default)]
    pub points: Vec<StartPoint>,
    /// Random starts (after the grid and the points).
    #[serde(default)]
    pub random: Option<RandomStarts>,
    /// SD of the placement error, m.
    #[serde(default)]
    pub position_jitter_m: f64,
    /// SD of the heading placement error, degrees.
    #[serde(default)]
    pub heading_jitter_deg: f64,
}

/// `[starts.random]`: `count` starts drawn uniformly in distance and angle over an
/// annular sector of the approach zone, from the scenario's seed (so every run of the
/// campaign, and `dock --index`, sees the same ones), each facing the dock like a grid
/// start. Labelled `r1`, `r2`, ….
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RandomStarts {
    /// How many.
    pub count: usize,
    /// Distance from the dock entrance, m: [low, high].
    pub distance_m: [f64; 2],
    /// Angle off the dock axis, degrees: [low, high].
    pub angle_deg: [f64; 2],
}

fn default_corner() -> f64 {
    70.0
}

/// `[axes]`: what varies across runs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxesSpec {
    /// Lighting programmes: preset names or keys of `[lighting.NAME]`.
    #[serde(default = "default_lighting")]
    pub lighting: Vec<String>,
    /// Segmentation modes.
    #[serde(default = "default_segmentation")]
    pub segmentation: Vec<SegmentationMode>,
    /// Terrains.
    #[serde(default = "default_terrain")]
    pub terrain: Vec<Terrain>,
    /// Paints of the two-block flap, `[left, right]` as `two_block` fiducial names them
    /// (`[["cyan", "magenta"], ["yellow", "blue"]]`): each run repaints the flap with one
    /// pair, in the world and in the profile the robot is built from (its table
    /// defaults), as `[profile_patch.fiducial.get::<crate::profile::TwoBlockSpec>().copied()] left_color/right_color` would.
    /// Absent: the profile's own paints, and the campaign is what it was without the axis.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fiducial_colors: Option<Vec<[NamedColor; 2]>>,
}

impl Default for AxesSpec {
    fn default() -> Self {
        Self {
            lighting: default_lighting(),
            segmentation: default_segmentation(),
            terrain: default_terrain(),
            fiducial_colors: None,
        }
    }
}

/// A flap's paint pair as tables and summaries show it: `left|right`.
///
/// ```
/// use marsupial::profile::NamedColor;
/// use marsupial::sim::scenario::colors_label;
/// assert_eq!(colors_label(&[NamedColor::Yellow, NamedColor::Blue]), "yellow|blue");
/// ```
pub fn colors_label(pair: &[NamedColor; 2]) -> String {
    format!("{}|{}", pair[0].as_str(), pair[1].as_str())
}

fn default_lighting() -> Vec<String> {
    vec!["lab".into()]
}
fn default_segmentation() -> Vec<SegmentationMode> {
    vec![SegmentationMode::Adaptive]
}
fn default_terrain() -> Vec<Terrain> {
    vec![Terrain::LabFloor]
}

/// `[sensor].white_balance`: how the simulated camera balances white.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WhiteBalanceSpec {
    /// The camera's own grey-world estimate over near-neutral pixels, settling with
    /// `white_balance_tau_s` (the default; fooled by coloured light and by views one
    /// colour fills, as a real camera's is).
    GreyWorld,
    /// A camera's indoor/outdoor white-balance switch, set for the run's setting as seed
    /// 004's operators set Bujold's camera ("moving the white balance switch on the camera"
    /// between lab and outdoor light, §VI-B): balanced for the room's illuminant under a
    /// lighting without sun, for daylight under one with sun. Nothing corrects dusk's or
    /// dawn's colour, or a flasher's.
    Switch,
    /// Balanced for each run's true illuminant: a perfect balance no real camera has.
    Perfect,
    /// Balanced once for daylight, whatever the light.
    Daylight,
    /// Balanced once for dusk.
    Dusk,
    /// Balanced once for tungsten.
    Tungsten,
    /// Balanced once for fluorescent light.
    Fluorescent,
    /// Balanced once for dawn.
    Dawn,
}

/// `[sensor]`: the simulated camera's sensor (see [`super::render::SensorParams`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SensorSpec {
    /// Full well at unity gain, electrons.
    pub full_well_e: f64,
    /// Read noise SD, electrons.
    pub read_noise_e: f64,
    /// Longest integration, as an exposure multiplier; beyond it the gain rises.
    pub max_integration: f64,
    /// Auto-exposure on.
    pub auto_exposure: bool,
    /// White balance.
    pub white_balance: WhiteBalanceSpec,
    /// Time constant of the grey-world balance, s (0 follows each frame's estimate at
    /// once).
    pub white_balance_tau_s: f64,
    /// Auto-exposure's highlight protection: the largest fraction of pixels it lets clip
    /// (0–1; 1 meters the mean alone and lets a sunlit target burn out).
    pub highlight_clip_frac: f64,
    /// Motion blur from the robot's own motion during each exposure, whose length
    /// follows auto-exposure (`SensorParams::exposure_time_s`). Off by default.
    pub motion_blur: bool,
    /// Rolling shutter: time from the first row's exposure to the last's, s (0, the
    /// default: a global shutter). At most 1 s.
    pub rolling_shutter_readout_s: f64,
    /// Vignetting: a corner's illumination relative to the centre, (0, 1]; 1 (the
    /// default) is none.
    pub vignetting_corner: f64,
    /// Defocus: the distance the lens is focused at, m. Absent (the default): a pin-hole,
    /// sharp at every depth.
    pub focus_m: Option<f64>,
    /// The lens's f-number, used with `focus_m` (default 2.0, a webcam's).
    pub f_number: f64,
    /// The lens's physical focal length, mm, used with `focus_m` (default 3.6, the usual
    /// webcam lens).
    pub focal_length_mm: f64,
    /// JPEG quality of the camera's stream, 1–100; 0 (the default) delivers raw frames.
    pub jpeg_quality: u32,
}

impl Default for SensorSpec {
    fn default() -> Self {
        let d = SensorParams::default();
        Self {
            full_well_e: f64::from(d.full_well_e),
            read_noise_e: f64::from(d.read_noise_e),
            max_integration: f64::from(d.max_integration),
            auto_exposure: true,
            white_balance: WhiteBalanceSpec::GreyWorld,
            white_balance_tau_s: f64::from(d.white_balance_tau_s),
            highlight_clip_frac: 0.01,
            motion_blur: false,
            rolling_shutter_readout_s: 0.0,
            vignetting_corner: 1.0,
            focus_m: None,
            f_number: 2.0,
            focal_length_mm: 3.6,
            jpeg_quality: 0,
        }
    }
}

impl SensorSpec {
    /// Checks every field, reporting problems under `prefix` (`sensor` in a scenario), so
    /// any file that describes a camera's sensor validates it the same way.
    pub fn validate_at(&self, prefix: &str, v: &mut Validator<'_>) {
        let at = |field: &str| format!("{prefix}.{field}");
        v.positive(&at("full_well_e"), self.full_well_e);
        v.non_negative(&at("read_noise_e"), self.read_noise_e);
        v.positive(&at("max_integration"), self.max_integration);
        v.non_negative(&at("white_balance_tau_s"), self.white_balance_tau_s);
        v.range(&at("highlight_clip_frac"), self.highlight_clip_frac, 0.0, 1.0);
        v.range(
            &at("rolling_shutter_readout_s"),
            self.rolling_shutter_readout_s,
            0.0,
            1.0,
        );
        v.fraction(&at("vignetting_corner"), self.vignetting_corner);
        if let Some(f) = self.focus_m {
            v.positive(&at("focus_m"), f);
        }
        v.range(&at("f_number"), self.f_number, 0.5, 64.0);
        v.range(&at("focal_length_mm"), self.focal_length_mm, 0.5, 300.0);
        if let Some(f) = self.focus_m {
            let mm = self.focal_length_mm;
            v.require(!f.is_finite() || f > mm * 1e-3, &at("focus_m"), || {
                format!("expected a focus farther than the focal length ({mm} mm), got {f} m")
            });
        }
        v.require(self.jpeg_quality <= 100, &at("jpeg_quality"), || {
            format!("expected 0 (off) or a quality 1–100, got {}", self.jpeg_quality)
        });
    }

    /// The renderer's sensor parameters under `lighting` (which a fixed white balance
    /// such as `switch` or `perfect` is set for).
    pub fn params(&self, lighting: &Lighting) -> SensorParams {
        use super::lighting::Illuminant as I;
        let fixed = |i: I| WhiteBalance::Fixed(i.rgb().map(|c| 1.0 / c));
        let white_balance = match self.white_balance {
            WhiteBalanceSpec::GreyWorld => WhiteBalance::GreyWorld,
            WhiteBalanceSpec::Switch if lighting.sun > 0.0 => fixed(I::Daylight),
            WhiteBalanceSpec::Switch | WhiteBalanceSpec::Perfect => fixed(lighting.illuminant),
            WhiteBalanceSpec::Daylight => fixed(I::Daylight),
            WhiteBalanceSpec::Dusk => fixed(I::Dusk),
            WhiteBalanceSpec::Tungsten => fixed(I::Tungsten),
            WhiteBalanceSpec::Fluorescent => fixed(I::Fluorescent),
            WhiteBalanceSpec::Dawn => fixed(I::Dawn),
        };
        SensorParams {
            full_well_e: self.full_well_e as f32,
            read_noise_e: self.read_noise_e as f32,
            max_integration: self.max_integration as f32,
            auto_exposure: self.auto_exposure,
            white_balance,
            white_balance_tau_s: self.white_balance_tau_s as f32,
            highlight_clip: self.highlight_clip_frac as f32,
            motion_blur: self.motion_blur,
            rolling_shutter_readout_s: self.rolling_shutter_readout_s as f32,
            vignetting_corner: self.vignetting_corner as f32,
            defocus: self.focus_m.map(|focus_m| Defocus {
                focus_m: focus_m as f32,
                f_number: self.f_number as f32,
                focal_length_mm: self.focal_length_mm as f32,
            }),
            jpeg_quality: self.jpeg_quality.min(100) as u8,
            ..SensorParams::default()
        }
    }
}

/// `[motion]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MotionSpec {
    /// Command latency, s.
    pub latency_s: f64,
    /// Linear acceleration limit, m/s².
    pub accel_mps2: f64,
    /// Yaw acceleration limit, deg/s².
    pub yaw_accel_dps2: f64,
    /// Slip override (default: the terrain's).
    pub slip: Option<SlipSpec>,
    /// Multiplier on the terrain's slip (1 = as tabulated).
    pub slip_scale: f64,
}

impl Default for MotionSpec {
    fn default() -> Self {
        Self {
            latency_s: 0.1,
            accel_mps2: 0.5,
            yaw_accel_dps2: 120.0,
            slip: None,
            slip_scale: 1.0,
        }
    }
}

/// `[imprint]`: what happens before each docking run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ImprintSpec {
    /// Run the departure (undock + imprint) first.
    pub enabled: bool,
    /// Lighting during departure (default: the run's).
    pub lighting: Option<String>,
    /// Seconds between departure and docking (the session clock advances).
    pub sleep_s: f64,
}

impl Default for ImprintSpec {
    fn default() -> Self {
        Self {
            enabled: true,
            lighting: None,
            sleep_s: 0.0,
        }
    }
}

/// `[ballistic]`: the robot is not placed facing the dock but told where it is a priori
/// (GPS, or remembered from departure), with an error, and must drive there first (the
/// ballistic region of seed 004 Fig. 1).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct BallisticSpec {
    /// Hand the agent an a-priori dock pose at each start.
    pub enabled: bool,
    /// SD of the a-priori position's error, m (each axis).
    pub error_m: f64,
    /// SD of the a-priori axis direction's error, degrees.
    pub heading_error_deg: f64,
}

/// `[endurance]`: the campaign is one continuous outing of `cycles` departure → dock
/// cycles with one robot, nothing reset between them ([`super::endurance`]). Each cycle
/// the robot departs from the dock (undocking and imprinting, as a campaign run's
/// departure), drives itself to a start drawn from `[starts]` (the excursion: a simple
/// waypoint driver standing in for the daughter's own mission away from the mother),
/// then docks from there. The light drifts through `lighting` over `day_s` of the
/// outing's clock.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnduranceSpec {
    /// Departure → dock cycles in the outing.
    pub cycles: usize,
    /// Lighting programmes the outing's light drifts through, evenly spaced over `day_s`
    /// (preset names or keys of `[lighting.NAME]`, without flashers or clouds): e.g.
    /// `["dawn", "noon", "dusk"]`. Replaces the `axes.lighting` axis.
    pub lighting: Vec<String>,
    /// Simulated seconds over which the light goes from the first programme to the last
    /// (it stays at the last after): set it near the outing's length.
    pub day_s: f64,
    /// The excursion driver's cruising speed, m/s (default 0.15).
    #[serde(default = "default_excursion_speed")]
    pub excursion_speed_mps: f64,
    /// Longest excursion, s (default 120): a robot not at its start by then docks from
    /// where it is.
    #[serde(default = "default_excursion_timeout")]
    pub excursion_timeout_s: f64,
}

fn default_excursion_speed() -> f64 {
    0.15
}
fn default_excursion_timeout() -> f64 {
    120.0
}

/// `[record]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct RecordSpec {
    /// Save every Nth camera frame as PNG with `--out` (0: none).
    pub frames_every: u32,
}

/// A scenario file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Name.
    pub name: String,
    /// Description.
    #[serde(default)]
    pub description: String,
    /// Profile path (relative to the scenario file).
    pub profile: PathBuf,
    /// Changes to the profile for this experiment only, merged key by key into the
    /// profile's TOML before it is parsed and validated (see [`crate::config::patch`]):
    /// `[profile_patch.fiducial.get::<crate::profile::TwoBlockSpec>().copied()] right_color = "yellow"` repaints one block and
    /// leaves every other setting following the profile file.
    #[serde(default)]
    pub profile_patch: Option<toml::Table>,
    /// Campaign seed.
    #[serde(default)]
    pub seed: u64,
    /// Trials per start and axis combination.
    #[serde(default = "one")]
    pub trials: u32,
    /// Run time limit, s (default 150, the paper's).
    #[serde(default = "default_timeout")]
    pub timeout_s: f64,
    /// Physics step, s.
    #[serde(default = "default_dt")]
    pub dt_s: f64,
    /// Starts.
    pub starts: StartsSpec,
    /// Varying axes.
    #[serde(default)]
    pub axes: AxesSpec,
    /// Named lighting programmes.
    #[serde(default)]
    pub lighting: BTreeMap<String, LightingSpec>,
    /// Named lighting distributions: each run on one draws its own programme
    /// ([`LightingDistribution`]).
    #[serde(default)]
    pub lighting_random: BTreeMap<String, LightingDistribution>,
    /// Sensor.
    #[serde(default)]
    pub sensor: SensorSpec,
    /// Motion.
    #[serde(default)]
    pub motion: MotionSpec,
    /// Departure and imprinting.
    #[serde(default)]
    pub imprint: ImprintSpec,
    /// A-priori dock location and its error.
    #[serde(default)]
    pub ballistic: BallisticSpec,
    /// Clutter.
    #[serde(default)]
    pub clutter: Vec<ClutterSpec>,
    /// Backdrop photos (relative to the scenario file).
    #[serde(default)]
    pub backgrounds: Vec<PathBuf>,
    /// Recording.
    #[serde(default)]
    pub record: RecordSpec,
    /// A published table to print beside the results.
    #[serde(default)]
    pub compare: Option<PaperTable>,
    /// Faults injected into the docking runs, one per run: an axis ([`super::faults`]).
    /// Empty: no faults, and the campaign is what it was without the table.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub faults: Vec<super::faults::FaultSpec>,
    /// An endurance outing instead of independent runs ([`EnduranceSpec`]). Absent: the
    /// campaign is what it was without the table.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub endurance: Option<EnduranceSpec>,
}

/// Which published table a scenario reproduces (`compare = "bujold-table1"`): the
/// campaign's results are printed beside it (`report::paper::comparison`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PaperTable {
    /// Seed 004 Table Ia (mean time to dock by symmetric start group) and §VI.A totals.
    BujoldTable1,
    /// Seed 004 Table II (time and success by lighting and segmentation).
    BujoldTable2,
    /// Seed 001 Table I (mean time, σ, v_mean and success by start group).
    RaposaTable1,
    /// Seed 001 §III: success against distance at 0°.
    RaposaRange,
    /// Seed 001 §III: 80°, 90° and 110° starts at about 1.5 m.
    RaposaWide,
    /// Seed 000 §V-B: 29 of 40 field runs docked, 20 of 24 away from the workspace
    /// boundary. Starts labelled `b…` are boundary starts (7 m, or beyond 40°), reported
    /// apart; every other start is away from the boundary (`fig10` among them).
    AxelField,
    /// Seed 000 §V-C: pure reeling docks only for |α| < 5° and tolerates |h| < 90°.
    /// Starts are labelled `r<m>/a<α°>/h<h°>` (α of the arm's tip about the module's axis,
    /// h the rover's heading from it); the table has one cell per (α, h), over every
    /// distance and terrain, beside the paper's limit.
    AxelReelOnly,
    /// Seed 000 §V-E: docked under uniform light and under an intense uneven shadow on
    /// the module's face, with the paper's fixed thresholds. Lighting programmes named
    /// `uniform` and `shadow` are set beside those figures.
    AxelLighting,
}

fn one() -> u32 {
    1
}
fn default_timeout() -> f64 {
    150.0
}
fn default_dt() -> f64 {
    0.01
}

fn preset_named(name: &str) -> Option<LightingPreset> {
    match name {
        "lab" => Some(LightingPreset::Lab),
        "flashers" => Some(LightingPreset::Flashers),
        "noon" => Some(LightingPreset::Noon),
        "dusk" => Some(LightingPreset::Dusk),
        "clouds" => Some(LightingPreset::Clouds),
        "dawn" => Some(LightingPreset::Dawn),
        _ => None,
    }
}

impl Validate for Scenario {
    fn validate(&self, v: &mut Validator<'_>) {
        v.require(!self.name.trim().is_empty(), "name", || {
            "expected a non-empty name".into()
        });
        v.require(self.trials >= 1, "trials", || "expected at least 1 trial".into());
        v.positive("timeout_s", self.timeout_s);
        v.non_negative("ballistic.error_m", self.ballistic.error_m);
        v.non_negative("ballistic.heading_error_deg", self.ballistic.heading_error_deg);
        v.require(self.dt_s > 0.0 && self.dt_s <= 0.05, "dt_s", || {
            format!("expected a physics step in (0, 0.05] s, got {}", self.dt_s)
        });
        let s = &self.starts;
        v.require(
            s.grid.is_some() || !s.points.is_empty() || s.random.is_some(),
            "starts",
            || "expected a `grid`, at least one entry in `points`, or `random`".into(),
        );
        if let Some(r) = &s.random {
            v.require((1..=10_000).contains(&r.count), "starts.random.count", || {
                format!("expected 1 to 10000 starts, got {}", r.count)
            });
            v.interval("starts.random.distance_m", r.distance_m, 0.0, 1000.0);
            v.interval("starts.random.angle_deg", r.angle_deg, -180.0, 180.0);
            v.require(r.distance_m[0] > 0.0, "starts.random.distance_m", || {
                "expected a positive lower distance".into()
            });
        }
        if let Some(sel) = &s.select {
            v.require(s.grid.is_some(), "starts.select", || "`select` needs a `grid`".into());
            for (i, p) in sel.iter().enumerate() {
                v.require((1..=16).contains(p), &format!("starts.select[{i}]"), || {
                    format!("expected a grid position 1–16, got {p}")
                });
            }
        }
        v.range("starts.corner_angle_deg", s.corner_angle_deg, 0.0, 90.0);
        v.non_negative("starts.position_jitter_m", s.position_jitter_m);
        v.non_negative("starts.heading_jitter_deg", s.heading_jitter_deg);
        for (i, p) in s.points.iter().enumerate() {
            let base = format!("starts.points[{i}]");
            let polar = p.distance_m.is_some() && p.angle_deg.is_some();
            let cart = p.x_m.is_some() && p.y_m.is_some();
            v.require(polar != cart, &base, || {
                "expected either distance_m and angle_deg, or x_m and y_m".into()
            });
            if let Some(d) = p.distance_m {
                v.positive(&format!("{base}.distance_m"), d);
            }
        }
        for (field, n) in [
            ("axes.lighting", self.axes.lighting.len()),
            ("axes.segmentation", self.axes.segmentation.len()),
            ("axes.terrain", self.axes.terrain.len()),
        ] {
            v.require(n >= 1, field, || "expected at least one value".into());
        }
        super::faults::validate_all(&self.faults, v);
        if let Some(pairs) = &self.axes.fiducial_colors {
            v.require(!pairs.is_empty(), "axes.fiducial_colors", || {
                "expected at least one [left, right] pair of colours (leave the axis out to keep the profile's paints)"
                    .into()
            });
            for (i, pair) in pairs.iter().enumerate() {
                for (j, c) in pair.iter().enumerate() {
                    v.require(
                        !matches!(c, NamedColor::White | NamedColor::Black),
                        &format!("axes.fiducial_colors[{i}][{j}]"),
                        || format!("`{}` lies on SCT's grey axis, which the segmentation never classifies: expected a chromatic colour", c.as_str()),
                    );
                }
                v.require(pair[0] != pair[1], &format!("axes.fiducial_colors[{i}]"), || {
                    format!("expected two different colours, got `{}` twice", pair[0].as_str())
                });
                if let Some(k) = pairs[..i].iter().position(|p| p == pair) {
                    v.problem(
                        &format!("axes.fiducial_colors[{i}]"),
                        format!("the pair {} is already axes.fiducial_colors[{k}]", colors_label(pair)),
                    );
                }
            }
        }
        for (i, name) in self.axes.lighting.iter().enumerate() {
            let known = self.lighting.contains_key(name)
                || self.lighting_random.contains_key(name)
                || preset_named(name).is_some();
            v.require(known, &format!("axes.lighting[{i}]"), || {
                format!("unknown lighting `{name}`: expected a preset (lab, flashers, noon, dusk, clouds, dawn), a [lighting.{name}] table or a [lighting_random.{name}] table")
            });
        }
        for name in self.lighting_random.keys() {
            v.require(
                !self.lighting.contains_key(name) && preset_named(name).is_none(),
                &format!("lighting_random.{name}"),
                || format!("`{name}` is already a lighting programme or preset: give the distribution its own name"),
            );
        }
        for (name, d) in &self.lighting_random {
            d.validate_at(&format!("lighting_random.{name}"), v);
        }
        if let Some(name) = &self.imprint.lighting {
            v.require(
                self.lighting.contains_key(name) || preset_named(name).is_some(),
                "imprint.lighting",
                || format!("unknown lighting `{name}`"),
            );
        }
        v.non_negative("imprint.sleep_s", self.imprint.sleep_s);
        for (name, l) in &self.lighting {
            l.validate_at(&format!("lighting.{name}"), v);
        }
        self.sensor.validate_at("sensor", v);
        v.non_negative("motion.latency_s", self.motion.latency_s);
        v.positive("motion.accel_mps2", self.motion.accel_mps2);
        v.positive("motion.yaw_accel_dps2", self.motion.yaw_accel_dps2);
        v.non_negative("motion.slip_scale", self.motion.slip_scale);
        if let Some(e) = &self.endurance {
            self.validate_endurance(e, v);
        }
        for (i, c) in self.clutter.iter().enumerate() {
            v.finite(&format!("clutter[{i}].x_m"), c.x_m);
            v.finite(&format!("clutter[{i}].y_m"), c.y_m);
            v.require(
                c.size_m.iter().all(|s| s.is_finite() && *s > 0.0),
                &format!("clutter[{i}].size_m"),
                || "expected positive sizes".into(),
            );
        }
    }
}

/// A start pose with its label.
#[derive(Debug, Clone, PartialEq)]
pub struct Start {
    /// Label ("1" … "16" for the grid).
    pub label: String,
    /// Pose before jitter.
    pub pose: Pose2,
    /// Distance from the entrance, m.
    pub distance: f64,
    /// Angle off the axis, degrees.
    pub angle_deg: f64,
}

/// One run of a campaign.
#[derive(Debug, Clone, PartialEq)]
pub struct RunSpec {
    /// Index in the campaign.
    pub index: usize,
    /// Start.
    pub start: Start,
    /// Lighting programme name.
    pub lighting: String,
    /// Segmentation mode.
    pub segmentation: SegmentationMode,
    /// Terrain.
    pub terrain: Terrain,
    /// The flap's paints `[left, right]` on a `fiducial_colors` axis (`None`: the
    /// profile's).
    pub fiducial_colors: Option<[NamedColor; 2]>,
    /// The injected fault: an index into the scenario's `faults` (`None`: no fault).
    pub fault: Option<usize>,
    /// Trial number.
    pub trial: u32,
    /// This run's seed.
    pub seed: u64,
    /// Seed shared by runs that differ only in segmentation (paired on the same imprint).
    pub pair_seed: u64,
}

/// A loaded scenario with its profile.
#[derive(Debug, Clone)]
pub struct Loaded {
    /// The scenario.
    pub scenario: Scenario,
    /// Its file.
    pub file: PathBuf,
    /// The profile it names.
    pub profile: Profile,
}

/// Loads `profile_file` with a scenario's `[profile_patch]` merged in. Problems are
/// reported against "the profile as patched by the scenario", without line numbers (the
/// merged text exists only in memory).
fn load_patched(
    profile_file: &Path,
    patch: &toml::Table,
    scenario_file: &Path,
    kinds: &FiducialKinds,
) -> Result<Profile, ConfigError> {
    let src = config::read_source(profile_file)?;
    let shown = PathBuf::from(format!(
        "{} as patched by [profile_patch] in {}",
        profile_file.display(),
        scenario_file.display()
    ));
    let text = crate::config::patch::patched(&src, patch).map_err(|message| ConfigError::Invalid {
        file: shown.clone(),
        problems: vec![config::Problem {
            path: "profile_patch".into(),
            line: None,
            message,
        }],
    })?;
    Profile::parse_with(&text, &shown, kinds).map_err(|e| match e {
        ConfigError::Invalid { file, problems } => ConfigError::Invalid {
            file,
            problems: problems
                .into_iter()
                .map(|p| config::Problem { line: None, ..p })
                .collect(),
        },
        other => other,
    })
}

impl Scenario {
    /// The checks of an `[endurance]` table: one outing needs one robot under one set of
    /// conditions, so every campaign axis has a single value.
    fn validate_endurance(&self, e: &EnduranceSpec, v: &mut Validator<'_>) {
        v.require((1..=10_000).contains(&e.cycles), "endurance.cycles", || {
            format!("expected 1 to 10000 cycles, got {}", e.cycles)
        });
        v.positive("endurance.day_s", e.day_s);
        v.positive("endurance.excursion_speed_mps", e.excursion_speed_mps);
        v.positive("endurance.excursion_timeout_s", e.excursion_timeout_s);
        v.require(!e.lighting.is_empty(), "endurance.lighting", || {
            "expected at least one lighting programme, e.g. [\"dawn\", \"noon\", \"dusk\"]".into()
        });
        for (i, name) in e.lighting.iter().enumerate() {
            let path = format!("endurance.lighting[{i}]");
            if !(self.lighting.contains_key(name) || preset_named(name).is_some()) {
                v.problem(
                    &path,
                    format!("unknown lighting `{name}`: expected a preset (lab, noon, dusk, dawn) or a [lighting.{name}] table"),
                );
                continue;
            }
            let l = self.lighting_named(name);
            v.require(l.flashers.is_empty() && l.clouds.is_none(), &path, || {
                format!("`{name}` has flashers or clouds, which an outing's light cannot drift: expected a programme without them")
            });
        }
        v.require(self.trials == 1, "trials", || {
            format!(
                "an endurance outing runs `endurance.cycles` cycles: expected trials = 1, got {}",
                self.trials
            )
        });
        v.require(self.axes.lighting == default_lighting(), "axes.lighting", || {
            "an endurance outing is lit by `endurance.lighting`: leave axes.lighting out".into()
        });
        for (field, n) in [
            ("axes.segmentation", self.axes.segmentation.len()),
            ("axes.terrain", self.axes.terrain.len()),
        ] {
            v.require(n == 1, field, || {
                format!("one robot makes an endurance outing: expected one value, got {n}")
            });
        }
        v.require(self.axes.fiducial_colors.is_none(), "axes.fiducial_colors", || {
            "one robot makes an endurance outing under one paint: leave axes.fiducial_colors out".into()
        });
        v.require(self.faults.is_empty(), "faults", || {
            "faults are not injected into endurance outings: leave [[faults]] out".into()
        });
        v.require(!self.ballistic.enabled, "ballistic.enabled", || {
            "an endurance outing docks from its excursion without an a-priori dock pose: expected false".into()
        });
        v.require(self.imprint.enabled, "imprint.enabled", || {
            "each endurance cycle starts with the departure: expected true".into()
        });
        v.require(self.imprint.lighting.is_none(), "imprint.lighting", || {
            "an endurance outing departs under the outing's light: leave imprint.lighting out".into()
        });
        v.require(self.imprint.sleep_s == 0.0, "imprint.sleep_s", || {
            "an endurance outing's clock is its own: expected 0".into()
        });
    }

    /// Loads and validates a scenario and the profile it names (with its
    /// `[profile_patch]`, if any).
    ///
    /// # Errors
    /// [`ConfigError`] for the scenario or its profile.
    pub fn load(path: &Path) -> Result<Loaded, ConfigError> {
        Self::load_with(path, &FiducialKinds::builtin())
    }

    /// [`Scenario::load`] for a profile whose fiducial is one of `kinds` (a catalog's:
    /// [`crate::behaviors::Catalog::fiducials`]).
    ///
    /// # Errors
    /// As [`Scenario::load`].
    pub fn load_with(path: &Path, kinds: &FiducialKinds) -> Result<Loaded, ConfigError> {
        let scenario: Scenario = config::load(path)?;
        let dir = path.parent().unwrap_or(Path::new("."));
        let profile_file = dir.join(&scenario.profile);
        let profile = match &scenario.profile_patch {
            None => Profile::load_with(&profile_file, kinds)?,
            Some(patch) => load_patched(&profile_file, patch, path, kinds)?,
        };
        if scenario.axes.fiducial_colors.is_some()
            && profile
                .fiducial
                .get::<crate::profile::TwoBlockSpec>()
                .copied()
                .is_none()
        {
            return Err(ConfigError::Invalid {
                file: path.to_path_buf(),
                problems: vec![config::Problem {
                    path: "axes.fiducial_colors".into(),
                    line: None,
                    message: format!(
                        "repaints a two-block flap, but profile `{}` has no `two_block` fiducial",
                        profile.name
                    ),
                }],
            });
        }
        for (i, b) in scenario.backgrounds.iter().enumerate() {
            let p = dir.join(b);
            if !p.is_file() {
                return Err(ConfigError::Invalid {
                    file: path.to_path_buf(),
                    problems: vec![config::Problem {
                        path: format!("backgrounds[{i}]"),
                        line: None,
                        message: format!("file {} not found", p.display()),
                    }],
                });
            }
        }
        Ok(Loaded {
            scenario,
            file: path.to_path_buf(),
            profile,
        })
    }

    /// The lighting of a run on axis value `name` with pair seed `pair_seed`: a fixed
    /// programme, or, for a `[lighting_random.NAME]`, the programme this run draws (seeded
    /// by the pair seed alone, so paired runs and `dock --index` see the same light) and
    /// the draw's record.
    pub fn lighting_for_run(&self, name: &str, pair_seed: u64) -> (Lighting, Option<LightingDraw>) {
        match self.lighting_random.get(name) {
            Some(d) => {
                let draw = d.draw(&mut Rng::named(pair_seed, "lighting_random"));
                (draw.spec.resolve(), Some(draw))
            }
            None => (self.lighting_named(name), None),
        }
    }

    /// The resolved lighting programme called `name` (a preset or a `[lighting.NAME]`).
    pub fn lighting_named(&self, name: &str) -> Lighting {
        match self.lighting.get(name) {
            Some(spec) => spec.resolve(),
            None => LightingSpec {
                preset: preset_named(name),
                ..Default::default()
            }
            .resolve(),
        }
    }

    /// Sensor parameters for a run under `lighting`.
    pub fn sensor_params(&self, lighting: &Lighting) -> SensorParams {
        self.sensor.params(lighting)
    }

    /// Slip on `terrain` for this scenario.
    pub fn slip(&self, terrain: Terrain) -> SlipSpec {
        let s = self.motion.slip.unwrap_or_else(|| terrain.slip());
        let k = self.motion.slip_scale;
        SlipSpec {
            slip_straight: s.slip_straight * k,
            slip_turn: (s.slip_turn * k).min(0.95),
            noise: s.noise * k,
            heading_noise: s.heading_noise * k,
            reel_yaw_noise: s.reel_yaw_noise * k,
        }
    }

    /// The start poses, in order. Headings default to "camera facing the dock". Polar
    /// starts (and the grid) measure the distance from the entrance to the robot's end
    /// nearest the dock, as a proctor places it; Cartesian starts give the robot's centre.
    pub fn starts(&self, profile: &Profile) -> Vec<Start> {
        let cam_yaw = profile.cameras.first().map_or(0.0, |c| c.mount.yaw_deg.to_radians());
        let half = profile.body.length_m / 2.0;
        let make = |label: String, x: f64, y: f64, heading: Option<f64>, polar: bool| {
            let theta = heading.map(f64::to_radians).unwrap_or_else(|| (-y).atan2(-x) - cam_yaw);
            let (cx, cy) = if polar {
                // Push the centre out along the bearing by half the body.
                let b = y.atan2(x);
                (x + half * b.cos(), y + half * b.sin())
            } else {
                (x, y)
            };
            Start {
                label,
                pose: Pose2::new(cx, cy, theta),
                distance: x.hypot(y),
                angle_deg: y.atan2(x).to_degrees(),
            }
        };
        let mut out = Vec::new();
        if self.starts.grid == Some(Grid::Paper16) {
            let a = self.starts.corner_angle_deg;
            let grid: [(f64, f64); 16] = [
                (0.33, -a),
                (0.33, 0.0),
                (0.33, a),
                (0.5, -30.0),
                (0.5, 0.0),
                (0.5, 30.0),
                (1.33, -60.0),
                (1.33, -30.0),
                (1.33, 0.0),
                (1.33, 30.0),
                (1.33, 60.0),
                (2.0, -60.0),
                (2.0, -30.0),
                (2.0, 0.0),
                (2.0, 30.0),
                (2.0, 60.0),
            ];
            for (i, (d, ang)) in grid.iter().enumerate() {
                if self.starts.select.as_ref().is_some_and(|s| !s.contains(&(i + 1))) {
                    continue;
                }
                let r = ang.to_radians();
                out.push(make((i + 1).to_string(), d * r.cos(), d * r.sin(), None, true));
            }
        }
        for (i, p) in self.starts.points.iter().enumerate() {
            let (x, y, polar) = match (p.distance_m, p.angle_deg, p.x_m, p.y_m) {
                (Some(d), Some(a), _, _) => (d * a.to_radians().cos(), d * a.to_radians().sin(), true),
                (_, _, Some(x), Some(y)) => (x, y, false),
                _ => continue,
            };
            let label = p.label.clone().unwrap_or_else(|| format!("p{}", i + 1));
            out.push(make(label, x, y, p.heading_deg, polar));
        }
        if let Some(r) = &self.starts.random {
            let mut rng = Rng::named(self.seed, "random_starts");
            for i in 0..r.count {
                let d = rng.range(r.distance_m[0], r.distance_m[1].max(r.distance_m[0]));
                let a = rng
                    .range(r.angle_deg[0], r.angle_deg[1].max(r.angle_deg[0]))
                    .to_radians();
                out.push(make(format!("r{}", i + 1), d * a.cos(), d * a.sin(), None, true));
            }
        }
        out
    }

    /// The values of the `fiducial_colors` axis: each pair, or one `None` (the profile's
    /// paints) when the axis is absent.
    pub fn fiducial_color_values(&self) -> Vec<Option<[NamedColor; 2]>> {
        match &self.axes.fiducial_colors {
            Some(pairs) => pairs.iter().copied().map(Some).collect(),
            None => vec![None],
        }
    }

    /// Every run of the campaign in a fixed order: starts × fiducial colours × lighting ×
    /// segmentation × terrain × trials. Runs that differ only in their paints share a pair
    /// seed (the same placement error and lighting draw), so colour pairs are compared
    /// on the same runs, as segmentation modes are.
    pub fn runs(&self, profile: &Profile) -> Vec<RunSpec> {
        if let Some(e) = &self.endurance {
            return self.cycles(e, profile);
        }
        let mut out = Vec::new();
        let colours = self.fiducial_color_values();
        for (si, start) in self.starts(profile).into_iter().enumerate() {
            for fiducial_colors in &colours {
                for (li, lighting) in self.axes.lighting.iter().enumerate() {
                    for seg in &self.axes.segmentation {
                        for (ti, terrain) in self.axes.terrain.iter().enumerate() {
                            for fault in self.fault_values() {
                                for trial in 0..self.trials {
                                    let index = out.len();
                                    let key =
                                        ((si as u64) << 40) ^ ((li as u64) << 32) ^ ((ti as u64) << 24) ^ trial as u64;
                                    out.push(RunSpec {
                                        index,
                                        start: start.clone(),
                                        lighting: lighting.clone(),
                                        segmentation: *seg,
                                        terrain: *terrain,
                                        fiducial_colors: *fiducial_colors,
                                        fault,
                                        trial,
                                        seed: super::rng::splitmix64(
                                            self.seed ^ super::rng::splitmix64(index as u64 + 1),
                                        ),
                                        pair_seed: super::rng::splitmix64(
                                            self.seed ^ super::rng::splitmix64(key ^ 0xA11CE),
                                        ),
                                    });
                                }
                            }
                        }
                    }
                }
            }
        }
        out
    }

    /// The cycles of an endurance outing, as runs: cycle `i` is run `i`, its start drawn
    /// uniformly from the scenario's starts (seeded by the scenario's seed), its lighting
    /// label the drift's programmes joined by `→`.
    fn cycles(&self, e: &EnduranceSpec, profile: &Profile) -> Vec<RunSpec> {
        let starts = self.starts(profile);
        if starts.is_empty() {
            return Vec::new();
        }
        let mut rng = Rng::named(self.seed, "endurance_starts");
        let lighting = e.lighting.join("→");
        let segmentation = self
            .axes
            .segmentation
            .first()
            .copied()
            .unwrap_or(SegmentationMode::Adaptive);
        let terrain = self.axes.terrain.first().copied().unwrap_or(Terrain::LabFloor);
        (0..e.cycles)
            .map(|index| {
                let k = ((rng.uniform() * starts.len() as f64) as usize).min(starts.len() - 1);
                let seed = super::rng::splitmix64(self.seed ^ super::rng::splitmix64(index as u64 + 1));
                RunSpec {
                    index,
                    start: starts[k].clone(),
                    lighting: lighting.clone(),
                    segmentation,
                    terrain,
                    fiducial_colors: None,
                    fault: None,
                    trial: 0,
                    seed,
                    pair_seed: seed,
                }
            })
            .collect()
    }

    /// The seed of an endurance outing's one simulation (its physics, rendering and
    /// odometry noise).
    pub fn outing_seed(&self) -> u64 {
        super::rng::splitmix64(self.seed ^ 0xE4D0_2A4C)
    }

    /// The values of the faults axis: each `[[faults]]` index, or one "no fault".
    fn fault_values(&self) -> Vec<Option<usize>> {
        if self.faults.is_empty() {
            vec![None]
        } else {
            (0..self.faults.len()).map(Some).collect()
        }
    }
}
