//! The lens and shutter's imperfections, applied to a frame's linear radiance before the
//! sensor exposes it: defocus, motion blur, a rolling shutter and vignetting.
//!
//! * **Defocus** (thin lens). A point at depth Z seen through a lens of focal length F and
//!   aperture diameter A = F/N (f-number N), focused at s, images as a disc of diameter
//!   c = A·F/(s − F)·|Z − s|/Z on the sensor, which is c_px = A·f_px·s/(s − F)·|1/s − 1/Z|
//!   pixels for a camera of f_px pixels focal length. Each pixel is replaced by the mean of
//!   a square box (a horizontal then a vertical pass) whose side √12/4 ≈ 0.87·c_px gives
//!   the box the disc's second moment. Simplified: the box is gathered at each pixel with
//!   that pixel's own depth (so a blurred near edge does not spill over a sharp background
//!   behind it, and a sharp far pixel does not take in the near blur), and a box is not a
//!   disc.
//! * **Motion blur and rolling shutter** (the camera's own motion). A static point at
//!   P = Z·(x, y, 1) in the camera frame moves as Ṗ = −ω × P − v for a camera turning at ω
//!   and moving at v (both in the camera frame), so its normalised image coordinate moves
//!   at ẋ = −ω_y(1 + x²) + ω_x·x·y + ω_z·y + (x·v_z − v_x)/Z: yaw, through ω_y, dominates on
//!   a skid-steer robot, and the translation term needs the pixel's depth Z. Row r is
//!   exposed over T seconds centred on t_r = (r + ½ − H/2)/H × readout (the middle row at
//!   the rendered instant), so the output pixel is the mean of its row of the rendered
//!   image over [x − f_px·ẋ·t_r − f_px·|ẋ|·T/2, … + f_px·|ẋ|·T/2]: a shift (the rolling
//!   shutter's skew) and a box (the blur). Simplified: only the horizontal image motion
//!   is modelled (the vertical, which on a level camera is the small radial part of
//!   forward motion, is dropped), the flow is taken at the output pixel with its own depth
//!   (a gather, like the defocus), and occlusions revealed by the motion are not rendered.
//! * **Vignetting** by the cos⁴ law: an off-axis pixel at angle θ receives cos⁴θ =
//!   1/(1 + tan²θ)² of the on-axis light. We keep its shape but scale the angle so the
//!   corner gets the stated relative illumination c: gain(ρ) = 1/(1 + a·ρ²)² with ρ the
//!   distance from the image centre over the centre-to-corner distance and
//!   a = 1/√c − 1 (a real lens adds mechanical vignetting to the natural cos⁴ falloff, so
//!   the corner value is the parameter, not the field of view).
//!
//! All of it works on rows through prefix sums (the integral of a row, piecewise
//! constant over its pixels), so a box of any fractional width costs two lookups, and a
//! box narrower than a pixel, centred on it, leaves the pixel exactly as it was.

/// A stand-in depth for pixels that see the sky, m: far enough for no translation flow
/// and no defocus difference from infinity that matters.
pub(super) const SKY_DEPTH: f32 = 1.0e4;

/// The camera's motion during an exposure, in the camera frame (x right, y down, z along
/// the optical axis): what the simulator knows of the robot's true motion at the frame.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct CameraMotion {
    /// Angular velocity of the camera, rad/s, camera frame.
    pub omega: [f32; 3],
    /// Linear velocity of the optical centre, m/s, camera frame.
    pub velocity: [f32; 3],
}

/// The thin lens: what the defocus blur needs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lens {
    /// Distance the lens is focused at, m.
    pub focus_m: f32,
    /// Aperture diameter A = F/N, m.
    pub aperture_m: f32,
    /// Focal length F, m.
    pub focal_m: f32,
    /// Focal length in pixels.
    pub f_px: f32,
}

