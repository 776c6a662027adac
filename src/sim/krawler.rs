//! The AutoKrawler's running gear as its belly fisheye sees it (seed 003, DESIGN §2.4).
//!
//! The scene is in the body frame (x forward, y left, z up, origin on the ground below the
//! body's centre) and is rebuilt from a [`KrawlerState`] each frame, so a test or an
//! experiment sets the ten degrees of freedom it wants the camera to observe and knows
//! them exactly. Each axle is a rigid assembly that rolls about the body's x axis through
//! its centre and sits a distance d below the camera: the axle beam, a plate on top
//! carrying two magenta markers (roll), two wheels steered about vertical kingpins at the
//! beam's ends, and a tie rod joining the wheels' steering arms, carrying two more
//! markers. Steering swings the arms, so the tie rod shifts sideways against the plate,
//! which is what the paper's ratio of marker distances measures. Each wheel is a
//! 48-sided prism (the paper's cylinder to 0.2 % of its radius) whose faces carry a
//! rubber tread texture, with three faces (22.5°) painted white: the once-per-turn
//! correction marker. Spinning a wheel turns its faces.
//!
//! **Ackermann linkage.** The steering arms form a trapezoid: each arm points from its
//! kingpin toward the centre of the *other* axle (the standard Ackermann trapezoid, arms'
//! lines meeting on the centre line at the opposite axle; seed 003 gives no linkage
//! geometry, so this and the arms' length, `[robot.gear] steering_arm_m`, are our choice). With the arms angled, steering
//! swings the two tie-rod ends by different amounts along x, so the tie rod both shifts
//! and tilts, and d(B1,A1) ≠ d(B2,A2) in world coordinates once λ ≠ 0: the paper's ratio
//! (eq. 5) moves away from 1 with |λ|, with λ's sign, before any camera is involved.
//!
//! **The paper's definitions, adopted as our truth.** Each axle's frame has its origin at
//! the midpoint of its two plate markers, and the axle rolls about that point (the paper:
//! "the midpoint of the two marker coordinates is the rotational centre of the axle"), so
//! [`KrawlerState::drop`] is the paper's d exactly: the vertical distance from the camera
//! down to the plate markers' midpoint. The tie-rod markers sit in the same plane as the
//! plate markers (the rod's top is level with the plate's), the plane the paper intersects
//! their rays with (§V-B, normal R_y(ψ)·ẑ through the midpoint). No conversion is needed.
//!
//! **Frames.** The paper's frame has y forward and z up, and we take its x to the right
//! (Fig. 2 is lost in the seed; right is what makes it right-handed); ours has x forward,
//! y left and z up. So paper (x, y, z) = ours (−y, x, z); its planes y = ±c are
//! our x = ±wheelbase/2, and its roll ψ about y is our roll about x (same sign for a
//! right-handed rotation about the forward axis: positive lifts the left wheel).
//!
//! **Error sources** ([`GearExtras`], for [`crate::sim::krawler_sequence`]'s knobs): the
//! body's shadow on the gear ([`SelfShadow`]), the camera mount's four thin plates in
//! view, and a floor fixed to the world so that it moves under the rover. The shadow is
//! applied to the materials, not traced: each primitive (a tread face, a box side) and
//! each painted marker is lit or shadowed as a whole by where its centre lies, so the
//! shadow's edge on a tread is stepped by the 7.5° faces.
//!
//! Simplified: both wheels of an axle steer by the same angle (the paper's assumption, one
//! λ per axle), so the tie rod is drawn between the arms' ends and its length is not held
//! rigid (it lengthens by 1.1 cm, 2 %, at ±30°); the steering arms themselves are not
//! drawn; the wheels stay on the axle's roll (they do not follow the ground); and the body
//! above the camera is not drawn (a belly camera does not see it).

use super::SimError;
use super::scene::{Material, PaintedSquare, Prim, Scene, Shape, Tag, albedo, boxed};
use super::world::paint;
use crate::kinematics::DriveModel;
use crate::perception::krawler::{ExpectedMarker, GearGeometry};
use crate::profile::{NamedColor, Profile};
use nalgebra::{Isometry3, Point3, Rotation3, Translation3, UnitQuaternion, Vector3};

