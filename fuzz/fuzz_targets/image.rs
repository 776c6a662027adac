//! Image decode plus both perception schemas, as `marsupial detect` runs them: the bytes
//! go through `image_io::decode_rgb` (the decoder `load_rgb` uses) with its
//! decompression-bomb guard set to `MAX_PIXELS`, then the two-block schema (Bujold's
//! profile) imprints on the frame and processes it twice, and the pyramid schema (RAPOSA's
//! profile) at the frame's size does the same. A frame of the wrong size must give a typed
//! error, never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;
use marsupial::image_io::{ImageFileError, decode_rgb};
use marsupial::perception::PyramidTrackerParams;
use marsupial::profile::Profile;
use marsupial::schemas::{CameraInput, Inputs, PerceptualSchema, PyramidSchema, TwoBlockSchema};
use std::path::Path;
use std::sync::OnceLock;

/// The decoded-size bound for fuzzing: 1 Mpx (8 MiB as 16-bit RGBA while decoding).
const MAX_PIXELS: u64 = 1 << 20;

struct Base {
    two_block: TwoBlockSchema,
    pyramid: PyramidTrackerParams,
}

fn base() -> &'static Base {
    static BASE: OnceLock<Base> = OnceLock::new();
    BASE.get_or_init(|| {
        let bujold = Profile::parse(include_str!("../../profiles/bujold.toml"), Path::new("bujold.toml"))
            .expect("shipped profile");
        let raposa = Profile::parse(include_str!("../../profiles/raposa.toml"), Path::new("raposa.toml"))
            .expect("shipped profile");
        Base {
            two_block: TwoBlockSchema::from_profile(&bujold, 0).expect("bujold has a two-block fiducial"),
            pyramid: PyramidTrackerParams::from_profile(&raposa, 0).expect("raposa has a pyramid"),
        }
    })
}

fuzz_target!(|data: &[u8]| {
    let im = match decode_rgb(data, Path::new("fuzz.img"), MAX_PIXELS) {
        Ok(im) => im,
        Err(e) => {
            if let ImageFileError::TooLarge { width, height, .. } = e {
                assert!(u64::from(width) * u64::from(height) > MAX_PIXELS);
            }
            std::hint::black_box(e.to_string());
            return;
        }
    };
    assert!(im.width() * im.height() <= MAX_PIXELS as usize);
    let view = im.view();
    let base = base();

    // The schema as built, on a frame of any size: a size mismatch is a typed error.
    let mut schema = base.two_block.clone();
    let cameras = [Some(CameraInput {
        stamp: 0.1,
        image: im.view(),
    })];
    std::hint::black_box(schema.perceive(&Inputs {
        cameras: &cameras,
        ..Inputs::empty(0.1)
    }));

    // As `detect --imprint`: fit the detector to the frame, imprint, process.
    schema.detector_mut().resize(im.width(), im.height());
    schema.imprint_frame(&view);
    schema.finish_imprint(0.0);
    for t in [0.1, 0.2] {
        if let Ok(p) = schema.process(&view, t) {
            std::hint::black_box(p);
        }
    }

    // The pyramid schema at the frame's size.
    let mut params = base.pyramid.clone();
    params.width = im.width();
    params.height = im.height();
    let mut pyramid = PyramidSchema::new(0, &params);
    if let Ok(p) = pyramid.imprint_frame(&view) {
        std::hint::black_box(p);
    }
    pyramid.finish_imprint(0.0);
    for t in [0.1, 0.2] {
        std::hint::black_box(pyramid.perceive(&Inputs {
            cameras: &cameras,
            ..Inputs::empty(t)
        }));
    }
});
