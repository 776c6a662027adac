//! Finding the toy's red beacon with the crate's perception from plain parameters, no
//! profile needed: red is a box in HSV (hue wrapping through 0°); the [`Segmenter`] writes
//! the red pixels into a [`Mask`], the [`Labeler`] finds its 8-connected blobs, and the
//! largest blob is the beacon. Every buffer is allocated once, for the camera's
//! resolution. Shared by the examples `custom_robot` and `compose`.

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
    red: [ColorRange; 1],
    segmenter: Segmenter,
    mask: [Mask; 1],
    labeler: Labeler,
}

impl RedBeacon {
    /// Blobs this small or smaller are noise, px.
    const MIN_PIXELS: u64 = 10;

    /// A finder for `width × height` frames.
    pub fn new(width: usize, height: usize) -> Self {
        Self {
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

    /// The largest red blob of `image`; `None` when there is none above the noise, or the
    /// frame has the wrong size (an error, not a beacon).
    pub fn find(&mut self, image: &RgbView<'_>) -> Option<Sighting> {
        self.segmenter.segment(image, &self.red, &mut self.mask).ok()?;
        let blobs = self.labeler.label(&self.mask[0]).ok()?;
        let blob = blobs.iter().max_by_key(|b| b.count)?;
        (blob.count > Self::MIN_PIXELS).then(|| Sighting {
            offset_px: blob.centroid().0 - image.width() as f64 / 2.0,
            pixels: blob.count,
        })
    }
}
