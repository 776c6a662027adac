//! The camera renderer: ray casting over screen-space bounding boxes, front-to-back
//! compositing, analytic anti-aliasing, then a sensor model.
//!
//! Each frame, every primitive is moved into the camera frame once (`hits::Surface`);
//! per-pixel rays are a table computed when the renderer is built (`rays::RayTable`), so
//! pin-hole and fisheye cameras share one path. Primitives are drawn near to far, each only
//! over the pixels its projected bounds cover, and each pixel accumulates coverage until it
//! is full; the ground and sky fill what is left. Edges are anti-aliased analytically: the
//! signed distance from a ray's hit point to the primitive's outline, divided by the
//! pixel's footprint at that depth, gives a coverage in [0, 1] that blends with what lies
//! behind, so moving a target by a fraction of a pixel changes the image.
//!
//! Each primitive is drawn a row at a time in two passes: a branch-free kernel intersects
//! the row's rays (`hits::hit_row`, vectorised by the compiler), then a shading pass
//! visits only the covered pixels that are not yet full (`texture`, shadows, glare).
//! The `sensor` module then turns radiance into 8-bit RGB.
//!
//! Between the two, when a scenario asks for them, the `optics` module applies the lens
//! and shutter's imperfections to the radiance (defocus from each pixel's depth, the
//! camera's own motion as blur and rolling-shutter skew, vignetting), and after the
//! sensor the `jpeg` module compresses and decodes the frame as a webcam's stream does.
//! With all of them off (the default) the renderer keeps no depth and does no extra pass.

mod hits;
pub mod jpeg;
pub mod optics;
mod rays;
mod sensor;
mod texture;

pub use optics::CameraMotion;
pub use sensor::{Defocus, SensorParams, WhiteBalance};

use super::lighting::LightState;
use super::scene::{Prim, Scene, Shape};
use crate::perception::RgbImage;
use crate::perception::camera_model::CameraModel;
use hits::{Kind, RowHits, Surface, cover_row, dot, hit_row};
use nalgebra::{Matrix3, Point3, Vector3};
use rays::RayTable;
use sensor::Sensor;
use texture::Texture;

/// A camera's pose in the world: rotation world ← camera, and position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraPose {
    /// Rotation taking camera-frame vectors to the world frame.
    pub rotation: Matrix3<f64>,
    /// Optical centre in the world, m.
    pub position: Point3<f64>,
}

impl CameraPose {
    /// A world point in the camera's frame (what [`CameraModel::project`] takes).
    pub fn to_camera(&self, p: &Point3<f64>) -> Vector3<f64> {
        self.rotation.transpose() * (p - self.position)
    }
}

/// Renders frames of one camera.
#[derive(Debug, Clone)]
pub struct Renderer {
    model: CameraModel,
    width: usize,
    height: usize,
    rays: RayTable,
    /// Linear radiance per pixel (zero between frames).
    radiance: Vec<[f32; 3]>,
    /// Accumulated coverage per pixel, front-to-back (zero between frames).
    alpha: Vec<f32>,
    /// Primitives by distance this frame.
    order: Vec<(f32, usize)>,
    /// One row's intersections.
    hits: RowHits,
    /// One row's texture gains (value-noise materials).
    tex_gain: Vec<f32>,
    /// One row's compositing weights (coverage × what is left to cover).
    weight: Vec<f32>,
    /// One row's open runs.
    runs: Vec<(usize, usize)>,
    sensor: Sensor,
    /// Depth along the optical axis of the surface that covers each pixel most, m
    /// (sized and kept only while an effect needs it).
    depth: Vec<f32>,
    /// Keep `depth` this frame.
    track_depth: bool,
    /// The camera's motion during the next exposure.
    motion: CameraMotion,
    /// Focal length in pixels (the pin-hole's fx; a fisheye's scale at the centre).
    f_px: f32,
    /// Vignetting gains per pixel, and the corner illumination they were built for.
    vignette: Vec<f32>,
    vignette_corner: f32,
    optics: optics::Scratch,
    jpeg: jpeg::JpegCodec,
}

