//! Lighting programmes: time-varying illumination from a scenario.
//!
//! Irradiance on a surface = ambient (sky or room) + sun·max(0, n·s) + coloured flashers,
//! all tinted by the illuminant; target surfaces can carry shadow bands (static, like the
//! sonar's shadow of seed 004 Fig. 10b, or moving) and the robot's own shadow; glossy
//! targets show a specular highlight of the key light (glare). Clouds switch the sun off
//! and on at random (seeded) instants. Presets `lab`, `flashers`, `noon`, `dusk`, `clouds`
//! and `dawn` reproduce DESIGN §2.1's conditions; every number can be set by hand.

use super::rng::Rng;
use super::scene::Tag;
use crate::config::Validator;

use nalgebra::{Point3, Vector3};
use serde::{Deserialize, Serialize};

/// Named lighting conditions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LightingPreset {
    /// Uniform fluorescent lab light.
    Lab,
    /// Lab light plus two rotating orange emergency lights 1.5 m from the fiducial, 0.5 m
    /// either side (seed 004 §VI.B).
    Flashers,
    /// Outdoors at noon: high sun, a hard moving shadow band, the robot's own shadow. (The
    /// 65° sun's highlight on an upright target reflects toward the ground, not a low
    /// camera.)
    Noon,
    /// Outdoors 90 min before sunset until dark: low warm sun, falling light.
    Dusk,
    /// Outdoors with sudden random cloud cover.
    Clouds,
    /// Outdoors at dawn: low, cool, rising light.
    Dawn,
}

/// Illuminant colours (relative RGB).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Illuminant {
    /// Neutral daylight.
    Daylight,
    /// Warm evening light.
    Dusk,
    /// Incandescent.
    Tungsten,
    /// Fluorescent (slightly green).
    Fluorescent,
    /// Cool morning light.
    Dawn,
}

impl Illuminant {
    /// Relative RGB irradiance.
    pub fn rgb(&self) -> [f32; 3] {
        match self {
            Illuminant::Daylight => [1.0, 1.0, 1.0],
            Illuminant::Dusk => [1.0, 0.72, 0.48],
            Illuminant::Tungsten => [1.0, 0.68, 0.38],
            Illuminant::Fluorescent => [0.95, 1.0, 0.92],
            Illuminant::Dawn => [0.85, 0.9, 1.0],
        }
    }
}

/// A rotating beacon.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FlasherSpec {
    /// Position (world), m.
    pub x_m: f64,
    /// Position (world), m.
    pub y_m: f64,
    /// Height, m.
    pub z_m: f64,
    /// Rotation period, s.
    pub period_s: f64,
    /// Peak irradiance at 1 m, relative to the ambient.
    pub power: f64,
    /// Colour (sRGB).
    pub rgb: [u8; 3],
}

/// A shadow band over the target surfaces.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShadowSpec {
    /// Fraction of light removed inside the shadow (0–1).
    pub strength: f64,
    /// Direction of the shadow edge's normal in the target plane, degrees (0: the shadow
    /// covers the target's +u side).
    pub angle_deg: f64,
    /// Edge position at rest, m from the target centre.
    pub offset_m: f64,
    /// Amplitude of the edge's motion, m (0: static).
    pub amplitude_m: f64,
    /// Period of the motion, s.
    pub period_s: f64,
    /// Penumbra width, m.
    pub softness_m: f64,
}

impl ShadowSpec {
    /// The band this shadow casts at session time `t` (its edge swung along its sine),
    /// its strength scaled by `weight` (1 in a steady light; a keyframe's share in a
    /// drifting one).
    fn band_at(&self, t: f64, weight: f64) -> ShadowBand {
        let off = self.offset_m + self.amplitude_m * (std::f64::consts::TAU * t / self.period_s).sin();
        let a = self.angle_deg.to_radians();
        ShadowBand {
            cos: a.cos() as f32,
            sin: a.sin() as f32,
            offset: off as f32,
            softness: self.softness_m as f32,
            strength: (self.strength * weight) as f32,
        }
    }
}

