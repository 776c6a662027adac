//! The wheel stage on whole frames (seed 003 §V-C): each wheel's rotation step between
//! two consecutive fisheye frames, and θ corrected once per turn by the white marker.
//!
//! For each wheel, every frame:
//! 1. **The tread cylinder** from its axle's roll ψ, drop d and steering λ ([`AxleState`],
//!    the estimates of this frame, or the last ones when the markers were lost, as the
//!    paper does) and the gear's layout ([`GearLayout`]).
//! 2. **The observation window**: the tread point 60° up the wheel on the side facing
//!    the camera (the paper's w60, [`WheelCylinder::window_centre`]) projected into the
//!    image; a square of [`WheelParams::window_half_px`] around it.
//! 3. **Shi–Tomasi corners** in the previous frame's window, **pyramidal Lucas–Kanade**
//!    forward to this frame and back, inconsistent tracks dropped
//!    ([`crate::perception::flow`]). Each frame's pyramid is built only around the
//!    windows of this frame and the previous one ([`WheelParams::pyramid_margin_px`]),
//!    with the whole frame's values there.
//! 4. **Per-feature steps**: both ends of a track are back-projected onto their frame's
//!    tread cylinder and expressed in that wheel's own frame (centre at the origin, axis
//!    y, forward x), so axle roll, drop and steering between the frames do not read as
//!    rotation; the step is the chord formula signed by the turn about the axis
//!    ([`WheelCylinder::step_angle`]). Tracks whose ends miss the tread are dropped.
//! 5. **RANSAC** over the steps with the caller's generator ([`ransac_angle`]); the mean
//!    of the inliers is the frame's step, counted when at least
//!    [`WheelParams::min_inliers`] agree. When too few agree (the white face fills the
//!    window and leaves few corners, a shadow, blur), θ coasts on the last measured step
//!    for up to [`WheelParams::coast_frames`] frames, reported as not measured: without
//!    it each pass of the white face lost two or three steps, 0.3 rad a turn.
//! 6. **The correction marker**: the mean grey level of a small patch at the window's
//!    centre, thresholded ([`WheelParams::white_level`]), tells when the white face
//!    passes the tread point w60. θ is read at the first and last white frames of a
//!    pass and their midpoint, the estimate of θ with the face centred on w60, is what
//!    is snapped to 2πm + c₀ ([`TurnCounter::snap`]). Using the midpoint makes the
//!    correction the same whichever way the wheel turns (the rising edge of the white is
//!    the face's leading edge, which changes side with the direction); the correction
//!    found there is applied to the current θ.
//!
//! Our additions to the paper: the signed step, the midpoint snap and the coasting.
//! Simplified: the white face is found by a fixed grey threshold at one point, so a
//! light change that lifts the rubber past it, or glare, would read as a pass.
//!
//! Every buffer is sized in [`WheelTracker::new`]; [`WheelTracker::update`] does not
//! allocate.

use super::axle::AxleGeometry;
use super::wheel::{TurnCounter, WheelCylinder, ransac_angle};
use crate::perception::flow::{CornerParams, GreyPyramid, LkParams, LucasKanade, Roi, ShiTomasi};
use crate::perception::image::RgbView;
use nalgebra::{Matrix3, Point3, Rotation3, Unit, Vector3};

/// An axle's roll, drop and steering: what places its wheels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxleState {
    /// Roll ψ, rad, positive lifting the left side.
    pub roll: f64,
    /// Vertical distance from the camera down to the plate markers' midpoint, m.
    pub drop: f64,
    /// Steering λ, rad, positive turning the wheels' fronts left.
    pub steer: f64,
}

