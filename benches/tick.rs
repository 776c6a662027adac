//! One tick of the composed Bujold behavior (`profiles/bujold.toml`'s `[behavior.tree]`
//! built by `Catalog::compose`), perception excluded. Target (issue: the
//! composition redesign): under 20 µs.
//!
//! The percepts are computed beforehand, by Bujold's two-block schema on a sequence of
//! frames in which the flap grows from 4 % to 50 % of the 256 × 240 image while odometry
//! backs the robot toward the dock, so the tree runs its search, approach, decision and
//! back-in states as on a real docking. Each timed tick is what the root does after its
//! perception: the memory digests the tick's percept (viewing-angle filter, dock pose in
//! odometry, the last sighting), then the declared tree ticks, with its arbiters and
//! decision records. When a docking mission ends, the next iteration begins another.
//!
//! Run: `cargo bench --bench tick` (add `-- --quick` for a fast pass).

use criterion::{Criterion, criterion_group, criterion_main};
use marsupial::behaviors::bujold;
use marsupial::geometry::Pose2;
use marsupial::perception::{RgbImage, TwoBlockPercept};
use marsupial::schemas::{Agent, CameraInput, Inputs, Mission, OdometryReading, Stamped, Status, TwoBlockSchema};
use std::hint::black_box;

#[path = "../tests/common/mod.rs"]
mod common;

/// Frames along an approach, with the pose each was seen from.
fn approach(n: usize, w: usize, h: usize) -> Vec<(RgbImage, Pose2)> {
    (0..n)
        .map(|k| {
            let f = k as f64 / (n - 1) as f64;
            let frame = common::scene(w, h, 0.04 + 0.46 * f, k as u64 + 1);
            (frame, Pose2::new(2.0 - 1.6 * f, 0.0, 0.0))
        })
        .collect()
}

fn bench_tick(c: &mut Criterion) {
    let profile = common::shipped_profile("bujold");
    let (w, h) = (profile.cameras[0].width_px, profile.cameras[0].height_px);
    let frames = approach(40, w, h);
    let mut schema = TwoBlockSchema::from_profile(&profile, 0).expect("schema");
    let percepts: Vec<TwoBlockPercept> = frames
        .iter()
        .enumerate()
        .map(|(k, (im, _))| schema.process(&im.view(), k as f64 * 0.1).expect("frame"))
        .collect();
    assert!(
        percepts.iter().filter(|p| p.found).count() > percepts.len() / 2,
        "the bench's frames must show the flap"
    );

    let mut agent = marsupial::behaviors::catalog::shipped()
        .compose(&bujold::Bujold, &profile)
        .expect("agent");
    agent.begin(&Mission::docking()).expect("docking");
    let (mut k, mut now, mut ticks) = (0usize, 0.0f64, 0u64);
    c.bench_function("bujold_composed_tick_without_perception", |b| {
        b.iter(|| {
            let (im, pose) = &frames[k % frames.len()];
            let cameras = [Some(CameraInput {
                stamp: now,
                image: im.view(),
            })];
            let mut inputs = Inputs::empty(now);
            inputs.cameras = &cameras;
            inputs.odometry = Some(Stamped::new(
                now,
                OdometryReading {
                    pose: *pose,
                    ..Default::default()
                },
            ));
            let percept = &percepts[k % percepts.len()];
            let step = agent.tick_perceived(&inputs, |m| m.digest(&inputs, percept));
            if !matches!(step, Some(s) if s.status == Status::Running || matches!(s.status, Status::Event(_))) {
                agent.begin(&Mission::docking()).expect("docking");
            }
            black_box(step);
            k += 1;
            ticks += 1;
            now += 0.1;
        })
    });
    black_box(ticks);
}

criterion_group!(benches, bench_tick);
criterion_main!(benches);
