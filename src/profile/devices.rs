//! `[[sensors]]` and `[[actuators]]`: every device beyond the cameras, the drive and
//! odometry, in one model.
//!
//! Each entry names a device and its *kind*: the kind says what the readings or commands
//! mean and which `params` it takes. The crate's own devices are kinds like any user's
//! ([`crate::schemas::devices`]): `tether` (the reel: a sensor for its length and current
//! and an actuator for its rate; needs a `[tether]` table), `dock_contact` (the pressure
//! plates), `arm`, `lights`, `guides`, `posture`, and the [`RANGE_KIND`] range finder. A
//! robot has the devices its profile declares, no more: the simulator builds those, the
//! loop reads and commands those, and a command for a kind the profile does not declare
//! goes nowhere. Kinds are open: a user's crate registers its own with
//! [`Registry::register_sensor_kind`](crate::behaviors::registry::Registry::register_sensor_kind)
//! (or `register_actuator_kind`), so a new device needs no change to marsupial. Readings
//! reach the schemas as [`Inputs::sensor`](crate::schemas::Inputs::sensor) (this list's
//! order) or typed ([`Inputs::reading`](crate::schemas::Inputs::reading)); commands leave
//! through [`Auxiliary::set`](crate::schemas::Auxiliary::set), to every actuator of their
//! kind.
//!
//! ```toml
//! [[sensors]]
//! name = "plates"
//! kind = "dock_contact"
//! stale_s = 0.5                  # required: safe stop when older (omit: optional)
//!
//! [[sensors]]
//! name = "bumper_ranges"
//! kind = "range"
//! params = { beams = 9, fov_deg = 120.0, max_range_m = 1.5 }
//!
//! [[actuators]]
//! name = "hips"
//! kind = "posture"
//! ```

use super::Profile;
use crate::config::Validator;
use serde::{Deserialize, Serialize};

/// The range-finder kind the crate ships: a planar fan of beams, each reading the distance
/// to the nearest obstacle along it (m), `max_range_m` when nothing is in range.
pub const RANGE_KIND: &str = "range";

pub use crate::schemas::devices::{BUILTIN_ACTUATOR_KINDS, BUILTIN_SENSOR_KINDS, INLINE_DEVICES, TETHER_KIND};

/// Checks a device kind's `params` table; the error names the field.
pub type KindCheckFn = fn(&toml::Table) -> Result<(), String>;

/// A kind that takes no params.
fn no_params(params: &toml::Table) -> Result<(), String> {
    match params.keys().next() {
        None => Ok(()),
        Some(k) => Err(format!("params: unknown field `{k}`: this kind takes no params")),
    }
}

/// The sensor kinds the crate ships, with their params checks: the [`RANGE_KIND`] range
/// finder and [`BUILTIN_SENSOR_KINDS`]. Every registry starts with them.
pub fn builtin_sensor_kinds() -> impl Iterator<Item = (&'static str, KindCheckFn)> {
    let range: KindCheckFn = |p| RangeParams::from_table(p).map(|_| ());
    std::iter::once((RANGE_KIND, range)).chain(BUILTIN_SENSOR_KINDS.map(|k| (k, no_params as KindCheckFn)))
}

/// The actuator kinds the crate ships ([`BUILTIN_ACTUATOR_KINDS`]), with their params
/// checks. Every registry starts with them.
pub fn builtin_actuator_kinds() -> impl Iterator<Item = (&'static str, KindCheckFn)> {
    BUILTIN_ACTUATOR_KINDS
        .into_iter()
        .map(|k| (k, no_params as KindCheckFn))
}

/// One `[[sensors]]` entry.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorSpec {
    /// Name, unique among the sensors (logs, errors).
    pub name: String,
    /// What it measures (a registered kind, e.g. [`RANGE_KIND`]).
    pub kind: String,
    /// Staleness limit, s: when set the sensor is required, and the loop stops the robot
    /// safely while its last reading is older, missing or not finite.
    #[serde(default)]
    pub stale_s: Option<f64>,
    /// The kind's own settings, checked by the kind when the behavior is built.
    #[serde(default)]
    pub params: toml::Table,
}

