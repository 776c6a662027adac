//! The camera renderer: ray casting over screen-space bounding boxes, painter's order,
//! analytic anti-aliasing, then a sensor model.
//!
//! Each frame, every primitive is moved into the camera frame once; per-pixel rays are a
//! table computed when the renderer is built (so pin-hole and fisheye cameras share one
//! path). The ground is drawn first, then primitives far to near, each only over the
//! pixels its projected bounds cover. Edges are anti-aliased analytically: the signed
//! distance from a ray's hit point to the primitive's boundary, divided by the pixel's
//! footprint at that depth, gives a coverage in [0, 1] that blends over what lies behind,
//! so moving a target by a fraction of a pixel changes the image.
//!
//! The sensor then applies white balance, exposure (auto-exposure moves only halfway
//! toward the level this frame needs, in log terms, so a sudden light change over- or
//! under-exposes the next few frames), shot
//! and read noise from a per-frame offset into a seeded noise table, clipping at
//! saturation, and sRGB gamma into 8-bit RGB.

use super::lighting::LightState;
use super::rng::NoiseTable;
use super::scene::{Material, Prim, Scene, Shape};
use crate::perception::RgbImage;
use crate::perception::camera_model::CameraModel;
use nalgebra::{Matrix3, Point3, Vector3};

/// Sensor settings (from the scenario).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorParams {
    /// Read noise SD, in 8-bit linear units.
    pub read_noise: f32,
    /// Shot-noise scale: SD = shot·√(signal) in 8-bit linear units.
    pub shot_noise: f32,
    /// Fixed exposure multiplier when auto-exposure is off.
    pub exposure: f32,
    /// Follow the scene brightness.
    pub auto_exposure: bool,
    /// Mean linear level auto-exposure aims for (0–1).
    pub target_level: f32,
    /// Analogue gain.
    pub gain: f32,
    /// Per-channel white-balance multipliers (1, 1, 1 is neutral).
    pub white_balance: [f32; 3],
    /// Highlight protection of auto-exposure: the largest fraction of pixels allowed to
    /// clip in any channel (1 = plain mean metering, which burns out a bright target in
    /// front of a dark body).
    pub highlight_clip: f32,
}

impl Default for SensorParams {
    fn default() -> Self {
        Self {
            read_noise: 1.5,
            shot_noise: 0.35,
            exposure: 1.0,
            auto_exposure: true,
            target_level: 0.18,
            gain: 1.0,
            white_balance: [1.0; 3],
            highlight_clip: 0.01,
        }
    }
}

/// A camera's pose in the world: rotation world ← camera, and position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraPose {
    /// Rotation taking camera-frame vectors to the world frame.
    pub rotation: Matrix3<f64>,
    /// Optical centre in the world, m.
    pub position: Point3<f64>,
}

/// Primitive moved into the camera frame, in `f32`.
#[derive(Debug, Clone, Copy)]
struct Local {
    /// Centre or origin.
    o: [f32; 3],
    u: [f32; 3],
    v: [f32; 3],
    n: [f32; 3],
    half: [f32; 2],
    kind: u8, // 0 rect, 1 disc, 2 triangle (o = p0, u = p1 − p0, v = p2 − p0), 3 sphere (half[0] = radius)
}

#[inline]
fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
fn cov(d: f32) -> f32 {
    (0.5 + d).clamp(0.0, 1.0)
}

/// Renders frames of one camera.
#[derive(Debug, Clone)]
pub struct Renderer {
    model: CameraModel,
    width: usize,
    height: usize,
    rays: Vec<[f32; 3]>,
    /// Angular size of each pixel, rad.
    pix_angle: Vec<f32>,
    radiance: Vec<[f32; 3]>,
    /// Accumulated coverage per pixel (front-to-back compositing).
    alpha: Vec<f32>,
    order: Vec<(f32, usize)>,
    noise: NoiseTable,
    to_srgb: Vec<u8>,
    sd_out: Vec<i32>,
    exposure: f32,
    /// Histogram of sampled pixels' brightest channel, by [`octave_bin`].
    highlights: [u32; HIGHLIGHT_BINS],
}

/// Bins of the highlight histogram: sixteen per octave, from 2⁻¹² to 2⁴ of full scale.
const HIGHLIGHT_BINS: usize = 256;

