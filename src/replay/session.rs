//! Running a profile on logged frames: its perceptual schema alone, or its whole behavior
//! open-loop (the commands are computed, never applied: the log's camera moved as it did).

use super::ReplayError;
use crate::arbiter::{LoopStatus, ReactiveLoop};
use crate::perception::{RgbImage, VisionError};
use crate::profile::Profile;
use crate::schemas::{
    Agent, CameraInput, ColourRanges, Inputs, KrawlerSchema, Mission, MotorOutput, ObservedPercept, OdometryReading,
    PerceptualSchema, PyramidSchema, Stamped, TwoBlockSchema,
};

/// The profile's perceptual schema, by fiducial.
enum Perception {
    TwoBlock(Box<TwoBlockSchema>),
    Pyramid(Box<PyramidSchema>),
    /// The AutoKrawler's state estimator (`markers` fiducial).
    Krawler(Box<KrawlerSchema>),
}

/// What runs on each frame.
enum Runner {
    Perception(Perception),
    Behavior(Box<ReactiveLoop<dyn Agent>>),
}

/// What one frame gave.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameOutput {
    /// The percept (`None` only when a behavior exposes none).
    pub percept: Option<ObservedPercept>,
    /// The colour ranges that will segment the next frame, when the schema has them.
    pub ranges: Option<ColourRanges>,
    /// With the behavior: the command it would have sent and the loop's status.
    pub command: Option<(MotorOutput, LoopStatus)>,
}

/// A profile replaying frames of its first camera.
pub struct Session {
    runner: Runner,
    /// The profile camera's size, which the behavior's geometry assumes.
    camera_size: (usize, usize),
}

impl Session {
    /// Builds the profile's perceptual schema for its camera 0 (two-block, pyramid, or the
    /// AutoKrawler's state estimator for a `markers` fiducial), or
    /// with `behavior` its whole agent, started on a docking mission. `odometry` says
    /// whether the log has odometry; without it the loop does not wait for any, and
    /// the profile's `[[sensors]]` (the tether reel and dock switch among them), which the
    /// log cannot have, are never awaited.
    ///
    /// # Errors
    /// [`ReplayError::Setup`] when the profile has no perception a replay runs, or no
    /// behavior.
    pub fn new(profile: &Profile, behavior: bool, odometry: bool) -> Result<Self, ReplayError> {
        Self::new_with(profile, crate::behaviors::catalog::shipped(), behavior, odometry)
    }

    /// [`Session::new`], the agent built from `catalog` (a crate's own robot kinds).
    ///
    /// # Errors
    /// As [`Session::new`].
    pub fn new_with(
        profile: &Profile,
        catalog: &crate::behaviors::Catalog,
        behavior: bool,
        odometry: bool,
    ) -> Result<Self, ReplayError> {
        let cam = profile
            .cameras
            .first()
            .ok_or_else(|| setup("the profile has no [[cameras]]"))?;
        let camera_size = (cam.width_px, cam.height_px);
        let runner = if behavior {
            let agent = catalog.agent(profile).map_err(|e| setup(&e.to_string()))?;
            let mut config = profile.loop_config();
            config.staleness.sensors.iter_mut().for_each(|s| *s = None);
            if !odometry {
                config.staleness.odometry = None;
            }
            let mut lp: ReactiveLoop<dyn Agent> = ReactiveLoop::new(agent, config);
            lp.begin(&Mission::docking()).map_err(|e| setup(&e.to_string()))?;
            Runner::Behavior(Box::new(lp))
        } else if profile
            .fiducial
            .get::<crate::profile::TwoBlockSpec>()
            .copied()
            .is_some()
        {
            Runner::Perception(Perception::TwoBlock(Box::new(
                TwoBlockSchema::from_profile(profile, 0).map_err(vision)?,
            )))
        } else if profile.fiducial.get::<crate::profile::PyramidSpec>().copied().is_some() {
            Runner::Perception(Perception::Pyramid(Box::new(
                PyramidSchema::from_profile(profile, 0).map_err(vision)?,
            )))
        } else if profile.fiducial.get::<crate::profile::MarkersSpec>().is_some() {
            let schema = crate::behaviors::krawler::schema(profile).map_err(|e| setup(&e.to_string()))?;
            Runner::Perception(Perception::Krawler(Box::new(schema)))
        } else {
            return Err(setup(
                "replay runs the two-block, pyramid or AutoKrawler perceptual schema; the profile has no `two_block`, `pyramid` or `markers` fiducial (use --behavior to run its agent)",
            ));
        };
        Ok(Self { runner, camera_size })
    }

    /// Whether a frame of `size` can be run: any size for the two-block schema alone
    /// (it has no geometry; its buffers follow the frame, as `marsupial detect`'s do),
    /// the profile camera's size otherwise (the pyramid's distances and the behavior's
    /// steering are in that camera's pixels).
    pub fn accepts(&self, size: (usize, usize)) -> bool {
        matches!(self.runner, Runner::Perception(Perception::TwoBlock(_))) || size == self.camera_size
    }

    /// The profile camera's size.
    pub fn camera_size(&self) -> (usize, usize) {
        self.camera_size
    }

    /// Runs one frame taken at `t` (s on the replay's clock) with the latest odometry.
    ///
    /// # Errors
    /// [`ReplayError::Setup`] when the schema refuses the frame (its size; see
    /// [`Session::accepts`]).
    pub fn frame(
        &mut self,
        t: f64,
        image: &RgbImage,
        odometry: Option<Stamped<OdometryReading>>,
    ) -> Result<FrameOutput, ReplayError> {
        // The tick's inputs, for the runners that take a tick's (the camera, odometry).
        let cameras = [Some(CameraInput {
            stamp: t,
            image: image.view(),
        })];
        let inputs = Inputs {
            odometry,
            cameras: &cameras,
            ..Inputs::empty(t)
        };
        match &mut self.runner {
            Runner::Perception(Perception::TwoBlock(s)) => {
                s.detector_mut().resize(image.width(), image.height());
                let p = s.process(&image.view(), t).map_err(vision)?;
                Ok(FrameOutput {
                    percept: Some(ObservedPercept::TwoBlock(p)),
                    ranges: Some(ColourRanges::Sct(s.model().ranges())),
                    command: None,
                })
            }
            Runner::Perception(Perception::Pyramid(s)) => {
                let p = s.process(&image.view(), t).map_err(vision)?;
                Ok(FrameOutput {
                    percept: Some(ObservedPercept::Pyramid(p)),
                    ranges: Some(ColourRanges::Hsv(s.bands())),
                    command: None,
                })
            }
            Runner::Perception(Perception::Krawler(s)) => {
                let p = s.perceive(&inputs);
                Ok(FrameOutput {
                    percept: Some(ObservedPercept::Krawler(p.observation())),
                    ranges: None,
                    command: None,
                })
            }
            Runner::Behavior(lp) => {
                let out = lp.tick(&inputs);
                let obs = lp.root().observe();
                Ok(FrameOutput {
                    percept: obs.map(|o| o.percept),
                    ranges: obs.and_then(|o| o.ranges),
                    command: Some((out.command, out.status)),
                })
            }
        }
    }
}

fn setup(why: &str) -> ReplayError {
    ReplayError::Setup(why.to_string())
}

fn vision(e: VisionError) -> ReplayError {
    ReplayError::Setup(e.to_string())
}