/// One `[[actuators]]` entry.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ActuatorSpec {
    /// Name, unique among the actuators.
    pub name: String,
    /// What it does (a registered kind).
    pub kind: String,
    /// The kind's own settings.
    #[serde(default)]
    pub params: toml::Table,
}

/// The built-in range finder's `params`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RangeParams {
    /// Number of beams, spread evenly over `fov_deg` (one beam points along `yaw_deg`).
    pub beams: usize,
    /// Fan width, degrees.
    pub fov_deg: f64,
    /// Longest range, m: beams that hit nothing read this.
    pub max_range_m: f64,
    /// Mount: forward of the body centre, m.
    pub x_m: f64,
    /// Mount: left of the body centre, m.
    pub y_m: f64,
    /// Mount: direction of the fan's centre beam, degrees CCW from the body's forward axis
    /// (180: looks backwards).
    pub yaw_deg: f64,
    /// 1-σ range noise, m (the simulator adds it; for a real device it documents it).
    pub noise_m: f64,
}

impl Default for RangeParams {
    fn default() -> Self {
        Self {
            beams: 9,
            fov_deg: 120.0,
            max_range_m: 1.5,
            x_m: 0.0,
            y_m: 0.0,
            yaw_deg: 0.0,
            noise_m: 0.01,
        }
    }
}

impl RangeParams {
    /// Reads and checks a `[[sensors]]` entry's params.
    ///
    /// # Errors
    /// A message naming the field.
    pub fn from_table(params: &toml::Table) -> Result<Self, String> {
        let p: Self = toml::Value::Table(params.clone())
            .try_into()
            .map_err(|e: toml::de::Error| format!("params: {}", e.message().trim()))?;
        if p.beams == 0 || p.beams > 360 {
            return Err(format!("params.beams: expected 1 to 360 beams, got {}", p.beams));
        }
        if !(p.fov_deg > 0.0 && p.fov_deg <= 360.0) {
            return Err(format!("params.fov_deg: expected (0, 360], got {}", p.fov_deg));
        }
        if !(p.noise_m >= 0.0 && p.noise_m.is_finite()) {
            return Err(format!(
                "params.noise_m: expected a non-negative distance, got {}",
                p.noise_m
            ));
        }
        if !(p.max_range_m > 0.0 && p.max_range_m.is_finite()) {
            return Err(format!(
                "params.max_range_m: expected a positive distance, got {}",
                p.max_range_m
            ));
        }
        Ok(p)
    }

    /// Direction of beam `i` in the body frame, rad.
    pub fn beam_angle(&self, i: usize) -> f64 {
        let yaw = self.yaw_deg.to_radians();
        if self.beams == 1 {
            return yaw;
        }
        let fov = self.fov_deg.to_radians();
        // A full circle does not repeat its first beam at the end.
        let span = if self.fov_deg >= 360.0 {
            fov * (self.beams - 1) as f64 / self.beams as f64
        } else {
            fov
        };
        yaw - span / 2.0 + span * i as f64 / (self.beams - 1) as f64
    }
}

/// Checks names (non-empty, unique), staleness limits (positive, at least one tick), the
/// actuator count, the built-in kinds' params (none) and that a `tether` device has the
/// `[tether]` table it is simulated and planned with.
pub(super) fn validate_devices(p: &Profile, v: &mut Validator<'_>) {
    let tick = 1.0 / p.loop_.rate_hz;
    let mut seen: Vec<&str> = Vec::new();
    for (i, s) in p.sensors.iter().enumerate() {
        let at = format!("sensors[{i}]");
        check_name(&s.name, &s.kind, &at, &mut seen, v);
        check_builtin(&s.kind, &s.params, &BUILTIN_SENSOR_KINDS, &at, p, v);
        if let Some(t) = s.stale_s {
            v.positive(&format!("{at}.stale_s"), t);
            if t.is_finite() && t > 0.0 && tick.is_finite() && t < tick {
                v.problem(
                    &format!("{at}.stale_s"),
                    format!("expected a limit of at least one tick (1/rate_hz = {tick:.4} s), got {t}"),
                );
            }
        }
    }
    seen.clear();
    for (i, a) in p.actuators.iter().enumerate() {
        let at = format!("actuators[{i}]");
        check_name(&a.name, &a.kind, &at, &mut seen, v);
        check_builtin(&a.kind, &a.params, &BUILTIN_ACTUATOR_KINDS, &at, p, v);
    }
    v.require(p.actuators.len() <= INLINE_DEVICES, "actuators", || {
        format!(
            "expected at most {INLINE_DEVICES} [[actuators]] (one tick's output holds that many commands), got {}",
            p.actuators.len()
        )
    });
}

