//! Builds the 3-D scene and the 2-D dock geometry for a profile.
//!
//! World (dock) frame: origin at the middle of the dock entrance on the ground, +x out of
//! the dock along its axis, +z up. The mother's (or station's) body lies at x < 0.

use super::SimError;
use super::dock::Cone;
use super::obstacles::{Footprint, Obstacles};
use super::scene::{CircleMark, Material, Prim, Scene, Shape, Tag, albedo, boxed, face_rect};
use crate::perception::RgbImage;
use crate::profile::{CirclePlacement, CirclesSpec, FiducialKind, NamedColor, Profile, PyramidSpec, TwoBlockSpec};
use nalgebra::{Point3, Vector3};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// A clutter object placed by a scenario.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClutterSpec {
    /// What it is.
    pub kind: ClutterKind,
    /// Centre x (world), m.
    pub x_m: f64,
    /// Centre y (world), m.
    pub y_m: f64,
    /// Height of the bottom (boxes) or centre (panels, copies) above ground, m.
    #[serde(default)]
    pub z_m: f64,
    /// Size (x, y, z) of a box, or (width, height) of a panel, m.
    #[serde(default)]
    pub size_m: Vec<f64>,
    /// Colour of a box or panel.
    #[serde(default)]
    pub color: Option<NamedColor>,
    /// Facing direction of panels and fiducial copies, degrees (0: faces +x, toward the
    /// approach zone).
    #[serde(default)]
    pub facing_deg: f64,
    /// A circle mark's bar rotation on its panel, degrees (`circle_mark` only; 0: the bar
    /// along the panel's width).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub mark_rotation_deg: f64,
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

impl ClutterSpec {
    /// Size along axis `i` (0: x or width, 1: y or height, 2: z), m; 0.1 m when the
    /// scenario gives none.
    fn size(&self, i: usize) -> f64 {
        self.size_m.get(i).copied().unwrap_or(0.1)
    }

    /// A box's lowest and highest corners (x, y, z), m.
    fn box_bounds(&self) -> ([f64; 3], [f64; 3]) {
        let (sx, sy, sz) = (self.size(0), self.size(1), self.size(2));
        (
            [self.x_m - sx / 2.0, self.y_m - sy / 2.0, self.z_m],
            [self.x_m + sx / 2.0, self.y_m + sy / 2.0, self.z_m + sz],
        )
    }
}

/// Kinds of clutter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ClutterKind {
    /// A coloured box. Standing lower than the robot's body (`z_m` under `body.height_m`)
    /// it is an obstacle: the robot cannot drive through it, and range finders see it.
    Box,
    /// A flat coloured panel.
    Panel,
    /// An exact copy of the fiducial, upright.
    FiducialCopy,
    /// A copy of the fiducial turned upside down (rotated 180° in its plane).
    FiducialCopyUpsideDown,
    /// One circle mark of a `circles`-fiducial profile (its diameter and pattern, the
    /// bar at `mark_rotation_deg`) on an upright panel of `size_m` (width, height) in
    /// `color` (default: the module's grey): a false mark near the module, the kind of
    /// circle-like blob seed 000's correspondence had to reject.
    CircleMark,
}

/// 2-D geometry the motion model and judge need.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DockGeometry {
    /// Body footprint: x from `-body_length` to 0, |y| ≤ `body_half_width`.
    pub body_length: f64,
    /// Half the body's width, m.
    pub body_half_width: f64,
    /// Half the entrance width, m.
    pub entrance_half: f64,
    /// Depth of the pouch from the entrance to the contact plates, m.
    pub depth: f64,
    /// Largest lateral error at the entrance, m.
    pub tol_lateral: f64,
    /// Largest heading error at the entrance, rad.
    pub tol_heading: f64,
    /// The robot must lower itself to enter (Bujold).
    pub needs_lowered: bool,
    /// The dock is a target on the ground that the robot drives onto (RAPOSA's pyramid):
    /// there is no body; the target is at the origin and enters the robot's rear.
    pub open: bool,
    /// Footprint of an open dock's target (x0, x1, y0, y1): touching it other than by
    /// docking is a collision.
    pub target_extent: Option<[f64; 4]>,
    /// A docking cone that only a tether-pulled leading arm enters (Axel), replacing the
    /// pouch: `entrance_half` and `depth` are then its mouth and depth, and the tolerances
    /// go unused (the cone's geometry decides).
    pub cone: Option<Cone>,
}

