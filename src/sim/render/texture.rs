//! Surface appearance: a material's albedo at local coordinates, averaged over a pixel's
//! footprint so texture finer than a pixel does not alias.
//!
//! A [`Texture`] is a material prepared for one primitive and frame: reciprocals and
//! tables computed once, so the per-pixel lookup multiplies instead of dividing and never
//! calls `powf`.

use super::hits::cov;
use crate::perception::RgbImage;
use crate::sim::scene::{CircleMark, Material, PaintedSquare, srgb_to_linear};
use std::sync::LazyLock;

/// Linear value of each sRGB byte, scaled by the 0.8 reflectance a printed photo has.
static PHOTO_LINEAR: LazyLock<[f32; 256]> =
    LazyLock::new(|| std::array::from_fn(|i| srgb_to_linear(i as f32 / 255.0) * 0.8));

/// ⌊x⌋ for |x| < 2²², by the float-rounding trick (adding 1.5·2²³ leaves the integer part
/// in the low mantissa bits): no libm call, and unlike `as i32` (which must saturate and
/// map NaN) it vectorises. An exact integer x may come out as x − 1, which for a noise
/// texture only moves a cell boundary by a rounding error. Beyond 2²² cells the result
/// is meaningless but harmless: hazed-out ground, 84 km away at 2 cm cells.
#[inline(always)]
fn fast_floor(x: f32) -> i32 {
    const MAGIC: f32 = 12_582_912.0; // 1.5 · 2²³
    (x - 0.5 + MAGIC).to_bits().wrapping_sub(MAGIC.to_bits()) as i32
}

/// The value-noise factor of cell (ix, iy) at full contrast, in [−1, 1].
#[inline(always)]
fn cell_noise(ix: i32, iy: i32) -> f32 {
    let mut hsh = (ix as u32).wrapping_mul(0x9E37_79B1) ^ (iy as u32).wrapping_mul(0x85EB_CA77);
    hsh ^= hsh >> 15;
    hsh = hsh.wrapping_mul(0x2C1B_3C6D);
    hsh ^= hsh >> 12;
    (hsh & 0xFFFF) as i32 as f32 * (2.0 / 65535.0) - 1.0
}

/// A material ready for per-pixel lookups on one primitive.
#[derive(Debug, Clone, Copy)]
pub(super) enum Texture<'a> {
    /// One albedo.
    Solid([f32; 3]),
    /// Two halves split at a = 0.
    TwoBlock {
        /// a < 0.
        left: [f32; 3],
        /// a ≥ 0.
        right: [f32; 3],
    },
    /// A photo stretched over the primitive.
    Image {
        /// The photo.
        im: &'a RgbImage,
        /// Columns per metre of a, and the column at a = 0.
        sx: f32,
        /// Rows per metre of −b, and the row at b = 0.
        sy: f32,
    },
    /// Circular fiducials on a base colour.
    Circles {
        /// Albedo between the marks.
        base: [f32; 3],
        /// Outer radius, m.
        radius: f32,
        /// The marks.
        marks: &'a [CircleMark],
    },
    /// Painted squares on a base colour.
    Squares {
        /// Albedo between the squares.
        base: [f32; 3],
        /// The squares.
        squares: &'a [PaintedSquare],
    },
    /// Value noise.
    Noise {
        /// Mean albedo.
        base: [f32; 3],
        /// Relative amplitude.
        contrast: f32,
        /// 1 / cell size.
        inv_cell: f32,
    },
}

impl<'a> Texture<'a> {
    /// Prepares `m` for a primitive of half extents `half` (photos stretch over them).
    pub fn new(m: &'a Material, half: [f32; 2]) -> Self {
        match m {
            Material::Solid(c) => Self::Solid(*c),
            Material::TwoBlock { left, right } => Self::TwoBlock {
                left: *left,
                right: *right,
            },
            Material::Image(im) => Self::Image {
                im,
                sx: im.width() as f32 / (2.0 * half[0]),
                sy: im.height() as f32 / (2.0 * half[1]),
            },
            Material::Circles { base, radius, marks } => Self::Circles {
                base: *base,
                radius: *radius,
                marks,
            },
            Material::Squares { base, squares } => Self::Squares { base: *base, squares },
            Material::Noise { base, contrast, cell } => Self::Noise {
                base: *base,
                contrast: *contrast,
                inv_cell: 1.0 / cell,
            },
        }
    }