/// The kinematic state the camera observes (seed 003's ten degrees of freedom).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KrawlerState {
    /// Axle roll ψ (front, rear), rad: positive lifts the left wheel.
    pub roll: [f64; 2],
    /// Vertical distance from the camera down to each axle's plate-marker midpoint, the
    /// axle's roll centre (front, rear), m: the paper's d.
    pub drop: [f64; 2],
    /// Steering λ (front, rear), rad: positive turns the wheels' fronts to the left.
    pub steer: [f64; 2],
    /// Wheel rotations θ (front left, front right, rear left, rear right), rad: positive
    /// rolls the robot forward. At θ = 0 the white correction face is on top.
    pub wheel: [f64; 4],
}

impl KrawlerState {
    /// Level axles at the height the wheels rest at on flat ground, straight, unrotated.
    ///
    /// # Errors
    /// As [`build`], for a profile that does not describe the AutoKrawler's gear.
    pub fn rest(profile: &Profile) -> Result<Self, SimError> {
        let gear = Gear::of(profile)?;
        let [front, rear] = gear.geometry.rest(gear.camera_z);
        Ok(Self {
            roll: [0.0; 2],
            drop: [front.drop, rear.drop],
            steer: [0.0; 2],
            wheel: [0.0; 4],
        })
    }
}

/// Dimensions of the running gear, from the profile (drive, camera mount, markers and
/// `[robot.gear]`, the same the estimator models it with); the beam's, the rod's and the
/// faces' are the constants below.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Gear {
    geometry: GearGeometry,
    track: f64,
    wheelbase: f64,
    wheel_radius: f64,
    wheel_width: f64,
    marker_y: f64,
    plate_top: f64,
    camera_z: f64,
    marker_side: f64,
    marker_color: NamedColor,
}

/// Tread faces per wheel: enough that the prism is the paper's cylinder to 0.2 % of the
/// radius (with 16, points between the faces' edges sat up to 2 % inside it, and the
/// estimator, which intersects rays with the cylinder, under-counted θ by 3 %).
const FACES: usize = 48;
/// The white correction marker covers this many faces either side of face 0: 22.5° of
/// the tread in all.
const WHITE_HALF: usize = 1;
/// The tie rod's height, m: its top, level with the plate's, carries the steering markers.
const ROD_HEIGHT: f64 = 0.024;

impl Gear {
    /// The gear `profile` describes: a double-Ackermann drive with a wheel radius, a
    /// camera, and eight markers.
    fn of(profile: &Profile) -> Result<Self, SimError> {
        let missing = |what: &str| {
            SimError::Unsupported(format!(
                "profile `{}` has no {what}: the AutoKrawler gear needs it",
                profile.name
            ))
        };
        let DriveModel::DoubleAckermann(drive) = profile.drive.model() else {
            return Err(missing("double-Ackermann drive"));
        };
        let wheel_radius = profile
            .drive
            .wheel_radius_m
            .ok_or_else(|| missing("drive.wheel_radius_m"))?;
        let camera = profile.cameras.first().ok_or_else(|| missing("camera"))?;
        let markers = profile
            .fiducial
            .get::<crate::profile::MarkersSpec>()
            .copied()
            .ok_or_else(|| missing("`markers` fiducial"))?;
        if markers.count != 8 {
            return Err(SimError::Unsupported(format!(
                "the gear carries 8 markers (two per axle plate and tie rod); profile `{}` asks for {}",
                profile.name, markers.count
            )));
        }
        let spec = crate::behaviors::krawler::gear_spec(profile).map_err(|e| SimError::Unsupported(e.to_string()))?;
        Ok(Self {
            geometry: GearGeometry {
                track: drive.track,
                wheelbase: drive.wheelbase,
                wheel_radius,
                spec,
            },
            track: drive.track,
            wheelbase: drive.wheelbase,
            wheel_radius,
            wheel_width: spec.tread_width_m,
            marker_y: spec.plate_marker_y_m,
            plate_top: spec.hub_below_plate_m,
            camera_z: camera.mount.z_m,
            marker_side: markers.side_m,
            marker_color: markers.color,
        })
    }
}