impl Renderer {
    /// A renderer for `model` at `width × height`; `noise_seed` seeds the noise table.
    pub fn new(model: CameraModel, width: usize, height: usize, noise_seed: u64) -> Self {
        let mut hits = RowHits::default();
        hits.reserve_row(width);
        let rays = RayTable::new(&model, width, height);
        let f_px = match &model {
            CameraModel::Pinhole(m) => m.fx as f32,
            _ => rays.inv_ang[(height / 2) * width + width / 2],
        };
        Self {
            rays,
            model,
            width,
            height,
            radiance: vec![[0.0; 3]; width * height],
            alpha: vec![0.0; width * height],
            order: Vec::new(),
            hits,
            tex_gain: vec![0.0; width],
            weight: vec![0.0; width],
            runs: Vec::new(),
            sensor: Sensor::new(noise_seed),
            depth: Vec::new(),
            track_depth: false,
            motion: CameraMotion::default(),
            f_px,
            vignette: Vec::new(),
            vignette_corner: 1.0,
            optics: optics::Scratch::default(),
            jpeg: jpeg::JpegCodec::new(),
        }
    }

    /// Sets the camera's motion during the next frames' exposures (camera frame), which
    /// motion blur and the rolling shutter act on; a renderer starts still.
    pub fn set_motion(&mut self, motion: CameraMotion) {
        self.motion = motion;
    }

    /// The focal length in pixels the lens effects use.
    pub fn focal_px(&self) -> f32 {
        self.f_px
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
        self.sensor.exposure()
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
        // Radiance and coverage are zero here: the ground pass and the sensor clear each
        // row as they finish with it, while it is in cache, instead of a pass of its own.
        let moving = sensor.motion_blur || sensor.rolling_shutter_readout_s > 0.0;
        self.track_depth = moving || sensor.defocus.is_some();
        if self.track_depth {
            // Sized once; every pixel starts at the sky's depth.
            self.depth.resize(self.width * self.height, optics::SKY_DEPTH);
            self.depth.fill(optics::SKY_DEPTH);
        }
        // Front to back by centre distance: pixels already fully covered are skipped.
        self.order.clear();
        for (i, p) in scene.prims.iter().enumerate() {
            self.order.push(((p.shape.centre() - pose.position).norm() as f32, i));
        }
        self.order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let key = f3(rt * light.key_direction());
        for k in 0..self.order.len() {
            let prim = &scene.prims[self.order[k].1];
            // The surface in the camera frame, and the world normal and point the light
            // is evaluated at (a sphere is lit as an upward-facing surface at its centre).
            let (surface, world_n, lit_at) = match (&prim.shape, prim.shape.plane()) {
                (Shape::Sphere { centre, radius }, _) => (
                    Some(Surface::sphere(f3(to_cam(centre)), *radius as f32)),
                    Vector3::z(),
                    *centre,
                ),
                (shape, Some(f)) => {
                    let (kind, half) = match shape {
                        Shape::Rect { half, .. } => (Kind::Rect, [half[0] as f32, half[1] as f32]),
                        Shape::Disc { radius, .. } => (Kind::Disc, [*radius as f32; 2]),
                        _ => (Kind::Triangle, [0.0; 2]),
                    };
                    let local = Surface::planar(
                        kind,
                        f3(to_cam(&f.origin)),
                        f3(rt * f.u),
                        f3(rt * f.v),
                        f3(rt * f.normal),
                        half,
                        prim.two_sided,
                    );
                    (local, f.normal, f.origin)
                }
                (_, None) => continue,
            };
            // A one-sided plane seen from behind, or seen edge-on, is invisible.
            let Some(surface) = surface else {
                continue;
            };
            let Some(bbox) = self.screen_bounds(prim, &to_cam) else {
                continue;
            };
            let irr = light.irradiance_at(&world_n, &lit_at, prim.tag);
            self.draw_prim(prim, &surface, bbox, irr, light, key);
        }
        self.draw_ground(scene, pose, light);
        self.apply_optics(sensor);
        self.sensor
            .expose(&mut self.radiance, self.width, sensor, frame_seed, out);
        if sensor.jpeg_quality > 0 {
            self.jpeg.round_trip(out, sensor.jpeg_quality);
        }
    }

