//! Axel's central module seen by the rover's cameras, for the circle-mark tests.

use marsupial::geometry::Pose2;
use marsupial::perception::RgbImage;
use marsupial::perception::camera_model::CameraModel;
use marsupial::profile::Profile;
use marsupial::sim::camera::camera_pose;
use marsupial::sim::lighting::LightState;
use marsupial::sim::render::{Renderer, SensorParams};
use marsupial::sim::world;

/// The robot `d` m from the module's face centre, `alpha_deg` off its axis, facing it
/// and then turned `turn_deg`.
pub fn facing(d: f64, alpha_deg: f64, turn_deg: f64) -> Pose2 {
    let a = alpha_deg.to_radians();
    Pose2::new(
        d * a.cos(),
        d * a.sin(),
        a + std::f64::consts::PI + turn_deg.to_radians(),
    )
}

/// Camera `cam` of `p` at robot pose `robot` in world `w`: the default sensor (noisy,
/// auto-exposed) after four frames, so the exposure has settled.
pub fn render(p: &Profile, w: &world::World, cam: usize, robot: &Pose2, seed: u64) -> RgbImage {
    render_lit(p, w, cam, robot, seed, &LightState::uniform(1.0))
}

/// [`render`] under `light`.
pub fn render_lit(p: &Profile, w: &world::World, cam: usize, robot: &Pose2, seed: u64, light: &LightState) -> RgbImage {
    let spec = &p.cameras[cam];
    let mut r = Renderer::new(CameraModel::from_spec(spec), spec.width_px, spec.height_px, seed);
    let pose = camera_pose(robot, &spec.mount);
    let mut im = RgbImage::default();
    for k in 0..4 {
        r.render(&w.scene, &pose, light, &SensorParams::default(), seed + k, &mut im);
    }
    im
}