/// Highlight-histogram bin of a linear level `v` > 0: the float's exponent and top four
/// mantissa bits (sixteen equal steps per octave, none wider than 6.25 %), offset so 2⁻¹²
/// is bin 0. No `log2` call: it runs on every sampled pixel.
#[inline]
fn octave_bin(v: f32) -> usize {
    let code = (v.max(1e-30).to_bits() >> 19) as i64 - ((127 - 12) << 4);
    code.clamp(0, HIGHLIGHT_BINS as i64 - 1) as usize
}

/// The upper edge (linear level) of highlight bin `b`.
fn octave_bin_top(b: usize) -> f32 {
    f32::from_bits((((b as u32) + 1 + ((127 - 12) << 4)) << 19).min(0x7f7f_ffff))
}

const LUT_BITS: usize = 12;
const LUT_MAX: f32 = ((1 << LUT_BITS) - 1) as f32;

impl Renderer {
    /// A renderer for `model` at `width × height`; `noise_seed` seeds the noise table.
    pub fn new(model: CameraModel, width: usize, height: usize, noise_seed: u64) -> Self {
        let mut rays = Vec::with_capacity(width * height);
        let mut pix_angle = Vec::with_capacity(width * height);
        for y in 0..height {
            for x in 0..width {
                let (u, v) = (x as f64 + 0.5, y as f64 + 0.5);
                let r = model.ray(u, v);
                let r1 = model.ray(u + 1.0, v);
                rays.push([r.x as f32, r.y as f32, r.z as f32]);
                pix_angle.push(r.angle(&r1).max(1e-5) as f32);
            }
        }
        let to_srgb = (0..=1usize << LUT_BITS)
            .map(|i| {
                let l = (i as f32 / LUT_MAX).min(1.0);
                let s = if l <= 0.003_130_8 {
                    12.92 * l
                } else {
                    1.055 * l.powf(1.0 / 2.4) - 0.055
                };
                (s * 255.0 + 0.5).clamp(0.0, 255.0) as u8
            })
            .collect();
        Self {
            model,
            width,
            height,
            rays,
            pix_angle,
            radiance: vec![[0.0; 3]; width * height],
            alpha: vec![0.0; width * height],
            order: Vec::new(),
            noise: NoiseTable::new(noise_seed),
            to_srgb,
            sd_out: vec![0; 256],
            exposure: 1.0,
            highlights: [0; HIGHLIGHT_BINS],
        }
    }

    /// (width, height).
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// The camera model.
    pub fn model(&self) -> &CameraModel {
        &self.model
    }

    /// Current exposure multiplier.
    pub fn exposure(&self) -> f32 {
        self.exposure
    }