    /// The lens and shutter on the radiance, in the order light meets them: defocus,
    /// the exposure's motion (blur and rolling shutter), vignetting. The exposure time
    /// is the one auto-exposure set from the frames before (a camera sets its shutter
    /// before it reads the frame).
    fn apply_optics(&mut self, sensor: &SensorParams) {
        let w = self.width;
        if let Some(d) = sensor.defocus {
            let focal_m = d.focal_length_mm * 1e-3;
            let lens = optics::Lens {
                focus_m: d.focus_m,
                aperture_m: focal_m / d.f_number.max(1e-3),
                focal_m,
                f_px: self.f_px,
            };
            optics::defocus(&mut self.radiance, &self.depth, w, &lens, &mut self.optics);
        }
        if sensor.motion_blur || sensor.rolling_shutter_readout_s > 0.0 {
            let k = if sensor.auto_exposure {
                self.sensor.exposure()
            } else {
                sensor.exposure
            };
            let shutter = optics::Shutter {
                exposure_s: if sensor.motion_blur {
                    sensor.exposure_time_s(k)
                } else {
                    0.0
                },
                readout_s: sensor.rolling_shutter_readout_s.max(0.0),
                f_px: self.f_px,
            };
            let rays = [&self.rays.x[..], &self.rays.y[..], &self.rays.z[..]];
            optics::smear(
                &mut self.radiance,
                &self.depth,
                rays,
                w,
                &self.motion,
                &shutter,
                &mut self.optics,
            );
        }
        if sensor.vignetting_corner < 1.0 {
            if self.vignette_corner != sensor.vignetting_corner || self.vignette.len() != w * self.height {
                optics::vignette_gains(w, self.height, sensor.vignetting_corner, &mut self.vignette);
                self.vignette_corner = sensor.vignetting_corner;
            }
            for (px, &g) in self.radiance.iter_mut().zip(&self.vignette) {
                for c in px.iter_mut() {
                    *c *= g;
                }
            }
        }
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

    /// Fills what the primitives left uncovered with the ground plane (z = 0, fading into
    /// haze far away) or the sky.
    fn draw_ground(&mut self, scene: &Scene, pose: &CameraPose, light: &LightState) {
        let rt = pose.rotation.transpose();
        let f3 = |v: Vector3<f64>| [v.x as f32, v.y as f32, v.z as f32];
        // The ground as an unbounded plane whose local coordinates are world x and y.
        let ground = Surface::planar(
            Kind::Plane,
            f3(rt * -pose.position.coords),
            f3(rt * Vector3::x()),
            f3(rt * Vector3::y()),
            f3(rt * Vector3::z()),
            [0.0; 2],
            false,
        )
        .map(|g| g.with_min_cos(0.05));
        let irr = light.irradiance(&Vector3::z());
        let sky = scene.sky.map(|s| s * light.sky_scale());
        let tex = Texture::new(&scene.ground, [1e9, 1e9]);
        let w = self.width;
        for y in 0..self.height {
            let row = y * w..(y + 1) * w;
            let (rad, alpha) = (&mut self.radiance[row.clone()], &mut self.alpha[row]);
            let Some(ground) = &ground else {
                // The camera is at or below the ground: it sees only sky.
                for (px, a) in rad.iter_mut().zip(alpha.iter_mut()) {
                    let rest = 1.0 - *a;
                    if rest > 1e-3 {
                        for c in 0..3 {
                            px[c] += rest * sky[c];
                        }
                    }
                    *a = 0.0;
                }
                continue;
            };
            open_runs(alpha, 0, &mut self.runs);
            for &(x0, x1) in &self.runs {
                let rays = self.rays.row(y, x0, x1);
                hit_row(ground, rays, &mut self.hits);
                let h = &self.hits;
                let n = x1 - x0;
                if self.track_depth {
                    // The ground is the deepest surface: it owns the pixels still less
                    // than half covered.
                    let depth = &mut self.depth[y * w + x0..y * w + x1];
                    for j in 0..n {
                        if alpha[x0 + j] < 0.5 && h.cov[j] > 0.0 {
                            depth[j] = h.t[j] * rays.z[j];
                        }
                    }
                }
                if let Some(base) = tex.noise_row(&h.a[..n], &h.b[..n], &h.fp[..n], &mut self.tex_gain) {
                    // Value-noise ground (the usual one): branch-free, so it vectorises.
                    // Full pixels add nothing; sky pixels add sky.
                    let (cov, t, gain) = (&h.cov[..n], &h.t[..n], &self.tex_gain[..n]);
                    let (rad, alpha) = (&mut rad[x0..x1], &alpha[x0..x1]);
                    let lit = [0, 1, 2].map(|c| base[c] * irr[c]);
                    for j in 0..n {
                        let rest = 1.0 - alpha[j];
                        let rest = if rest > 1e-3 { rest } else { 0.0 };
                        let hit = cov[j] > 0.0;
                        // Fade to the sky colour far away (haze), which also hides
                        // texture aliasing.
                        let haze = if hit { haze(t[j]) } else { 1.0 };
                        let g = if hit { gain[j] * (1.0 - haze) } else { 0.0 };
                        let px = &mut rad[j];
                        for c in 0..3 {
                            px[c] += rest * (lit[c] * g + sky[c] * haze);
                        }
                    }
                    continue;
                }
                for (j, (px, a)) in rad[x0..x1].iter_mut().zip(&alpha[x0..x1]).enumerate() {
                    let rest = 1.0 - a;
                    if rest <= 1e-3 {
                        continue;
                    }
                    if h.cov[j] <= 0.0 {
                        for c in 0..3 {
                            px[c] += rest * sky[c];
                        }
                        continue;
                    }
                    let alb = tex.sample(h.a[j], h.b[j], h.fp[j]);
                    // Fade to the sky colour far away (haze), which also hides texture aliasing.
                    let haze = haze(h.t[j]);
                    for c in 0..3 {
                        px[c] += rest * (alb[c] * irr[c] * (1.0 - haze) + sky[c] * haze);
                    }
                }
            }
            // The last pass to read this row's coverage clears it for the next frame.
            alpha.fill(0.0);
        }
    }

    /// Draws one primitive over `bbox` (x0, y0, x1, y1): intersects each row, then shades
    /// and composites the covered pixels that are not yet full.
    fn draw_prim(
        &mut self,
        prim: &Prim,
        s: &Surface,
        bbox: [usize; 4],
        irr: [f32; 3],
        light: &LightState,
        key: [f32; 3],
    ) {
        let w = self.width;
        let shadows = light.shadows_for(prim.tag);
        let glare = prim.gloss * light.glare_strength() * SPECULAR_PEAK;
        let key_colour = light.key_colour();
        let tex = Texture::new(&prim.material, s.half);
        // Matte and unshadowed: shading is albedo × irradiance, composited branch-free.
        let matte = shadows.is_empty() && glare <= 0.0;
        let solid = match tex {
            Texture::Solid(c) => Some(c),
            _ => None,
        };
        // Matte and one colour: coverage is all the shading needs.
        let plain_solid = matte && solid.is_some();
        let [bx0, y0, bx1, y1] = bbox;
        let mut runs = std::mem::take(&mut self.runs);
        for y in y0..y1 {
            open_runs(&self.alpha[y * w + bx0..y * w + bx1], bx0, &mut runs);
            for &(x0, x1) in &runs {
                let rays = self.rays.row(y, x0, x1);
                if plain_solid && !self.track_depth {
                    cover_row(s, rays, &mut self.hits);
                } else {
                    hit_row(s, rays, &mut self.hits);
                }
                let h = &self.hits;
                let n = x1 - x0;
                if self.track_depth {
                    // The surface whose coverage takes a pixel past half owns its depth.
                    let base = y * w + x0;
                    let (alpha, depth) = (&self.alpha[base..base + n], &mut self.depth[base..base + n]);
                    for j in 0..n {
                        let (a, rest) = (alpha[j], 1.0 - alpha[j]);
                        let k = if (h.cov[j] > 0.0) & (rest > 1e-3) {
                            rest * h.cov[j]
                        } else {
                            0.0
                        };
                        if a < 0.5 && a + k >= 0.5 {
                            depth[j] = h.t[j] * rays.z[j];
                        }
                    }
                }
                let noise_base = tex.noise_row(&h.a[..n], &h.b[..n], &h.fp[..n], &mut self.tex_gain);
                let base = y * w + x0;
                if matte {
                    // Matte, one colour or value noise (most of a scene): branch-free, so
                    // it vectorises. Full or missed pixels add k = 0.
                    if let Some(alb) = solid.or(noise_base) {
                        let (rad, alpha) = (&mut self.radiance[base..base + n], &mut self.alpha[base..base + n]);
                        let weight = &mut self.weight[..n];
                        composite_weights(&h.cov[..n], alpha, weight);
                        if solid.is_some() {
                            composite_solid(rad, weight, alb, irr);
                        } else {
                            composite_noise(rad, weight, &self.tex_gain[..n], alb, irr);
                        }
                        continue;
                    }
                }
                for j in 0..n {
                    let coverage = h.cov[j];
                    if coverage <= 0.0 {
                        continue;
                    }
                    let i = base + j;
                    let rest = 1.0 - self.alpha[i];
                    if rest <= 1e-3 {
                        continue;
                    }
                    let (a, b, t, nr) = (h.a[j], h.b[j], h.t[j], h.nr[j]);
                    let alb = match noise_base {
                        Some(base) => base.map(|c| c * self.tex_gain[j]),
                        None => tex.sample(a, b, h.fp[j]),
                    };
                    let mut shade = 1.0f32;
                    if !shadows.is_empty() {
                        let fp = t * rays.ang[j];
                        for sh in shadows {
                            let d = a * sh.cos + b * sh.sin - sh.offset;
                            shade *= 1.0 - sh.strength * hits::cov(d / (sh.softness + fp));
                        }
                    }
                    let mut col = [
                        alb[0] * irr[0] * shade,
                        alb[1] * irr[1] * shade,
                        alb[2] * irr[2] * shade,
                    ];
                    if glare > 0.0 {
                        // Blinn–Phong highlight of the key light: glare on glossy targets.
                        let r = [rays.x[j], rays.y[j], rays.z[j]];
                        let n = if s.kind == Kind::Sphere {
                            let p = [r[0] * t - s.o[0], r[1] * t - s.o[1], r[2] * t - s.o[2]];
                            let len = dot(p, p).sqrt().max(1e-6);
                            [p[0] / len, p[1] / len, p[2] / len]
                        } else if nr > 0.0 {
                            [-s.n[0], -s.n[1], -s.n[2]]
                        } else {
                            s.n
                        };
                        let hv = [key[0] - r[0], key[1] - r[1], key[2] - r[2]];
                        let hl = dot(hv, hv).sqrt().max(1e-6);
                        let nh = (dot(n, hv) / hl).max(0.0);
                        let lit = dot(n, key).max(0.0);
                        let sp = glare * shade * lit * nh.powi(SPECULAR_EXP);
                        for c in 0..3 {
                            col[c] += sp * key_colour[c];
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
        self.runs = runs;
    }
}

/// Front-to-back compositing weights of one row's matte surface: each pixel takes its
/// coverage of what is still uncovered (nothing once it is full, or where the surface
/// misses), and its coverage grows by that much. Branch-free, so it vectorises.
#[inline(always)]
fn composite_weights(cov: &[f32], alpha: &mut [f32], weight: &mut [f32]) {
    let n = cov.len().min(alpha.len()).min(weight.len());
    let (cov, alpha, weight) = (&cov[..n], &mut alpha[..n], &mut weight[..n]);
    for j in 0..n {
        let rest = 1.0 - alpha[j];
        let k = if (cov[j] > 0.0) & (rest > 1e-3) {
            rest * cov[j]
        } else {
            0.0
        };
        weight[j] = k;
        alpha[j] += k;
    }
}

/// Adds a one-colour matte surface (albedo `alb` under irradiance `irr`) to a row's
/// radiance with the weights of [`composite_weights`]. Pixels are taken four at a time,
/// as twelve interleaved channels, so the three-channel layout still vectorises.
#[inline(always)]
fn composite_solid(rad: &mut [[f32; 3]], weight: &[f32], alb: [f32; 3], irr: [f32; 3]) {
    let lit = [0, 1, 2].map(|c| alb[c] * irr[c]);
    let n = rad.len().min(weight.len());
    let (flat, weight) = (rad[..n].as_flattened_mut(), &weight[..n]);
    let mut blocks = flat.chunks_exact_mut(12);
    let mut weights = weight.chunks_exact(4);
    for (r, k) in (&mut blocks).zip(&mut weights) {
        for m in 0..12 {
            r[m] += k[m / 3] * lit[m % 3];
        }
    }
    for (r, &k) in blocks.into_remainder().chunks_exact_mut(3).zip(weights.remainder()) {
        for c in 0..3 {
            r[c] += k * lit[c];
        }
    }
}

/// As [`composite_solid`], for a value-noise surface whose albedo is `alb` × the pixel's
/// `gain`.
#[inline(always)]
fn composite_noise(rad: &mut [[f32; 3]], weight: &[f32], gain: &[f32], alb: [f32; 3], irr: [f32; 3]) {
    let n = rad.len().min(weight.len()).min(gain.len());
    let (flat, weight, gain) = (rad[..n].as_flattened_mut(), &weight[..n], &gain[..n]);
    let mut blocks = flat.chunks_exact_mut(12);
    let mut weights = weight.chunks_exact(4);
    let mut gains = gain.chunks_exact(4);
    for ((r, k), g) in (&mut blocks).zip(&mut weights).zip(&mut gains) {
        for m in 0..12 {
            r[m] += k[m / 3] * (alb[m % 3] * g[m / 3] * irr[m % 3]);
        }
    }
    let tail = blocks.into_remainder().chunks_exact_mut(3);
    for ((r, &k), &g) in tail.zip(weights.remainder()).zip(gains.remainder()) {
        for c in 0..3 {
            r[c] += k * (alb[c] * g * irr[c]);
        }
    }
}

/// How far the ground has faded into the sky colour at distance `t`, m: linearly, to
/// nothing at 40 m. It also hides the texture's aliasing far away.
#[inline(always)]
fn haze(t: f32) -> f32 {
    (t * (1.0 / 40.0)).min(1.0)
}

/// The runs of a row still open to paint (pixels not yet fully covered), as (x0, x1)
/// offset by `offset`, into `runs`. Runs closer than [`RUN_GAP`] pixels are merged, so a
/// ragged edge does not split a span into slivers. Intersecting only these saves the work
/// behind nearer surfaces: a wall behind the mother's body is cast left and right of it.
fn open_runs(alpha: &[f32], offset: usize, runs: &mut Vec<(usize, usize)>) {
    runs.clear();
    let mut x = 0;
    while let Some(start) = find_state::<true>(alpha, x) {
        let end = find_state::<false>(alpha, start).unwrap_or(alpha.len());
        match runs.last_mut() {
            Some(last) if start - (last.1 - offset) < RUN_GAP => last.1 = offset + end,
            _ => runs.push((offset + start, offset + end)),
        }
        x = end;
    }
}

/// Whether a pixel with coverage `a` is still open to paint.
#[inline(always)]
fn is_open(a: f32) -> bool {
    1.0 - a > 1e-3
}

/// The first index at or after `from` whose pixel is open (`OPEN`) or full (`!OPEN`).
/// Rows are scanned sixteen pixels at a time with a branch-free test that the compiler
/// vectorises, then the chunk that holds the change is searched pixel by pixel: rows are
/// long runs of one state, and a pixel-by-pixel scan of them was an eighth of a frame.
#[inline]
fn find_state<const OPEN: bool>(alpha: &[f32], from: usize) -> Option<usize> {
    const LANES: usize = 16;
    let rest = &alpha[from..];
    let mut chunks = rest.chunks_exact(LANES);
    let mut base = from;
    for chunk in &mut chunks {
        let hits = chunk.iter().fold(0u32, |acc, &a| acc | u32::from(is_open(a) == OPEN));
        if hits != 0 {
            return chunk.iter().position(|&a| is_open(a) == OPEN).map(|p| base + p);
        }
        base += LANES;
    }
    chunks
        .remainder()
        .iter()
        .position(|&a| is_open(a) == OPEN)
        .map(|p| base + p)
}

/// Full pixels between two open runs below which they are cast as one.
const RUN_GAP: usize = 16;

/// Blinn–Phong exponent of glossy targets' highlights (a lobe about 17° wide at half
/// height in the viewing direction).
const SPECULAR_EXP: i32 = 64;

/// Peak of the energy-normalised Blinn–Phong lobe for a dielectric surface, in the units
/// of diffuse albedo × irradiance: Fresnel reflectance at normal incidence (F0 = 0.04 for
/// paint, plastic or lamination, n ≈ 1.5) times the normalisation (n + 8) / 8. With a
/// perfectly glossy surface (gloss 1) under a sun of irradiance E, the highlight's centre
/// is 0.36·E, against 0.85·E for a white paper; a pure mirror would blind the camera.
const SPECULAR_PEAK: f32 = 0.04 * (SPECULAR_EXP as f32 + 8.0) / 8.0;

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The pixel-by-pixel scan that `open_runs` replaced: the reference it must match.
    fn open_runs_reference(alpha: &[f32], offset: usize, runs: &mut Vec<(usize, usize)>) {
        runs.clear();
        let mut x = 0;
        while let Some(p) = alpha[x..].iter().position(|a| 1.0 - a > 1e-3) {
            let start = x + p;
            let end = alpha[start..]
                .iter()
                .position(|a| 1.0 - a <= 1e-3)
                .map_or(alpha.len(), |q| start + q);
            match runs.last_mut() {
                Some(last) if start - (last.1 - offset) < RUN_GAP => last.1 = offset + end,
                _ => runs.push((offset + start, offset + end)),
            }
            x = end;
        }
    }

    /// Coverage values around the open/full threshold, and runs of one state as a row has.
    fn row() -> impl Strategy<Value = Vec<f32>> {
        let value = prop_oneof![
            Just(0.0f32),
            Just(1.0f32),
            Just(1.0f32 - 1e-3),
            Just(0.9995f32),
            Just(0.998f32),
            0.0f32..=1.0,
        ];
        prop::collection::vec((value, 1usize..40), 0..12)
            .prop_map(|spans| spans.into_iter().flat_map(|(v, n)| std::iter::repeat_n(v, n)).collect())
    }

    proptest! {
        #[test]
        fn open_runs_matches_the_pixel_by_pixel_scan(alpha in row(), offset in 0usize..300) {
            let (mut fast, mut slow) = (Vec::new(), Vec::new());
            open_runs(&alpha, offset, &mut fast);
            open_runs_reference(&alpha, offset, &mut slow);
            prop_assert_eq!(fast, slow);
        }
    }

    #[test]
    fn open_runs_merges_close_runs_and_keeps_far_ones() {
        let mut alpha = vec![1.0f32; 100];
        alpha[2..5].fill(0.0);
        alpha[10..12].fill(0.5); // 5 full pixels between: merged
        alpha[60..70].fill(0.0); // 48 full pixels between: a run of its own
        let mut runs = Vec::new();
        open_runs(&alpha, 7, &mut runs);
        assert_eq!(runs, vec![(9, 19), (67, 77)]);
        open_runs(&[1.0; 40], 0, &mut runs);
        assert!(runs.is_empty());
        open_runs(&[0.0; 40], 3, &mut runs);
        assert_eq!(runs, vec![(3, 43)]);
    }
}