impl DockGeometry {
    /// How far behind the robot's rear plane an open dock's target centre counts as
    /// meeting the socket's mouth, arriving at `heading` (rad): the target's front
    /// (radius ahead of its centre) reaches the plane, earlier by up to the mouth's
    /// half-width × |sin heading| when the footprint's front corners arrive first, plus
    /// 1.5 cm of contact slack.
    pub fn mouth_reach(&self, heading: f64) -> f64 {
        let front = self.target_extent.map_or(0.035, |e| e[1]);
        front + self.entrance_half * heading.sin().abs() + 0.015
    }
}

/// A built world.
#[derive(Debug, Clone)]
pub struct World {
    /// What cameras see.
    pub scene: Scene,
    /// What the judge checks.
    pub dock: DockGeometry,
    /// Index of the primitives that form the target (for shadows and tests).
    pub target_prims: Vec<usize>,
    /// What the robot can bump into and range finders see.
    pub obstacles: Obstacles,
}

fn y_axis() -> Vector3<f64> {
    Vector3::y()
}

fn z_axis() -> Vector3<f64> {
    Vector3::z()
}

/// Rotates `v` about +z by `deg`.
fn yaw(v: Vector3<f64>, deg: f64) -> Vector3<f64> {
    let (s, c) = deg.to_radians().sin_cos();
    Vector3::new(c * v.x - s * v.y, s * v.x + c * v.y, v.z)
}

/// A painted surface of a named colour: its linear reflectance from the paint model the
/// perception's table defaults share ([`crate::profile::paint`]). Without the model's
/// floor a rendered cyan sits exactly on SCT's B = 90° edge wherever no highlight reaches
/// it, and a faint highlight moved it 12° (to B 78°) in the dusk departure frames we
/// measured: an edge no real paint sits on.
pub(super) fn paint(c: NamedColor) -> [f32; 3] {
    c.reflectance()
}

/// Builds the world for `profile` with `clutter` and optional backdrop photos.
///
/// # Errors
/// [`SimError::Unsupported`] for a fiducial kind the simulator cannot build yet.
pub fn build(profile: &Profile, clutter: &[ClutterSpec], backdrops: &[Arc<RgbImage>]) -> Result<World, SimError> {
    build_face(profile, clutter, backdrops, &[], &[])
}

/// [`build`] with `painters` drawing the dock (a crate's own fiducial kinds).
///
/// # Errors
/// [`SimError::Unsupported`] for a fiducial kind no painter draws.
pub fn build_with(
    profile: &Profile,
    clutter: &[ClutterSpec],
    backdrops: &[Arc<RgbImage>],
    painters: &DockPainters,
) -> Result<World, SimError> {
    paint_world(
        profile,
        clutter,
        backdrops,
        FaceMarks {
            covered: &[],
            painted: &[],
        },
        painters,
    )
}

