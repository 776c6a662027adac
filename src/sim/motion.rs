//! Robot motion with motor limits, command latency and terrain-dependent slip.
//!
//! The drive executes the realised command after `latency_s`, with speeds ramped at the
//! motors' acceleration limits. The wheels then slip: forward speed is lost by
//! `slip_straight`, and yaw by `slip_turn` (skid steer loses much more yaw than speed, and
//! more the harder it turns), plus random slip noise. The encoders report the wheels'
//! travel before slip, so odometry drifts from the truth exactly as on a real robot.

use super::rng::Rng;
use crate::geometry::{Pose2, Twist, integrate_body_velocity};
use crate::kinematics::{DriveLimits, DriveModel};
use crate::robot::WheelTravel;
use crate::schemas::DriveCommand;
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;

/// Ground types with their slip.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Terrain {
    /// Smooth lab floor.
    LabFloor,
    /// Steel gate / ramp: tracks slip unevenly (seed 004 §V).
    Steel,
    /// Short grass.
    Grass,
    /// Loose gravel.
    Gravel,
    /// Loose sand or soil (Axel's loose terrain, seed 000 §V-A): the grousers sink in,
    /// so reeling drags the rover smoothly (no yaw disturbance under the tether's pull).
    Sand,
    /// Compacted mixed sand and gravel (Axel's firm terrain, seed 000 §V-A, §V-B): the
    /// large discrete grousers meet the ground alternately, so a rover dragged by the
    /// tether rocks side to side (yaw disturbance under the pull) and can leave the ±5°
    /// heading tolerance.
    CompactSandGravel,
    /// Uneven outdoor ground (RAPOSA outdoor).
    Uneven,
}

/// Slip parameters of a terrain.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SlipSpec {
    /// Fraction of forward speed lost.
    pub slip_straight: f64,
    /// Fraction of yaw rate lost when turning in place (skid steer); differential and
    /// Ackermann drives lose a fifth of this.
    pub slip_turn: f64,
    /// SD of random speed and yaw-rate slip, as a fraction of the commanded value.
    pub noise: f64,
    /// SD of random heading disturbance while moving, rad per metre (uneven ground).
    pub heading_noise: f64,
    /// SD of the yaw disturbance while the tether drags a rover on free wheels, rad per
    /// √metre dragged: grousers alternately catching firm ground (seed 000 §V-B). Only a
    /// leading-arm tether (Axel) drags the rover this way.
    #[serde(default)]
    pub reel_yaw_noise: f64,
}

impl Terrain {
    /// The name used in TOML and output.
    pub fn as_str(&self) -> &'static str {
        match self {
            Terrain::LabFloor => "lab_floor",
            Terrain::Steel => "steel",
            Terrain::Grass => "grass",
            Terrain::Gravel => "gravel",
            Terrain::Sand => "sand",
            Terrain::Uneven => "uneven",
            Terrain::CompactSandGravel => "compact_sand_gravel",
        }
    }

    /// Default slip of this terrain.
    pub fn slip(&self) -> SlipSpec {
        // Compact sand/gravel: firmer than loose sand (less slip), but the grousers rock
        // the rover while moving and, worse, while it is dragged in (our estimates; the
        // paper compares the two terrains only qualitatively).
        let (s, t, n, h, r) = match self {
            Terrain::LabFloor => (0.02, 0.25, 0.03, 0.01, 0.0),
            Terrain::Steel => (0.05, 0.40, 0.08, 0.03, 0.0),
            Terrain::Grass => (0.08, 0.45, 0.10, 0.05, 0.0),
            Terrain::Gravel => (0.10, 0.50, 0.15, 0.08, 0.0),
            Terrain::Sand => (0.20, 0.55, 0.20, 0.10, 0.0),
            Terrain::Uneven => (0.10, 0.50, 0.20, 0.15, 0.0),
            Terrain::CompactSandGravel => (0.08, 0.45, 0.12, 0.12, 0.08),
        };
        SlipSpec {
            slip_straight: s,
            slip_turn: t,
            noise: n,
            heading_noise: h,
            reel_yaw_noise: r,
        }
    }
}