    /// Renders `scene` seen from `pose` under `light` into `out` (resized if needed).
    /// `frame_seed` picks this frame's noise.
    pub fn render(
        &mut self,
        scene: &Scene,
        pose: &CameraPose,
        light: &LightState,
        sensor: &SensorParams,
        frame_seed: u64,
        out: &mut RgbImage,
    ) {
        let rt = pose.rotation.transpose(); // camera ← world
        let to_cam = |p: &Point3<f64>| -> Vector3<f64> { rt * (p - pose.position) };
        let f3 = |v: Vector3<f64>| [v.x as f32, v.y as f32, v.z as f32];
        for (px, a) in self.radiance.iter_mut().zip(self.alpha.iter_mut()) {
            *px = [0.0; 3];
            *a = 0.0;
        }
        // Front to back by centre distance: pixels already fully covered are skipped.
        self.order.clear();
        for (i, p) in scene.prims.iter().enumerate() {
            let c = match &p.shape {
                Shape::Rect { centre, .. } | Shape::Disc { centre, .. } | Shape::Sphere { centre, .. } => *centre,
                Shape::Triangle { p } => Point3::from((p[0].coords + p[1].coords + p[2].coords) / 3.0),
            };
            self.order.push(((c - pose.position).norm() as f32, i));
        }
        self.order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        for k in 0..self.order.len() {
            let prim = &scene.prims[self.order[k].1];
            let local = match &prim.shape {
                Shape::Rect { centre, u, v, half } => Local {
                    o: f3(to_cam(centre)),
                    u: f3(rt * u),
                    v: f3(rt * v),
                    n: f3(rt * u.cross(v)),
                    half: [half[0] as f32, half[1] as f32],
                    kind: 0,
                },
                Shape::Disc { centre, u, v, radius } => Local {
                    o: f3(to_cam(centre)),
                    u: f3(rt * u),
                    v: f3(rt * v),
                    n: f3(rt * u.cross(v)),
                    half: [*radius as f32; 2],
                    kind: 1,
                },
                Shape::Triangle { p } => {
                    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
                    Local {
                        o: f3(to_cam(&p[0])),
                        u: f3(rt * e1),
                        v: f3(rt * e2),
                        n: f3(rt * e1.cross(&e2).normalize()),
                        half: [0.0; 2],
                        kind: 2,
                    }
                }
                Shape::Sphere { centre, radius } => Local {
                    o: f3(to_cam(centre)),
                    u: [1.0, 0.0, 0.0],
                    v: [0.0, 1.0, 0.0],
                    n: [0.0, 0.0, 1.0],
                    half: [*radius as f32; 2],
                    kind: 3,
                },
            };
            // A one-sided plane seen from behind is invisible.
            if !prim.two_sided && local.kind != 3 && dot(local.n, local.o) >= 0.0 {
                continue;
            }
            let Some(bbox) = self.screen_bounds(prim, &to_cam) else {
                continue;
            };
            let world_n = match &prim.shape {
                Shape::Rect { u, v, .. } | Shape::Disc { u, v, .. } => u.cross(v),
                Shape::Triangle { p } => (p[1] - p[0]).cross(&(p[2] - p[0])).normalize(),
                Shape::Sphere { .. } => Vector3::z(),
            };
            let centre = match &prim.shape {
                Shape::Rect { centre, .. } | Shape::Disc { centre, .. } | Shape::Sphere { centre, .. } => *centre,
                Shape::Triangle { p } => p[0],
            };
            let irr = light.irradiance_at(&world_n, &centre, prim.tag);
            let spec_dir = f3(rt * light.key_direction());
            self.draw_prim(prim, &local, bbox, irr, light, spec_dir);
        }
        self.draw_ground(scene, pose, light);
        self.expose(sensor, frame_seed, out);
    }

    fn screen_bounds(&self, prim: &Prim, to_cam: &dyn Fn(&Point3<f64>) -> Vector3<f64>) -> Option<[usize; 4]> {
        let full = Some([0, 0, self.width, self.height]);
        // Fixed-size scratch: culling runs for every primitive every frame.
        let corners = prim.bounds();
        let mut pts = [Vector3::zeros(); 8];
        let n = corners.as_slice().len();
        for (q, p) in pts.iter_mut().zip(corners.as_slice()) {
            *q = to_cam(p);
        }
        let pts = &pts[..n];
        let fisheye = matches!(self.model, CameraModel::Fisheye(_));
        if fisheye {
            // Wide-angle projection bends edges: project the corners, widen generously, and
            // fall back to the whole frame when a corner is outside the model's field.
            let mut lo = [f64::INFINITY; 2];
            let mut hi = [f64::NEG_INFINITY; 2];
            for p in pts {
                let px = self.model.project(p)?;
                for i in 0..2 {
                    lo[i] = lo[i].min(px[i]);
                    hi[i] = hi[i].max(px[i]);
                }
            }
            let pad = 0.25 * (hi[0] - lo[0]).max(hi[1] - lo[1]) + 3.0;
            return self
                .clip_box([lo[0] - pad, lo[1] - pad, hi[0] + pad, hi[1] + pad])
                .or(full);
        }
        // Pin-hole: clip the outline (a polygon, or the box corners of a sphere) to z ≥ near,
        // then project. Clipping a polygon against one plane adds at most one vertex.
        const NEAR: f64 = 1e-3;
        let mut clipped = [Vector3::zeros(); 9];
        let mut m = 0;
        if matches!(prim.shape, Shape::Sphere { .. }) {
            if pts.iter().all(|p| p.z <= NEAR) {
                return None;
            }
            if pts.iter().any(|p| p.z <= NEAR) {
                return full;
            }
            clipped[..n].copy_from_slice(pts);
            m = n;
        } else {
            for i in 0..n {
                let (a, b) = (pts[i], pts[(i + 1) % n]);
                if a.z >= NEAR {
                    clipped[m] = a;
                    m += 1;
                }
                if (a.z >= NEAR) != (b.z >= NEAR) {
                    let t = (NEAR - a.z) / (b.z - a.z);
                    clipped[m] = a + (b - a) * t;
                    m += 1;
                }
            }
        }
        let outline = &clipped[..m];
        if outline.is_empty() {
            return None;
        }
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for p in outline {
            // Project without distortion first (exact for the clipped polygon's extent)…
            let (x, y) = (p.x / p.z, p.y / p.z);
            let px = match &self.model {
                CameraModel::Pinhole(m) if m.k1 == 0.0 && m.k2 == 0.0 => [m.fx * x + m.cx, m.fy * y + m.cy],
                _ => match self.model.project(p) {
                    Some(px) => px,
                    None => return full,
                },
            };
            for i in 0..2 {
                lo[i] = lo[i].min(px[i]);
                hi[i] = hi[i].max(px[i]);
            }
        }
        let distorted = matches!(&self.model, CameraModel::Pinhole(m) if m.k1 != 0.0 || m.k2 != 0.0);
        let pad = if distorted {
            0.1 * (hi[0] - lo[0]).max(hi[1] - lo[1]) + 2.0
        } else {
            2.0
        };
        self.clip_box([lo[0] - pad, lo[1] - pad, hi[0] + pad + 1.0, hi[1] + pad + 1.0])
    }