/// [`build`], with the module's face edited for `marsupial pose-trials`' occlusion
/// campaigns (ignored by a profile without `circles` fiducial):
/// * the circle marks `covered` (indices into ``circles` fiducial.placements`) are covered
///   flush with a patch of the face's paint: the module keeps its size and the other
///   marks, and those are not painted;
/// * `painted` false marks are painted on the face among the real ones: circle marks of
///   the layout's size and pattern at those face positions (`y_m` across the face, `z_m`
///   above the ground) and rotations, which the module's model does not have. It is the
///   hard case for the correspondence (seed 000 §V-D: four true marks and one false one
///   fit a homography exactly).
///
/// Both are painted by the face because a panel held in front of it would be drawn
/// behind it: the renderer orders primitives by their centres' distance.
///
/// # Errors
/// As [`build`].
pub fn build_face(
    profile: &Profile,
    clutter: &[ClutterSpec],
    backdrops: &[Arc<RgbImage>],
    covered: &[usize],
    painted: &[CirclePlacement],
) -> Result<World, SimError> {
    paint_world(
        profile,
        clutter,
        backdrops,
        FaceMarks { covered, painted },
        &DockPainters::builtin(),
    )
}

/// Builds the world: the dock `painters` draw for the profile's fiducial kind, the
/// clutter, the backdrop walls.
fn paint_world(
    profile: &Profile,
    clutter: &[ClutterSpec],
    backdrops: &[Arc<RgbImage>],
    face: FaceMarks<'_>,
    painters: &DockPainters,
) -> Result<World, SimError> {
    let mut prims = Vec::new();
    let mut target_prims = Vec::new();
    let dock_spec = profile
        .dock
        .ok_or_else(|| SimError::Unsupported("a profile without [dock]".into()))?;
    let entrance_half = dock_spec.entrance_width_m / 2.0;
    let mut dock = DockGeometry {
        body_length: 1.2,
        body_half_width: 0.45,
        entrance_half,
        depth: dock_spec.depth_m,
        tol_lateral: profile.success.lateral_tolerance_m,
        tol_heading: profile.success.heading_tolerance_deg.to_radians(),
        needs_lowered: false,
        open: false,
        target_extent: None,
        cone: None,
    };
    if let (Some(c), Some(t)) = (dock_spec.cone, profile.tether) {
        dock.cone = Some(Cone {
            mouth_half: entrance_half,
            depth: dock_spec.depth_m,
            throat_half: dock_spec.throat_half_width(),
            axis_height: c.axis_height_m,
            tilt: c.tilt_deg.to_radians(),
            seat_length: c.seat_length_m,
            anchor_depth: t.anchor_depth_m,
            arm: t.arm_m,
            tip_radius: t.tip_diameter_m / 2.0,
            tip_height: t.tip_height_m,
        });
    }
    let painter = painters.get(profile.fiducial.kind()).ok_or_else(|| {
        let known: Vec<&str> = painters.kinds().collect();
        SimError::Unsupported(format!(
            "the simulator has no dock painter for fiducial kind `{}` (profile `{}`; painters: {})",
            profile.fiducial.kind(),
            profile.name,
            known.join(", ")
        ))
    })?;
    painter(&mut DockCanvas {
        profile,
        prims: &mut prims,
        target_prims: &mut target_prims,
        dock: &mut dock,
        face,
    })?;
    for c in clutter {
        add_clutter(&mut prims, c, profile);
    }
    // Backdrop: walls 3 m behind the dock and to the sides, with photos when given. A
    // cone's station stands outdoors (Axel in the Mars Yard, seed 000 §V-A), with starts
    // out to the approach radius (7 m) at 40°: its "walls" are a distant skyline 5 m
    // beyond the approach radius (12 m for Axel), 2.4 m high.
    let (back, side, half_w, half_h) = if dock.cone.is_some() {
        let far = dock_spec.approach_radius_m + 5.0;
        (far, far, far + 2.0, 1.2)
    } else {
        (3.0, 3.2, 3.5, 1.2)
    };
    let walls = [
        (Point3::new(-back, 0.0, half_h), y_axis(), half_w),
        (Point3::new(0.5, side, half_h), Vector3::x(), half_w),
        (Point3::new(0.5, -side, half_h), -Vector3::x(), half_w),
    ];
    for (i, (centre, u, half_w)) in walls.iter().enumerate() {
        let material = match backdrops.get(i % backdrops.len().max(1)) {
            Some(im) if !backdrops.is_empty() => Material::Image(im.clone()),
            _ => Material::Noise {
                base: albedo([150, 148, 140], 1.0),
                contrast: 0.2,
                cell: 0.25,
            },
        };
        prims.push(Prim::new(
            Shape::Rect {
                centre: *centre,
                u: *u,
                v: z_axis(),
                half: [*half_w, half_h],
            },
            material,
            Tag::Backdrop,
        ));
    }
    // Boxes standing lower than the robot's body are in its way.
    let solid = clutter
        .iter()
        .filter(|c| c.kind == ClutterKind::Box && c.z_m < profile.body.height_m)
        .map(|c| {
            let (lo, hi) = c.box_bounds();
            Footprint {
                x0: lo[0],
                y0: lo[1],
                x1: hi[0],
                y1: hi[1],
            }
        })
        .collect();
    Ok(World {
        scene: Scene::on_floor(prims),
        obstacles: Obstacles::new(solid, &dock),
        dock,
        target_prims,
    })
}

