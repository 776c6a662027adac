//! Randomized lighting: a distribution over lighting programmes, declared in a scenario's
//! `[lighting_random.NAME]` and named on its `lighting` axis like a preset. Each run draws
//! its own programme from a generator seeded by the run's pair seed, so the runs that
//! differ only in segmentation mode see the same light, and `dock --index` replays the
//! draw. The draw is recorded in `runs.jsonl` (`lighting_draw`): the concrete programme,
//! and a flat table of the drawn parameters that `trials --bin` groups results by.
//!
//! Every range is `[lo, hi]`, drawn uniformly, except the overall intensity, drawn
//! uniformly in its logarithm (light levels span decades, and a uniform draw would leave
//! dim light nearly unsampled). Counts are drawn uniformly over the integers in their
//! range. The defaults span what a robot meets indoors and out; each can be narrowed.

use super::lighting::{CloudSpec, FlasherSpec, Illuminant, LightingPreset, LightingSpec, ShadowSpec};
use super::rng::Rng;
use crate::config::Validator;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The most beacons or shadow edges one run may draw.
pub const MAX_COUNT: u32 = 8;

/// A distribution over lighting programmes (see the module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LightingDistribution {
    /// Illuminants to choose from, equally likely.
    pub illuminants: Vec<Illuminant>,
    /// Overall light multiplier (log-uniform; lab light is 1, noon 3).
    pub intensity: [f64; 2],
    /// Probability that the run is outdoors, with a sun; otherwise ambient light alone.
    pub outdoor_probability: f64,
    /// Ambient (room or sky) level.
    pub ambient: [f64; 2],
    /// Sun level, outdoors.
    pub sun: [f64; 2],
    /// Sun elevation, degrees (low values put a low sun behind the target or into the
    /// lens, depending on the azimuth).
    pub sun_elevation_deg: [f64; 2],
    /// Sun azimuth, degrees (0 = along +x, behind a robot approaching the dock).
    pub sun_azimuth_deg: [f64; 2],
    /// Glare multiplier on glossy targets' highlights (1 = painted or laminated).
    pub glare: [f64; 2],
    /// Number of rotating beacons.
    pub beacons: [u32; 2],
    /// Beacon colours (sRGB) to choose from, equally likely.
    pub beacon_colours: Vec<[u8; 3]>,
    /// Beacon peak irradiance at 1 m, relative to the ambient.
    pub beacon_power: [f64; 2],
    /// Beacon rotation period, s.
    pub beacon_period_s: [f64; 2],
    /// Beacon distance from the dock's origin, m (near: beside the target; far: across
    /// the room).
    pub beacon_distance_m: [f64; 2],
    /// Beacon bearing from the dock's axis (+x), degrees.
    pub beacon_bearing_deg: [f64; 2],
    /// Beacon height, m.
    pub beacon_height_m: [f64; 2],
    /// Number of shadow edges across the target.
    pub shadows: [u32; 2],
    /// Fraction of light a shadow removes.
    pub shadow_strength: [f64; 2],
    /// Penumbra width, m (a sharp edge from a near object, a soft one from a far one).
    pub shadow_softness_m: [f64; 2],
    /// Peak speed of a shadow edge across the target, m/s (0 = static; a person walking
    /// by casts one at about 1 m/s).
    pub shadow_speed_mps: [f64; 2],
    /// How far an edge travels either side of its rest position, m.
    pub shadow_travel_m: [f64; 2],
    /// Direction of the edge's normal in the target plane, degrees.
    pub shadow_angle_deg: [f64; 2],
    /// Probability of random cloud cover, outdoors.
    pub cloud_probability: f64,
    /// Mean time between cloud changes, s.
    pub cloud_interval_s: [f64; 2],
    /// Fraction of the sun a cloud removes.
    pub cloud_depth: [f64; 2],
}

impl Default for LightingDistribution {
    fn default() -> Self {
        Self {
            illuminants: vec![
                Illuminant::Daylight,
                Illuminant::Dusk,
                Illuminant::Tungsten,
                Illuminant::Fluorescent,
                Illuminant::Dawn,
            ],
            intensity: [0.2, 3.0],
            outdoor_probability: 0.5,
            ambient: [0.3, 1.0],
            sun: [0.3, 1.0],
            sun_elevation_deg: [3.0, 70.0],
            sun_azimuth_deg: [-180.0, 180.0],
            glare: [0.5, 3.0],
            beacons: [0, 3],
            beacon_colours: vec![
                [255, 120, 0],
                [255, 30, 0],
                [0, 60, 255],
                [255, 200, 0],
                [0, 200, 60],
                [255, 0, 200],
                [0, 220, 255],
            ],
            beacon_power: [0.5, 4.0],
            beacon_period_s: [0.5, 2.0],
            beacon_distance_m: [0.5, 3.0],
            beacon_bearing_deg: [-90.0, 90.0],
            beacon_height_m: [0.2, 1.5],
            shadows: [0, 2],
            shadow_strength: [0.2, 0.8],
            shadow_softness_m: [0.005, 0.05],
            shadow_speed_mps: [0.0, 1.0],
            shadow_travel_m: [0.02, 0.1],
            shadow_angle_deg: [0.0, 360.0],
            cloud_probability: 0.3,
            cloud_interval_s: [5.0, 30.0],
            cloud_depth: [0.3, 0.9],
        }
    }
}