/// Where the wheels sit on their axle: what the paper calls the swivel joints'
/// positions in the axle frame and the wheels' centres in the swivel frame (built from the
/// profile's gear, [`super::GearGeometry::layout`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GearLayout {
    /// Distance between the two kingpins (the wheels' centres), m.
    pub track: f64,
    /// Tread radius r, m.
    pub wheel_radius: f64,
    /// Half the tread's width, m.
    pub tread_half_width: f64,
    /// How far the wheels' centres sit below the plate markers' plane, m.
    pub hub_below_plate: f64,
    /// How far each plate marker sits either side of its axle's centre line, m (what
    /// the mount compensation measures the camera's motion against).
    pub marker_half_spacing: f64,
}

impl GearLayout {
    /// The pose of wheel `wheel` (0 front left, 1 front right, 2 rear left, 3 rear right)
    /// in the body frame, for an axle in `state` whose plane is x = `axle_x` below a
    /// camera at height `camera_z`: the tread cylinder and the wheel's rotation (its
    /// columns forward, the axis to the left, up).
    pub fn wheel(&self, wheel: usize, axle_x: f64, camera_z: f64, state: &AxleState) -> (WheelCylinder, Matrix3<f64>) {
        let side = if wheel.is_multiple_of(2) { 1.0 } else { -1.0 };
        let axle = Rotation3::from_axis_angle(&Vector3::x_axis(), state.roll);
        let origin = Point3::new(axle_x, 0.0, camera_z - state.drop);
        let centre = origin + axle * Vector3::new(0.0, side * self.track / 2.0, -self.hub_below_plate);
        let rot = axle * Rotation3::from_axis_angle(&Vector3::z_axis(), state.steer);
        let m = *rot.matrix();
        (
            WheelCylinder {
                centre,
                axis: Unit::new_normalize(m.column(1).into_owned()),
                radius: self.wheel_radius,
                half_width: self.tread_half_width,
            },
            m,
        )
    }
}

/// Parameters of the wheel stage.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WheelParams {
    /// Half-size of the square observation window, px.
    pub window_half_px: f64,
    /// The corner detector's settings (at most `max_corners` features per wheel).
    pub corners: CornerParams,
    /// The tracker's settings, forward–backward tolerance included.
    pub lk: LkParams,
    /// Pyramid levels for Lucas–Kanade.
    pub levels: usize,
    /// RANSAC inlier tolerance, rad.
    pub ransac_tolerance: f64,
    /// RANSAC iterations.
    pub ransac_iterations: usize,
    /// A frame's step counts only with at least this many inliers.
    pub min_inliers: usize,
    /// A wheel whose step cannot be measured (the white face fills its window, a
    /// shadow, blur) coasts on its last measured step for up to this many frames in a
    /// row, flagged as not measured; 0 adds nothing instead.
    pub coast_frames: usize,
    /// Mean grey level (0–255, luma (R + 2G + B)/4) over the correction patch above
    /// which the white face is taken to be on w60.
    pub white_level: f32,
    /// Half-size of the correction patch, px.
    pub white_half_px: usize,
    /// Build each frame's pyramid only around the observation windows (this frame's and
    /// the previous frame's, grown by this margin at full resolution, px), or over the
    /// whole frame (`None`). The pixels built are exactly the whole frame's; a track
    /// whose Lucas–Kanade window would leave them is treated as leaving the image (lost
    /// at full resolution, unrefined at a coarser level), so the margin must exceed a
    /// frame's motion on the tread plus the coarsest level's window (48 px gives the
    /// 3-level, r = 4 tracker about 18 px of motion at every level; the sequences'
    /// treads move a few pixels a frame).
    pub pyramid_margin_px: Option<usize>,
}