    /// Linear albedo at local (a, b), m, for a pixel of footprint `fp` (m).
    #[inline(always)]
    pub fn sample(&self, a: f32, b: f32, fp: f32) -> [f32; 3] {
        match self {
            Self::Solid(c) => *c,
            Self::TwoBlock { left, right } => {
                let wr = cov(a / fp.max(1e-6));
                [0, 1, 2].map(|c| left[c] + (right[c] - left[c]) * wr)
            }
            Self::Image { im, sx, sy } => {
                let (w, h) = (im.width(), im.height());
                let x = (a * sx + 0.5 * w as f32).clamp(0.0, w as f32 - 1.0) as usize;
                let y = (0.5 * h as f32 - b * sy).clamp(0.0, h as f32 - 1.0) as usize;
                let i = (y * w + x) * 3;
                let p = &im.as_bytes()[i..i + 3];
                let lin = &*PHOTO_LINEAR;
                [lin[p[0] as usize], lin[p[1] as usize], lin[p[2] as usize]]
            }
            Self::Circles { base, radius, marks } => circles(*base, *radius, marks, a, b, fp),
            Self::Squares { base, squares } => {
                let fp = fp.max(1e-6);
                let mut out = *base;
                for q in squares.iter() {
                    let c = cov((q.half - (a - q.a).abs()) / fp) * cov((q.half - (b - q.b).abs()) / fp);
                    if c > 0.0 {
                        out = [0, 1, 2].map(|i| out[i] + (q.albedo[i] - out[i]) * c);
                    }
                }
                out
            }
            Self::Noise {
                base,
                contrast,
                inv_cell,
            } => {
                let k = noise_gain(*contrast, *inv_cell, a, b, fp);
                [base[0] * k, base[1] * k, base[2] * k]
            }
        }
    }

    /// For value noise, writes each pixel's albedo multiplier (of the base colour) for
    /// local coordinates `a`, `b` and footprints `fp`, in one pass the compiler
    /// vectorises, and returns the base colour; other materials return `None` and are
    /// sampled per pixel with [`Texture::sample`].
    pub fn noise_row(&self, a: &[f32], b: &[f32], fp: &[f32], gain: &mut [f32]) -> Option<[f32; 3]> {
        let Self::Noise {
            base,
            contrast,
            inv_cell,
        } = *self
        else {
            return None;
        };
        let n = gain.len().min(a.len()).min(b.len()).min(fp.len());
        let (a, b, fp, gain) = (&a[..n], &b[..n], &fp[..n], &mut gain[..n]);
        for i in 0..n {
            gain[i] = noise_gain(contrast, inv_cell, a[i], b[i], fp[i]);
        }
        Some(base)
    }
}

/// Albedo of printed paper: the white margin and ring of a circle mark.
const MARK_WHITE: f32 = 0.85;
/// Albedo of the black print (a matte black ink's floor).
const MARK_BLACK: f32 = 0.04;

/// A circle-mark surface at (a, b): the pattern of [`CircleMark`], each edge anti-aliased
/// over the footprint `fp`.
#[inline]
fn circles(base: [f32; 3], radius: f32, marks: &[CircleMark], a: f32, b: f32, fp: f32) -> [f32; 3] {
    let fp = fp.max(1e-6);
    let reach = 1.3 * radius + fp;
    for m in marks {
        let (da, db) = (a - m.a, b - m.b);
        let r2 = da * da + db * db;
        if r2 >= reach * reach {
            continue;
        }
        let r = r2.sqrt();
        let inside = |edge: f32| cov((edge - r) / fp);
        let margin = inside(1.3 * radius);
        let core = inside(0.6 * radius);
        let ring = inside(0.8 * radius) - core;
        let off_bar = (db * m.dir[0] - da * m.dir[1]).abs();
        let bar = core * cov((0.12 * radius - off_bar) / fp);
        let black = (inside(radius) - ring - bar).max(0.0);
        let white = (margin - black).max(0.0);
        let rest = 1.0 - margin;
        return base.map(|c| c * rest + MARK_WHITE * white + MARK_BLACK * black);
    }
    base
}