impl Lens {
    /// Diameter of the circle of confusion, px, of a point at depth `z` m (module docs).
    pub fn coc_px(&self, z: f32) -> f32 {
        let s = self.focus_m;
        let k = self.aperture_m * self.f_px * s / (s - self.focal_m).max(1e-6);
        k * (1.0 / s - 1.0 / z.max(1e-3)).abs()
    }

    /// The depths (near, far), m, between which the box standing for the circle of
    /// confusion is at most `px` pixels wide after scaling by `scale`: a pixel there
    /// needs no blur, which a comparison tells without a division.
    fn sharp_depths(&self, scale: f32, px: f32) -> (f32, f32) {
        let s = self.focus_m;
        let k = scale * self.aperture_m * self.f_px * s / (s - self.focal_m).max(1e-6);
        let d = px / k.max(1e-12);
        let near = 1.0 / (1.0 / s + d);
        let far = if 1.0 / s - d > 0.0 {
            1.0 / (1.0 / s - d)
        } else {
            f32::INFINITY
        };
        (near, far)
    }
}

/// Row scratch: a line of values and its prefix sums.
#[derive(Debug, Clone, Default)]
pub(super) struct Scratch {
    line: Vec<[f32; 3]>,
    prefix: Vec<[f32; 3]>,
    width: Vec<f32>,
    shift: Vec<f32>,
}

impl Scratch {
    /// Sizes the scratch for lines up to `n` long (allocates only when growing).
    fn reserve(&mut self, n: usize) {
        if self.line.len() < n {
            self.line.resize(n, [0.0; 3]);
            self.prefix.resize(n + 1, [0.0; 3]);
            self.width.resize(n, 0.0);
            self.shift.resize(n, 0.0);
        }
    }
}

/// The integral from 0 to `a` (clamped to the line) of the piecewise-constant line
/// (pixel i covers [i, i + 1)) whose prefix sums are `p` (`p[i]` = the sum of the first
/// i pixels; a pixel's value is the difference of two, so the line itself may be
/// overwritten while its integral is read).
#[inline]
fn integral(p: &[[f32; 3]], a: f32) -> [f32; 3] {
    let n = p.len() - 1;
    let a = a.clamp(0.0, n as f32);
    let i = (a as usize).min(n - 1);
    let f = a - i as f32;
    let (lo, hi) = (p[i], p[i + 1]);
    [
        lo[0] + f * (hi[0] - lo[0]),
        lo[1] + f * (hi[1] - lo[1]),
        lo[2] + f * (hi[2] - lo[2]),
    ]
}

/// Replaces each value of `line` by its mean over [centre − w/2, centre + w/2] with
/// centre = i + ½ + `shift[i]` and w = `width[i]`, the box clipped to the line (the mean
/// over what is left of it; a box wholly off the line takes the nearest end pixel).
/// `prefix` is scratch, one longer than the line.
fn box_line(line: &mut [[f32; 3]], prefix: &mut [[f32; 3]], width: &[f32], shift: &[f32]) {
    let n = line.len();
    if n == 0 {
        return;
    }
    let mut acc = [0.0f32; 3];
    prefix[0] = acc;
    for (p, v) in prefix[1..=n].iter_mut().zip(line.iter()) {
        acc = [acc[0] + v[0], acc[1] + v[1], acc[2] + v[2]];
        *p = acc;
    }
    let p = &prefix[..=n];
    let nf = n as f32;
    for i in 0..n {
        let w = width[i].max(0.0);
        let centre = i as f32 + 0.5 + shift[i];
        let (lo, hi) = ((centre - 0.5 * w).clamp(0.0, nf), (centre + 0.5 * w).clamp(0.0, nf));
        if hi - lo < 1e-4 {
            // A box of no width, or wholly off the line: the pixel under its centre.
            let j = centre.clamp(0.0, nf - 1.0) as usize;
            let (a, b) = (p[j], p[j + 1]);
            line[i] = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            continue;
        }
        let (a, b) = (integral(p, lo), integral(p, hi));
        let inv = 1.0 / (hi - lo);
        line[i] = [(b[0] - a[0]) * inv, (b[1] - a[1]) * inv, (b[2] - a[2]) * inv];
    }
}