/// A built-in kind takes no params, and the tether needs its table.
fn check_builtin(kind: &str, params: &toml::Table, builtin: &[&str], at: &str, p: &Profile, v: &mut Validator<'_>) {
    if !builtin.contains(&kind) {
        return;
    }
    if let Some(k) = params.keys().next() {
        v.problem(
            &format!("{at}.params"),
            format!("unknown field `{k}`: kind `{kind}` takes no params"),
        );
    }
    if kind == TETHER_KIND && p.tether.is_none() {
        v.problem(
            &format!("{at}.kind"),
            "a `tether` device needs the profile's [tether] table (its length, reel rate and geometry)",
        );
    }
}

fn check_name<'a>(name: &'a str, kind: &str, at: &str, seen: &mut Vec<&'a str>, v: &mut Validator<'_>) {
    v.require(!name.trim().is_empty(), &format!("{at}.name"), || {
        "expected a non-empty name".into()
    });
    v.require(!kind.trim().is_empty(), &format!("{at}.kind"), || {
        "expected a non-empty kind".into()
    });
    if seen.contains(&name) {
        v.problem(&format!("{at}.name"), format!("`{name}` is declared twice"));
    }
    seen.push(name);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn beams_spread_over_the_fan_and_a_full_circle_does_not_repeat() {
        let p = RangeParams {
            beams: 3,
            fov_deg: 90.0,
            ..RangeParams::default()
        };
        let a: Vec<f64> = (0..3).map(|i| p.beam_angle(i).to_degrees()).collect();
        assert!((a[0] + 45.0).abs() < 1e-9 && a[1].abs() < 1e-9 && (a[2] - 45.0).abs() < 1e-9);
        let ring = RangeParams {
            beams: 4,
            fov_deg: 360.0,
            ..RangeParams::default()
        };
        let last = ring.beam_angle(3).to_degrees() - ring.beam_angle(0).to_degrees();
        assert!((last - 270.0).abs() < 1e-9);
    }

    #[test]
    fn a_bad_builtin_device_is_an_error_at_its_line() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/bujold.toml");
        let text = std::fs::read_to_string(&path).unwrap()
            + "\n[[sensors]]\nname = \"reel\"\nkind = \"tether\"\nparams = { gain = 1.0 }\n";
        let e = Profile::parse(&text, &path).unwrap_err();
        let problems = e.problems();
        let at = |field: &str| {
            problems
                .iter()
                .find(|p| p.path == field)
                .unwrap_or_else(|| panic!("{e}"))
        };
        let kind_line = text.lines().position(|l| l == "kind = \"tether\"").unwrap() + 1;
        assert_eq!(at("sensors[1].kind").line, Some(kind_line), "{e}");
        assert!(at("sensors[1].kind").message.contains("[tether]"), "{e}");
        assert!(at("sensors[1].params").message.contains("`gain`"), "{e}");
    }

    #[test]
    fn bad_range_params_name_the_field() {
        let t: toml::Table = toml::from_str("beams = 0").unwrap();
        assert!(RangeParams::from_table(&t).unwrap_err().contains("params.beams"));
        let t: toml::Table = toml::from_str("max_range = 2.0").unwrap();
        assert!(RangeParams::from_table(&t).unwrap_err().contains("max_range"));
    }
}
