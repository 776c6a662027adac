//! Rendering one camera frame of Bujold's scene (ray casting, anti-aliasing, lighting,
//! sensor noise and gamma) at 256×240 and 640×480. Targets (issue: simulator): under 1 ms
//! and under 4 ms median on one core.
//!
//! Run: `cargo bench --bench render` (add `-- --quick` for a fast pass).

use criterion::{Criterion, criterion_group, criterion_main};
use marsupial::geometry::Pose2;
use marsupial::perception::RgbImage;
use marsupial::perception::camera_model::CameraModel;
use marsupial::profile::Profile;
use marsupial::sim::camera::camera_pose;
use marsupial::sim::lighting::{LightingRun, LightingSpec};
use marsupial::sim::render::{Renderer, SensorParams};
use marsupial::sim::rng::Rng;
use std::hint::black_box;
use std::path::Path;

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("render_bujold");
    for (w, h) in [(256, 240), (640, 480)] {
        let mut p =
            Profile::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/bujold.toml")).expect("profile");
        p.cameras[0].width_px = w;
        p.cameras[0].height_px = h;
        let world = marsupial::sim::world::build(&p, &[], &[]).expect("world");
        let cam = &p.cameras[0];
        let mut r = Renderer::new(CameraModel::from_spec(cam), w, h, 1);
        let light = LightingRun::new(LightingSpec::default().resolve(), &mut Rng::new(1), 100.0);
        let state = light.at(1.0);
        let pose = camera_pose(&Pose2::new(1.0, 0.1, 0.1), &cam.mount);
        let mut out = RgbImage::new(w, h);
        let mut k = 0u64;
        g.bench_function(format!("{w}x{h}"), |b| {
            b.iter(|| {
                k += 1;
                r.render(&world.scene, &pose, &state, &SensorParams::default(), k, &mut out);
                black_box(out.as_bytes()[0])
            })
        });
    }
    g.finish();
}

criterion_group!(render, bench);
criterion_main!(render);
