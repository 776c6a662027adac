//! The AutoKrawler's belly camera rendering a gear state, for the estimator's tests.

use marsupial::geometry::Pose2;
use marsupial::perception::RgbImage;
use marsupial::perception::krawler::{AxleGeometry, AxleState, GearGeometry, GearLayout};
use marsupial::profile::Profile;
use marsupial::sim::camera::camera_pose;
use marsupial::sim::krawler::{KrawlerState, build};
use marsupial::sim::lighting::LightState;
use marsupial::sim::render::{CameraPose, Renderer, SensorParams};

/// The shipped AutoKrawler, its camera's geometry and a renderer of its gear.
pub struct Rig {
    pub profile: Profile,
    pub geometry: AxleGeometry,
    pub layout: GearLayout,
    pub pose: CameraPose,
    pub rest: KrawlerState,
    pub sensor: SensorParams,
    renderer: Renderer,
    frame: u64,
}

impl Rig {
    /// The rig with `sensor`; `seed` seeds the sensor's noise.
    pub fn new(sensor: SensorParams, seed: u64) -> Self {
        let profile = super::shipped_profile("autokrawler");
        let geometry = AxleGeometry::from_profile(&profile, 0).unwrap();
        let gear = marsupial::behaviors::krawler::gear_spec(&profile).unwrap();
        let layout = GearGeometry::from_profile(&profile, gear).unwrap().layout();
        let pose = camera_pose(&Pose2::new(0.0, 0.0, 0.0), &profile.cameras[0].mount);
        let rest = KrawlerState::rest(&profile).unwrap();
        let cam = &profile.cameras[0];
        let renderer = Renderer::new(geometry.model.clone(), cam.width_px, cam.height_px, seed);
        Self {
            profile,
            geometry,
            layout,
            pose,
            rest,
            sensor,
            renderer,
            frame: 0,
        }
    }

    /// Renders the next frame of the sequence, the gear in `state`, into `image`.
    pub fn render(&mut self, state: &KrawlerState, image: &mut RgbImage) {
        let gear = build(&self.profile, state).unwrap();
        self.renderer.render(
            &gear.scene,
            &self.pose,
            &LightState::uniform(1.0),
            &self.sensor,
            self.frame,
            image,
        );
        self.frame += 1;
    }
}

/// The axles' part of a state, as the wheel stage takes it.
pub fn axles(s: &KrawlerState) -> [AxleState; 2] {
    [0, 1].map(|a| AxleState {
        roll: s.roll[a],
        drop: s.drop[a],
        steer: s.steer[a],
    })
}

/// RANSAC's index draw from the simulator's generator: an index below `n`.
pub fn draw(rng: &mut marsupial::sim::rng::Rng) -> impl FnMut(usize) -> usize + '_ {
    move |n| (rng.next_u64() % n as u64) as usize
}
