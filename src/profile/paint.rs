//! How a named paint looks: the one paint model shared by the segmentation's table
//! defaults and the simulator's painted surfaces.
//!
//! No real paint or ink is a pure sRGB primary. The binder's surface reflects about 4 % of
//! all light (Fresnel at n ≈ 1.5) and pigments leak a few per cent outside their band, so
//! a blue flap still returns some red and green. A paint is therefore its pigment's
//! reflectance, peaking at [`PAINT_PEAK`], plus a floor of [`PAINT_FLOOR`] at every
//! wavelength.
//!
//! The floor moves a paint's SCT angles far from its pigment's: blue's pigment
//! (0, 64, 255) sits at B = 90°, the painted flap at B = 55° (measured on rendered frames
//! in lab light: 56°, `tests/paint_sct.rs`). The fallback table therefore starts from the
//! paint's colour, [`NamedColor::paint_srgb`], as a colorimeter would give it, not from
//! the pigment's nominal sRGB: a table at B = 90° ± 24° never segments blue paint.

use super::NamedColor;

/// Peak reflectance of a pigment's band (a matte paint's white is about 85 %).
pub const PAINT_PEAK: f32 = 0.85;

/// Reflectance every paint returns at every wavelength (see the module docs).
pub const PAINT_FLOOR: f32 = 0.04;

/// The sRGB transfer function's inverse (perception's, which weighs marker pixels in
/// linear light with it).
pub use crate::perception::srgb_to_linear;

/// The sRGB transfer function: linear light in [0, 1] to a code value in [0, 1].
pub fn linear_to_srgb(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

impl NamedColor {
    /// Linear reflectance of the paint in (R, G, B): the pigment's nominal sRGB
    /// ([`NamedColor::rgb`]) scaled to [`PAINT_PEAK`] above a floor of [`PAINT_FLOOR`].
    ///
    /// ```
    /// use marsupial::profile::NamedColor;
    /// let r = NamedColor::Blue.reflectance();
    /// assert!((r[0] - 0.04).abs() < 1e-6 && (r[2] - 0.85).abs() < 1e-6);
    /// ```
    pub fn reflectance(&self) -> [f32; 3] {
        let k = PAINT_PEAK - PAINT_FLOOR;
        self.rgb().map(|c| srgb_to_linear(c as f32 / 255.0) * k + PAINT_FLOOR)
    }

    /// The paint's colour under white light, in 8-bit sRGB: what a colorimeter (or a
    /// white-balanced camera at full exposure) reads off the painted surface. The
    /// segmentation's table defaults start here.
    ///
    /// ```
    /// use marsupial::perception::Sct;
    /// use marsupial::profile::NamedColor;
    /// // Blue paint is far bluer-green than its pigment in SCT's B angle.
    /// let painted = Sct::from_rgb(NamedColor::Blue.paint_srgb()).b.to_degrees();
    /// assert!((painted - 55.1).abs() < 0.5, "{painted}");
    /// assert_eq!(NamedColor::Cyan.paint_srgb(), [56, 237, 237]);
    /// ```
    pub fn paint_srgb(&self) -> [u8; 3] {
        self.reflectance()
            .map(|x| (linear_to_srgb(x) * 255.0).round().clamp(0.0, 255.0) as u8)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn transfer_functions_invert_each_other() {
        for i in 0..=255u16 {
            let c = f32::from(i) / 255.0;
            assert!((linear_to_srgb(srgb_to_linear(c)) - c).abs() < 1e-5, "{i}");
        }
    }

    #[test]
    fn every_paint_stays_off_the_cube_faces() {
        for c in [
            NamedColor::Cyan,
            NamedColor::Magenta,
            NamedColor::Yellow,
            NamedColor::Orange,
            NamedColor::Blue,
            NamedColor::Red,
            NamedColor::Green,
            NamedColor::White,
            NamedColor::Black,
        ] {
            let s = c.paint_srgb();
            assert!(s.iter().all(|&v| (56..=237).contains(&v)), "{c:?} {s:?}");
        }
    }
}