/// Random cloud cover.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CloudSpec {
    /// Mean time between sudden changes, s.
    pub mean_interval_s: f64,
    /// Fraction of the sun a cloud removes (0–1).
    pub depth: f64,
}

/// A lighting programme. A preset fills in everything; any field given overrides it.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightingSpec {
    /// Base preset (default `lab`).
    #[serde(default)]
    pub preset: Option<LightingPreset>,
    /// Overall light multiplier.
    #[serde(default)]
    pub intensity: Option<f64>,
    /// Illuminant colour.
    #[serde(default)]
    pub illuminant: Option<Illuminant>,
    /// Ambient (sky or room) level.
    #[serde(default)]
    pub ambient: Option<f64>,
    /// Sun level (0 indoors).
    #[serde(default)]
    pub sun: Option<f64>,
    /// Sun elevation, degrees.
    #[serde(default)]
    pub sun_elevation_deg: Option<f64>,
    /// Sun azimuth, degrees (0 = along +x, behind an approaching robot).
    #[serde(default)]
    pub sun_azimuth_deg: Option<f64>,
    /// Multiplier on the physically based highlight of glossy targets: 1 is a painted or
    /// laminated surface (Fresnel reflectance 4 %); larger values model wet or lacquered
    /// surfaces, 0 turns highlights off.
    #[serde(default)]
    pub glare: Option<f64>,
    /// Relative light change per hour of session time (dusk < 0, dawn > 0).
    #[serde(default)]
    pub change_per_hour: Option<f64>,
    /// Each run starts at a random time in [0, session_s) of the session (the paper's
    /// outdoor sessions lasted two hours at noon and 90 minutes at dusk).
    #[serde(default)]
    pub session_s: Option<f64>,
    /// Rotating beacons.
    #[serde(default)]
    pub flashers: Option<Vec<FlasherSpec>>,
    /// Shadow bands on the target.
    #[serde(default)]
    pub shadows: Option<Vec<ShadowSpec>>,
    /// Cloud cover.
    #[serde(default)]
    pub clouds: Option<CloudSpec>,
    /// The robot's own shadow falls on the target (outdoor presets).
    #[serde(default)]
    pub self_shadow: Option<bool>,
}

/// The resolved programme (preset + overrides).
#[derive(Debug, Clone, PartialEq)]
pub struct Lighting {
    /// Overall multiplier.
    pub intensity: f64,
    /// Illuminant.
    pub illuminant: Illuminant,
    /// Ambient level.
    pub ambient: f64,
    /// Sun level.
    pub sun: f64,
    /// Unit vector toward the sun.
    pub sun_dir: Vector3<f64>,
    /// Glare strength.
    pub glare: f64,
    /// Relative change per hour.
    pub change_per_hour: f64,
    /// Session length, s.
    pub session_s: f64,
    /// Beacons.
    pub flashers: Vec<FlasherSpec>,
    /// Shadow bands.
    pub shadows: Vec<ShadowSpec>,
    /// Clouds.
    pub clouds: Option<CloudSpec>,
    /// Robot self-shadow.
    pub self_shadow: bool,
}

impl Lighting {
    /// Steady ambient light alone, of `illuminant`'s colour at `intensity`: no sun, glare,
    /// drift, beacons, shadows or clouds (the sun's direction is then unused; straight up).
    pub fn ambient_only(intensity: f64, illuminant: Illuminant) -> Self {
        Self {
            intensity,
            illuminant,
            ambient: 1.0,
            sun: 0.0,
            sun_dir: Vector3::z(),
            glare: 0.0,
            change_per_hour: 0.0,
            session_s: 0.0,
            flashers: Vec::new(),
            shadows: Vec::new(),
            clouds: None,
            self_shadow: false,
        }
    }
}