/// One run's draw: the concrete programme and the drawn parameters, flat, for grouping.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LightingDraw {
    /// The programme drawn (every field set).
    pub spec: LightingSpec,
    /// Scalar summaries of the draw, by name (see [`LightingDraw::PARAMS`]).
    pub params: BTreeMap<String, f64>,
}

impl LightingDraw {
    /// The names in `params`: each drawn scalar, and for beacons and shadows the count and
    /// the strongest (largest power, nearest, fastest, deepest) of the run (0 when none).
    pub const PARAMS: [&'static str; 14] = [
        "intensity",
        "outdoor",
        "ambient",
        "sun",
        "sun_elevation_deg",
        "sun_azimuth_deg",
        "glare",
        "beacons",
        "beacon_power",
        "beacon_distance_m",
        "shadows",
        "shadow_speed_mps",
        "shadow_strength",
        "clouds",
    ];
}

impl LightingDistribution {
    /// Checks every range (ordered, finite, within its physical bounds), the counts and
    /// the lists, naming the field under `base` (e.g. `lighting_random.mixed`).
    pub(crate) fn validate_at(&self, base: &str, v: &mut Validator<'_>) {
        let p = |f: &str| format!("{base}.{f}");
        let mut range = |f: &str, r: [f64; 2], lo: f64, hi: f64| v.interval(&p(f), r, lo, hi);
        range("intensity", self.intensity, 1e-3, 100.0);
        range("ambient", self.ambient, 0.0, 100.0);
        range("sun", self.sun, 0.0, 100.0);
        range("sun_elevation_deg", self.sun_elevation_deg, -10.0, 90.0);
        range("sun_azimuth_deg", self.sun_azimuth_deg, -360.0, 360.0);
        range("glare", self.glare, 0.0, 100.0);
        range("beacon_power", self.beacon_power, 0.0, 1000.0);
        range("beacon_period_s", self.beacon_period_s, 1e-2, 3600.0);
        range("beacon_distance_m", self.beacon_distance_m, 0.0, 100.0);
        range("beacon_bearing_deg", self.beacon_bearing_deg, -360.0, 360.0);
        range("beacon_height_m", self.beacon_height_m, 0.0, 100.0);
        range("shadow_strength", self.shadow_strength, 0.0, 1.0);
        range("shadow_softness_m", self.shadow_softness_m, 0.0, 10.0);
        range("shadow_speed_mps", self.shadow_speed_mps, 0.0, 100.0);
        range("shadow_travel_m", self.shadow_travel_m, 0.0, 10.0);
        range("shadow_angle_deg", self.shadow_angle_deg, -360.0, 360.0);
        range("cloud_interval_s", self.cloud_interval_s, 1e-2, 1e6);
        range("cloud_depth", self.cloud_depth, 0.0, 1.0);
        for (f, c) in [("beacons", self.beacons), ("shadows", self.shadows)] {
            v.require(c[0] <= c[1] && c[1] <= MAX_COUNT, &p(f), || {
                format!("expected [low, high] with low ≤ high ≤ {MAX_COUNT}, got {c:?}")
            });
        }
        // Probabilities: 0 (never outdoors, never cloudy) is as valid as 1.
        v.range(&p("outdoor_probability"), self.outdoor_probability, 0.0, 1.0);
        v.range(&p("cloud_probability"), self.cloud_probability, 0.0, 1.0);
        v.require(!self.illuminants.is_empty(), &p("illuminants"), || {
            "expected at least one illuminant".into()
        });
        v.require(
            self.beacons[1] == 0 || !self.beacon_colours.is_empty(),
            &p("beacon_colours"),
            || "expected at least one colour (or `beacons = [0, 0]`)".into(),
        );
    }