impl Default for WheelParams {
    /// A 41×41 window, up to 40 corners (3×3 box, quality 0.02, 4 px apart), 9×9 LK
    /// windows over 3 levels with a 0.3 px forward–backward tolerance, RANSAC at
    /// 0.01 rad over 40 draws with at least 4 inliers, coasting up to 4 frames, a
    /// 5×5 correction patch white above grey 170, and pyramids built 48 px around the
    /// windows.
    fn default() -> Self {
        Self {
            window_half_px: 20.0,
            corners: CornerParams {
                block_radius: 1,
                quality: 0.02,
                min_eigen: 20.0,
                min_distance: 4.0,
                max_corners: 40,
            },
            lk: LkParams {
                radius: 4,
                max_fb_px: 0.3,
                ..LkParams::default()
            },
            levels: 3,
            ransac_tolerance: 0.01,
            ransac_iterations: 40,
            min_inliers: 4,
            coast_frames: 4,
            white_level: 170.0,
            white_half_px: 2,
            pyramid_margin_px: Some(48),
        }
    }
}

/// One wheel's result for one frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct WheelStep {
    /// The rotation step since the previous frame, rad, when measured.
    pub step: Option<f64>,
    /// The step added without a measurement (coasting on the last measured one), rad.
    pub coasted: Option<f64>,
    /// Features found in the previous frame's window.
    pub features: usize,
    /// Tracks that survived the forward–backward check and landed on the tread.
    pub tracks: usize,
    /// RANSAC inliers of the step.
    pub inliers: usize,
    /// The correction applied by the white marker this frame, rad (0 when none).
    pub correction: f64,
    /// The window's centre this frame, px (camera-model convention), when it projects.
    pub window: Option<[f64; 2]>,
    /// Whether the white face was on w60 this frame.
    pub white: bool,
}

/// Per-wheel memory between frames.
#[derive(Debug, Clone, Copy, Default)]
struct WheelMemory {
    /// The previous frame's window, and the wheel's pose then.
    roi: Option<Roi>,
    cylinder: Option<(WheelCylinder, Matrix3<f64>)>,
    counter: TurnCounter,
    /// The last measured step, and how many frames in a row have coasted on it.
    last_step: Option<f64>,
    coasting: usize,
    /// θ at the first white frame of the current pass, and θ at its latest white frame.
    white_pass: Option<(f64, f64)>,
}

/// The wheel stage: pyramids of the last two frames, the detector, the tracker, and each
/// wheel's θ.
#[derive(Debug, Clone)]
pub struct WheelTracker {
    params: WheelParams,
    layout: GearLayout,
    prev: GreyPyramid,
    next: GreyPyramid,
    has_prev: bool,
    corners: ShiTomasi,
    lk: LucasKanade,
    points: Vec<[f64; 2]>,
    tracked: Vec<Option<[f64; 2]>>,
    steps: Vec<f64>,
    wheels: [WheelMemory; 4],
    /// The previous frame's camera mount (body_from_camera, centre): its tracks' first
    /// ends are back-projected with it.
    prev_mount: (Matrix3<f64>, Point3<f64>),
}

impl WheelTracker {
    /// A tracker for `width × height` frames of a gear laid out as `layout`.
    pub fn new(width: usize, height: usize, layout: GearLayout, params: WheelParams) -> Self {
        let n = params.corners.max_corners;
        Self {
            params,
            layout,
            prev: GreyPyramid::new(params.levels),
            next: GreyPyramid::new(params.levels),
            has_prev: false,
            corners: ShiTomasi::new(width, height, params.corners),
            lk: LucasKanade::new(params.lk, n),
            points: Vec::with_capacity(n),
            tracked: vec![None; n],
            steps: Vec::with_capacity(n),
            wheels: [WheelMemory::default(); 4],
            prev_mount: (Matrix3::identity(), Point3::origin()),
        }
    }

    /// The parameters.
    pub fn params(&self) -> &WheelParams {
        &self.params
    }

    /// Each wheel's θ so far (FL, FR, RL, RR), rad, from 0 at the first frame.
    pub fn theta(&self) -> [f64; 4] {
        self.wheels.map(|w| w.counter.theta)
    }

    /// Forgets the previous frame and sets each θ to `theta` (c₀ is kept: the marker's
    /// place on the wheel does not change).
    pub fn restart(&mut self, theta: [f64; 4]) {
        self.has_prev = false;
        for (w, t) in self.wheels.iter_mut().zip(theta) {
            w.counter.theta = t;
            w.roi = None;
            w.cylinder = None;
            w.white_pass = None;
            w.last_step = None;
            w.coasting = 0;
        }
    }