impl LightingSpec {
    /// Resolves the preset and overrides.
    pub fn resolve(&self) -> Lighting {
        let preset = self.preset.unwrap_or(LightingPreset::Lab);
        let mut l = match preset {
            LightingPreset::Lab | LightingPreset::Flashers => Lighting {
                sun_dir: sun_vector(70.0, 0.0),
                glare: 1.0,
                ..Lighting::ambient_only(1.0, Illuminant::Fluorescent)
            },
            LightingPreset::Noon => Lighting {
                intensity: 3.0,
                illuminant: Illuminant::Daylight,
                ambient: 0.35,
                sun: 1.0,
                sun_dir: sun_vector(65.0, 20.0),
                glare: 1.0,
                change_per_hour: 0.0,
                session_s: 7200.0,
                flashers: Vec::new(),
                shadows: vec![ShadowSpec {
                    strength: 0.7,
                    angle_deg: 90.0,
                    offset_m: 0.02,
                    amplitude_m: 0.03,
                    period_s: 90.0,
                    softness_m: 0.01,
                }],
                clouds: None,
                self_shadow: true,
            },
            LightingPreset::Dusk => Lighting {
                intensity: 0.5,
                illuminant: Illuminant::Dusk,
                ambient: 0.45,
                sun: 0.6,
                sun_dir: sun_vector(6.0, -30.0),
                glare: 1.0,
                change_per_hour: -0.55,
                session_s: 5400.0,
                flashers: Vec::new(),
                shadows: vec![ShadowSpec {
                    strength: 0.6,
                    angle_deg: 0.0,
                    offset_m: 0.03,
                    amplitude_m: 0.04,
                    period_s: 120.0,
                    softness_m: 0.02,
                }],
                clouds: None,
                self_shadow: true,
            },
            LightingPreset::Clouds => Lighting {
                intensity: 2.5,
                illuminant: Illuminant::Daylight,
                ambient: 0.35,
                sun: 1.0,
                sun_dir: sun_vector(50.0, 10.0),
                glare: 1.0,
                change_per_hour: 0.0,
                session_s: 7200.0,
                flashers: Vec::new(),
                shadows: Vec::new(),
                clouds: Some(CloudSpec {
                    mean_interval_s: 15.0,
                    depth: 0.85,
                }),
                self_shadow: true,
            },
            LightingPreset::Dawn => Lighting {
                intensity: 0.4,
                illuminant: Illuminant::Dawn,
                ambient: 0.5,
                sun: 0.5,
                sun_dir: sun_vector(4.0, 160.0),
                glare: 1.0,
                change_per_hour: 0.8,
                session_s: 0.0,
                flashers: Vec::new(),
                shadows: Vec::new(),
                clouds: None,
                self_shadow: true,
            },
        };
        if preset == LightingPreset::Flashers {
            l.flashers = [-0.5, 0.5]
                .iter()
                .map(|&y| FlasherSpec {
                    x_m: 1.5,
                    y_m: y,
                    z_m: 0.6,
                    period_s: 1.2,
                    power: 2.5,
                    rgb: [255, 120, 0],
                })
                .collect();
        }
        if let Some(v) = self.intensity {
            l.intensity = v;
        }
        if let Some(v) = self.illuminant {
            l.illuminant = v;
        }
        if let Some(v) = self.ambient {
            l.ambient = v;
        }
        if let Some(v) = self.sun {
            l.sun = v;
        }
        if self.sun_elevation_deg.is_some() || self.sun_azimuth_deg.is_some() {
            let (e, a) = sun_angles(&l.sun_dir);
            l.sun_dir = sun_vector(self.sun_elevation_deg.unwrap_or(e), self.sun_azimuth_deg.unwrap_or(a));
        }
        if let Some(v) = self.glare {
            l.glare = v;
        }
        if let Some(v) = self.change_per_hour {
            l.change_per_hour = v;
        }
        if let Some(v) = self.session_s {
            l.session_s = v;
        }
        if let Some(v) = &self.flashers {
            l.flashers = v.clone();
        }
        if let Some(v) = &self.shadows {
            l.shadows = v.clone();
        }
        if let Some(v) = self.clouds {
            l.clouds = Some(v);
        }
        if let Some(v) = self.self_shadow {
            l.self_shadow = v;
        }
        l
    }