    fn clip_box(&self, b: [f64; 4]) -> Option<[usize; 4]> {
        let (w, h) = (self.width as f64, self.height as f64);
        if !b.iter().all(|v| v.is_finite()) {
            return None;
        }
        let x0 = b[0].floor().clamp(0.0, w);
        let y0 = b[1].floor().clamp(0.0, h);
        let x1 = b[2].ceil().clamp(0.0, w);
        let y1 = b[3].ceil().clamp(0.0, h);
        (x0 < x1 && y0 < y1).then_some([x0 as usize, y0 as usize, x1 as usize, y1 as usize])
    }

    fn draw_ground(&mut self, scene: &Scene, pose: &CameraPose, light: &LightState) {
        let r = pose.rotation;
        let row = |i: usize| [r[(i, 0)] as f32, r[(i, 1)] as f32, r[(i, 2)] as f32];
        let (rx, ry, rz) = (row(0), row(1), row(2));
        let cz = pose.position.z as f32;
        let (cx, cy) = (pose.position.x as f32, pose.position.y as f32);
        let irr = light.irradiance(&Vector3::z());
        let sky = scene.sky.map(|s| s * light.sky_scale());
        for (((px, alpha), ray), ang) in self
            .radiance
            .iter_mut()
            .zip(&self.alpha)
            .zip(&self.rays)
            .zip(&self.pix_angle)
        {
            let rest = 1.0 - *alpha;
            if rest <= 1e-3 {
                continue;
            }
            let dz = dot(rz, *ray);
            if dz >= -1e-4 || cz <= 0.0 {
                for c in 0..3 {
                    px[c] += rest * sky[c];
                }
                continue;
            }
            let t = -cz / dz;
            let (gx, gy) = (cx + t * dot(rx, *ray), cy + t * dot(ry, *ray));
            let fp = t * ang / (-dz).max(0.05);
            let a = sample(&scene.ground, gx, gy, fp, [1e9, 1e9]);
            // Fade to the sky colour far away (haze), which also hides texture aliasing.
            let haze = (t / 40.0).min(1.0);
            for c in 0..3 {
                px[c] += rest * (a[c] * irr[c] * (1.0 - haze) + sky[c] * haze);
            }
        }
    }

