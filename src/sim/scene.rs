//! 3-D scene description: textured planar primitives and spheres in the world frame.
//!
//! World (dock) frame: origin at the middle of the dock entrance on the ground, +x out of
//! the dock along its axis (toward the approach zone), +z up. Metres.

use crate::perception::RgbImage;
use nalgebra::{Point3, Vector3};
use std::sync::Arc;

/// Linear-light albedo from an sRGB byte colour, scaled by a paint reflectance.
pub fn albedo(srgb: [u8; 3], reflectance: f32) -> [f32; 3] {
    srgb.map(|c| srgb_to_linear(c as f32 / 255.0) * reflectance)
}

pub use crate::profile::paint::srgb_to_linear;

/// What a surface looks like, as a function of its local coordinates (a, b) in metres
/// (a along the primitive's `u` axis, b along `v`, origin at its centre).
#[derive(Debug, Clone)]
pub enum Material {
    /// One linear albedo.
    Solid([f32; 3]),
    /// Two halves split at a = 0: `left` for a < 0, `right` for a ≥ 0 (anti-aliased).
    TwoBlock {
        /// Albedo for a < 0.
        left: [f32; 3],
        /// Albedo for a ≥ 0.
        right: [f32; 3],
    },
    /// A photo stretched over the primitive (row 0 at b = +half_v, column 0 at a = −half_u).
    Image(Arc<RgbImage>),
    /// Circular fiducials printed on a `base`-coloured surface (Axel's central module):
    /// see [`CircleMark`] for the pattern.
    Circles {
        /// Albedo of the surface between the marks.
        base: [f32; 3],
        /// Outer radius of every mark's black disc, m.
        radius: f32,
        /// The marks.
        marks: Arc<[CircleMark]>,
    },
    /// Coloured squares painted on a `base`-coloured surface (the AutoKrawler's markers).
    Squares {
        /// Albedo between the squares.
        base: [f32; 3],
        /// The squares.
        squares: Arc<[PaintedSquare]>,
    },
    /// Value noise in cells of `cell` metres around `base` with relative contrast `contrast`.
    Noise {
        /// Mean albedo.
        base: [f32; 3],
        /// Relative amplitude.
        contrast: f32,
        /// Cell size, m.
        cell: f32,
    },
}

/// One circular fiducial at local (a, b) of its surface. Seen from the front, with outer
/// radius R: a white margin out to 1.3 R, a black disc of radius R, a white ring from
/// 0.6 R to 0.8 R (so the black and white blobs share a centroid, which is what a detector
/// pairs), and in the black core a white bar 0.24 R wide through the centre. The bar's
/// direction is the mark's rotation (0: along the surface's u axis, counter-clockwise
/// toward v); −45°, 0°, 45° and 90° are the four distinct ones, as the bar is symmetric.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CircleMark {
    /// Centre, along u, m.
    pub a: f32,
    /// Centre, along v, m.
    pub b: f32,
    /// Bar direction (cos, sin) in (u, v).
    pub dir: [f32; 2],
}

impl CircleMark {
    /// A mark centred at (a, b) whose bar is turned `rotation_rad` from the u axis.
    pub fn new(a: f32, b: f32, rotation_rad: f32) -> Self {
        Self {
            a,
            b,
            dir: [rotation_rad.cos(), rotation_rad.sin()],
        }
    }
}

/// A square of paint at local (a, b) of its surface, sides along u and v. Painting marks
/// as texture, not as primitives laid on top, keeps them in front of their surface
/// whatever the draw order.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PaintedSquare {
    /// Centre, along u, m.
    pub a: f32,
    /// Centre, along v, m.
    pub b: f32,
    /// Half the side, m.
    pub half: f32,
    /// Albedo.
    pub albedo: [f32; 3],
}