/// The rendered gear: the scene, and where the state put each marker.
#[derive(Debug, Clone)]
pub struct KrawlerScene {
    /// Everything the belly camera can see, in the body frame, over the ground.
    pub scene: Scene,
    /// Marker centres in the body frame: front plate left, right; front tie rod left,
    /// right; then the same for the rear axle. In the paper's labels (Fig. 4): A1, A2,
    /// B1, B2, C1, C2, D1, D2, taking 1 as the left side (the figure is lost in the seed).
    pub markers: [Point3<f64>; 8],
    /// Centre of each wheel's white correction face (FL, FR, RL, RR), body frame.
    pub correction: [Point3<f64>; 4],
}

/// Builds the gear of an AutoKrawler `profile` in `state`.
///
/// # Errors
/// [`SimError::Unsupported`] for a profile without a double-Ackermann drive, a wheel
/// radius, a camera, or eight `markers` fiducial.
pub fn build(profile: &Profile, state: &KrawlerState) -> Result<KrawlerScene, SimError> {
    build_with(profile, state, &GearExtras::default())
}

/// The body's shadow on the gear (seed 003 §VI's self-shadowing): a straight band across
/// the body frame's xy plane (the shadow of a part of the body, such as a strut, under a
/// low sun), the gear inside it darkened. Applied through the gear's materials (each
/// primitive, and each painted marker, shaded by where its centre lies), so it falls on
/// the robot's own parts only; the ground is not shadowed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SelfShadow {
    /// Unit normal of the band's edges in the body's xy plane.
    pub normal: [f64; 2],
    /// The band's centre line's offset along the normal, m.
    pub offset: f64,
    /// The band's width, m: points p with |normal·p − offset| < width/2 are in shadow.
    pub width: f64,
    /// Light removed in the shadow (0–1).
    pub strength: f32,
}

impl SelfShadow {
    /// The shading factor at body point `p`: 1 lit, 1 − strength in shadow.
    pub fn shade(&self, p: &Point3<f64>) -> f32 {
        if (self.normal[0] * p.x + self.normal[1] * p.y - self.offset).abs() < self.width / 2.0 {
            1.0 - self.strength
        } else {
            1.0
        }
    }
}

/// The ground under the rover, moved: the rover at `(x, y)` with `heading` (rad) on a
/// world-fixed floor, so the floor's texture flows through the image as the rover drives.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GroundPose {
    /// The rover's position on the floor, m.
    pub x: f64,
    /// See `x`.
    pub y: f64,
    /// The rover's heading, rad.
    pub heading: f64,
}

/// What a sequence's error knobs add to the gear's scene (all off by default: the scene
/// [`build`] gives).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct GearExtras {
    /// The body's shadow on the gear.
    pub shadow: Option<SelfShadow>,
    /// The camera mount's four thin plates in view (seed 003 Fig. 3).
    pub mount_plates: bool,
    /// A floor fixed to the world instead of to the body.
    pub ground: Option<GroundPose>,
}

/// The camera mount's plates, m (estimates): each runs from this far from the optical
/// axis...
const PLATE_INNER: f64 = 0.03;
/// ...to this far...
const PLATE_OUTER: f64 = 0.12;
/// ...from this far below the lens's plane up to [`PLATE_TOP_GAP`] below it (the rest of
/// the plate, up to the body, is outside the fisheye's view), and is this thick.
const PLATE_BELOW: f64 = 0.03;
/// See [`PLATE_BELOW`].
const PLATE_TOP_GAP: f64 = 0.002;
/// See [`PLATE_BELOW`].
const PLATE_THICK: f64 = 0.004;