    pub(crate) fn validate_at(&self, base: &str, v: &mut Validator<'_>) {
        let p = |f: &str| format!("{base}.{f}");
        for (f, x) in [
            ("intensity", self.intensity),
            ("ambient", self.ambient),
            ("sun", self.sun),
            ("glare", self.glare),
        ] {
            if let Some(x) = x {
                v.non_negative(&p(f), x);
            }
        }
        if let Some(x) = self.intensity {
            v.require(x > 0.0, &p("intensity"), || {
                format!("expected a positive intensity, got {x}")
            });
        }
        if let Some(e) = self.sun_elevation_deg {
            v.range(&p("sun_elevation_deg"), e, -10.0, 90.0);
        }
        if let Some(s) = self.session_s {
            v.non_negative(&p("session_s"), s);
        }
        if let Some(c) = self.change_per_hour {
            v.range(&p("change_per_hour"), c, -0.99, 10.0);
        }
        for (i, f) in self.flashers.iter().flatten().enumerate() {
            v.positive(&p(&format!("flashers[{i}].period_s")), f.period_s);
            v.non_negative(&p(&format!("flashers[{i}].power")), f.power);
        }
        for (i, s) in self.shadows.iter().flatten().enumerate() {
            v.range(&p(&format!("shadows[{i}].strength")), s.strength, 0.0, 1.0);
            v.non_negative(&p(&format!("shadows[{i}].softness_m")), s.softness_m);
            v.positive(&p(&format!("shadows[{i}].period_s")), s.period_s);
        }
        if let Some(c) = self.clouds {
            v.positive(&p("clouds.mean_interval_s"), c.mean_interval_s);
            v.range(&p("clouds.depth"), c.depth, 0.0, 1.0);
        }
    }
}

fn sun_vector(elev_deg: f64, az_deg: f64) -> Vector3<f64> {
    let (e, a) = (elev_deg.to_radians(), az_deg.to_radians());
    Vector3::new(e.cos() * a.cos(), e.cos() * a.sin(), e.sin())
}

fn sun_angles(v: &Vector3<f64>) -> (f64, f64) {
    (v.z.asin().to_degrees(), v.y.atan2(v.x).to_degrees())
}

/// A shadow band evaluated at one instant, in a target's local coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadowBand {
    /// Edge normal (cos, sin) in (a, b).
    pub cos: f32,
    /// See `cos`.
    pub sin: f32,
    /// Edge offset, m.
    pub offset: f32,
    /// Penumbra, m.
    pub softness: f32,
    /// Light removed.
    pub strength: f32,
}

/// One run's lighting: the programme plus its seeded randomness (start time in the
/// session, cloud switching instants), or a drift through several programmes over an
/// endurance outing ([`LightingRun::drifting`]).
#[derive(Debug, Clone, PartialEq)]
pub struct LightingRun {
    lighting: Lighting,
    start_s: f64,
    cloud_switches: Vec<f64>,
    drift: Option<Drift>,
}

/// Keyframe programmes spread evenly over `span_s` of simulation time.
#[derive(Debug, Clone, PartialEq)]
struct Drift {
    keys: Vec<Lighting>,
    span_s: f64,
}