/// Value noise's albedo multiplier at (a, b) for footprint `fp`: texture finer than the
/// pixel averages out, with full contrast up to half a cell per pixel and none from 1.5.
#[inline(always)]
#[allow(
    clippy::manual_clamp,
    reason = "max/min send NaN to 0 and vectorise; clamp keeps NaN"
)]
fn noise_gain(contrast: f32, inv_cell: f32, a: f32, b: f32, fp: f32) -> f32 {
    let n = cell_noise(fast_floor(a * inv_cell), fast_floor(b * inv_cell));
    let fade = (1.5 - fp * inv_cell).max(0.0).min(1.0);
    1.0 + contrast * n * fade
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    #[test]
    fn noise_texture_averages_out_below_the_pixel_footprint() {
        let m = Material::Noise {
            base: [0.2, 0.3, 0.4],
            contrast: 0.25,
            cell: 0.02,
        };
        let t = Texture::new(&m, [1.0; 2]);
        let spread = |fp: f32| {
            let v: Vec<f32> = (0..200).map(|i| t.sample(i as f32 * 0.013, 0.37, fp)[0]).collect();
            v.iter().cloned().fold(f32::MIN, f32::max) - v.iter().cloned().fold(f32::MAX, f32::min)
        };
        assert!(spread(0.005) > 0.08, "fine pixels see the texture: {}", spread(0.005));
        assert_eq!(spread(0.04), 0.0, "pixels two cells wide see the mean");
        // Floors of negative coordinates fall in their own cells, not cell 0 twice.
        assert_ne!(t.sample(-0.001, 0.0, 0.001), t.sample(0.001, 0.0, 0.001));
    }

    #[test]
    fn the_row_pass_matches_the_per_pixel_lookup() {
        let m = Material::Noise {
            base: [0.2, 0.3, 0.4],
            contrast: 0.25,
            cell: 0.02,
        };
        let t = Texture::new(&m, [1.0; 2]);
        let a: Vec<f32> = (0..97).map(|i| -0.9 + i as f32 * 0.0191).collect();
        let b: Vec<f32> = (0..97).map(|i| 3.1 - i as f32 * 0.0077).collect();
        let fp: Vec<f32> = (0..97).map(|i| 0.001 + i as f32 * 0.0004).collect();
        let mut gain = vec![0.0; 97];
        assert_eq!(t.noise_row(&a, &b, &fp, &mut gain), Some([0.2, 0.3, 0.4]));
        for i in 0..97 {
            let want = t.sample(a[i], b[i], fp[i]);
            assert!((want[1] - 0.3 * gain[i]).abs() < 1e-6, "{i}");
        }
        assert_eq!(
            Texture::new(&Material::Solid([0.5; 3]), [1.0; 2]).noise_row(&a, &b, &fp, &mut gain),
            None
        );
    }

    #[test]
    fn a_circle_mark_has_its_rings_and_its_bar_where_specified() {
        let base = [0.3, 0.3, 0.3];
        let r = 0.05;
        // Mark at (0.1, 0.2) with its bar turned 90°: along v.
        let m = Material::Circles {
            base,
            radius: r,
            marks: Arc::from(vec![CircleMark::new(0.1, 0.2, std::f32::consts::FRAC_PI_2)]),
        };
        let t = Texture::new(&m, [1.0; 2]);
        let at = |da: f32, db: f32| t.sample(0.1 + da, 0.2 + db, 1e-4)[0];
        assert_eq!(at(0.0, 0.0), MARK_WHITE, "the bar crosses the centre");
        assert_eq!(at(0.0, 0.5 * r), MARK_WHITE, "and runs along v");
        assert_eq!(at(0.5 * r, 0.0), MARK_BLACK, "the core beside the bar is black");
        assert_eq!(at(-0.7 * r, 0.0), MARK_WHITE, "the white ring");
        assert_eq!(at(0.0, -0.9 * r), MARK_BLACK, "the black outer ring");
        assert_eq!(at(0.7, 0.0), 0.3, "far away: the surface");
        assert_eq!(at(1.2 * r, 0.0), MARK_WHITE, "the margin");
        assert_eq!(at(2.0 * r, 0.0), 0.3, "beyond it, the surface");
        // Anti-aliased: a footprint as wide as the ring averages it with the black around.
        let blurred = t.sample(0.1 - 0.7 * r, 0.2, 0.4 * r)[0];
        assert!(blurred > MARK_BLACK && blurred < MARK_WHITE, "{blurred}");
    }

    #[test]
    fn fast_floor_of_far_away_coordinates_is_harmless() {
        for x in [1e30f32, -1e30, f32::INFINITY, f32::NEG_INFINITY, f32::NAN, 5e6, -5e6] {
            let _ = fast_floor(x); // no overflow panic, in any build
            let _ = noise_gain(0.5, 50.0, x, -x, 0.01).is_finite();
        }
    }

    #[test]
    fn fast_floor_is_floor() {
        for i in -4000..4000 {
            let x = i as f32 * 0.37 + 0.01;
            if x.fract() == 0.0 {
                assert!(fast_floor(x) - x as i32 <= 0 && fast_floor(x) - x as i32 >= -1, "{x}");
            } else {
                assert_eq!(fast_floor(x), x.floor() as i32, "{x}");
            }
        }
    }

    #[test]
    fn a_photo_is_stretched_over_the_primitive_with_row_zero_on_top() {
        let mut im = RgbImage::new(2, 2);
        im.as_bytes_mut()
            .copy_from_slice(&[255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255]);
        let m = Material::Image(Arc::new(im));
        let t = Texture::new(&m, [0.5, 0.5]);
        let lin1 = srgb_to_linear(1.0) * 0.8;
        assert_eq!(t.sample(-0.25, 0.25, 0.01), [lin1, 0.0, 0.0], "top left");
        assert_eq!(t.sample(0.25, 0.25, 0.01), [0.0, lin1, 0.0], "top right");
        assert_eq!(t.sample(-0.25, -0.25, 0.01), [0.0, 0.0, lin1], "bottom left");
        // Outside the photo, the edge pixel.
        assert_eq!(t.sample(9.0, -9.0, 0.01), [lin1; 3]);
    }
}
