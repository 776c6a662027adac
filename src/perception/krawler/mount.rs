//! Mount-vibration compensation: the camera's own small motion on its mount, measured each
//! frame from the four plate markers (seed 003 §VI names "excessive camera mount
//! vibration" as an error source; compensating it is ours).
//!
//! The plate markers are not fixed to the body (each pair rolls and drops with its axle),
//! but their layout constrains them: each pair lies in its axle's plane x = ±c, its
//! midpoint on the body's centre line (y = 0), the two markers a known distance apart
//! ([`super::GearLayout::marker_half_spacing`]). Two axles' four markers give eight ray
//! measurements for four axle unknowns (ψ and d of each), so four combinations of the
//! camera's six-DOF offset can be measured: the yaw (the pairs turned out of the lateral
//! direction), the pitch and the forward shift together (the pairs seen off their
//! planes: both move the two axles' markers alike, so only their combined effect is
//! measured, and split by the prior), and the sideways shift with the roll (the
//! midpoints off the centre line). Two cannot: a vertical shift reads exactly as both
//! axles dropping, and a roll about the forward axis reads as both axles rolling plus a
//! sideways shift. What matters downstream is that the fitted mount reproduces where the
//! gear is seen, which the measured combinations do. [`fit_mount`] solves for the camera's rotation and its
//! forward and sideways shift together with the axles' roll and drop by Gauss–Newton on
//! the markers' ray errors, with a zero-mean prior on the offset of the mount's typical
//! size ([`MountParams`]): the measured combinations follow the markers, the unmeasured
//! ones stay at the prior's best guess. The vertical shift is left at zero (the drops
//! carry it, as they did without compensation). The camera's roll is split with the
//! sideways shift in the ratio of their priors, so only part of a roll vibration is
//! removed from the axles' roll.
//!
//! The fitted offset moves the geometry every later stage uses this frame (the plate
//! markers' ray-plane intersections, the tie-rod plane, the wheels' observation windows
//! and the back-projection of each tread feature), and the wheel stage back-projects the
//! previous frame's end of each track with the previous frame's offset, so the mount's
//! shake between two frames does not read as wheel rotation.
//!
//! Fixed-size arithmetic throughout: no allocation.

use super::axle::AxleGeometry;
use nalgebra::{Point3, Rotation3, SMatrix, SVector, Vector3};

/// Unknowns of the fit: the camera's rotation vector (3), its forward and sideways shift
/// (2), then roll and drop of the front and rear axles.
const N: usize = 9;

/// The compensation's settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MountParams {
    /// Whether to compensate at all (off: every frame uses the nominal mount, the
    /// estimator as it was).
    pub enabled: bool,
    /// The prior's SD of the mount's rotation per frame, degrees.
    pub rotation_sd_deg: f64,
    /// The prior's SD of the mount's displacement per frame, mm.
    pub translation_sd_mm: f64,
    /// SD of a marker centre's ray direction, rad (its pixel noise over the fisheye's
    /// scale, about 175 px/rad).
    pub ray_sd_rad: f64,
    /// Gauss–Newton iterations.
    pub iterations: usize,
}

impl Default for MountParams {
    /// On, with a prior of 0.5° and 2 mm a frame (our estimate of a small rover's belly
    /// mount shaking over rough ground; the paper gives no figure), marker rays good to
    /// 1 mrad (about 0.2 px), three iterations.
    fn default() -> Self {
        Self {
            enabled: true,
            rotation_sd_deg: 0.5,
            translation_sd_mm: 2.0,
            ray_sd_rad: 1e-3,
            iterations: 3,
        }
    }
}

/// The camera's offset from its nominal mount, body frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MountOffset {
    /// Rotation vector (axis × angle, rad) taking the nominal camera orientation to the
    /// actual: body_from_camera = R(rotation) · nominal.
    pub rotation: Vector3<f64>,
    /// Displacement of the camera's centre, m (z is always 0: not measurable).
    pub translation: Vector3<f64>,
}

impl MountOffset {
    /// Sets `frame`'s mount to `nominal`'s moved by this offset (the model and the axles'
    /// planes are not touched: `frame` is a copy of `nominal` made once).
    pub fn apply(&self, nominal: &AxleGeometry, frame: &mut AxleGeometry) {
        frame.body_from_camera = Rotation3::new(self.rotation).matrix() * nominal.body_from_camera;
        frame.camera = nominal.camera + self.translation;
    }
}