impl LightingRun {
    /// Instantiates `lighting` for one run; `horizon_s` bounds the cloud schedule.
    pub fn new(lighting: Lighting, rng: &mut Rng, horizon_s: f64) -> Self {
        let start_s = rng.uniform() * lighting.session_s;
        let mut cloud_switches = Vec::new();
        if let Some(c) = lighting.clouds {
            let mut t = 0.0;
            while t < horizon_s {
                t += -c.mean_interval_s * (1.0 - rng.uniform()).ln();
                cloud_switches.push(t);
            }
        }
        Self {
            lighting,
            start_s,
            cloud_switches,
            drift: None,
        }
    }

    /// Light that drifts through the programmes `keys` (at least one), spread evenly
    /// over `span_s` seconds of simulation time from time 0: the first holds at 0, the
    /// last from `span_s` on, and between two neighbours every quantity is interpolated
    /// with the fraction `f` of the way from one to the next: the light level
    /// geometrically (`a^(1−f)·b^f`, as daylight changes by factors), the illuminant's
    /// colour, ambient, sun and glare linearly, the sun's direction along the great circle
    /// (normalised linear interpolation), and each programme's shadow bands fade out and
    /// in with its weight. Each programme's own session clock (`change_per_hour`,
    /// `session_s`) does not apply: the drift is the clock. Flashers and clouds are not
    /// drifted (a scenario's `[endurance]` refuses programmes with them).
    ///
    /// # Panics
    /// Never; `keys` empty is treated as the `lab` programme.
    pub fn drifting(keys: Vec<Lighting>, span_s: f64) -> Self {
        let keys = if keys.is_empty() {
            vec![LightingSpec::default().resolve()]
        } else {
            keys
        };
        Self {
            lighting: keys[0].clone(),
            start_s: 0.0,
            cloud_switches: Vec::new(),
            drift: Some(Drift {
                keys,
                span_s: span_s.max(1e-9),
            }),
        }
    }

    /// The drift's neighbouring keyframes at time `t` and the fraction between them.
    fn drift_at(d: &Drift, t: f64) -> (&Lighting, &Lighting, f64) {
        let n = d.keys.len();
        if n == 1 {
            return (&d.keys[0], &d.keys[0], 0.0);
        }
        let u = (t / d.span_s).clamp(0.0, 1.0) * (n - 1) as f64;
        let i = (u.floor() as usize).min(n - 2);
        (&d.keys[i], &d.keys[i + 1], u - i as f64)
    }

    fn fill_drift(d: &Drift, t: f64, state: &mut LightState) {
        let (a, b, f) = Self::drift_at(d, t);
        let lerp = |x: f64, y: f64| x + (y - x) * f;
        let level = (a.intensity.ln() * (1.0 - f) + b.intensity.ln() * f).exp();
        let (ca, cb) = (a.illuminant.rgb(), b.illuminant.rgb());
        let sun = lerp(a.sun, b.sun);
        let dir = a.sun_dir * (1.0 - f) + b.sun_dir * f;
        state.illum = [0, 1, 2].map(|c| lerp(f64::from(ca[c]), f64::from(cb[c])) as f32);
        state.level = level as f32;
        state.ambient = lerp(a.ambient, b.ambient) as f32;
        state.sun = sun as f32;
        state.sun_dir = if dir.norm() > 1e-9 { dir.normalize() } else { a.sun_dir };
        state.glare = (lerp(a.glare, b.glare) * sun.max(0.3)) as f32;
        state.shadows.clear();
        for (l, w) in [(a, 1.0 - f), (b, f)] {
            state
                .shadows
                .extend(l.shadows.iter().filter(|_| w > 0.0).map(|s| s.band_at(t, w)));
        }
        state.flashers.clear();
    }

    /// Delays the session clock by `s` seconds (e.g. hours asleep between imprint and dock).
    pub fn advance_session(&mut self, s: f64) {
        self.start_s += s;
    }

    /// The resolved programme.
    pub fn lighting(&self) -> &Lighting {
        &self.lighting
    }

    /// The state at run time `t` (s).
    pub fn at(&self, t: f64) -> LightState {
        let mut state = LightState::uniform(0.0);
        self.fill(t, &mut state);
        state
    }