/// [`build`] with a sequence's `extras`: the body's shadow on the gear, the mount's
/// plates, a floor fixed to the world.
///
/// # Errors
/// As [`build`].
pub fn build_with(profile: &Profile, state: &KrawlerState, extras: &GearExtras) -> Result<KrawlerScene, SimError> {
    let g = Gear::of(profile)?;
    let marker_albedo = paint(g.marker_color);
    let metal_albedo = albedo([90, 92, 95], 1.0);
    let metal = Material::Solid(metal_albedo);
    let plate_albedo = albedo([150, 150, 150], 1.0);
    // A pair of markers, ±marker_y across a surface's v axis (its local b).
    let pair = |base: [f32; 3], a: f64| Material::Squares {
        base,
        squares: [1.0f32, -1.0]
            .map(|side| PaintedSquare {
                a: a as f32,
                b: side * g.marker_y as f32,
                half: g.marker_side as f32 / 2.0,
                albedo: marker_albedo,
            })
            .to_vec()
            .into(),
    };
    let rubber = Material::Noise {
        base: albedo([45, 45, 48], 1.0),
        contrast: 0.6,
        cell: 0.012,
    };
    let rubber_inverted = Material::Noise {
        base: albedo([45, 45, 48], 1.0),
        contrast: -0.6,
        cell: 0.012,
    };
    let white = Material::Solid(albedo([255, 255, 255], 0.85));
    let mut prims = Vec::new();
    let mut markers = [Point3::origin(); 8];
    let mut correction = [Point3::origin(); 4];
    for axle in 0..2 {
        // Front axle ahead (+x); each axle's arms point back toward the other axle.
        let (x, inboard) = if axle == 0 {
            (g.wheelbase / 2.0, -1.0)
        } else {
            (-g.wheelbase / 2.0, 1.0)
        };
        // The axle frame's origin is the plate markers' midpoint, its roll centre.
        let pose = Isometry3::from_parts(
            Translation3::new(x, 0.0, g.camera_z - state.drop[axle]),
            UnitQuaternion::from_axis_angle(&Vector3::x_axis(), state.roll[axle]),
        );
        let mut put = |p: Prim| prims.push(transform(p, &pose));
        let half_beam = g.track / 2.0 - g.wheel_width / 2.0 - 0.01;
        for p in boxed(
            Point3::new(-0.02, -half_beam, -0.02 - g.plate_top),
            Point3::new(0.02, half_beam, 0.02 - g.plate_top),
            metal.clone(),
            Tag::Own,
        ) {
            put(p);
        }
        put(flat(Point3::origin(), [0.03, 0.16], pair(plate_albedo, 0.0)));
        // The tie rod joins the arms' ends, each swung by the steering about its kingpin.
        let rod_ends = g.geometry.tie_rod_ends(inboard, state.steer[axle]);
        let (left_end, right_end) = (rod_ends[0], rod_ends[1]);
        let mid = nalgebra::center(&left_end, &right_end);
        let along = (left_end - right_end).normalize();
        let half_rod = (left_end - right_end).norm() / 2.0;
        let rod_pose = Isometry3::from_parts(
            Translation3::new(mid.x, mid.y, 0.0),
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), along.y.atan2(along.x) - std::f64::consts::FRAC_PI_2),
        );
        let mut rod_box = boxed(
            Point3::new(-0.012, -half_rod, -ROD_HEIGHT),
            Point3::new(0.012, half_rod, 0.0),
            metal.clone(),
            Tag::Own,
        );
        // The box's top face is centred on the rod, u along its width, v along its length.
        rod_box[4].material = pair(metal_albedo, 0.0);
        for p in rod_box {
            put(transform(p, &rod_pose));
        }
        for (k, side) in [1.0, -1.0].into_iter().enumerate() {
            let on_plate = Point3::new(0.0, side * g.marker_y, 0.0);
            let on_rod = rod_pose * Point3::new(0.0, side * g.marker_y, 0.0);
            markers[axle * 4 + k] = pose * on_plate;
            markers[axle * 4 + 2 + k] = pose * on_rod;
        }
        // Wheels: kingpins at the beam's ends; the left wheel is index 0 of the axle.
        for (k, side) in [1.0, -1.0].into_iter().enumerate() {
            let hub = Isometry3::from_parts(
                Translation3::new(0.0, side * g.track / 2.0, -g.plate_top),
                UnitQuaternion::from_axis_angle(&Vector3::z_axis(), state.steer[axle]),
            );
            let wheel = pose * hub;
            let theta = state.wheel[axle * 2 + k];
            for f in 0..FACES {
                let phi = theta + std::f64::consts::TAU * f as f64 / FACES as f64;
                let (sp, cp) = phi.sin_cos();
                let apothem = g.wheel_radius * (std::f64::consts::PI / FACES as f64).cos();
                let half_arc = g.wheel_radius * (std::f64::consts::PI / FACES as f64).sin();
                let centre = Point3::new(apothem * sp, 0.0, apothem * cp);
                // The texture is laid out from each face's centre, so neighbouring faces
                // would repeat it every face (7.5°) and a tracker would alias; turning
                // every other face's texture by 180° and inverting it on every other pair
                // makes it repeat every fourth face (30°).
                let turn = if f % 2 == 1 { -1.0 } else { 1.0 };
                let face = Prim::new(
                    Shape::Rect {
                        centre,
                        u: Vector3::new(cp, 0.0, -sp) * turn,
                        v: Vector3::y() * turn,
                        half: [half_arc, g.wheel_width / 2.0],
                    },
                    if f <= WHITE_HALF || f >= FACES - WHITE_HALF {
                        white.clone()
                    } else if (f / 2) % 2 == 1 {
                        rubber_inverted.clone()
                    } else {
                        rubber.clone()
                    },
                    Tag::Own,
                );
                if f == 0 {
                    correction[axle * 2 + k] = wheel * centre;
                }
                prims.push(transform(face, &wheel));
            }
            for wall in [1.0, -1.0] {
                let n = Vector3::y() * wall;
                prims.push(transform(
                    Prim::new(
                        Shape::Disc {
                            centre: Point3::new(0.0, wall * g.wheel_width / 2.0, 0.0),
                            u: n.cross(&Vector3::z()),
                            v: Vector3::z(),
                            radius: g.wheel_radius * 0.98,
                        },
                        metal.clone(),
                        Tag::Own,
                    ),
                    &wheel,
                ));
            }
        }
    }
    if let Some(shadow) = &extras.shadow {
        for p in &mut prims {
            shade_prim(p, shadow);
        }
    }
    if extras.mount_plates {
        // Four plates in the planes x = cx and y = cy through the camera's centre, a cross
        // seen edge-on: thin slivers radiating from the image's centre.
        let c = &profile.cameras[0].mount;
        let (z0, z1) = (g.camera_z - PLATE_BELOW, g.camera_z - PLATE_TOP_GAP);
        let t = PLATE_THICK / 2.0;
        // A plate's extent along one axis: out from the camera on the side it points
        // to, its thickness about the centre across.
        let span = |d: f64| {
            let (a, b) = (PLATE_INNER, PLATE_OUTER);
            if d > 0.0 {
                (a, b)
            } else if d < 0.0 {
                (-b, -a)
            } else {
                (-t, t)
            }
        };
        for (dx, dy) in [(1.0, 0.0), (-1.0, 0.0), (0.0, 1.0), (0.0, -1.0)] {
            let ((x0, x1), (y0, y1)) = (span(dx), span(dy));
            prims.extend(boxed(
                Point3::new(c.x_m + x0, c.y_m + y0, z0),
                Point3::new(c.x_m + x1, c.y_m + y1, z1),
                Material::Solid(albedo([70, 70, 74], 1.0)),
                Tag::Own,
            ));
        }
    }
    let mut scene = Scene::on_floor(prims);
    if let Some(ground) = &extras.ground {
        // The floor as a large world-fixed sheet just above the body-fixed one, its
        // centre and axes seen from the rover. The renderer draws front to back by
        // centre distance, so the centre is kept far away (at world (−GROUND_AWAY, 0)),
        // behind every part of the gear; the sheet reaches well past the rover.
        let (s, c) = ground.heading.sin_cos();
        let to_body = |wx: f64, wy: f64| Vector3::new(c * wx + s * wy, -s * wx + c * wy, 0.0);
        let origin = to_body(-GROUND_AWAY - ground.x, -ground.y);
        scene.prims.push(Prim::new(
            Shape::Rect {
                centre: Point3::new(origin.x, origin.y, 5e-4),
                u: to_body(1.0, 0.0),
                v: to_body(0.0, 1.0),
                half: [GROUND_HALF, GROUND_HALF],
            },
            scene.ground.clone(),
            Tag::Backdrop,
        ));
    }
    Ok(KrawlerScene {
        scene,
        markers,
        correction,
    })
}

