//! `[fiducial.*]`: the visual target. Exactly one sub-table is given.

use crate::config::Validator;
use serde::{Deserialize, Serialize};

/// A named colour for fiducials and the segmentation's table defaults.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NamedColor {
    /// (0, 255, 255).
    Cyan,
    /// (255, 0, 255).
    Magenta,
    /// (255, 255, 0).
    Yellow,
    /// (255, 128, 0).
    Orange,
    /// (0, 64, 255).
    Blue,
    /// (255, 0, 0).
    Red,
    /// (0, 200, 0).
    Green,
    /// (255, 255, 255).
    White,
    /// (0, 0, 0).
    Black,
}

impl NamedColor {
    /// The name used in TOML and output (`"cyan"`).
    pub fn as_str(&self) -> &'static str {
        match self {
            NamedColor::Cyan => "cyan",
            NamedColor::Magenta => "magenta",
            NamedColor::Yellow => "yellow",
            NamedColor::Orange => "orange",
            NamedColor::Blue => "blue",
            NamedColor::Red => "red",
            NamedColor::Green => "green",
            NamedColor::White => "white",
            NamedColor::Black => "black",
        }
    }

    /// Nominal sRGB value of the paint's pigment. A real paint is paler: see
    /// [`NamedColor::reflectance`] and [`NamedColor::paint_srgb`] (`profile::paint`).
    pub fn rgb(&self) -> [u8; 3] {
        match self {
            NamedColor::Cyan => [0, 255, 255],
            NamedColor::Magenta => [255, 0, 255],
            NamedColor::Yellow => [255, 255, 0],
            NamedColor::Orange => [255, 128, 0],
            NamedColor::Blue => [0, 64, 255],
            NamedColor::Red => [255, 0, 0],
            NamedColor::Green => [0, 200, 0],
            NamedColor::White => [255, 255, 255],
            NamedColor::Black => [0, 0, 0],
        }
    }
}

/// Bujold's two-block flap (seed 004 §V).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TwoBlockSpec {
    /// Overall width of the flap, m.
    pub width_m: f64,
    /// Height of the flap, m.
    pub height_m: f64,
    /// Colour of the block on the left when facing the fiducial from outside the dock.
    pub left_color: NamedColor,
    /// Colour of the block on the right when facing the fiducial.
    pub right_color: NamedColor,
    /// Height of the flap's centre above the ground, m.
    pub center_height_m: f64,
}

/// RAPOSA's tether-end pyramid: an orange ball/guide and blue edges (seed 001 §II.C).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PyramidSpec {
    /// Diameter of the orange bi-conical guide, m.
    pub ball_diameter_m: f64,
    /// Length h of each painted blue edge, m.
    pub blue_edge_length_m: f64,
    /// Distance m from a blue edge's midpoint to the ellipse centre (top view), m.
    pub edge_to_ball_m: f64,
    /// Height of the ball's centre above the ground, m.
    pub ball_height_m: f64,
    /// Colour of the guide.
    pub ball_color: NamedColor,
    /// Colour of the edges.
    pub edge_color: NamedColor,
}

/// One of Axel's circular fiducials on the central module.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CirclePlacement {
    /// Position across the module face (dock frame y), m.
    pub y_m: f64,
    /// Height above the ground, m.
    pub z_m: f64,
    /// Pattern rotation: one of −45, 0, 45, 90 degrees.
    pub rotation_deg: f64,
}

/// Axel's eight circular fiducials (seed 000).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CirclesSpec {
    /// Outer diameter of every circle, m.
    pub diameter_m: f64,
    /// Placements in an asymmetric layout.
    pub placements: Vec<CirclePlacement>,
    /// The paper's fixed thresholds in place of our adaptive one, `[black_below,
    /// white_above]` grey levels (0–255, grey = (R + 2G + B)/4): darker pixels are black,
    /// brighter ones white, everywhere in the frame. Seed 000 §V-E docked 8 of 15 runs
    /// with fixed thresholds under an uneven shadow and gives no levels. For comparison
    /// only; absent (the default), the detector thresholds against the local mean.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fixed_threshold: Option<[u8; 2]>,
}

/// The AutoKrawler's magenta body markers (seed 003).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MarkersSpec {
    /// Number of markers.
    pub count: usize,
    /// Side of each square marker, m.
    pub side_m: f64,
    /// Marker colour.
    pub color: NamedColor,
    /// Steering calibration λ = f(x) per axle (front, rear), for the tie-rod ratio x
    /// (seed 003 eq. 5, Fig. 6): the coefficients of 1, (x − 1), (x − 1)² and optionally
    /// (x − 1)³, degrees. Fitted and written by `marsupial calibrate-steering`; without
    /// it the steering is not estimated.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub steering_poly_deg: Option<[SteeringCoeffs; 2]>,
}