    /// Writes the state at run time `t` (s) into `state`, reusing its lists (the
    /// simulator calls this every tick without allocating).
    pub fn fill(&self, t: f64, state: &mut LightState) {
        if let Some(d) = &self.drift {
            Self::fill_drift(d, t, state);
            return;
        }
        let l = &self.lighting;
        let hours = (self.start_s + t) / 3600.0;
        let level = (l.intensity * (1.0 + l.change_per_hour * hours)).max(0.02 * l.intensity);
        let clouded = self.cloud_switches.iter().take_while(|&&s| s <= t).count() % 2 == 1;
        let sun = l.sun
            * if clouded {
                1.0 - l.clouds.map_or(0.0, |c| c.depth)
            } else {
                1.0
            };
        state.illum = l.illuminant.rgb();
        state.level = level as f32;
        state.ambient = l.ambient as f32;
        state.sun = sun as f32;
        state.sun_dir = l.sun_dir;
        state.glare = (l.glare * sun.max(0.3)) as f32;
        state.shadows.clear();
        state.shadows.extend(l.shadows.iter().map(|s| s.band_at(t, 1.0)));
        state.flashers.clear();
        state.flashers.extend(l.flashers.iter().map(|f| {
            let angle = std::f64::consts::TAU * t / f.period_s;
            (
                Point3::new(f.x_m, f.y_m, f.z_m),
                angle,
                f.power as f32,
                super::scene::albedo(f.rgb, 1.0),
            )
        }));
    }

    /// True when the robot's own shadow should be cast on the target.
    pub fn self_shadow(&self) -> bool {
        self.lighting.self_shadow
    }

    /// True when the robot's own shadow should be cast on the target at time `t`: the
    /// programme's setting, or, drifting, the nearer keyframe's.
    pub fn self_shadow_at(&self, t: f64) -> bool {
        match &self.drift {
            None => self.lighting.self_shadow,
            Some(d) => {
                let (a, b, f) = Self::drift_at(d, t);
                if f < 0.5 { a.self_shadow } else { b.self_shadow }
            }
        }
    }
}

/// Lighting at one instant, as the renderer uses it.
#[derive(Debug, Clone, PartialEq)]
pub struct LightState {
    illum: [f32; 3],
    level: f32,
    ambient: f32,
    sun: f32,
    sun_dir: Vector3<f64>,
    glare: f32,
    flashers: Vec<(Point3<f64>, f64, f32, [f32; 3])>,
    shadows: Vec<ShadowBand>,
}

impl LightState {
    /// The lights went out (fault injection): the light falls to 0.1 % of what it was (a
    /// 500 lx lab to a dark room's 0.5 lx), with
    /// no sun, glare or flashers; the camera's auto-exposure then lifts mostly noise.
    pub fn lights_out(&mut self) {
        self.level *= 0.001;
        self.sun = 0.0;
        self.glare = 0.0;
        self.flashers.clear();
    }

    /// Plain uniform light of `level` (for tests).
    pub fn uniform(level: f32) -> Self {
        Self {
            illum: [1.0; 3],
            level,
            ambient: 1.0,
            sun: 0.0,
            sun_dir: Vector3::z(),
            glare: 0.0,
            flashers: Vec::new(),
            shadows: Vec::new(),
        }
    }

    /// Adds a shadow band on the targets for this instant (e.g. the robot's own shadow).
    pub fn push_target_shadow(&mut self, band: ShadowBand) {
        self.shadows.push(band);
    }

    /// Unit vector toward the sun and the sun's level (0 indoors or under cloud).
    pub fn sun(&self) -> (Vector3<f64>, f32) {
        (self.sun_dir, self.sun)
    }