/// How far the world-fixed floor's centre is from the world's origin, m.
const GROUND_AWAY: f64 = 100.0;
/// Half the side of the world-fixed floor, m: it reaches 100 m past the world's origin,
/// far beyond anything the belly camera sees over the longest sequence's path.
const GROUND_HALF: f64 = 2.0 * GROUND_AWAY;

/// `p` darkened where `shadow` falls on it: by its centre, and each painted square by its
/// own centre (so a shadow edge between a plate's two markers hides one of them).
fn shade_prim(p: &mut Prim, shadow: &SelfShadow) {
    let centre = p.shape.centre();
    let f = shadow.shade(&centre);
    let scale = |c: [f32; 3], f: f32| c.map(|v| v * f);
    p.material = match &p.material {
        Material::Solid(c) => Material::Solid(scale(*c, f)),
        Material::Noise { base, contrast, cell } => Material::Noise {
            base: scale(*base, f),
            contrast: *contrast,
            cell: *cell,
        },
        Material::Squares { base, squares } => {
            let frame = p.shape.plane();
            Material::Squares {
                base: scale(*base, f),
                squares: squares
                    .iter()
                    .map(|sq| {
                        let at = frame
                            .as_ref()
                            .map_or(centre, |fr| fr.origin + fr.u * f64::from(sq.a) + fr.v * f64::from(sq.b));
                        PaintedSquare {
                            albedo: scale(sq.albedo, shadow.shade(&at)),
                            ..*sq
                        }
                    })
                    .collect::<Vec<_>>()
                    .into(),
            }
        }
        other => other.clone(),
    };
}

