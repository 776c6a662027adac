//! What Axel's schemas share: the circle-fiducial perceptual schema (`stereo.rs`: both cameras'
//! detectors, the module's model, the stereo rig), this tick's odometry and reel reading,
//! the planning geometry taken from the profile, the retry counter and the arc counter.
//!
//! Perception is sense-plan-act as in the paper (seed 000 §II): it runs only while a
//! schema asks to look ([`Memory::looking`]), which the schemas do only with the rover
//! stopped and settled, so a pose is never measured from a moving rover's frames. Each
//! look yields a [`Sighting`]: the rover's pose in the module frame with the pose's
//! quality figures. A schema trusts a sighting only by its quality ([`Trust`]); both are
//! in `sighting.rs`, re-exported here.

pub use super::geometry::Geometry;
use super::legs::Motion;
use super::look::Looks;
pub use super::sighting::{Sighting, Trust};
use super::stereo::Perception;
use super::tuning::AxelRobot;
use crate::behaviors::common::retries::Retries;
use crate::behaviors::composed::SharedMemory;
use crate::geometry::Pose2;
use crate::kinematics::two_arc::PlanParams;
use crate::profile::Profile;
use crate::schemas::{
    AgentStats, DriveCommand, FailureReason, Feedback, Inputs, Mission, MissionError, MotorOutput, Outcome, Step,
    TetherCommand, TetherReading,
};
use serde::Deserialize;

/// The reel's current above which a driven rover's tether counts as taut, A: the top of
/// the 0.5–1.0 A the paper's reel drew in vision-guided docking (seed 000 §V-C).
pub const TAUT_CURRENT_A: f64 = 1.0;

/// The reel's current below which a standing rover's tether counts as slack, A: a
/// winding reel draws about 0.4 A with no load, so this is a pull of a few newtons.
/// Lower than [`TAUT_CURRENT_A`] because the take-up ([`Memory::take_up`]) winds at the
/// reel's top rate and reads the current once a tick: a tick's overshoot then stays
/// within the 0.5–1.0 A the paper's reel drew (seed 000 §V-C).
pub const SLACK_CURRENT_A: f64 = 0.7;

/// Where the planner must keep the module (node params `view`, ours): the paper asked
/// only that the module stay in the field of view "as much as possible" (§IV-A-1).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ViewLimits {
    /// The module's centre stays this far inside the cameras' half field of view,
    /// degrees: the off-centre camera of the 35 cm pair, the module's own width and the
    /// fish-eye's compressed edge lose marks before the centre leaves the view.
    pub margin_deg: f64,
    /// No plan drives farther from the module than this, m: the marks' detection range
    /// (a plan that reversed out of it lost the module, README).
    pub range_m: f64,
}

impl Default for ViewLimits {
    fn default() -> Self {
        Self {
            margin_deg: 5.0,
            range_m: 4.0,
        }
    }
}

impl ViewLimits {
    /// `base` with these limits.
    pub fn plan_params(&self, base: &PlanParams) -> PlanParams {
        PlanParams {
            view_margin_rad: self.margin_deg.to_radians(),
            max_range_m: self.range_m,
            ..*base
        }
    }
}

/// The module-frame pose now, from the module-frame pose `at` measured when odometry read
/// `odo_then`, and odometry's `odo_now`: the motion since, in the rover's frame then,
/// applied to the fix.
pub fn dead_reckon(at: &Pose2, odo_then: &Pose2, odo_now: &Pose2) -> Pose2 {
    at.compose(&odo_then.relative(odo_now))
}

/// Axel's shared memory (see the module docs).
pub struct Memory {
    perception: Perception,
    /// The planning geometry.
    pub geometry: Geometry,
    /// A schema asks perception to run on the next ticks' frames (set while stopped).
    pub looking: bool,
    /// The latest sighting (kept until the next look replaces it).
    pub sighting: Option<Sighting>,
    /// Loop time of this tick, s.
    pub now: f64,
    /// Loop time of this docking's first tick, s (feedback's elapsed time counts from it).
    pub run_start: Option<f64>,
    /// Odometry pose of this tick.
    pub odo: Pose2,
    /// The reel's reading this tick.
    pub reel: Option<TetherReading>,
    /// Realignments (reverse and retry) this docking, of `behavior.max_retries`.
    pub retries: Retries,
    /// Arcs driven this docking.
    pub arcs: u32,
    /// The sign of the acquisition's turn (+1 counter-clockwise): toward the side the
    /// module was last seen on.
    pub search_sign: f64,
    /// A trusted pose was seen this docking.
    pub seen: bool,
    /// The pose the alignment committed to mating from (the penultimate look).
    pub commit: Option<Pose2>,
    /// The last trusted sighting's module-frame pose and the odometry pose at it: where
    /// the module is believed to be once it is lost ([`Memory::reckoned`]).
    pub last_fix: Option<(Pose2, Pose2)>,
    /// What the running phase's looks have counted.
    pub looks: Looks,
    /// The motion the last look decided, until `axel.step` takes it.
    pub step: Option<Motion>,
}