/// Motion state of a simulated base.
#[derive(Debug, Clone, PartialEq)]
pub struct Motion {
    model: DriveModel,
    limits: DriveLimits,
    slip: SlipSpec,
    latency_s: f64,
    accel: f64,
    yaw_accel: f64,
    queue: VecDeque<(f64, DriveCommand)>,
    current: DriveCommand,
    v: f64,
    omega: f64,
    travel: WheelTravel,
    track: f64,
    /// What each side's motor delivers of its command, (left, right): (1, 1) healthy, 0
    /// a stalled track, 0.5 a motor at half speed (fault injection, [`super::faults`]).
    side_gain: (f64, f64),
}

impl Motion {
    /// A base with kinematics `model`, `limits`, terrain `slip`, command `latency_s` and
    /// acceleration limits (m/s², rad/s²).
    pub fn new(
        model: DriveModel,
        limits: DriveLimits,
        slip: SlipSpec,
        latency_s: f64,
        accel: f64,
        yaw_accel: f64,
    ) -> Self {
        let track = match model {
            DriveModel::Differential(d) => d.track,
            DriveModel::SkidSteer(s) | DriveModel::TurnOrDrive(s) => s.d_min(),
            DriveModel::DoubleAckermann(a) => a.track,
        };
        Self {
            model,
            limits,
            slip,
            latency_s,
            accel,
            yaw_accel,
            queue: VecDeque::new(),
            current: DriveCommand::Stop,
            v: 0.0,
            omega: 0.0,
            travel: WheelTravel::default(),
            track,
            side_gain: (1.0, 1.0),
        }
    }

    /// The terrain's slip this base moves with (the tether's drag reads its
    /// `reel_yaw_noise`).
    pub fn slip_spec(&self) -> &SlipSpec {
        &self.slip
    }

    /// Sets what each side's motor delivers of its command (see `side_gain`).
    pub fn set_side_gain(&mut self, left: f64, right: f64) {
        self.side_gain = (left, right);
    }

    /// Queues a command issued at `t` that reaches the motors `latency_s` later (a
    /// latency spike), never before a command queued earlier: the bus delivers in order.
    pub fn command_delayed(&mut self, t: f64, cmd: DriveCommand, latency_s: f64) {
        let due = self.queue.back().map_or(t + latency_s, |(d, _)| d.max(t + latency_s));
        self.queue.push_back((due, self.model.realise(&cmd, &self.limits)));
    }

    /// Queues a command issued at time `t`; it takes effect `latency_s` later.
    pub fn command(&mut self, t: f64, cmd: DriveCommand) {
        self.queue
            .push_back((t + self.latency_s, self.model.realise(&cmd, &self.limits)));
    }

    /// Cumulative wheel travel as the encoders see it (before slip).
    pub fn encoders(&self) -> WheelTravel {
        self.travel
    }

    /// The wheels' current twist (before slip).
    pub fn wheel_twist(&self) -> Twist {
        Twist::new(self.v, self.omega)
    }

    /// Stops at once (emergency stop on contact).
    pub fn halt(&mut self) {
        self.queue.clear();
        self.current = DriveCommand::Stop;
        self.v = 0.0;
        self.omega = 0.0;
    }