/// Where each of the eight markers of the gear in `state` projects in camera 0 of
/// `profile`, and how large (squares of the profile's side, lying flat): the prediction
/// a marker tracker starts from, in [`KrawlerScene::markers`]' order.
///
/// # Errors
/// As [`build`], and [`SimError::Unsupported`] when a marker does not project into the
/// camera.
pub fn expected_markers(profile: &Profile, state: &KrawlerState) -> Result<[ExpectedMarker; 8], SimError> {
    let gear = build(profile, state)?;
    let cam = &profile.cameras[0];
    let model = crate::perception::CameraModel::from_spec(cam);
    let pose = super::camera::camera_pose(&crate::geometry::Pose2::new(0.0, 0.0, 0.0), &cam.mount);
    let side = profile
        .fiducial
        .get::<crate::profile::MarkersSpec>()
        .copied()
        .map_or(0.03, |m| m.side_m);
    let project = |q: [f64; 3]| model.project(&pose.to_camera(&Point3::from(q)));
    let mut out = [ExpectedMarker {
        at: [0.0; 2],
        area: 0.0,
    }; 8];
    for (o, m) in out.iter_mut().zip(&gear.markers) {
        *o = ExpectedMarker::from_square(project, m.coords.into(), [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], side)
            .ok_or_else(|| SimError::Unsupported("a marker of the gear does not project into the camera".into()))?;
    }
    Ok(out)
}

/// A flat horizontal square or rectangle facing up (+z), half extents along x and y.
fn flat(centre: Point3<f64>, half: [f64; 2], material: Material) -> Prim {
    Prim::new(
        Shape::Rect {
            centre,
            u: Vector3::x(),
            v: Vector3::y(),
            half,
        },
        material,
        Tag::Own,
    )
}

/// `p` moved by `iso`.
fn transform(mut p: Prim, iso: &Isometry3<f64>) -> Prim {
    let r: Rotation3<f64> = iso.rotation.to_rotation_matrix();
    p.shape = match p.shape {
        Shape::Rect { centre, u, v, half } => Shape::Rect {
            centre: iso * centre,
            u: r * u,
            v: r * v,
            half,
        },
        Shape::Disc { centre, u, v, radius } => Shape::Disc {
            centre: iso * centre,
            u: r * u,
            v: r * v,
            radius,
        },
        Shape::Triangle { p: q } => Shape::Triangle { p: q.map(|x| iso * x) },
        Shape::Sphere { centre, radius } => Shape::Sphere {
            centre: iso * centre,
            radius,
        },
    };
    p
}

#[cfg(test)]
mod tests {
    use super::*;