/// Defocus of `radiance` (`width` wide) by `lens`, each pixel's circle of confusion from
/// its depth in `depth` (module docs).
pub(super) fn defocus(radiance: &mut [[f32; 3]], depth: &[f32], width: usize, lens: &Lens, s: &mut Scratch) {
    let height = radiance.len() / width.max(1);
    s.reserve(width.max(height));
    const BOX_OF_DISC: f32 = 0.866_025_4; // √12 / 4
    let Scratch {
        line,
        prefix,
        width: w,
        shift,
    } = s;
    shift[..width.max(height)].fill(0.0);
    // A box within its own pixel changes nothing: rows and columns whose every depth is
    // in this range are left alone.
    let (near, far) = lens.sharp_depths(BOX_OF_DISC, 1.0);
    let sharp = |z: f32| z >= near && z <= far;
    for y in 0..height {
        let row = &mut radiance[y * width..(y + 1) * width];
        let d = &depth[y * width..(y + 1) * width];
        if d.iter().all(|&z| sharp(z)) {
            continue;
        }
        for (wi, &z) in w[..width].iter_mut().zip(d) {
            *wi = BOX_OF_DISC * lens.coc_px(z);
        }
        line[..width].copy_from_slice(row);
        box_line(&mut line[..width], &mut prefix[..=width], &w[..width], &shift[..width]);
        row.copy_from_slice(&line[..width]);
    }
    for x in 0..width {
        if (0..height).all(|y| sharp(depth[y * width + x])) {
            continue;
        }
        for y in 0..height {
            w[y] = BOX_OF_DISC * lens.coc_px(depth[y * width + x]);
            line[y] = radiance[y * width + x];
        }
        box_line(
            &mut line[..height],
            &mut prefix[..=height],
            &w[..height],
            &shift[..height],
        );
        for y in 0..height {
            radiance[y * width + x] = line[y];
        }
    }
}

/// A row whose every shift is below this, px, and whose blur stays within each pixel is
/// left as rendered: a fiftieth of a pixel changes no output level that matters.
const MIN_SHIFT_PX: f32 = 0.02;

/// What [`smear`] needs of the camera besides its motion.
#[derive(Debug, Clone, Copy)]
pub(super) struct Shutter {
    /// Exposure time, s.
    pub exposure_s: f32,
    /// Time from the first row's exposure to the last's, s (0: a global shutter).
    pub readout_s: f32,
    /// Focal length in pixels.
    pub f_px: f32,
}

/// Motion blur and rolling-shutter skew of `radiance` from the camera's `motion`
/// (module docs). `rays` are the unit rays per pixel (x, y, z components), `depth` each
/// pixel's depth along the optical axis.
pub(super) fn smear(
    radiance: &mut [[f32; 3]],
    depth: &[f32],
    rays: [&[f32]; 3],
    width: usize,
    motion: &CameraMotion,
    shutter: &Shutter,
    s: &mut Scratch,
) {
    let height = radiance.len() / width.max(1);
    s.reserve(width);
    let [wx, wy, wz] = motion.omega;
    let [vx, _, vz] = motion.velocity;
    let f = shutter.f_px;
    for y in 0..height {
        let t_row = ((y as f32 + 0.5) / height as f32 - 0.5) * shutter.readout_s;
        let base = y * width;
        let mut moved = false;
        for x in 0..width {
            let i = base + x;
            let rz = rays[2][i].max(1e-3);
            let (xn, yn) = (rays[0][i] / rz, rays[1][i] / rz);
            let z = depth[i].max(1e-3);
            let xdot = -wy * (1.0 + xn * xn) + wx * xn * yn + wz * yn + (xn * vz - vx) / z;
            let u = f * xdot; // px/s
            s.shift[x] = -u * t_row;
            s.width[x] = u.abs() * shutter.exposure_s;
            moved |= s.shift[x].abs() > MIN_SHIFT_PX || s.width[x] > 1.0;
        }
        if !moved {
            continue;
        }
        let row = &mut radiance[base..base + width];
        s.line[..width].copy_from_slice(row);
        box_line(
            &mut s.line[..width],
            &mut s.prefix[..=width],
            &s.width[..width],
            &s.shift[..width],
        );
        row.copy_from_slice(&s.line[..width]);
    }
}

