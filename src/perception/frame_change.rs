//! How much the camera's view changed since the last frame: a cheap cue that the robot is
//! not moving although it is commanded to.
//!
//! Track encoders cannot tell a robot turning in place from one whose corner is jammed
//! against the mother's body: the tracks spin either way. The camera can. Each frame is
//! reduced to a 16 × 12 grid of mean brightness; the cue is the mean absolute difference
//! between consecutive grids, in 8-bit levels. A turn at 25°/s moves a 70° image by a
//! twenty-eighth of its width per 10 Hz frame, which reads 3.6–8.2 levels on rendered
//! Bujold scenes (`tests/sim_render.rs`); a still robot sees only sensor noise, averaged
//! over each cell's samples to a fraction of a level (±6 levels of pixel noise read under
//! 0.5, tested below).
//! Lighting that changes (a flashing beacon) reads as motion, so the cue errs on the side
//! of "moving".

use super::image::RgbView;

/// Grid columns.
pub const GRID_W: usize = 16;
/// Grid rows.
pub const GRID_H: usize = 12;

/// The frame-change cue, with its two grids (no allocation per frame).
///
/// # Example
///
/// A 16×12 frame has one pixel per grid cell. Brightening every pixel by 10 levels moves
/// every cell by 10, so the cue reads exactly 10; the same frame again reads 0.
///
/// ```
/// use marsupial::perception::RgbImage;
/// use marsupial::perception::frame_change::FrameChange;
///
/// let mut im = RgbImage::new(16, 12);
/// im.fill([100, 100, 100]);
/// let mut cue = FrameChange::new();
/// assert_eq!(cue.observe(&im.view()), None, "no previous frame");
/// assert_eq!(cue.observe(&im.view()), Some(0.0));
/// im.fill([110, 110, 110]);
/// assert_eq!(cue.observe(&im.view()), Some(10.0));
/// // A frame smaller than the 16 × 12 grid gives no reading.
/// assert_eq!(cue.observe(&RgbImage::new(8, 8).view()), None);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct FrameChange {
    previous: [f32; GRID_W * GRID_H],
    current: [f32; GRID_W * GRID_H],
    /// Size of the frame `previous` came from (0 × 0: none yet).
    size: (usize, usize),
}

impl Default for FrameChange {
    fn default() -> Self {
        Self::new()
    }
}

impl FrameChange {
    /// A cue with no previous frame.
    pub const fn new() -> Self {
        Self {
            previous: [0.0; GRID_W * GRID_H],
            current: [0.0; GRID_W * GRID_H],
            size: (0, 0),
        }
    }

    /// Forgets the previous frame.
    pub fn reset(&mut self) {
        self.size = (0, 0);
    }

    /// Takes `frame` and returns the mean absolute change of the grid's cells from the
    /// previous frame, in 8-bit levels; `None` for the first frame, after a change of size,
    /// or for a frame smaller than the grid.
    pub fn observe(&mut self, frame: &RgbView<'_>) -> Option<f32> {
        let (w, h) = (frame.width(), frame.height());
        if w < GRID_W || h < GRID_H {
            self.size = (0, 0);
            return None;
        }
        let data = frame.as_bytes();
        for gy in 0..GRID_H {
            let (y0, y1) = (gy * h / GRID_H, (gy + 1) * h / GRID_H);
            for gx in 0..GRID_W {
                let (x0, x1) = (gx * w / GRID_W, (gx + 1) * w / GRID_W);
                // Every other row and column: a quarter of the pixels is plenty.
                let (mut sum, mut n) = (0u32, 0u32);
                for y in (y0..y1).step_by(2) {
                    let row = &data[(y * w + x0) * 3..(y * w + x1) * 3];
                    for px in row.chunks_exact(3).step_by(2) {
                        sum += px[0] as u32 + 2 * px[1] as u32 + px[2] as u32;
                        n += 1;
                    }
                }
                self.current[gy * GRID_W + gx] = sum as f32 / (4 * n.max(1)) as f32;
            }
        }
        let change = (self.size == (w, h)).then(|| {
            self.current
                .iter()
                .zip(&self.previous)
                .map(|(a, b)| (a - b).abs())
                .sum::<f32>()
                / (GRID_W * GRID_H) as f32
        });
        std::mem::swap(&mut self.previous, &mut self.current);
        self.size = (w, h);
        change
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::perception::RgbImage;

    /// A textured frame (vertical stripes of varying brightness) shifted by `dx` pixels,
    /// with ±`noise` levels of deterministic pixel noise.
    fn frame(dx: usize, noise: i32, seed: u32) -> RgbImage {
        let (w, h) = (256, 240);
        let mut im = RgbImage::new(w, h);
        let mut s = seed.wrapping_mul(2_654_435_761).wrapping_add(1);
        for y in 0..h {
            for x in 0..w {
                s ^= s << 13;
                s ^= s >> 17;
                s ^= s << 5;
                let n = (s % (2 * noise as u32 + 1)) as i32 - noise;
                let base = 60 + (((x + dx) * 7 / 10) % 9) as i32 * 15;
                let v = (base + n).clamp(0, 255) as u8;
                im.put(x, y, [v, v, v]);
            }
        }
        im
    }

    #[test]
    fn still_frames_read_as_noise_and_a_turn_as_change() {
        let mut c = FrameChange::new();
        assert_eq!(c.observe(&frame(0, 6, 1).view()), None, "first frame");
        let still = c.observe(&frame(0, 6, 2).view()).unwrap();
        assert!(still < 0.5, "sensor noise only: {still}");
        // 8 px: what one 10 Hz tick of a 25°/s turn moves a 256-px, 70° image.
        let moved = c.observe(&frame(8, 6, 3).view()).unwrap();
        assert!(moved > 10.0 * still.max(0.1) && moved > 5.0, "turning: {moved}");
    }

    #[test]
    fn a_size_change_or_a_tiny_frame_restarts_the_cue() {
        let mut c = FrameChange::new();
        c.observe(&frame(0, 0, 1).view());
        let small = RgbImage::new(64, 48);
        assert_eq!(c.observe(&small.view()), None, "new size");
        assert_eq!(c.observe(&small.view()), Some(0.0));
        assert_eq!(c.observe(&RgbImage::new(8, 8).view()), None, "smaller than the grid");
        c.reset();
        assert_eq!(c.observe(&small.view()), None);
    }
}
