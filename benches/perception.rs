//! Bujold's perceptual schema (SCT segmentation of both colours, labelling, pairing,
//! adaptation) on 640×480 and 256×240 frames, with the per-stage split and the colour
//! space conversions for reference. Targets (issue: colour perception): whole schema under
//! 1 ms at 640×480 and under 0.25 ms at 256×240, one core.
//!
//! Run: `cargo bench --bench perception` (add `-- --quick` for a fast pass).

use criterion::{Criterion, criterion_group, criterion_main};
use marsupial::perception::{
    ColorRange, HsvPlanes, Labeler, Mask, SctPlanes, Segmenter, TwoBlockDetector, TwoBlockSchema, hsv_from_rgb,
    sct_from_rgb,
};
use marsupial::profile::Profile;
use std::hint::black_box;
use std::path::Path;

#[path = "../tests/common/mod.rs"]
mod common;

fn profile_at(w: usize, h: usize) -> Profile {
    let mut p = Profile::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/bujold.toml")).expect("profile");
    p.cameras[0].width_px = w;
    p.cameras[0].height_px = h;
    p
}

fn bench_size(c: &mut Criterion, w: usize, h: usize) {
    let frame = common::scene(w, h, 0.3, 1);
    let view = frame.view();
    let profile = profile_at(w, h);
    let mut schema = TwoBlockSchema::from_profile(&profile, 0).expect("schema");
    // Warm up into the adapted state, as on a real approach.
    for k in 0..5 {
        assert!(
            schema.process(&view, k as f64 * 0.1).expect("frame").found,
            "bench scene must contain the fiducial"
        );
    }
    let mut t = 1.0;
    let mut g = c.benchmark_group(format!("bujold_schema_{w}x{h}"));
    g.bench_function("whole_schema", |b| {
        b.iter(|| {
            t += 0.1;
            black_box(schema.process(black_box(&view), t).expect("frame"))
        })
    });
    let ranges = schema.model().ranges();
    let cr = [ColorRange::Sct(ranges[0]), ColorRange::Sct(ranges[1])];
    let mut seg = Segmenter::new();
    let mut masks = [Mask::new(w, h), Mask::new(w, h)];
    g.bench_function("stage_1_segment_both_colours", |b| {
        b.iter(|| seg.segment(black_box(&view), &cr, &mut masks).expect("segment"))
    });
    let mut lab = [Labeler::new(w, h), Labeler::new(w, h)];
    g.bench_function("stage_2_label_both_masks", |b| {
        b.iter(|| {
            for (l, m) in lab.iter_mut().zip(&masks) {
                black_box(l.label(m).expect("label").len());
            }
        })
    });
    let mut det = TwoBlockDetector::new(w, h, *schema.detector().limits());
    g.bench_function("stages_1_to_3_detect", |b| {
        b.iter(|| black_box(det.detect(&view, &ranges).expect("detect")))
    });
    let pair = det.detect(&view, &ranges).expect("detect").expect("found");
    g.bench_function("stage_4_adaptation_statistics", |b| {
        b.iter(|| black_box(det.measure(&view, &pair)))
    });
    let mut sct = SctPlanes::new(w, h);
    g.bench_function("reference_sct_frame_fast_atan", |b| {
        b.iter(|| sct_from_rgb(&view, &mut sct).expect("sct"))
    });
    let mut hsv = HsvPlanes::new(w, h);
    g.bench_function("reference_hsv_frame", |b| {
        b.iter(|| hsv_from_rgb(&view, &mut hsv).expect("hsv"))
    });
    g.finish();
}

fn benches(c: &mut Criterion) {
    bench_size(c, 640, 480);
    bench_size(c, 256, 240);
}

criterion_group!(perception, benches);
criterion_main!(perception);