/// The grey of a mother's or a module's painted body.
const BODY_GREY: [u8; 3] = [70, 72, 75];

/// What a dock painter paints on: the scene's primitives (the dock's body and its
/// fiducial, in the dock frame of the module docs), the indices of the fiducial's
/// primitives, and the 2-D geometry the judge and motion model use.
pub struct DockCanvas<'a> {
    /// The profile whose dock is painted.
    pub profile: &'a Profile,
    /// The scene's primitives so far (append to them).
    pub prims: &'a mut Vec<Prim>,
    /// Indices into `prims` of the fiducial's primitives (for shadows and tests).
    pub target_prims: &'a mut Vec<usize>,
    /// The dock's geometry, preset from `[dock]` and `[success]`: a painter sets what its
    /// dock differs in (a body's size, an open target, a cone).
    pub dock: &'a mut DockGeometry,
    /// Marks a perception campaign covers or paints on a module's face
    /// ([`build_face`]); painters of other kinds ignore them.
    pub face: FaceMarks<'a>,
}

/// Paints one fiducial kind's dock ([`DockCanvas`]).
pub type DockPainter = dyn Fn(&mut DockCanvas<'_>) -> Result<(), SimError> + Send + Sync;

/// The dock painters by fiducial kind: how the simulator draws the dock of a profile
/// whose `[fiducial] kind` names them. [`DockPainters::builtin`] paints the crate's
/// kinds; a crate with a fiducial kind of its own registers a painter for it to run its
/// robot in the simulator.
#[derive(Clone)]
pub struct DockPainters(std::collections::BTreeMap<String, Arc<DockPainter>>);

impl Default for DockPainters {
    fn default() -> Self {
        Self::builtin()
    }
}

impl std::fmt::Debug for DockPainters {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list().entries(self.0.keys()).finish()
    }
}

impl DockPainters {
    /// Painters of the crate's fiducial kinds: Silver Bullet's rear with the two-block
    /// flap, RAPOSA's pyramid on the ground, Axel's central module with its circles.
    pub fn builtin() -> Self {
        let mut p = Self(Default::default());
        p.register(TwoBlockSpec::KIND, paint_two_block)
            .register(PyramidSpec::KIND, paint_pyramid)
            .register(CirclesSpec::KIND, paint_circles);
        p
    }

