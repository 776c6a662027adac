//! `[drive]`: kinematics and limits of the base.

use crate::config::{Validate, Validator};
use crate::kinematics::{Differential, DoubleAckermann, DriveLimits, DriveModel, SkidSteer};
use serde::{Deserialize, Serialize};

/// Kind of base.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DriveKind {
    /// Ideal differential drive (Axel's two wheels).
    Differential,
    /// Skid steer with an effective track (RAPOSA's tracks).
    SkidSteer,
    /// Restricted skid steer: turn in place OR drive straight (Bujold).
    TurnOrDrive,
    /// Four-wheel double-Ackermann steering (AutoKrawler).
    DoubleAckermann,
}

/// The `[drive]` table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DriveSpec {
    /// Kind of base.
    pub kind: DriveKind,
    /// Physical track width (distance between left and right contact lines), m.
    pub track_m: f64,
    /// Largest forward speed, m/s.
    pub max_speed_mps: f64,
    /// Largest yaw rate, degrees per second.
    pub max_turn_rate_dps: f64,
    /// Wheel radius, m (optional; used by encoders and the AutoKrawler wheel tracker).
    #[serde(default)]
    pub wheel_radius_m: Option<f64>,
    /// Skid steer: smallest effective track, m.
    #[serde(default)]
    pub d_min_m: Option<f64>,
    /// Skid steer: largest effective track, m.
    #[serde(default)]
    pub d_max_m: Option<f64>,
    /// Skid steer: calibrated effective track used by odometry, m.
    #[serde(default)]
    pub effective_track_m: Option<f64>,
    /// Double-Ackermann: distance between the axles, m.
    #[serde(default)]
    pub wheelbase_m: Option<f64>,
    /// Double-Ackermann: steering limit per axle, degrees.
    #[serde(default)]
    pub max_steer_deg: Option<f64>,
}

impl DriveSpec {
    /// Speed limits in SI units.
    pub fn limits(&self) -> DriveLimits {
        DriveLimits {
            max_speed: self.max_speed_mps,
            max_turn_rate: self.max_turn_rate_dps.to_radians(),
        }
    }

    /// The kinematic model. Call only on a validated spec; missing optional values fall
    /// back to the physical track so this never panics.
    pub fn model(&self) -> DriveModel {
        let skid = || {
            let d_min = self.d_min_m.unwrap_or(self.track_m);
            let d_max = self.d_max_m.unwrap_or(d_min);
            let eff = self.effective_track_m.unwrap_or(d_min);
            SkidSteer::clamped(d_min, eff, d_max)
        };
        match self.kind {
            DriveKind::Differential => DriveModel::Differential(Differential { track: self.track_m }),
            DriveKind::SkidSteer => DriveModel::SkidSteer(skid()),
            DriveKind::TurnOrDrive => DriveModel::TurnOrDrive(skid()),
            DriveKind::DoubleAckermann => DriveModel::DoubleAckermann(DoubleAckermann {
                wheelbase: self.wheelbase_m.unwrap_or(1.0),
                track: self.track_m,
                max_steer: self.max_steer_deg.unwrap_or(30.0).to_radians(),
            }),
        }
    }
}

impl Validate for DriveSpec {
    fn validate(&self, v: &mut Validator<'_>) {
        v.positive("drive.track_m", self.track_m);
        v.positive("drive.max_speed_mps", self.max_speed_mps);
        v.positive("drive.max_turn_rate_dps", self.max_turn_rate_dps);
        if let Some(r) = self.wheel_radius_m {
            v.positive("drive.wheel_radius_m", r);
        }
        match self.kind {
            DriveKind::SkidSteer | DriveKind::TurnOrDrive => {
                let mut vals = [0.0; 3];
                for (i, (name, val)) in [
                    ("d_min_m", self.d_min_m),
                    ("effective_track_m", self.effective_track_m),
                    ("d_max_m", self.d_max_m),
                ]
                .into_iter()
                .enumerate()
                {
                    let path = format!("drive.{name}");
                    match val {
                        None => v.problem("drive", format!("missing field `{name}`: a skid-steer drive needs d_min_m, effective_track_m and d_max_m")),
                        Some(x) => {
                            v.positive(&path, x);
                            vals[i] = x;
                        }
                    }
                }
                let [d_min, eff, d_max] = vals;
                if d_min > 0.0 && d_max > 0.0 && d_min > d_max {
                    v.problem(
                        "drive.d_min_m",
                        format!("expected d_min_m ≤ d_max_m, got {d_min} > {d_max}"),
                    );
                } else if eff > 0.0 && d_min > 0.0 && d_max > 0.0 && !(d_min <= eff && eff <= d_max) {
                    v.problem(
                        "drive.effective_track_m",
                        format!("expected d_min_m ≤ effective_track_m ≤ d_max_m, got {d_min} ≤ {eff} ≤ {d_max}"),
                    );
                }
            }
            DriveKind::DoubleAckermann => {
                match self.wheelbase_m {
                    None => v.problem(
                        "drive",
                        "missing field `wheelbase_m`: a double-Ackermann drive needs it",
                    ),
                    Some(w) => v.positive("drive.wheelbase_m", w),
                }
                match self.max_steer_deg {
                    None => v.problem(
                        "drive",
                        "missing field `max_steer_deg`: a double-Ackermann drive needs it",
                    ),
                    Some(s) => v.require(s.is_finite() && s > 0.0 && s < 90.0, "drive.max_steer_deg", || {
                        format!("expected a steering limit in (0, 90) degrees, got {s}")
                    }),
                }
            }
            DriveKind::Differential => {}
        }
    }
}