impl Memory {
    /// The memory for an Axel profile.
    ///
    /// # Errors
    /// A message when the profile lacks the cameras, fiducial, dock, tether
    /// or two-arc gains.
    pub fn new(profile: &Profile, robot: &AxelRobot) -> Result<Self, String> {
        let fov = Geometry::camera_half_fov(profile).ok_or("Axel's behavior needs a camera")?;
        Ok(Self {
            perception: Perception::from_profile(profile)?,
            geometry: Geometry::from_profile(profile, fov, &robot.two_arc)?,
            looking: false,
            sighting: None,
            now: 0.0,
            run_start: None,
            odo: Pose2::default(),
            reel: None,
            retries: Retries::new(profile.behavior.max_retries),
            arcs: 0,
            search_sign: 1.0,
            seen: false,
            commit: None,
            last_fix: None,
            looks: Looks::new(0.0, f64::INFINITY),
            step: None,
        })
    }

    /// A stopped base with its wheels braked, the reel taking up slack
    /// ([`Memory::take_up`]), feedback `phase`.
    pub fn hold(&self, phase: &'static str) -> Step {
        let out = MotorOutput::stop().with_aux(crate::schemas::Auxiliary::with(TetherCommand {
            reel_rate: self.take_up(),
            free_wheel: false,
        }));
        Step::running(out, self.feedback(phase))
    }

    /// The reel rate that takes up slack while the base stands or turns in place, m/s:
    /// the top rate while the reel's current says the tether is slack
    /// ([`SLACK_CURRENT_A`]), then none. A turn in place swings the arm's tip about the
    /// axle, and an arc that slipped ends short of where the reel paid out for; with no
    /// tension sensor and no pose during a search, the current is what tells slack from
    /// taut (a slack tether loads the reel with its idle current alone). The braked wheels
    /// hold the rover against the pull.
    pub fn take_up(&self) -> f64 {
        if self.reel.is_none() {
            return 0.0;
        }
        self.wind_below(self.geometry.max_reel_rate, SLACK_CURRENT_A)
    }

    /// The current-limited reel, the one rule both [`Memory::drive`] and
    /// [`Memory::take_up`] apply: `rate` (m/s, positive in), but no winding in once the
    /// reel's current reaches `limit_a` (paying out is never held back).
    fn wind_below(&self, rate: f64, limit_a: f64) -> f64 {
        if self.reel.is_some_and(|r| r.motor_current_a >= limit_a) {
            rate.min(0.0)
        } else {
            rate
        }
    }

    /// Driving `drive` while reeling at `reel_rate` (m/s, positive in), wheels driven.
    /// The planned rate is the linear approximation's; when the wheels slip the tether
    /// shortens less than planned, so while the reel's current says the tether is taut
    /// ([`TAUT_CURRENT_A`]) it does not reel in (a current-limited reel: no tension sensor).
    pub fn drive(&self, drive: DriveCommand, reel_rate: f64, phase: &'static str) -> Step {
        let rate = self.wind_below(reel_rate, TAUT_CURRENT_A);
        let out = MotorOutput::drive(drive).with_aux(crate::schemas::Auxiliary::with(TetherCommand {
            reel_rate: rate.clamp(-self.geometry.max_reel_rate, self.geometry.max_reel_rate),
            free_wheel: false,
        }));
        Step::running(out, self.feedback(phase))
    }

    /// The base stopped with its wheels in free rotation, the reel winding in at its top
    /// rate (pure reeling), feedback `phase`.
    pub fn free_reel(&self, phase: &'static str) -> Step {
        let out = MotorOutput::stop().with_aux(crate::schemas::Auxiliary::with(TetherCommand {
            reel_rate: self.geometry.max_reel_rate,
            free_wheel: true,
        }));
        Step::running(out, self.feedback(phase))
    }

    /// Records a trusted sighting as the last fix, with this tick's odometry.
    pub fn fix(&mut self, s: &Sighting) {
        self.seen = true;
        self.last_fix = Some((s.pose, self.odo));
    }

    /// The rover's module-frame pose now, dead-reckoned from the last fix by odometry;
    /// `None` before any fix this docking.
    pub fn reckoned(&self) -> Option<Pose2> {
        let (at, odo) = self.last_fix?;
        Some(dead_reckon(&at, &odo, &self.odo))
    }