    /// Draws one run's programme from `rng`.
    pub fn draw(&self, rng: &mut Rng) -> LightingDraw {
        let uni = |rng: &mut Rng, r: [f64; 2]| if r[0] < r[1] { rng.range(r[0], r[1]) } else { r[0] };
        let count = |rng: &mut Rng, c: [u32; 2]| {
            let span = c[1].saturating_sub(c[0]) + 1;
            c[0] + (rng.uniform() * span as f64).floor().min(span as f64 - 1.0) as u32
        };
        let pick = |rng: &mut Rng, n: usize| ((rng.uniform() * n as f64) as usize).min(n.saturating_sub(1));
        let illuminant = self.illuminants[pick(rng, self.illuminants.len())];
        let [lo, hi] = self.intensity.map(|x| x.max(1e-6).ln());
        let intensity = uni(rng, [lo, hi]).exp();
        let outdoor = rng.uniform() < self.outdoor_probability;
        let ambient = uni(rng, self.ambient);
        let sun = uni(rng, self.sun);
        let elevation = uni(rng, self.sun_elevation_deg);
        let azimuth = uni(rng, self.sun_azimuth_deg);
        let glare = uni(rng, self.glare);
        let n_beacons = count(rng, self.beacons);
        let flashers: Vec<FlasherSpec> = (0..n_beacons)
            .map(|_| {
                let d = uni(rng, self.beacon_distance_m);
                let b = uni(rng, self.beacon_bearing_deg).to_radians();
                FlasherSpec {
                    x_m: d * b.cos(),
                    y_m: d * b.sin(),
                    z_m: uni(rng, self.beacon_height_m),
                    period_s: uni(rng, self.beacon_period_s),
                    power: uni(rng, self.beacon_power),
                    rgb: self.beacon_colours[pick(rng, self.beacon_colours.len())],
                }
            })
            .collect();
        let n_shadows = count(rng, self.shadows);
        let mut fastest = 0.0f64;
        let shadows: Vec<ShadowSpec> = (0..n_shadows)
            .map(|_| {
                let strength = uni(rng, self.shadow_strength);
                let softness_m = uni(rng, self.shadow_softness_m);
                let speed = uni(rng, self.shadow_speed_mps);
                let travel = uni(rng, self.shadow_travel_m);
                let angle_deg = uni(rng, self.shadow_angle_deg);
                let offset_m = rng.range(-0.05, 0.05);
                fastest = fastest.max(speed);
                // A sinusoidal sweep of ±travel whose peak speed is `speed`: 2π·travel/T.
                let (amplitude_m, period_s) = if speed > 0.0 && travel > 0.0 {
                    (travel, std::f64::consts::TAU * travel / speed)
                } else {
                    (0.0, 1.0)
                };
                ShadowSpec {
                    strength,
                    angle_deg,
                    offset_m,
                    amplitude_m,
                    period_s,
                    softness_m,
                }
            })
            .collect();
        let cloudy = outdoor && rng.uniform() < self.cloud_probability;
        let clouds = CloudSpec {
            mean_interval_s: uni(rng, self.cloud_interval_s),
            depth: uni(rng, self.cloud_depth),
        };
        // In the order of [`LightingDraw::PARAMS`], which names them.
        let values = [
            intensity,
            f64::from(u8::from(outdoor)),
            ambient,
            if outdoor { sun } else { 0.0 },
            elevation,
            azimuth,
            glare,
            f64::from(n_beacons),
            flashers.iter().map(|f| f.power).fold(0.0, f64::max),
            flashers
                .iter()
                .map(|f| f.x_m.hypot(f.y_m))
                .reduce(f64::min)
                .unwrap_or(0.0),
            f64::from(n_shadows),
            fastest,
            shadows.iter().map(|s| s.strength).fold(0.0, f64::max),
            f64::from(u8::from(cloudy)),
        ];
        let params = LightingDraw::PARAMS
            .iter()
            .zip(values)
            .map(|(k, v)| (k.to_string(), v))
            .collect();
        let spec = LightingSpec {
            preset: Some(LightingPreset::Lab),
            intensity: Some(intensity),
            illuminant: Some(illuminant),
            ambient: Some(ambient),
            sun: Some(if outdoor { sun } else { 0.0 }),
            sun_elevation_deg: Some(elevation),
            sun_azimuth_deg: Some(azimuth),
            glare: Some(glare),
            change_per_hour: Some(0.0),
            session_s: Some(0.0),
            flashers: Some(flashers),
            shadows: Some(shadows),
            clouds: cloudy.then_some(clouds),
            self_shadow: Some(outdoor),
        };
        LightingDraw { spec, params }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn validate(d: &LightingDistribution) -> Vec<String> {
        let mut v = Validator::new("", None);
        d.validate_at("lighting_random.x", &mut v);
        v.into_problems()
            .into_iter()
            .map(|p| format!("{}: {}", p.path, p.message))
            .collect()
    }

    #[test]
    fn the_defaults_are_valid_and_bad_bounds_are_named() {
        assert!(validate(&LightingDistribution::default()).is_empty());
        // Probabilities of 0 and 1 are valid: an indoor-only or always-cloudy distribution.
        let edges = LightingDistribution {
            outdoor_probability: 0.0,
            cloud_probability: 1.0,
            ..LightingDistribution::default()
        };
        assert!(validate(&edges).is_empty(), "{:?}", validate(&edges));
        let bad = LightingDistribution {
            beacon_power: [-1.0, 2.0],
            intensity: [3.0, 1.0],
            beacon_colours: vec![],
            illuminants: vec![],
            shadows: [0, 20],
            cloud_probability: 1.5,
            glare: [f64::NAN, 1.0],
            ..LightingDistribution::default()
        };
        let problems = validate(&bad).join("\n");
        for field in [
            "lighting_random.x.beacon_power",
            "lighting_random.x.intensity",
            "lighting_random.x.beacon_colours",
            "lighting_random.x.illuminants",
            "lighting_random.x.shadows",
            "lighting_random.x.cloud_probability",
            "lighting_random.x.glare",
        ] {
            assert!(problems.contains(field), "{field} not named in:\n{problems}");
        }
        // No beacons asked for: no colour needed.
        let none = LightingDistribution {
            beacons: [0, 0],
            beacon_colours: vec![],
            ..LightingDistribution::default()
        };
        assert!(validate(&none).is_empty());
    }

    #[test]
    fn draws_stay_in_their_bounds_cover_them_and_repeat_with_the_seed() {
        let d = LightingDistribution::default();
        let draws: Vec<LightingDraw> = (0..2000).map(|i| d.draw(&mut Rng::new(i))).collect();
        for w in &draws {
            let s = &w.spec;
            let p = &w.params;
            assert!((0.2..=3.0).contains(&s.intensity.unwrap()));
            assert!((0.5..=3.0).contains(&s.glare.unwrap()));
            let fl = s.flashers.as_ref().unwrap();
            assert!(fl.len() <= 3 && p["beacons"] == fl.len() as f64);
            for f in fl {
                assert!((0.5..=4.0).contains(&f.power) && (0.5..=2.0).contains(&f.period_s));
                assert!((0.5 - 1e-9..=3.0 + 1e-9).contains(&f.x_m.hypot(f.y_m)));
                assert!(f.x_m >= -1e-9, "bearing within ±90°: in front of the dock");
                assert!(d.beacon_colours.contains(&f.rgb));
            }
            for sh in s.shadows.as_ref().unwrap() {
                assert!((0.2..=0.8).contains(&sh.strength));
                // The recorded peak speed is the sweep's: 2π·amplitude/period.
                let speed = std::f64::consts::TAU * sh.amplitude_m / sh.period_s;
                assert!(speed <= 1.0 + 1e-9);
            }
            assert_eq!(s.sun.unwrap() > 0.0, p["outdoor"] == 1.0);
            assert!(s.clouds.is_none() || p["outdoor"] == 1.0, "clouds only outdoors");
            assert_eq!(LightingDraw::PARAMS.len(), p.len());
        }
        // Every count and every illuminant comes up; intensity is log-uniform (about as
        // many draws below 0.77, the geometric mean, as above).
        for n in 0..=3 {
            assert!(draws.iter().any(|w| w.params["beacons"] == n as f64), "{n} beacons");
        }
        for i in &d.illuminants {
            assert!(draws.iter().any(|w| w.spec.illuminant == Some(*i)), "{i:?}");
        }
        let below = draws
            .iter()
            .filter(|w| w.params["intensity"] < (0.2f64 * 3.0).sqrt())
            .count();
        assert!((900..1100).contains(&below), "{below} of 2000 below the geometric mean");
        // Same seed, same draw.
        assert_eq!(d.draw(&mut Rng::new(7)), d.draw(&mut Rng::new(7)));
        assert_ne!(d.draw(&mut Rng::new(7)), d.draw(&mut Rng::new(8)));
    }

    #[test]
    fn a_drawn_programme_validates_and_resolves() {
        let d = LightingDistribution::default();
        for i in 0..200 {
            let w = d.draw(&mut Rng::new(i));
            let mut v = Validator::new("", None);
            w.spec.validate_at("drawn", &mut v);
            assert!(v.into_problems().is_empty(), "draw {i}");
            let l = w.spec.resolve();
            assert_eq!(l.flashers.len() as f64, w.params["beacons"]);
        }
    }
}