/// The body-frame point of plate marker `side` (+1 left, −1 right) of an axle in plane
/// x = `axle_x`, rolled by `roll` and `drop` below a camera at height `camera_z`.
fn plate_marker(axle_x: f64, camera_z: f64, half_spacing: f64, roll: f64, drop: f64, side: f64) -> Point3<f64> {
    let (s, c) = roll.sin_cos();
    Point3::new(
        axle_x,
        side * half_spacing * c,
        camera_z - drop + side * half_spacing * s,
    )
}

/// The camera's offset this frame from the plate markers' pixel centres `plate` (front
/// left, front right, rear left, rear right; a missing marker is left out), starting
/// from the axles' `start` (roll, drop) (front, rear), for plate markers
/// `half_spacing` m either side of their axle's centre. `None` when compensation is off,
/// fewer than two markers are found, or the fit does not solve.
pub fn fit_mount(
    geometry: &AxleGeometry,
    plate: [Option<[f64; 2]>; 4],
    start: [(f64, f64); 2],
    half_spacing: f64,
    params: &MountParams,
) -> Option<MountOffset> {
    if !params.enabled || plate.iter().flatten().count() < 2 {
        return None;
    }
    // Each found marker's ray in the body frame (nominal mount) and a basis of the plane
    // across it, in which its error is measured.
    let rays = plate.map(|p| {
        p.map(|at| {
            let r: Vector3<f64> = (geometry.body_from_camera * geometry.model.ray(at[0], at[1])).normalize();
            let helper = if r.x.abs() < 0.9 { Vector3::x() } else { Vector3::y() };
            let e1 = r.cross(&helper).normalize();
            let e2 = r.cross(&e1);
            (r, e1, e2)
        })
    });
    let residuals = |x: &SVector<f64, N>| -> SVector<f64, 8> {
        let rot = Rotation3::new(Vector3::new(x[0], x[1], x[2]));
        let centre = geometry.camera + Vector3::new(x[3], x[4], 0.0);
        let mut out = SVector::<f64, 8>::zeros();
        for (k, ray) in rays.iter().enumerate() {
            let Some((_, e1, e2)) = ray else { continue };
            let axle = k / 2;
            let side = if k % 2 == 0 { 1.0 } else { -1.0 };
            let p = plate_marker(
                geometry.axle_x[axle],
                geometry.camera.z,
                half_spacing,
                x[5 + 2 * axle],
                x[6 + 2 * axle],
                side,
            );
            // The marker's direction as the shaken camera sees it, in the nominal frame.
            let v = (rot.inverse() * (p - centre)).normalize();
            out[2 * k] = e1.dot(&v) / params.ray_sd_rad;
            out[2 * k + 1] = e2.dot(&v) / params.ray_sd_rad;
        }
        out
    };
    // The prior's information: the offset's typical size; a faint one on the axles keeps
    // an axle whose markers are both missing at its start.
    let rot_sd = params.rotation_sd_deg.to_radians().max(1e-9);
    let tr_sd = (params.translation_sd_mm / 1000.0).max(1e-9);
    let mut prior = SVector::<f64, N>::zeros();
    for i in 0..3 {
        prior[i] = 1.0 / (rot_sd * rot_sd);
    }
    for i in 3..5 {
        prior[i] = 1.0 / (tr_sd * tr_sd);
    }
    for i in 5..N {
        prior[i] = 1e-6;
    }
    let mut x = SVector::<f64, N>::zeros();
    let mut x0 = SVector::<f64, N>::zeros();
    for axle in 0..2 {
        x0[5 + 2 * axle] = start[axle].0;
        x0[6 + 2 * axle] = start[axle].1;
    }
    x.copy_from(&x0);
    let h = 1e-7;
    for _ in 0..params.iterations {
        let r = residuals(&x);
        let mut jac = SMatrix::<f64, 8, N>::zeros();
        for j in 0..N {
            let mut xp = x;
            let mut xm = x;
            xp[j] += h;
            xm[j] -= h;
            jac.set_column(j, &((residuals(&xp) - residuals(&xm)) / (2.0 * h)));
        }
        let mut normal = jac.transpose() * jac;
        let mut grad = jac.transpose() * r;
        for i in 0..N {
            normal[(i, i)] += prior[i];
            grad[i] += prior[i] * (x[i] - x0[i]);
        }
        let step = normal.cholesky()?.solve(&(-grad));
        x += step;
        if step.norm() < 1e-10 {
            break;
        }
    }
    x.iter().all(|v| v.is_finite()).then(|| MountOffset {
        rotation: Vector3::new(x[0], x[1], x[2]),
        translation: Vector3::new(x[3], x[4], 0.0),
    })
}
