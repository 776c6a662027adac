use marsupial::geometry::Pose2;
use marsupial::perception::camera_model::CameraModel;
use marsupial::perception::{RgbImage, TwoBlockSchema};
use marsupial::profile::Profile;
use marsupial::sim::lighting::{LightingPreset, LightingRun, LightingSpec};
use marsupial::sim::render::{Renderer, SensorParams};
use marsupial::sim::rng::Rng;
use std::path::Path;
fn main() {
    let p = Profile::load(Path::new("profiles/bujold.toml")).unwrap();
    let world = marsupial::sim::world::build(&p, &[], &[]).unwrap();
    let cam = &p.cameras[0];
    let mut r = Renderer::new(CameraModel::from_spec(cam), cam.width_px, cam.height_px, 1);
    let mut out = RgbImage::default();
    let a: Vec<f64> = std::env::args().skip(1).map(|x| x.parse().unwrap()).collect();
    let spec = LightingSpec {
        preset: Some(
            [
                LightingPreset::Lab,
                LightingPreset::Flashers,
                LightingPreset::Noon,
                LightingPreset::Dusk,
            ][a[3] as usize],
        ),
        ..Default::default()
    };
    let run = LightingRun::new(spec.resolve(), &mut Rng::new(1), 200.0);
    let pose = Pose2::new(a[0], a[1], a[2].to_radians());
    let cp = marsupial::sim::camera::camera_pose(&pose, &cam.mount);
    let mut s = TwoBlockSchema::from_profile(&p, 0).unwrap();
    for k in 0..5 {
        r.render(
            &world.scene,
            &cp,
            &run.at(k as f64),
            &SensorParams::default(),
            k,
            &mut out,
        );
    }
    let pc = s.process(&out.view(), 0.0).unwrap();
    println!(
        "found {} L {} R {} lb {:?} rb {:?} off {:.1}",
        pc.found, pc.left_px, pc.right_px, pc.left_bbox, pc.right_bbox, pc.offset_px
    );
    let (w, h) = (256.0, 240.0);
    println!(
        "fractions L [{:.3},{:.3},{:.3},{:.3}] R [{:.3},{:.3},{:.3},{:.3}]",
        pc.left_bbox[0] as f64 / w,
        pc.left_bbox[1] as f64 / h,
        (pc.left_bbox[2] + 1) as f64 / w,
        (pc.left_bbox[3] + 1) as f64 / h,
        pc.right_bbox[0] as f64 / w,
        pc.right_bbox[1] as f64 / h,
        (pc.right_bbox[2] + 1) as f64 / w,
        (pc.right_bbox[3] + 1) as f64 / h
    );
    image::RgbImage::from_raw(out.width() as u32, out.height() as u32, out.as_bytes().to_vec())
        .unwrap()
        .save("/tmp/frame.png")
        .unwrap();
}