    /// The docking's end when the running phase's clock has run past its limit
    /// ([`Looks::limit`]): `target_lost` when a trusted pose was seen this docking,
    /// `target_never_detected` otherwise, stopped; `None` while time is left.
    pub fn gave_up(&self, phase: &'static str) -> Option<Step> {
        let overran = self.now - self.looks.began > self.looks.limit;
        overran.then(|| {
            let why = if self.seen {
                FailureReason::TargetLost
            } else {
                FailureReason::TargetNeverDetected
            };
            self.hold(phase).finishing(Outcome::Failed(why))
        })
    }

    /// Feedback for `phase` with this docking's retries.
    pub fn feedback(&self, phase: &'static str) -> Feedback {
        Feedback {
            phase,
            elapsed: self.now - self.run_start.unwrap_or(self.now),
            retries: self.retries.used(),
        }
    }
}

impl SharedMemory for Memory {
    fn perceive(&mut self, inputs: &Inputs<'_>) {
        self.now = inputs.now;
        self.run_start.get_or_insert(inputs.now);
        if let Some(o) = inputs.odometry {
            self.odo = o.value.pose;
        }
        self.reel = inputs.tether().map(|t| t.value);
        if !self.looking {
            return;
        }
        if let Some((t, pose)) = self.perception.look(inputs) {
            let [x, y, theta] = pose.rover_in_module();
            self.sighting = Some(Sighting {
                t,
                pose: Pose2::new(x, y, theta),
                source: pose.source,
                marks: pose.marks_used,
                reprojection_px: pose.reprojection_px,
                residual_m: pose.rms_residual_m,
            });
        }
    }

    fn begin(&mut self, _mission: &Mission) -> Result<(), MissionError> {
        self.run_start = None;
        self.looking = false;
        self.sighting = None;
        self.retries.reset();
        self.arcs = 0;
        self.search_sign = 1.0;
        self.seen = false;
        self.commit = None;
        self.last_fix = None;
        self.looks = Looks::new(0.0, f64::INFINITY);
        self.step = None;
        Ok(())
    }

    fn stats(&self) -> AgentStats {
        AgentStats { manoeuvres: self.arcs }
    }
}

#[cfg(test)]
impl Memory {
    /// The memory of the shipped `profiles/axel.toml` (the schemas' unit tests).
    pub(super) fn shipped_axel() -> Self {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/profiles/axel.toml");
        let profile = Profile::load(std::path::Path::new(path)).expect("axel profile");
        crate::behaviors::catalog::memory(&super::Axel, &profile).expect("memory")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn the_reel_takes_up_slack_until_its_current_says_taut() {
        let mut m = Memory::shipped_axel();
        // No reading: nothing to judge slack by, the reel holds.
        assert_eq!(m.take_up(), 0.0);
        // Winding a slack tether: the idle current alone, wind at the top rate.
        m.reel = Some(TetherReading {
            length: 3.0,
            motor_current_a: 0.4,
        });
        assert_eq!(m.take_up(), m.geometry.max_reel_rate);
        // Taut: a few newtons on top of the idle current, stop.
        m.reel = Some(TetherReading {
            length: 3.0,
            motor_current_a: SLACK_CURRENT_A,
        });
        assert_eq!(m.take_up(), 0.0);
        // A stopped rover holds the reel at the take-up's rate.
        m.reel = Some(TetherReading {
            length: 3.0,
            motor_current_a: 0.0,
        });
        let step = m.hold("test");
        let reel = step
            .output
            .aux
            .get::<TetherCommand>()
            .expect("a reel command")
            .reel_rate;
        assert_eq!(reel, m.geometry.max_reel_rate);
    }

    #[test]
    fn dead_reckoning_carries_the_odometry_motion_into_the_module_frame() {
        // Fixed at 3 m on the axis facing the module; odometry (its own frame, turned
        // 90°) then drives 1 m ahead and turns 30° left: 2 m out, turned 30°.
        let at = Pose2::new(3.0, 0.0, PI);
        let then = Pose2::new(5.0, -2.0, PI / 2.0);
        let now = Pose2::new(5.0, -1.0, PI / 2.0 + 30f64.to_radians());
        let p = dead_reckon(&at, &then, &now);
        assert!((p.x - 2.0).abs() < 1e-9 && p.y.abs() < 1e-9, "{p:?}");
        assert!(
            (crate::geometry::wrap_angle(p.theta - PI) - 30f64.to_radians()).abs() < 1e-9,
            "{p:?}"
        );
    }
}