    /// Takes a new frame with its axles' states (front, rear): measures each wheel's step
    /// from the previous frame, adds it to θ, and applies the white marker's correction.
    /// `geometry` is this frame's (its mount moved by the vibration compensation, if any):
    /// the previous frame's end of each track is back-projected with the previous frame's.
    /// `draw(n)` gives an index below n from the caller's generator (RANSAC). Frames must
    /// all have the size given to [`WheelTracker::new`] (the geometry's image).
    pub fn update(
        &mut self,
        frame: &RgbView<'_>,
        geometry: &AxleGeometry,
        axles: &[AxleState; 2],
        mut draw: impl FnMut(usize) -> usize,
    ) -> [WheelStep; 4] {
        let (w, h) = (frame.width(), frame.height());
        let camera_from_body = geometry.body_from_camera.transpose();
        let mut out = [WheelStep::default(); 4];
        // Each wheel's tread cylinder and observation window this frame.
        let placed = std::array::from_fn::<_, 4, _>(|k| {
            let axle = k / 2;
            let (cyl, rot) = self
                .layout
                .wheel(k, geometry.axle_x[axle], geometry.camera.z, &axles[axle]);
            // The tread's side facing the camera: ahead of the wheel's centre or behind.
            let forward = rot.column(0).into_owned();
            let front = forward.dot(&(geometry.camera - cyl.centre)) > 0.0;
            let w60 = cyl.window_centre(forward, front);
            let window = geometry.model.project(&(camera_from_body * (w60 - geometry.camera)));
            let roi = window.map(|c| Roi::around(c[0] - 0.5, c[1] - 0.5, self.params.window_half_px, w, h));
            (cyl, rot, window, roi)
        });
        std::mem::swap(&mut self.prev, &mut self.next);
        match self.params.pyramid_margin_px {
            None => self.next.build_from_rgb(frame),
            Some(margin) => {
                // This frame's pixels are read around this frame's windows (the next
                // frame's corners, the white patch) and around the previous frame's
                // (where this frame's tracks land): one rectangle per wheel spanning
                // both, grown by the margin.
                let mut rects = [Roi::default(); 4];
                let mut n = 0;
                for (k, placed) in placed.iter().enumerate() {
                    let before = if self.has_prev { self.wheels[k].roi } else { None };
                    let span = match (placed.3, before) {
                        (Some(a), Some(b)) => Some(Roi {
                            x0: a.x0.min(b.x0),
                            y0: a.y0.min(b.y0),
                            x1: a.x1.max(b.x1),
                            y1: a.y1.max(b.y1),
                        }),
                        (a, b) => a.or(b),
                    };
                    if let Some(r) = span {
                        rects[n] = Roi {
                            x0: r.x0.saturating_sub(margin),
                            y0: r.y0.saturating_sub(margin),
                            x1: (r.x1 + margin).min(w),
                            y1: (r.y1 + margin).min(h),
                        };
                        n += 1;
                    }
                }
                self.next.build_from_rgb_in(frame, &rects[..n]);
            }
        }
        for (k, result) in out.iter_mut().enumerate() {
            let (cyl, rot, window, roi) = placed[k];
            result.window = window;
            if self.has_prev
                && let (Some(prev_roi), Some(prev_cyl)) = (self.wheels[k].roi, self.wheels[k].cylinder)
            {
                self.measure(prev_roi, &prev_cyl, (&cyl, &rot), geometry, result, &mut draw);
            }
            let memory = &mut self.wheels[k];
            match result.step {
                Some(s) => {
                    memory.counter.step(s);
                    memory.last_step = Some(s);
                    memory.coasting = 0;
                }
                None if self.has_prev && memory.coasting < self.params.coast_frames => {
                    if let Some(s) = memory.last_step {
                        memory.counter.step(s);
                        memory.coasting += 1;
                        result.coasted = Some(s);
                    }
                }
                None => memory.last_step = None,
            }
            result.white = window.is_some_and(|c| self.is_white(c));
            let theta = self.wheels[k].counter.theta;
            let memory = &mut self.wheels[k];
            match (result.white, memory.white_pass) {
                (true, None) => memory.white_pass = Some((theta, theta)),
                (true, Some((first, _))) => memory.white_pass = Some((first, theta)),
                (false, Some((first, last))) => {
                    memory.white_pass = None;
                    result.correction = memory.counter.snap((first + last) / 2.0);
                }
                (false, None) => {}
            }
            memory.roi = roi;
            memory.cylinder = Some((cyl, rot));
        }
        self.has_prev = true;
        self.prev_mount = (geometry.body_from_camera, geometry.camera);
        out
    }

