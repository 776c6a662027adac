//! Bayer mosaics (`bayer_rggb8`, `bayer_bggr8`, `bayer_grbg8`, `bayer_gbrg8`) to packed
//! RGB8, by **bilinear demosaicing**: each pixel keeps its own sample, and each missing
//! colour is the mean of that colour's samples among its eight neighbours (the two or
//! four nearest, since a 2×2 tile holds one red, two greens and one blue), rounded half
//! up. A border pixel averages the neighbours it has in the frame.
//!
//! Bilinear is the simplest demosaic and blurs colour edges by about a pixel, with some
//! zippering on sharp ones; a segmentation on blobs many pixels wide does not notice,
//! and it costs a few additions per pixel. A camera whose driver debayers better (most
//! do, on the sensor or in the ISP) should send `rgb8` or `bgr8`; this is for the raw
//! machine-vision cameras that send the mosaic.
//!
//! The pattern names the top-left 2×2 tile in reading order: `rggb` is `R G` over `G B`.
//! Needs at least 2×2 pixels; the sizes are checked by the caller
//! ([`super::pixels::rgb_into_raw`]).

use crate::perception::RgbImage;

/// The colour-filter layout of a Bayer sensor, by its top-left 2×2 tile.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pattern {
    /// `R G / G B` (`bayer_rggb8`).
    Rggb,
    /// `B G / G R` (`bayer_bggr8`).
    Bggr,
    /// `G R / B G` (`bayer_grbg8`).
    Grbg,
    /// `G B / R G` (`bayer_gbrg8`).
    Gbrg,
}

impl Pattern {
    /// The channel (0 red, 1 green, 2 blue) sampled at pixel (x, y).
    ///
    /// # Example
    ///
    /// ```
    /// use marsupial::msgs::bayer::Pattern;
    ///
    /// assert_eq!([0, 1, 2, 3].map(|i| Pattern::Grbg.channel_at(i % 2, i / 2)), [1, 0, 2, 1]);
    /// ```
    pub fn channel_at(self, x: usize, y: usize) -> usize {
        let tile = match self {
            Pattern::Rggb => [0, 1, 1, 2],
            Pattern::Bggr => [2, 1, 1, 0],
            Pattern::Grbg => [1, 0, 2, 1],
            Pattern::Gbrg => [1, 2, 0, 1],
        };
        tile[(y % 2) * 2 + x % 2]
    }
}

/// Mean of four samples, rounded half up.
fn mean4(a: u8, b: u8, c: u8, d: u8) -> u8 {
    ((u16::from(a) + u16::from(b) + u16::from(c) + u16::from(d) + 2) >> 2) as u8
}

/// Mean of two samples, rounded half up.
fn mean2(a: u8, b: u8) -> u8 {
    ((u16::from(a) + u16::from(b) + 1) >> 1) as u8
}

/// The mean of the in-frame pixels of the 3×3 window around (x, y) that sample
/// `channel`, rounded half up: the definition, used along the borders (where the window
/// leaves the frame) and as the tests' reference.
fn window_mean(
    pattern: Pattern,
    (w, h): (usize, usize),
    step: usize,
    data: &[u8],
    (x, y): (usize, usize),
    channel: usize,
) -> u8 {
    let (mut sum, mut n) = (0u32, 0u32);
    for yy in y.saturating_sub(1)..=(y + 1).min(h - 1) {
        for xx in x.saturating_sub(1)..=(x + 1).min(w - 1) {
            if pattern.channel_at(xx, yy) == channel {
                sum += u32::from(data.get(yy * step + xx).copied().unwrap_or(0));
                n += 1;
            }
        }
    }
    (sum + n / 2).checked_div(n).unwrap_or(0) as u8
}