    fn draw_prim(
        &mut self,
        prim: &Prim,
        l: &Local,
        bbox: [usize; 4],
        irr: [f32; 3],
        light: &LightState,
        key: [f32; 3],
    ) {
        let w = self.width;
        let shadows = light.shadows_for(prim.tag);
        for y in bbox[1]..bbox[3] {
            for x in bbox[0]..bbox[2] {
                let i = y * w + x;
                let rest = 1.0 - self.alpha[i];
                if rest <= 1e-3 {
                    continue;
                }
                let r = self.rays[i];
                let ang = self.pix_angle[i];
                let Some((coverage, a, b, t, nr)) = intersect(l, r, ang, prim.two_sided) else {
                    continue;
                };
                if coverage <= 0.0 {
                    continue;
                }
                let fp = t * ang;
                let alb = sample(&prim.material, a, b, fp / nr.abs().max(0.1), l.half);
                let mut shade = 1.0f32;
                for s in shadows {
                    let d = a * s.cos + b * s.sin - s.offset;
                    shade *= 1.0 - s.strength * cov(d / (s.softness + fp));
                }
                let mut col = [
                    alb[0] * irr[0] * shade,
                    alb[1] * irr[1] * shade,
                    alb[2] * irr[2] * shade,
                ];
                if prim.gloss > 0.0 {
                    // Blinn–Phong highlight of the key light: glare on glossy targets.
                    let n = if l.kind == 3 {
                        let p = [r[0] * t - l.o[0], r[1] * t - l.o[1], r[2] * t - l.o[2]];
                        let len = dot(p, p).sqrt().max(1e-6);
                        [p[0] / len, p[1] / len, p[2] / len]
                    } else if nr > 0.0 {
                        [-l.n[0], -l.n[1], -l.n[2]]
                    } else {
                        l.n
                    };
                    let h = [key[0] - r[0], key[1] - r[1], key[2] - r[2]];
                    let hl = dot(h, h).sqrt().max(1e-6);
                    let nh = (dot(n, h) / hl).max(0.0);
                    let lit = dot(n, key).max(0.0);
                    let s = prim.gloss * light.glare_strength() * shade * SPECULAR_PEAK * lit * nh.powi(SPECULAR_EXP);
                    let kc = light.key_colour();
                    for c in 0..3 {
                        col[c] += s * kc[c];
                    }
                }
                let k = rest * coverage;
                let px = &mut self.radiance[i];
                for c in 0..3 {
                    px[c] += k * col[c];
                }
                self.alpha[i] += k;
            }
        }
    }

    fn expose(&mut self, sensor: &SensorParams, frame_seed: u64, out: &mut RgbImage) {
        let (w, h) = (self.width, self.height);
        out.resize(w, h);
        if sensor.auto_exposure {
            // Mean green level, subsampled, and a histogram of each sample's brightest
            // white-balanced channel: the exposure aims the mean at the target unless that
            // would clip more than `highlight_clip` of the pixels, then it protects the
            // highlights. It adapts partly toward the aim each frame (camera lag).
            let mut sum = 0.0f32;
            let mut n = 0u32;
            self.highlights.fill(0);
            let wbn = sensor.white_balance;
            for px in self.radiance.iter().step_by(7) {
                sum += px[1];
                n += 1;
                let m = (px[0] * wbn[0]).max(px[1] * wbn[1]).max(px[2] * wbn[2]);
                self.highlights[octave_bin(m)] += 1;
            }
            let mean = (sum / n.max(1) as f32).max(1e-4);
            let mut want = sensor.target_level / mean;
            let allowed = (sensor.highlight_clip.clamp(0.0, 1.0) * n as f32) as u32;
            if allowed < n {
                let mut above = 0u32;
                for b in (0..HIGHLIGHT_BINS).rev() {
                    above += self.highlights[b];
                    if above > allowed {
                        want = want.min(1.0 / (octave_bin_top(b) * sensor.gain.max(1e-6)));
                        break;
                    }
                }
            }
            self.exposure *= (want / self.exposure).powf(0.5);
            self.exposure = self.exposure.clamp(1e-3, 1e3);
        } else {
            self.exposure = sensor.exposure;
        }
        let k = self.exposure * sensor.gain;
        let wb = [0, 1, 2].map(|c| sensor.white_balance[c] * k * LUT_MAX);
        // Noise SD per output level, in output units × 256: read noise (amplified when the
        // scene is dark and the camera's gain is up) plus shot noise ∝ √signal, both taken
        // through the slope of the sRGB curve at that level.
        let read = sensor.read_noise * k.max(1.0).sqrt();
        for (level, sd) in self.sd_out.iter_mut().enumerate() {
            let s = level as f32 / 255.0;
            let lin = super::scene::srgb_to_linear(s);
            let lin2 = super::scene::srgb_to_linear((s + 1.0 / 255.0).min(1.0));
            let slope = if lin2 > lin {
                (1.0 / 255.0) / (lin2 - lin) / 255.0
            } else {
                1.0
            };
            let sd_lin = read + sensor.shot_noise * (lin * 255.0).sqrt();
            *sd = (sd_lin * slope.min(8.0) * 256.0 / 256.0).round() as i32;
        }
        let lut = &self.to_srgb;
        let sd_out = &self.sd_out;
        let row_len = w * 3;
        for (y, (rad_row, out_row)) in self
            .radiance
            .chunks_exact(w)
            .zip(out.as_bytes_mut().chunks_exact_mut(row_len))
            .enumerate()
        {
            // Each row reads the noise table sequentially from a random start: cache
            // friendly, and no visible repetition between rows or frames.
            let start = super::rng::splitmix64(frame_seed ^ ((y as u64) << 32)) as usize;
            let noise = self.noise.window(start, row_len);
            for ((px, o), n) in rad_row
                .iter()
                .zip(out_row.chunks_exact_mut(3))
                .zip(noise.chunks_exact(3))
            {
                for c in 0..3 {
                    // f32 → i32 → usize is one instruction, where f32 → usize is several.
                    let g = lut[(px[c] * wb[c]).clamp(0.0, LUT_MAX) as i32 as usize] as i32;
                    let v = g + ((n[c] as i32 * sd_out[g as usize]) >> 8);
                    o[c] = v.clamp(0, 255) as u8;
                }
            }
        }
    }
}

