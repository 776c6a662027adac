//! Finding the toy's red beacon with the crate's perception from plain parameters, no
//! profile needed: red is a box in HSV (hue wrapping through 0°); the [`Segmenter`] writes
//! the red pixels into a [`Mask`], the [`Labeler`] finds its 8-connected blobs, and the
//! largest blob is the beacon. Every buffer is allocated once, for the camera's
//! resolution. Shared by the examples `custom_robot`, `compose` and `plugin_robot`.

use marsupial::perception::{ColorRange, HsvRange, Labeler, Mask, RgbView, Segmenter};

/// The beacon in one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sighting {
    /// Column offset of its centroid from the image centre, px (positive right).
    pub offset_px: f64,
    /// Pixels of the blob (grows as the robot closes in).
    pub pixels: u64,
}

/// See the module docs.
pub struct RedBeacon {
    min_pixels: u64,
    red: [ColorRange; 1],
    segmenter: Segmenter,
    mask: [Mask; 1],
    labeler: Labeler,
}

impl RedBeacon {
    /// A finder for `width × height` frames; blobs of 10 px or fewer are noise.
    pub fn new(width: usize, height: usize) -> Self {
        Self {
            min_pixels: 10,
            red: [ColorRange::Hsv(HsvRange {
                h: [340.0, 20.0],
                s: [0.5, 1.0],
                v: [0.4, 1.0],
            })],
            segmenter: Segmenter::new(),
            mask: [Mask::new(width, height)],
            labeler: Labeler::new(width, height),
        }
    }

    /// This finder, taking blobs of `n` px or fewer for noise.
    #[allow(dead_code)] // the examples that need no other threshold do not call it
    pub fn with_min_pixels(mut self, n: u64) -> Self {
        self.min_pixels = n;
        self
    }

    /// The largest red blob of `image`; `None` when there is none above the noise, or the
    /// frame has the wrong size (an error, not a beacon).
    pub fn find(&mut self, image: &RgbView<'_>) -> Option<Sighting> {
        self.segmenter.segment(image, &self.red, &mut self.mask).ok()?;
        let blobs = self.labeler.label(&self.mask[0]).ok()?;
        let blob = blobs.iter().max_by_key(|b| b.count)?;
        (blob.count > self.min_pixels).then(|| Sighting {
            offset_px: blob.centroid().0 - image.width() as f64 / 2.0,
            pixels: blob.count,
        })
    }
}