/// A validated mosaic (`step ≥ width`, `height` rows, both sides ≥ 2) into `out`, which
/// is `width × height`.
pub(crate) fn fill_from_bayer(pattern: Pattern, step: usize, data: &[u8], out: &mut RgbImage) {
    let (w, h) = (out.width(), out.height());
    if w < 2 || h < 2 || data.len() < step * (h - 1) + w {
        return;
    }
    for (y, dst) in out.as_bytes_mut().chunks_exact_mut(w * 3).enumerate() {
        let interior_row = y > 0 && y + 1 < h;
        for (x, d) in dst.chunks_exact_mut(3).enumerate() {
            let own = pattern.channel_at(x, y);
            let at = |xx: usize, yy: usize| data[yy * step + xx];
            if !interior_row || x == 0 || x + 1 == w {
                for (c, v) in d.iter_mut().enumerate() {
                    *v = if c == own {
                        at(x, y)
                    } else {
                        window_mean(pattern, (w, h), step, data, (x, y), c)
                    };
                }
            } else if own == 1 {
                // Green: the row's other colour left and right, the column's above and below.
                d[1] = at(x, y);
                d[pattern.channel_at(x + 1, y)] = mean2(at(x - 1, y), at(x + 1, y));
                d[pattern.channel_at(x, y + 1)] = mean2(at(x, y - 1), at(x, y + 1));
            } else {
                // Red or blue: green on the four sides, the other on the four diagonals.
                d[own] = at(x, y);
                d[1] = mean4(at(x - 1, y), at(x + 1, y), at(x, y - 1), at(x, y + 1));
                d[2 - own] = mean4(at(x - 1, y - 1), at(x + 1, y - 1), at(x - 1, y + 1), at(x + 1, y + 1));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The definition itself: each missing channel is the rounded mean of the in-frame
    /// pixels of the 3×3 window that sample it.
    fn reference(pattern: Pattern, w: usize, h: usize, step: usize, data: &[u8]) -> Vec<u8> {
        let mut out = Vec::with_capacity(w * h * 3);
        for y in 0..h {
            for x in 0..w {
                for c in 0..3 {
                    if pattern.channel_at(x, y) == c {
                        out.push(data[y * step + x]);
                        continue;
                    }
                    let (mut sum, mut n) = (0u32, 0u32);
                    for yy in y.saturating_sub(1)..=(y + 1).min(h - 1) {
                        for xx in x.saturating_sub(1)..=(x + 1).min(w - 1) {
                            if pattern.channel_at(xx, yy) == c {
                                sum += u32::from(data[yy * step + xx]);
                                n += 1;
                            }
                        }
                    }
                    out.push(((sum + n / 2) / n) as u8);
                }
            }
        }
        out
    }

    #[test]
    fn a_flat_grey_stays_grey_and_a_flat_colour_its_colour() {
        for pattern in [Pattern::Rggb, Pattern::Bggr, Pattern::Grbg, Pattern::Gbrg] {
            let (w, h) = (5, 4);
            let data: Vec<u8> = (0..w * h)
                .map(|i| [200, 90, 10][pattern.channel_at(i % w, i / w)])
                .collect();
            let mut out = RgbImage::new(w, h);
            fill_from_bayer(pattern, w, &data, &mut out);
            assert!(
                out.as_bytes().chunks_exact(3).all(|p| p == [200, 90, 10]),
                "{pattern:?}"
            );
        }
    }

    proptest::proptest! {
        /// Every pattern, size from 2×2, row pad and content gives exactly the reference.
        #[test]
        fn demosaic_is_the_neighbour_mean(w in 2usize..9, h in 2usize..9, pad in 0usize..4, p in 0usize..4, seed: u64) {
            let pattern = [Pattern::Rggb, Pattern::Bggr, Pattern::Grbg, Pattern::Gbrg][p];
            let step = w + pad;
            let mut x = seed | 1;
            let data: Vec<u8> = (0..step * h).map(|_| { x ^= x << 13; x ^= x >> 7; x ^= x << 17; x as u8 }).collect();
            let mut out = RgbImage::new(w, h);
            fill_from_bayer(pattern, step, &data, &mut out);
            proptest::prop_assert_eq!(out.as_bytes(), &reference(pattern, w, h, step, &data)[..]);
        }
    }
}