    /// Registers (or replaces) the painter of fiducial kind `kind`.
    pub fn register(
        &mut self,
        kind: impl Into<String>,
        painter: impl Fn(&mut DockCanvas<'_>) -> Result<(), SimError> + Send + Sync + 'static,
    ) -> &mut Self {
        self.0.insert(kind.into(), Arc::new(painter));
        self
    }

    /// The painter of `kind`.
    pub fn get(&self, kind: &str) -> Option<&DockPainter> {
        self.0.get(kind).map(|p| p.as_ref())
    }

    /// The kinds painted, sorted.
    pub fn kinds(&self) -> impl Iterator<Item = &str> {
        self.0.keys().map(String::as_str)
    }
}

/// Silver Bullet's rear: a box body with the pouch opening at x = 0, the two-block flap
/// over it.
fn paint_two_block(c: &mut DockCanvas<'_>) -> Result<(), SimError> {
    let fid = *c
        .profile
        .fiducial
        .require::<TwoBlockSpec>()
        .map_err(SimError::Unsupported)?;
    let (dock, prims, target_prims) = (&mut *c.dock, &mut *c.prims, &mut *c.target_prims);
    let entrance_half = dock.entrance_half;
    let body_grey = albedo(BODY_GREY, 1.0);
    dock.needs_lowered = true;
    let (h, w2) = (0.75, dock.body_half_width);
    let top = fid.center_height_m + fid.height_m / 2.0 + 0.08;
    let bottom = (fid.center_height_m - fid.height_m / 2.0 - 0.04).max(0.02);
    let mut body = boxed(
        Point3::new(-dock.body_length, -w2, 0.05),
        Point3::new(0.0, w2, h),
        Material::Solid(body_grey),
        Tag::Body,
    );
    body.remove(0); // the rear face is rebuilt around the opening
    prims.extend(body);
    let rear =
        |y0: f64, y1: f64, z0: f64, z1: f64| face_rect(0.0, [y0, y1], [z0, z1], Material::Solid(body_grey), Tag::Body);
    prims.push(rear(-w2, -entrance_half, 0.05, h));
    prims.push(rear(entrance_half, w2, 0.05, h));
    prims.push(rear(-entrance_half, entrance_half, top, h));
    // The dark pouch behind the flap, and the gate folded down as a ramp.
    prims.push(Prim::new(
        Shape::Rect {
            centre: Point3::new(-0.01, 0.0, (bottom + top) / 2.0),
            u: y_axis(),
            v: z_axis(),
            half: [entrance_half, (top - bottom) / 2.0],
        },
        Material::Solid(albedo([20, 20, 22], 1.0)),
        Tag::Body,
    ));
    let ramp_len: f64 = 0.35;
    let slope = (bottom / ramp_len).atan();
    prims.push(Prim::new(
        Shape::Rect {
            centre: Point3::new(ramp_len / 2.0, 0.0, bottom / 2.0),
            u: y_axis(),
            v: Vector3::new(-slope.cos(), 0.0, slope.sin()),
            half: [entrance_half + 0.03, ramp_len / 2.0 / slope.cos()],
        },
        Material::Noise {
            base: albedo([110, 110, 112], 1.0),
            contrast: 0.15,
            cell: 0.01,
        },
        Tag::Body,
    ));
    // The flap: left colour on the viewer's left (world −y) when facing it from +x.
    target_prims.push(prims.len());
    let mut flap = Prim::new(
        Shape::Rect {
            centre: Point3::new(0.004, 0.0, fid.center_height_m),
            u: y_axis(),
            v: z_axis(),
            half: [fid.width_m / 2.0, fid.height_m / 2.0],
        },
        Material::TwoBlock {
            left: paint(fid.left_color),
            right: paint(fid.right_color),
        },
        Tag::Target,
    );
    flap.gloss = 0.6;
    prims.push(flap);
    Ok(())
}

/// RAPOSA's tether-end pyramid lying on the ground (an open dock).
fn paint_pyramid(c: &mut DockCanvas<'_>) -> Result<(), SimError> {
    let pyr = *c
        .profile
        .fiducial
        .require::<PyramidSpec>()
        .map_err(SimError::Unsupported)?;
    let (dock, prims, target_prims) = (&mut *c.dock, &mut *c.prims, &mut *c.target_prims);
    // RAPOSA's tether-end pyramid lying on the ground, its axis along +x: the orange
    // guide ball at the origin (what enters the socket), a grey pyramid body tapering
    // back from it, and at distance m behind the ball a square frame of blue-painted
    // edges of side h, centred at the ball's height (seed 001 Fig. 1, 2, 6). The frame
    // bars have depth, so the edges stay visible (thin) even side-on.
    let (h, m, r) = (pyr.blue_edge_length_m, pyr.edge_to_ball_m, pyr.ball_diameter_m / 2.0);
    let zc = pyr.ball_height_m.max(h / 2.0);
    dock.open = true;
    dock.body_length = 0.0;
    dock.body_half_width = 0.0;
    dock.target_extent = Some([-m - 0.03, r, -h / 2.0 - 0.01, h / 2.0 + 0.01]);
    let grey = Material::Solid(albedo([150, 150, 150], 1.0));
    let b = 0.35 * h;
    let base = [(-b, -b), (-b, b), (b, b), (b, -b)].map(|(y, dz)| Point3::new(-m, y, zc + dz));
    let apex = Point3::new(0.0, 0.0, zc);
    for i in 0..4 {
        let mut t = Prim::new(
            Shape::Triangle {
                p: [base[i], base[(i + 1) % 4], apex],
            },
            grey.clone(),
            Tag::Target,
        );
        t.two_sided = true;
        target_prims.push(prims.len());
        prims.push(t);
    }
    let blue = Material::Solid(paint(pyr.edge_color));
    let (bar, depth) = (0.15 * h, 0.02);
    let (x0, x1) = (-m - depth / 2.0, -m + depth / 2.0);
    let (y0, y1, z0, z1) = (-h / 2.0, h / 2.0, zc - h / 2.0, zc + h / 2.0);
    for (lo, hi) in [
        ((y0, z0), (y0 + bar, z1)),             // one side
        ((y1 - bar, z0), (y1, z1)),             // other side
        ((y0 + bar, z1 - bar), (y1 - bar, z1)), // top
        ((y0 + bar, z0), (y1 - bar, z0 + bar)), // bottom
    ] {
        for p in boxed(
            Point3::new(x0, lo.0, lo.1),
            Point3::new(x1, hi.0, hi.1),
            blue.clone(),
            Tag::Target,
        ) {
            target_prims.push(prims.len());
            prims.push(p);
        }
    }
    target_prims.push(prims.len());
    let mut ball = Prim::new(
        Shape::Sphere {
            centre: Point3::new(0.0, 0.0, zc),
            radius: r,
        },
        Material::Solid(paint(pyr.ball_color)),
        Tag::Target,
    );
    ball.gloss = 0.3;
    prims.push(ball);
    // The tether leaves the pyramid's back along the ground.
    prims.extend(boxed(
        Point3::new(-2.9, -0.01, 0.0),
        Point3::new(-m - depth, 0.01, 0.012),
        Material::Solid(albedo([30, 30, 32], 1.0)),
        Tag::Body,
    ));
    Ok(())
}

/// Axel's central module with its circle marks ([`build_central_module`]).
fn paint_circles(c: &mut DockCanvas<'_>) -> Result<(), SimError> {
    let circles = c
        .profile
        .fiducial
        .require::<CirclesSpec>()
        .map_err(SimError::Unsupported)?;
    let face = FaceMarks {
        covered: c.face.covered,
        painted: c.face.painted,
    };
    build_central_module(circles, face, c.dock, c.prims, c.target_prims, albedo(BODY_GREY, 1.0));
    Ok(())
}

/// Which of the layout's marks the face shows, and what false marks it adds.
#[derive(Clone, Copy)]
pub struct FaceMarks<'a> {
    /// Layout indices not painted.
    pub covered: &'a [usize],
    /// False marks painted besides the layout's.
    pub painted: &'a [CirclePlacement],
}