/// One axle's steering polynomial as a profile writes it: three coefficients (the
/// paper's second order) or four (third order), degrees.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "Vec<f64>", into = "Vec<f64>")]
pub struct SteeringCoeffs {
    /// Coefficients of 1, (x − 1), (x − 1)², (x − 1)³ (0 for a second-order polynomial).
    pub deg: [f64; 4],
    /// 2 or 3.
    pub order: usize,
}

impl TryFrom<Vec<f64>> for SteeringCoeffs {
    type Error = String;

    fn try_from(v: Vec<f64>) -> Result<Self, String> {
        match v[..] {
            [a, b, c] => Ok(Self {
                deg: [a, b, c, 0.0],
                order: 2,
            }),
            [a, b, c, d] => Ok(Self {
                deg: [a, b, c, d],
                order: 3,
            }),
            _ => Err(format!(
                "expected 3 coefficients (second order) or 4 (third order), got {}",
                v.len()
            )),
        }
    }
}

impl From<SteeringCoeffs> for Vec<f64> {
    fn from(c: SteeringCoeffs) -> Self {
        c.deg[..=c.order].to_vec()
    }
}

/// The `[fiducial]` table: exactly one of the sub-tables.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FiducialSpec {
    /// Two-block colour flap.
    #[serde(default)]
    pub two_block: Option<TwoBlockSpec>,
    /// Ball-and-edges pyramid.
    #[serde(default)]
    pub pyramid: Option<PyramidSpec>,
    /// Circular fiducials.
    #[serde(default)]
    pub circles: Option<CirclesSpec>,
    /// Body markers.
    #[serde(default)]
    pub markers: Option<MarkersSpec>,
}

pub(crate) fn validate_fiducial(f: &FiducialSpec, v: &mut Validator<'_>) {
    let n = [
        f.two_block.is_some(),
        f.pyramid.is_some(),
        f.circles.is_some(),
        f.markers.is_some(),
    ]
    .iter()
    .filter(|b| **b)
    .count();
    v.require(n == 1, "fiducial", || {
        format!("expected exactly one of [fiducial.two_block], [fiducial.pyramid], [fiducial.circles], [fiducial.markers]; got {n}")
    });
    if let Some(t) = &f.two_block {
        v.positive("fiducial.two_block.width_m", t.width_m);
        v.positive("fiducial.two_block.height_m", t.height_m);
        v.non_negative("fiducial.two_block.center_height_m", t.center_height_m);
        v.require(t.left_color != t.right_color, "fiducial.two_block.right_color", || {
            "expected the two blocks to have different colours".into()
        });
    }
    if let Some(p) = &f.pyramid {
        v.positive("fiducial.pyramid.ball_diameter_m", p.ball_diameter_m);
        v.positive("fiducial.pyramid.blue_edge_length_m", p.blue_edge_length_m);
        v.positive("fiducial.pyramid.edge_to_ball_m", p.edge_to_ball_m);
        v.non_negative("fiducial.pyramid.ball_height_m", p.ball_height_m);
    }
    if let Some(c) = &f.circles {
        v.positive("fiducial.circles.diameter_m", c.diameter_m);
        v.require(c.placements.len() >= 5, "fiducial.circles.placements", || {
            format!(
                "expected at least 5 circles (4 make the homography degenerate), got {}",
                c.placements.len()
            )
        });
        for (i, pl) in c.placements.iter().enumerate() {
            v.finite(&format!("fiducial.circles.placements[{i}].y_m"), pl.y_m);
            v.non_negative(&format!("fiducial.circles.placements[{i}].z_m"), pl.z_m);
            v.require(
                [-45.0, 0.0, 45.0, 90.0].contains(&pl.rotation_deg),
                &format!("fiducial.circles.placements[{i}].rotation_deg"),
                || format!("expected one of −45, 0, 45, 90, got {}", pl.rotation_deg),
            );
        }
        if let Some([black, white]) = c.fixed_threshold {
            v.require(black <= white, "fiducial.circles.fixed_threshold", || {
                format!("expected [black_below, white_above] with black_below ≤ white_above, got [{black}, {white}]")
            });
        }
    }
    if let Some(m) = &f.markers {
        v.nonzero("fiducial.markers.count", m.count);
        v.positive("fiducial.markers.side_m", m.side_m);
        for (a, poly) in m.steering_poly_deg.iter().flatten().enumerate() {
            for (k, c) in poly.deg[..=poly.order].iter().enumerate() {
                v.finite(&format!("fiducial.markers.steering_poly_deg[{a}][{k}]"), *c);
            }
        }
    }
}