/// Per-pixel cos⁴-law gains for a `width × height` image whose corners receive `corner`
/// of the centre's light (module docs), into `gains`.
pub(super) fn vignette_gains(width: usize, height: usize, corner: f32, gains: &mut Vec<f32>) {
    gains.clear();
    let a = 1.0 / corner.clamp(1e-3, 1.0).sqrt() - 1.0;
    let (cx, cy) = (width as f32 / 2.0, height as f32 / 2.0);
    let r2_corner = (cx * cx + cy * cy).max(1e-6);
    for y in 0..height {
        for x in 0..width {
            let (dx, dy) = (x as f32 + 0.5 - cx, y as f32 + 0.5 - cy);
            let q = 1.0 + a * (dx * dx + dy * dy) / r2_corner;
            gains.push(1.0 / (q * q));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line_of(values: &[f32]) -> Vec<[f32; 3]> {
        values.iter().map(|&v| [v; 3]).collect()
    }

    #[test]
    fn a_box_within_its_pixel_changes_nothing_and_a_wide_one_averages() {
        let mut line = line_of(&[0.0, 1.0, 0.0, 0.0, 4.0, 0.0]);
        let original = line.clone();
        let mut prefix = vec![[0.0; 3]; 7];
        box_line(&mut line, &mut prefix, &[1.0; 6], &[0.0; 6]);
        assert_eq!(line, original);
        // Width 3 centred on pixel 4: (0 + 4 + 0) / 3.
        box_line(&mut line, &mut prefix, &[3.0; 6], &[0.0; 6]);
        assert!((line[4][0] - 4.0 / 3.0).abs() < 1e-6, "{:?}", line[4]);
        // A shift of one pixel samples the neighbour.
        let mut line = original.clone();
        box_line(&mut line, &mut prefix, &[1.0; 6], &[-1.0; 6]);
        assert!((line[2][0] - 1.0).abs() < 1e-6, "{:?}", line);
    }

    #[test]
    fn the_corner_gets_the_stated_light_and_the_centre_all_of_it() {
        let mut g = Vec::new();
        vignette_gains(200, 100, 0.6, &mut g);
        let corner = g[0];
        let centre = g[50 * 200 + 100];
        // The pixel centres are half a pixel inside the corner.
        assert!((corner - 0.6).abs() < 0.01, "corner {corner}");
        assert!(centre > 0.999, "centre {centre}");
        vignette_gains(20, 10, 1.0, &mut g);
        assert!(g.iter().all(|&v| v == 1.0));
    }

    #[test]
    fn the_circle_of_confusion_follows_the_thin_lens() {
        // 3.6 mm f/2 focused at 1 m, 183 px focal length: in focus at 1 m, 0.67 px at
        // 0.33 m, and at infinity A·f_px/s·s/(s − F).
        let lens = Lens {
            focus_m: 1.0,
            aperture_m: 0.0018,
            focal_m: 0.0036,
            f_px: 183.0,
        };
        assert!(lens.coc_px(1.0) < 1e-4);
        let near = lens.coc_px(0.33);
        assert!(
            (near - 0.0018 * 183.0 / 0.9964 * (1.0 / 0.33 - 1.0)).abs() < 1e-3,
            "{near}"
        );
        let far = lens.coc_px(SKY_DEPTH);
        assert!((far - 0.0018 * 183.0 / 0.9964).abs() < 1e-3, "{far}");
    }
}