/// Axel's central module (seed 000): a box body whose front face (x = 0, facing +x)
/// carries the circle fiducials at their placements, above the funnel-like docking cone.
/// The cone's mouth (drawn square, `entrance_width_m` on a side, about the cone's axis
/// height) narrows over the dock depth to the throat the caster arm must enter. Without
/// a `[dock.cone]` table the mouth sits on the ground. The body is 1 m deep and wide
/// enough for the mouth and the marks; it is tall enough for the highest mark. The
/// station's forward tilt acts in the contact model ([`Cone`]) but is not drawn.
fn build_central_module(
    circles: &CirclesSpec,
    face: FaceMarks<'_>,
    dock: &mut DockGeometry,
    prims: &mut Vec<Prim>,
    target_prims: &mut Vec<usize>,
    body_grey: [f32; 3],
) {
    let radius = circles.diameter_m / 2.0;
    let margin = 1.3 * radius + 0.05;
    let widest = circles.placements.iter().map(|p| p.y_m.abs()).fold(0.0, f64::max);
    let highest = circles.placements.iter().map(|p| p.z_m).fold(0.0, f64::max);
    dock.body_length = 1.0;
    dock.body_half_width = (widest + margin).max(dock.entrance_half + 0.05);
    let e = dock.entrance_half;
    let axis = dock.cone.map_or(e, |c| c.axis_height);
    let (w2, top, z0) = (dock.body_half_width, highest + margin, axis + e);
    let mut body = boxed(
        Point3::new(-dock.body_length, -w2, 0.0),
        Point3::new(0.0, w2, top),
        Material::Solid(body_grey),
        Tag::Body,
    );
    body.remove(0); // the front face is rebuilt: marks above, the cone's mouth below
    prims.extend(body);
    let (face_h, face_zc) = ((top - z0) / 2.0, (top + z0) / 2.0);
    let marks: Vec<CircleMark> = circles
        .placements
        .iter()
        .enumerate()
        .filter(|(i, _)| !face.covered.contains(i))
        .map(|(_, p)| p)
        .chain(face.painted)
        .map(|p| {
            CircleMark::new(
                p.y_m as f32,
                (p.z_m - face_zc) as f32,
                p.rotation_deg.to_radians() as f32,
            )
        })
        .collect();
    target_prims.push(prims.len());
    prims.push(Prim::new(
        Shape::Rect {
            centre: Point3::new(0.0, 0.0, face_zc),
            u: y_axis(),
            v: z_axis(),
            half: [w2, face_h],
        },
        Material::Circles {
            base: body_grey,
            radius: radius as f32,
            marks: marks.into(),
        },
        Tag::Target,
    ));
    // Beside and below the mouth, the front face comes down to the ground.
    let (lo, hi) = (axis - e, axis + e);
    for (y0, y1, z0, z1) in [(-w2, -e, lo, hi), (e, w2, lo, hi), (-w2, w2, 0.0, lo)] {
        if y1 - y0 > 1e-6 && z1 - z0 > 1e-6 {
            prims.push(face_rect(
                0.0,
                [y0, y1],
                [z0, z1],
                Material::Solid(body_grey),
                Tag::Body,
            ));
        }
    }
    // The cone: four walls from the mouth to the throat, and the dark throat.
    let d = dock.depth;
    let te = dock.cone.map_or(e / 4.0, |c| c.throat_half);
    let mouth = [
        Point3::new(0.0, -e, lo),
        Point3::new(0.0, e, lo),
        Point3::new(0.0, e, hi),
        Point3::new(0.0, -e, hi),
    ];
    let throat = [
        Point3::new(-d, -te, axis - te),
        Point3::new(-d, te, axis - te),
        Point3::new(-d, te, axis + te),
        Point3::new(-d, -te, axis + te),
    ];
    let cone = Material::Solid(albedo([95, 97, 100], 1.0));
    for i in 0..4 {
        let j = (i + 1) % 4;
        for p in [[mouth[i], mouth[j], throat[j]], [mouth[i], throat[j], throat[i]]] {
            let mut t = Prim::new(Shape::Triangle { p }, cone.clone(), Tag::Body);
            t.two_sided = true;
            prims.push(t);
        }
    }
    prims.push(Prim::new(
        Shape::Rect {
            centre: Point3::new(-d, 0.0, axis),
            u: y_axis(),
            v: z_axis(),
            half: [te, te],
        },
        Material::Solid(albedo([20, 20, 22], 1.0)),
        Tag::Body,
    ));
}