/// Geometry of a primitive.
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    /// A rectangle: centre, unit axes `u` and `v` (normal = u × v), half extents.
    Rect {
        /// Centre.
        centre: Point3<f64>,
        /// First in-plane axis (unit).
        u: Vector3<f64>,
        /// Second in-plane axis (unit).
        v: Vector3<f64>,
        /// Half extents along u and v, m.
        half: [f64; 2],
    },
    /// A disc: centre, in-plane axes, radius.
    Disc {
        /// Centre.
        centre: Point3<f64>,
        /// First in-plane axis (unit).
        u: Vector3<f64>,
        /// Second in-plane axis (unit).
        v: Vector3<f64>,
        /// Radius, m.
        radius: f64,
    },
    /// A triangle.
    Triangle {
        /// Vertices.
        p: [Point3<f64>; 3],
    },
    /// A sphere.
    Sphere {
        /// Centre.
        centre: Point3<f64>,
        /// Radius, m.
        radius: f64,
    },
}

/// A planar shape's frame: an origin, two in-plane axes and the unit normal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlaneFrame {
    /// Centre (rect, disc) or first vertex (triangle).
    pub origin: Point3<f64>,
    /// First axis: unit for rects and discs, the first edge of a triangle.
    pub u: Vector3<f64>,
    /// Second axis: unit for rects and discs, the second edge of a triangle.
    pub v: Vector3<f64>,
    /// Unit normal, u × v normalised (the side a one-sided shape is seen from).
    pub normal: Vector3<f64>,
}

impl Shape {
    /// The frame of a planar shape; `None` for a sphere.
    pub fn plane(&self) -> Option<PlaneFrame> {
        match self {
            Shape::Rect { centre, u, v, .. } | Shape::Disc { centre, u, v, .. } => Some(PlaneFrame {
                origin: *centre,
                u: *u,
                v: *v,
                normal: u.cross(v),
            }),
            Shape::Triangle { p } => {
                let (u, v) = (p[1] - p[0], p[2] - p[0]);
                Some(PlaneFrame {
                    origin: p[0],
                    u,
                    v,
                    normal: u.cross(&v).normalize(),
                })
            }
            Shape::Sphere { .. } => None,
        }
    }

    /// Where the shape is, for draw order: its centre, or a triangle's centroid.
    pub fn centre(&self) -> Point3<f64> {
        match self {
            Shape::Rect { centre, .. } | Shape::Disc { centre, .. } | Shape::Sphere { centre, .. } => *centre,
            Shape::Triangle { p } => Point3::from((p[0].coords + p[1].coords + p[2].coords) / 3.0),
        }
    }
}

/// What a primitive is, so lighting effects can target it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tag {
    /// Part of a docking target (fiducial, pyramid, module markers).
    Target,
    /// The mother robot or dock body.
    Body,
    /// Clutter.
    Clutter,
    /// Background walls and photos.
    Backdrop,
    /// The robot's own parts.
    Own,
}

/// One renderable object.
#[derive(Debug, Clone)]
pub struct Prim {
    /// Geometry.
    pub shape: Shape,
    /// Appearance.
    pub material: Material,
    /// Fraction of the surface's Fresnel reflection that goes into a specular highlight
    /// (0 = matte, where it is diffuse; 1 = polished or laminated).
    pub gloss: f32,
    /// Seen from both sides (otherwise only from the side the normal points to).
    pub two_sided: bool,
    /// Role.
    pub tag: Tag,
}

impl Prim {
    /// A matte, one-sided primitive.
    pub fn new(shape: Shape, material: Material, tag: Tag) -> Self {
        Self {
            shape,
            material,
            gloss: 0.0,
            two_sided: false,
            tag,
        }
    }