    /// Advances from `t` by `dt`; returns the new true pose.
    pub fn step(&mut self, t: f64, dt: f64, pose: &Pose2, rng: &mut Rng) -> Pose2 {
        while self.queue.front().is_some_and(|(at, _)| *at <= t + 1e-12) {
            self.current = self.queue.pop_front().map(|(_, c)| c).unwrap_or(DriveCommand::Stop);
        }
        let target = self.current.to_twist();
        let ramp = |cur: f64, want: f64, rate: f64| cur + (want - cur).clamp(-rate * dt, rate * dt);
        self.v = ramp(self.v, target.v, self.accel);
        self.omega = ramp(self.omega, target.omega, self.yaw_accel);
        // What the motors deliver: all of it when healthy (kept apart so healthy runs stay
        // bit for bit what they were), less on a failing side.
        let (v, omega) = if self.side_gain == (1.0, 1.0) {
            (self.v, self.omega)
        } else {
            let half = self.omega * self.track / 2.0;
            let (l, r) = ((self.v - half) * self.side_gain.0, (self.v + half) * self.side_gain.1);
            ((l + r) / 2.0, (r - l) / self.track)
        };
        // Encoders: wheel surface travel of the delivered motion.
        let half = omega * self.track / 2.0;
        self.travel.left += (v - half) * dt;
        self.travel.right += (v + half) * dt;
        // Slip.
        let skid = matches!(self.model, DriveModel::SkidSteer(_) | DriveModel::TurnOrDrive(_));
        let turn_share = (omega.abs() * self.track / 2.0) / (v.abs() + omega.abs() * self.track / 2.0 + 1e-9);
        let yaw_loss = self.slip.slip_turn * if skid { 0.5 + 0.5 * turn_share } else { 0.2 };
        let n = self.slip.noise;
        let v_true = v * (1.0 - self.slip.slip_straight) * (1.0 + n * rng.normal());
        let w_true = omega * (1.0 - yaw_loss) * (1.0 + n * rng.normal())
            + self.slip.heading_noise * v.abs().sqrt() * rng.normal() * dt.sqrt();
        let lateral = if skid { 0.02 * v.abs() * rng.normal() } else { 0.0 };
        integrate_body_velocity(pose, v_true, lateral, w_true, dt)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::{Differential, SkidSteer};

    fn lim() -> DriveLimits {
        DriveLimits {
            max_speed: 0.5,
            max_turn_rate: 1.0,
        }
    }

    fn no_slip() -> SlipSpec {
        SlipSpec {
            slip_straight: 0.0,
            slip_turn: 0.0,
            noise: 0.0,
            heading_noise: 0.0,
            reel_yaw_noise: 0.0,
        }
    }

    #[test]
    fn names_match_the_toml_spelling() {
        use Terrain::*;
        for t in [LabFloor, Steel, Grass, Gravel, Sand, Uneven, CompactSandGravel] {
            assert_eq!(serde_json::to_value(t).unwrap(), t.as_str());
        }
        for m in [
            crate::profile::SegmentationMode::Adaptive,
            crate::profile::SegmentationMode::Static,
            crate::profile::SegmentationMode::Fixed,
        ] {
            assert_eq!(serde_json::to_value(m).unwrap(), m.as_str());
        }
    }

    #[test]
    fn latency_and_ramp() {
        let mut m = Motion::new(
            DriveModel::Differential(Differential { track: 0.3 }),
            lim(),
            no_slip(),
            0.2,
            1.0,
            5.0,
        );
        let mut rng = Rng::new(1);
        let mut p = Pose2::default();
        m.command(0.0, DriveCommand::Straight { v: 0.2 });
        for k in 0..10 {
            p = m.step(k as f64 * 0.01, 0.01, &p, &mut rng);
        }
        assert_eq!(p.x, 0.0, "nothing moves before the latency");
        for k in 10..100 {
            p = m.step(k as f64 * 0.01, 0.01, &p, &mut rng);
        }
        // 0.2 s ramp at 1 m/s² to 0.2 m/s, then 0.6 s at 0.2: 0.02 + 0.12 − one step's lag.
        assert!((p.x - 0.14).abs() < 0.005, "{p:?}");
        assert!((m.encoders().left - p.x).abs() < 1e-9);
    }

    #[test]
    fn skid_steer_turning_slips_more_than_driving() {
        let slip = Terrain::Steel.slip();
        let model = DriveModel::SkidSteer(SkidSteer::new(0.3, 0.4, 0.6).unwrap());
        let run = |cmd| {
            let mut m = Motion::new(
                model,
                lim(),
                SlipSpec {
                    noise: 0.0,
                    heading_noise: 0.0,
                    ..slip
                },
                0.0,
                100.0,
                100.0,
            );
            m.command(0.0, cmd);
            let mut p = Pose2::default();
            for k in 0..100 {
                p = m.step(k as f64 * 0.01, 0.01, &p, &mut Rng::new(0));
            }
            p
        };
        let straight = run(DriveCommand::Straight { v: 0.2 });
        let spin = run(DriveCommand::Turn { omega: 0.5 });
        assert!((straight.x - 0.2 * (1.0 - slip.slip_straight)).abs() < 0.01);
        // Turning in place loses the full slip_turn.
        assert!((spin.theta - 0.5 * (1.0 - slip.slip_turn)).abs() < 0.01, "{spin:?}");
    }
}