/// Blinn–Phong exponent of glossy targets' highlights (a lobe about 17° wide at half
/// height in the viewing direction).
const SPECULAR_EXP: i32 = 64;

/// Peak of the energy-normalised Blinn–Phong lobe for a dielectric surface, in the units
/// of diffuse albedo × irradiance: Fresnel reflectance at normal incidence (F0 = 0.04 for
/// paint, plastic or lamination, n ≈ 1.5) times the normalisation (n + 8) / 8. With a
/// perfectly glossy surface (gloss 1) under a sun of irradiance E, the highlight's centre
/// is 0.36·E, against 0.85·E for a white paper; a pure mirror would blind the camera.
const SPECULAR_PEAK: f32 = 0.04 * (SPECULAR_EXP as f32 + 8.0) / 8.0;

/// Ray–primitive intersection with analytic coverage: (coverage, a, b, t, n·r).
#[inline]
fn intersect(l: &Local, r: [f32; 3], ang: f32, two_sided: bool) -> Option<(f32, f32, f32, f32, f32)> {
    if l.kind == 3 {
        // Sphere: coverage from the ray's distance to the centre.
        let tc = dot(l.o, r);
        if tc <= 0.0 {
            return None;
        }
        let d2 = (dot(l.o, l.o) - tc * tc).max(0.0);
        let rad = l.half[0];
        let fp = tc * ang;
        let c = cov((rad - d2.sqrt()) / fp);
        if c <= 0.0 {
            return None;
        }
        let inside = (rad * rad - d2).max(0.0).sqrt();
        let t = tc - inside;
        // Local coordinates: image-plane offsets from the centre (for textures).
        let p = [r[0] * t - l.o[0], r[1] * t - l.o[1], r[2] * t - l.o[2]];
        return Some((c, p[0], -p[1], t, -1.0));
    }
    let nr = dot(l.n, r);
    if nr.abs() < 1e-6 || (!two_sided && nr > 0.0) {
        return None;
    }
    let t = dot(l.n, l.o) / nr;
    if t <= 1e-3 {
        return None;
    }
    let p = [r[0] * t - l.o[0], r[1] * t - l.o[1], r[2] * t - l.o[2]];
    let fp = t * ang / nr.abs().max(0.1);
    match l.kind {
        0 => {
            let (a, b) = (dot(p, l.u), dot(p, l.v));
            let c = cov((l.half[0] - a.abs()) / fp) * cov((l.half[1] - b.abs()) / fp);
            Some((c, a, b, t, nr))
        }
        1 => {
            let (a, b) = (dot(p, l.u), dot(p, l.v));
            let c = cov((l.half[0] - (a * a + b * b).sqrt()) / fp);
            Some((c, a, b, t, nr))
        }
        _ => {
            // Triangle: barycentric coordinates from the plane, coverage from the edges.
            let (e1, e2) = (l.u, l.v);
            let (d11, d12, d22) = (dot(e1, e1), dot(e1, e2), dot(e2, e2));
            let (pd1, pd2) = (dot(p, e1), dot(p, e2));
            let den = d11 * d22 - d12 * d12;
            if den.abs() < 1e-12 {
                return None;
            }
            let s = (d22 * pd1 - d12 * pd2) / den;
            let q = (d11 * pd2 - d12 * pd1) / den;
            // Distances to the three edges, in metres (approximate via edge lengths).
            let h1 = den.sqrt() / d11.sqrt(); // height over edge e1
            let h2 = den.sqrt() / d22.sqrt();
            let e3 = [e2[0] - e1[0], e2[1] - e1[1], e2[2] - e1[2]];
            let h3 = den.sqrt() / dot(e3, e3).sqrt();
            let c = cov(q * h1 / fp) * cov(s * h2 / fp) * cov((1.0 - s - q) * h3 / fp);
            Some((c, s, q, t, nr))
        }
    }
}