    /// Corner points bounding the primitive (for screen-space culling): the outline of a
    /// planar primitive in order, or the eight box corners of a sphere. A fixed array, so
    /// the renderer's per-frame culling allocates nothing.
    pub fn bounds(&self) -> Corners {
        let mut c = Corners {
            pts: [Point3::origin(); 8],
            len: 0,
        };
        let square = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
        match &self.shape {
            Shape::Rect { centre, u, v, half } => {
                for (a, b) in square {
                    c.push(centre + u * (a * half[0]) + v * (b * half[1]));
                }
            }
            Shape::Disc { centre, u, v, radius } => {
                for (a, b) in square {
                    c.push(centre + u * (a * radius) + v * (b * radius));
                }
            }
            Shape::Triangle { p } => p.iter().for_each(|q| c.push(*q)),
            Shape::Sphere { centre, radius } => {
                for dx in [-1.0, 1.0] {
                    for dy in [-1.0, 1.0] {
                        for dz in [-1.0, 1.0] {
                            c.push(centre + Vector3::new(dx, dy, dz) * *radius);
                        }
                    }
                }
            }
        }
        c
    }
}

/// Up to eight bounding points of a primitive.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Corners {
    pts: [Point3<f64>; 8],
    len: usize,
}

impl Corners {
    fn push(&mut self, p: Point3<f64>) {
        if self.len < self.pts.len() {
            self.pts[self.len] = p;
            self.len += 1;
        }
    }

    /// The points.
    pub fn as_slice(&self) -> &[Point3<f64>] {
        &self.pts[..self.len]
    }
}

/// A rectangle in the plane x = `x` facing +x (a dock's face, as the dock frame has it),
/// spanning `y` = [y0, y1] across and `z` = [z0, z1] up: helper for faces built in pieces
/// round an opening or a fiducial (the renderer orders primitives by their centres'
/// distance, so a rectangle laid over a wider one could be drawn behind it).
pub fn face_rect(x: f64, y: [f64; 2], z: [f64; 2], material: Material, tag: Tag) -> Prim {
    let ([y0, y1], [z0, z1]) = (y, z);
    Prim::new(
        Shape::Rect {
            centre: Point3::new(x, (y0 + y1) / 2.0, (z0 + z1) / 2.0),
            u: Vector3::y(),
            v: Vector3::z(),
            half: [(y1 - y0) / 2.0, (z1 - z0) / 2.0],
        },
        material,
        tag,
    )
}

/// Axis-aligned box as five visible faces (no bottom): helper for bodies and clutter.
pub fn boxed(min: Point3<f64>, max: Point3<f64>, material: Material, tag: Tag) -> Vec<Prim> {
    let c = Point3::from((min.coords + max.coords) / 2.0);
    let h = (max - min) / 2.0;
    let (x, y, z) = (Vector3::x(), Vector3::y(), Vector3::z());
    let face = |centre: Point3<f64>, u: Vector3<f64>, v: Vector3<f64>, half: [f64; 2]| {
        Prim::new(Shape::Rect { centre, u, v, half }, material.clone(), tag)
    };
    vec![
        face(c + x * h.x, y, z, [h.y, h.z]),  // +x face, normal +x
        face(c - x * h.x, -y, z, [h.y, h.z]), // −x face
        face(c + y * h.y, -x, z, [h.x, h.z]), // +y face
        face(c - y * h.y, x, z, [h.x, h.z]),  // −y face
        face(c + z * h.z, x, y, [h.x, h.y]),  // top
    ]
}

/// A scene: primitives over a textured ground plane (z = 0) under a sky.
#[derive(Debug, Clone)]
pub struct Scene {
    /// Objects.
    pub prims: Vec<Prim>,
    /// Ground appearance.
    pub ground: Material,
    /// Sky radiance (linear), seen where no ray hits anything.
    pub sky: [f32; 3],
}

impl Scene {
    /// `prims` over the simulator's floor (a concrete-grey value-noise texture in 2 cm
    /// cells) under a bright, slightly blue sky: the setting every built world shares.
    pub fn on_floor(prims: Vec<Prim>) -> Self {
        Self {
            prims,
            ground: Material::Noise {
                base: albedo([125, 122, 115], 1.0),
                contrast: 0.25,
                cell: 0.02,
            },
            sky: [0.9, 0.95, 1.0],
        }
    }
}