    /// Corners in the previous frame's window of a wheel, tracked to this frame, each
    /// track's step in the wheel's frame, and their consensus.
    fn measure(
        &mut self,
        roi: Roi,
        prev: &(WheelCylinder, Matrix3<f64>),
        next: (&WheelCylinder, &Matrix3<f64>),
        geometry: &AxleGeometry,
        result: &mut WheelStep,
        draw: &mut impl FnMut(usize) -> usize,
    ) {
        let found = self.corners.detect(self.prev.level(0), roi);
        self.points.clear();
        self.points.extend_from_slice(found);
        let n = self.points.len();
        result.features = n;
        self.lk
            .track_checked(&self.prev, &self.next, &self.points, &mut self.tracked[..n]);
        let unit = WheelCylinder {
            centre: Point3::origin(),
            axis: Vector3::y_axis(),
            radius: self.layout.wheel_radius,
            half_width: self.layout.tread_half_width,
        };
        let local = |px: [f64; 2],
                     (cyl, rot): (&WheelCylinder, &Matrix3<f64>),
                     (body_from_camera, camera): (&Matrix3<f64>, &Point3<f64>)| {
            let ray = body_from_camera * geometry.model.ray(px[0] + 0.5, px[1] + 0.5);
            let p = cyl.on_tread(*camera, ray)?;
            Some(Point3::from(rot.transpose() * (p - cyl.centre)))
        };
        let prev_mount = (&self.prev_mount.0, &self.prev_mount.1);
        let this_mount = (&geometry.body_from_camera, &geometry.camera);
        self.steps.clear();
        for (p, q) in self.points.iter().zip(&self.tracked[..n]) {
            let Some(q) = q else { continue };
            if let (Some(a), Some(b)) = (local(*p, (&prev.0, &prev.1), prev_mount), local(*q, next, this_mount)) {
                self.steps.push(unit.step_angle(a, b));
            }
        }
        result.tracks = self.steps.len();
        if let Some((step, inliers)) = ransac_angle(
            &self.steps,
            self.params.ransac_tolerance,
            self.params.ransac_iterations,
            &mut *draw,
        ) {
            result.inliers = inliers;
            if inliers >= self.params.min_inliers {
                result.step = Some(step);
            }
        }
    }

    /// Whether the patch around `at` (camera-model pixel) in the newest frame is white.
    fn is_white(&self, at: [f64; 2]) -> bool {
        let im = self.next.level(0);
        let r = self.params.white_half_px as i64;
        let (cx, cy) = (at[0].floor() as i64, at[1].floor() as i64);
        let (mut sum, mut n) = (0.0f32, 0u32);
        for y in cy - r..=cy + r {
            for x in cx - r..=cx + r {
                if x < 0 || y < 0 || x >= im.width() as i64 || y >= im.height() as i64 {
                    return false;
                }
                sum += im.at(x as usize, y as usize);
                n += 1;
            }
        }
        n > 0 && sum / n as f32 >= self.params.white_level
    }
}
