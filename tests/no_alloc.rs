//! The perceptual schema allocates nothing per frame in steady state: segmentation,
//! labelling, pairing, adaptation and the fallback chain all reuse their buffers.
//! A counting global allocator (gated to this thread) proves it.

mod common;

use marsupial::perception::TwoBlockSchema;
use marsupial::profile::Profile;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;
static ALLOCS: AtomicUsize = AtomicUsize::new(0);
thread_local!(static COUNTING: Cell<bool> = const { Cell::new(false) });

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        if COUNTING.with(|c| c.get()) {
            ALLOCS.fetch_add(1, Ordering::SeqCst);
        }
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        if COUNTING.with(|c| c.get()) {
            ALLOCS.fetch_add(1, Ordering::SeqCst);
        }
        unsafe { System.realloc(p, l, n) }
    }
}

#[global_allocator]
static A: Counting = Counting;

#[test]
fn steady_state_schema_does_not_allocate() {
    for (w, h) in [(640, 480), (256, 240)] {
        let mut p = Profile::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/bujold.toml")).unwrap();
        p.cameras[0].width_px = w;
        p.cameras[0].height_px = h;
        let mut schema = TwoBlockSchema::from_profile(&p, 0).unwrap();
        // Frames with the fiducial at several sizes, and empty frames (lost → fallbacks).
        let frames: Vec<_> = (0..6).map(|k| common::scene(w, h, 0.1 + 0.08 * k as f64, k)).collect();
        let empty = common::background(w, h);
        for (k, f) in frames.iter().enumerate() {
            schema.process(&f.view(), k as f64 * 0.1).unwrap(); // warm-up
        }
        ALLOCS.store(0, Ordering::SeqCst);
        COUNTING.with(|c| c.set(true));
        let mut found = 0;
        let mut t = 1.0;
        for round in 0..20 {
            for f in &frames {
                t += 0.1;
                found += schema.process(&f.view(), t).unwrap().found as usize;
            }
            if round % 5 == 4 {
                // Ten seconds without the fiducial: adapted → imprinted/table fallbacks.
                for _ in 0..100 {
                    t += 0.1;
                    schema.process(&empty.view(), t).unwrap();
                }
            }
        }
        COUNTING.with(|c| c.set(false));
        assert_eq!(ALLOCS.load(Ordering::SeqCst), 0, "{w}×{h}: allocations in steady state");
        assert_eq!(found, 120, "{w}×{h}: every fiducial frame detected");
    }
    // Control: the counter does see allocations.
    COUNTING.with(|c| c.set(true));
    let v: Vec<u8> = Vec::with_capacity(std::hint::black_box(64));
    COUNTING.with(|c| c.set(false));
    drop(v);
    assert!(ALLOCS.load(Ordering::SeqCst) >= 1);
}