fn add_clutter(prims: &mut Vec<Prim>, c: &ClutterSpec, profile: &Profile) {
    let colour = c.color.map(paint).unwrap_or(albedo([200, 200, 200], 0.8));
    let u = yaw(y_axis(), c.facing_deg);
    match c.kind {
        ClutterKind::Box => {
            let (lo, hi) = c.box_bounds();
            prims.extend(boxed(
                Point3::new(lo[0], lo[1], lo[2]),
                Point3::new(hi[0], hi[1], hi[2]),
                Material::Solid(colour),
                Tag::Clutter,
            ));
        }
        ClutterKind::Panel => {
            let mut p = Prim::new(
                Shape::Rect {
                    centre: Point3::new(c.x_m, c.y_m, c.z_m.max(c.size(1) / 2.0)),
                    u,
                    v: z_axis(),
                    half: [c.size(0) / 2.0, c.size(1) / 2.0],
                },
                Material::Solid(colour),
                Tag::Clutter,
            );
            p.two_sided = true;
            prims.push(p);
        }
        ClutterKind::FiducialCopy | ClutterKind::FiducialCopyUpsideDown => {
            if let Some(f) = profile.fiducial.get::<crate::profile::TwoBlockSpec>().copied() {
                let upside_down = c.kind == ClutterKind::FiducialCopyUpsideDown;
                // Turning the flap 180° in its plane puts the right colour on the left.
                let (left, right) = if upside_down {
                    (f.right_color, f.left_color)
                } else {
                    (f.left_color, f.right_color)
                };
                let z = if c.z_m > 0.0 { c.z_m } else { f.center_height_m };
                prims.push(Prim::new(
                    Shape::Rect {
                        centre: Point3::new(c.x_m, c.y_m, z),
                        u,
                        v: z_axis(),
                        half: [f.width_m / 2.0, f.height_m / 2.0],
                    },
                    Material::TwoBlock {
                        left: paint(left),
                        right: paint(right),
                    },
                    Tag::Clutter,
                ));
            }
        }
        ClutterKind::CircleMark => {
            if let Some(f) = profile.fiducial.get::<crate::profile::CirclesSpec>() {
                let base = c.color.map(paint).unwrap_or(albedo([70, 72, 75], 1.0));
                let mark = CircleMark::new(0.0, 0.0, c.mark_rotation_deg.to_radians() as f32);
                let mut p = Prim::new(
                    Shape::Rect {
                        centre: Point3::new(c.x_m, c.y_m, c.z_m.max(c.size(1) / 2.0)),
                        u,
                        v: z_axis(),
                        half: [c.size(0) / 2.0, c.size(1) / 2.0],
                    },
                    Material::Circles {
                        base,
                        radius: (f.diameter_m / 2.0) as f32,
                        marks: vec![mark].into(),
                    },
                    Tag::Clutter,
                );
                p.two_sided = true;
                prims.push(p);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::paint::PAINT_FLOOR;

    #[test]
    fn paints_reflect_a_little_of_every_colour() {
        for c in [NamedColor::Cyan, NamedColor::Magenta, NamedColor::Yellow] {
            let a = paint(c);
            let lo = a.iter().copied().fold(f32::MAX, f32::min);
            let hi = a.iter().copied().fold(f32::MIN, f32::max);
            assert!((lo - PAINT_FLOOR).abs() < 1e-6, "{c:?}: {a:?}");
            assert!((hi - 0.85).abs() < 1e-6, "{c:?}: {a:?}");
        }
    }
}