    fn profile() -> Profile {
        Profile::load(&std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/autokrawler.toml")).unwrap()
    }

    fn rest() -> (Profile, KrawlerState) {
        let p = profile();
        let s = KrawlerState {
            roll: [0.05, -0.03],
            steer: [0.2, -0.1],
            wheel: [0.3, 1.1, 2.0, 4.0],
            ..KrawlerState::rest(&p).unwrap()
        };
        (p, s)
    }

    /// Every albedo a material holds (its base, then each painted square's), red channel.
    fn reds(m: &Material) -> Vec<f32> {
        match m {
            Material::Solid(c) | Material::Noise { base: c, .. } => vec![c[0]],
            Material::Squares { base, squares } => std::iter::once(base[0])
                .chain(squares.iter().map(|s| s.albedo[0]))
                .collect(),
            _ => vec![],
        }
    }

    #[test]
    fn with_the_extras_off_the_scene_is_the_plain_one() {
        let (p, s) = rest();
        let a = build(&p, &s).unwrap();
        let b = build_with(&p, &s, &GearExtras::default()).unwrap();
        assert_eq!(format!("{:?}", a.scene), format!("{:?}", b.scene));
        assert_eq!(a.markers, b.markers);
    }

    /// A band over the left side darkens exactly the parts (and the painted squares) whose
    /// centres are inside it, by its strength.
    #[test]
    fn the_shadow_falls_on_the_gear_inside_its_band_only() {
        let (p, s) = rest();
        // Over y = 0.075…0.325: the left markers and the left wheels, not the right.
        let shadow = SelfShadow {
            normal: [0.0, 1.0],
            offset: 0.2,
            width: 0.25,
            strength: 0.5,
        };
        let plain = build(&p, &s).unwrap();
        let shaded = build_with(
            &p,
            &s,
            &GearExtras {
                shadow: Some(shadow),
                ..GearExtras::default()
            },
        )
        .unwrap();
        assert_eq!(plain.scene.prims.len(), shaded.scene.prims.len());
        let (mut dark, mut lit) = (0, 0);
        for (a, b) in plain.scene.prims.iter().zip(&shaded.scene.prims) {
            let want = shadow.shade(&a.shape.centre());
            let (ra, rb) = (reds(&a.material), reds(&b.material));
            assert!((rb[0] - ra[0] * want).abs() < 1e-6);
            if want < 1.0 {
                dark += 1;
            } else {
                lit += 1;
            }
            if ra.len() == 3 {
                // A plate or rod top: the left square (b = +marker_y) is in the band, the
                // right one is not, whatever the base.
                assert!((rb[1] - ra[1] * 0.5).abs() < 1e-6, "left marker shadowed");
                assert_eq!(rb[2], ra[2], "right marker lit");
            }
        }
        assert!(dark > 0 && lit > dark, "{dark} dark, {lit} lit");
    }

    #[test]
    fn the_plates_and_the_moving_ground_add_their_parts() {
        let (p, s) = rest();
        let plain = build(&p, &s).unwrap().scene.prims.len();
        let plates = build_with(
            &p,
            &s,
            &GearExtras {
                mount_plates: true,
                ..GearExtras::default()
            },
        )
        .unwrap();
        let one_box = boxed(
            Point3::origin(),
            Point3::new(1.0, 1.0, 1.0),
            Material::Solid([0.5; 3]),
            Tag::Own,
        )
        .len();
        assert_eq!(plates.scene.prims.len(), plain + 4 * one_box, "four boxes");
        let pose = GroundPose {
            x: 1.0,
            y: -0.5,
            heading: std::f64::consts::FRAC_PI_2,
        };
        let ground = build_with(
            &p,
            &s,
            &GearExtras {
                ground: Some(pose),
                ..GearExtras::default()
            },
        )
        .unwrap();
        let sheet = ground.scene.prims.last().unwrap();
        // Seen from a rover at (1, −0.5) heading along the world's +y, the sheet's centre
        // at world (−100, 0) is 0.5 m ahead and 101 m to the left, body (0.5, 101), and
        // the world's x axis points to the body's right.
        let Shape::Rect { centre, u, .. } = sheet.shape else {
            panic!("a rectangle")
        };
        assert!((centre - Point3::new(0.5, 101.0, 5e-4)).norm() < 1e-9, "{centre}");
        assert!((u - Vector3::new(0.0, -1.0, 0.0)).norm() < 1e-12, "{u}");
    }
}