/// Floor without a libm call (the baseline x86-64 target has no `roundss`).
#[inline]
fn fast_floor(x: f32) -> i32 {
    let i = x as i32;
    if (i as f32) > x { i - 1 } else { i }
}

/// Texture lookup at local (a, b) with footprint `fp` (m) for anti-aliasing.
#[inline(always)]
fn sample(m: &Material, a: f32, b: f32, fp: f32, half: [f32; 2]) -> [f32; 3] {
    match m {
        Material::Solid(c) => *c,
        Material::TwoBlock { left, right } => {
            let wr = cov(a / fp.max(1e-6));
            [0, 1, 2].map(|c| left[c] + (right[c] - left[c]) * wr)
        }
        Material::Image(im) => {
            let (w, h) = (im.width() as f32, im.height() as f32);
            let x = ((a / (2.0 * half[0]) + 0.5) * w).clamp(0.0, w - 1.0) as usize;
            let y = ((0.5 - b / (2.0 * half[1])) * h).clamp(0.0, h - 1.0) as usize;
            let i = (y * im.width() + x) * 3;
            let p = &im.as_bytes()[i..i + 3];
            [0, 1, 2].map(|c| super::scene::srgb_to_linear(p[c] as f32 / 255.0) * 0.8)
        }
        Material::Noise { base, contrast, cell } => {
            let (ix, iy) = (fast_floor(a / cell), fast_floor(b / cell));
            let mut hsh = (ix as u32).wrapping_mul(0x9E37_79B1) ^ (iy as u32).wrapping_mul(0x85EB_CA77);
            hsh ^= hsh >> 15;
            hsh = hsh.wrapping_mul(0x2C1B_3C6D);
            hsh ^= hsh >> 12;
            let n = ((hsh & 0xFFFF) as f32 / 65535.0 - 0.5) * 2.0;
            // Average out texture finer than the pixel footprint.
            let fade = (1.0 - (fp / cell - 0.5).max(0.0)).clamp(0.0, 1.0);
            let k = 1.0 + contrast * n * fade;
            [base[0] * k, base[1] * k, base[2] * k]
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn octave_bins_bracket_their_values() {
        for k in 0..2000 {
            let v = 2f32.powf(-11.5 + k as f32 * 0.0075);
            let b = octave_bin(v);
            assert!(octave_bin_top(b) >= v, "{v}: bin {b} tops at {}", octave_bin_top(b));
            assert!(b == 0 || octave_bin_top(b - 1) <= v, "{v}: bin {b}");
            // Sixteen steps per octave, none wider than 6.25 %.
            assert!(octave_bin_top(b) <= v * 1.0625 * 1.0001);
        }
        assert_eq!(octave_bin(0.0), 0);
        assert_eq!(octave_bin(1e9), HIGHLIGHT_BINS - 1);
    }
}