    /// Irradiance (linear RGB) on a surface with world normal `n` at `at`.
    pub fn irradiance_at(&self, n: &Vector3<f64>, at: &Point3<f64>, tag: Tag) -> [f32; 3] {
        let mut e = self.irradiance(n);
        if tag != Tag::Backdrop {
            for (pos, angle, power, rgb) in &self.flashers {
                let d = pos - at;
                let dist = d.norm().max(0.2);
                let dir = d / dist;
                // Beam sweeping in the horizontal plane; the lit fraction is its lobe.
                let beam = Vector3::new(angle.cos(), angle.sin(), 0.0);
                let lobe = (-beam.dot(&dir)).max(0.0).powi(6) as f32;
                let facing = n.dot(&dir).max(0.0) as f32;
                for c in 0..3 {
                    e[c] += power * lobe * facing * rgb[c] / (dist * dist) as f32;
                }
            }
        }
        e
    }

    /// Ambient plus sun on a surface with world normal `n`, with no flashers (the ground
    /// and backdrops, which have no single position).
    pub fn irradiance(&self, n: &Vector3<f64>) -> [f32; 3] {
        let direct = self.sun * (n.dot(&self.sun_dir).max(0.0) as f32);
        [0, 1, 2].map(|c| self.illum[c] * self.level * (self.ambient + direct))
    }

    /// Sky brightness multiplier.
    pub fn sky_scale(&self) -> f32 {
        self.level * (self.ambient + 0.5 * self.sun)
    }

    /// Direction (world) of the key light for highlights.
    pub fn key_direction(&self) -> Vector3<f64> {
        self.sun_dir
    }

    /// Colour of highlights: the illuminant at the current level (the key light's own
    /// strength is in [`glare_strength`](Self::glare_strength)).
    pub fn key_colour(&self) -> [f32; 3] {
        [0, 1, 2].map(|c| self.illum[c] * self.level)
    }

    /// The key light's level times the programme's glare multiplier: the sun outdoors, and
    /// at least 0.3 (ceiling fixtures indoors, bright overcast under cloud).
    pub fn glare_strength(&self) -> f32 {
        self.glare
    }

    /// Shadow bands applying to primitives tagged `tag`.
    pub fn shadows_for(&self, tag: Tag) -> &[ShadowBand] {
        if tag == Tag::Target { &self.shadows } else { &[] }
    }

    /// Mean scene level (for tests).
    pub fn level(&self) -> f32 {
        self.level
    }
}

#[cfg(test)]
mod drift_tests {
    use super::*;

    fn preset(p: LightingPreset) -> Lighting {
        LightingSpec {
            preset: Some(p),
            ..Default::default()
        }
        .resolve()
    }

    #[test]
    fn drift_passes_through_its_keyframes_and_interpolates_between() {
        let keys = vec![
            preset(LightingPreset::Dawn),
            preset(LightingPreset::Noon),
            preset(LightingPreset::Dusk),
        ];
        let run = LightingRun::drifting(keys.clone(), 1000.0);
        let level = |t: f64| f64::from(run.at(t).level());
        for (t, k) in [(0.0, 0), (500.0, 1), (1000.0, 2), (5000.0, 2)] {
            assert!((level(t) - keys[k].intensity).abs() < 1e-6, "t {t}: {}", level(t));
        }
        // Geometric between dawn (0.4) and noon (3.0): their geometric mean halfway.
        assert!((level(250.0) - (0.4f64 * 3.0).sqrt()).abs() < 1e-6);
        // The sun direction stays a unit vector, between the two keyframes' elevations.
        let (dir, _) = run.at(250.0).sun();
        assert!((dir.norm() - 1.0).abs() < 1e-9);
        assert!(dir.z > keys[0].sun_dir.z && dir.z < keys[1].sun_dir.z);
        // Noon's shadow band fades in: half strength a quarter of the way.
        let s = run.at(250.0);
        assert_eq!(s.shadows_for(super::super::scene::Tag::Target).len(), 1);
        assert!((s.shadows_for(super::super::scene::Tag::Target)[0].strength - 0.35).abs() < 1e-6);
    }
}
