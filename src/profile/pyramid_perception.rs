//! `[perception.pyramid]`: RAPOSA's HSV bands and the shape and pair filters of the
//! pyramid detector (seed 001 §II.D).

use crate::config::Validator;
use crate::perception::HsvRange;
use serde::{Deserialize, Serialize};

/// A colour as a box in HSV (seed 001 §II.D: "a volume in this space, defined by the
/// intersection of one interval for each axis"). Hue in degrees; `h_deg[0] > h_deg[1]`
/// wraps through red. S and V in [0, 1].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HsvBand {
    /// [H_lo, H_hi], degrees in [0, 360].
    pub h_deg: [f64; 2],
    /// [S_lo, S_hi] in [0, 1].
    pub s: [f64; 2],
    /// [V_lo, V_hi] in [0, 1].
    pub v: [f64; 2],
}

impl HsvBand {
    /// The band as the segmenter's range.
    pub fn range(&self) -> HsvRange {
        HsvRange {
            h: self.h_deg.map(|x| x as f32),
            s: self.s.map(|x| x as f32),
            v: self.v.map(|x| x as f32),
        }
    }
}

/// Pyramid detector settings. Every field is optional; see [`PyramidPerceptionSpec::default`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PyramidPerceptionSpec {
    /// The orange guide's band.
    pub orange: HsvBand,
    /// The blue edges' band.
    pub blue: HsvBand,
    /// Smallest orange blob kept as an ellipse, px (the range limit: seed 001 §III).
    pub min_ellipse_px: u32,
    /// Largest ellipse axis ratio (major / minor) kept.
    pub max_axis_ratio: f64,
    /// Smallest fill of the fitted ellipse (blob pixels / π·a·b); rejects ragged blobs.
    pub min_fill: f64,
    /// Smallest blue blob kept, px.
    pub min_blue_px: u32,
    /// Loose pair limits; when several pairs pass, the same tests run again with every
    /// tolerance multiplied by `tighten` (seed 001 §II.D).
    pub tighten: f64,
    /// Largest relative deviation of the blue height from the height the ball's size
    /// predicts (1 allows a factor of 2 either way).
    pub max_size_dev: f64,
    /// Largest vertical offset of the ellipse centre from the blue region's centre, in
    /// blue heights.
    pub max_vertical_dev: f64,
    /// Slack on the horizontal offset the geometry allows, as a fraction of it.
    pub max_horizontal_dev: f64,
    /// Ellipse pixels / blue bounding-box area: [lo, hi].
    pub area_ratio: [f64; 2],
    /// Radius of the tracking ball around the previous ellipse, px (paper: 20).
    pub tracking_ball_px: f64,
    /// The tracking ball is dropped after this many frames without a detection.
    pub tracking_reset_frames: u32,
    /// At most this many blobs per colour are considered (the largest), bounding time in
    /// clutter.
    pub max_candidates: u32,
    /// Imprint/adapt (`perception.mode` = "adaptive" or "static"; seed 001's future work):
    /// [floor, ceiling] of the hue SD, degrees. Bands are mean ± `perception.n_sd`·SD.
    pub hue_sd_deg: [f64; 2],
    /// [floor, ceiling] of the saturation and value SDs.
    pub sv_sd: [f64; 2],
    /// Learned bands never admit saturation below this (greys stay out).
    pub min_s: f64,
    /// Learned bands never admit value below this (black stays out).
    pub min_v: f64,
    /// Camera-to-ball distance at which the departing robot imprints, m.
    pub imprint_distance_m: f64,
    /// Frames imprinted.
    pub imprint_frames: u32,
    /// The imprint finds the pyramid with the table bands widened by this factor (hue
    /// half-width ×, V lower bound ÷; saturation kept); only a pair where the departure
    /// geometry puts it is sampled.
    pub imprint_widen: f64,
}

impl Default for PyramidPerceptionSpec {
    fn default() -> Self {
        Self {
            orange: HsvBand {
                h_deg: [8.0, 45.0],
                s: [0.45, 1.0],
                v: [0.25, 1.0],
            },
            blue: HsvBand {
                h_deg: [200.0, 250.0],
                s: [0.40, 1.0],
                v: [0.12, 1.0],
            },
            min_ellipse_px: 40,
            max_axis_ratio: 2.5,
            min_fill: 0.7,
            min_blue_px: 20,
            tighten: 0.5,
            max_size_dev: 1.0,
            max_vertical_dev: 0.6,
            max_horizontal_dev: 0.5,
            area_ratio: [0.08, 6.0],
            tracking_ball_px: 20.0,
            tracking_reset_frames: 5,
            max_candidates: 16,
            hue_sd_deg: [1.5, 12.0],
            sv_sd: [0.02, 0.12],
            min_s: 0.2,
            min_v: 0.06,
            imprint_distance_m: 0.6,
            imprint_frames: 5,
            imprint_widen: 2.0,
        }
    }
}

fn validate_band(name: &str, b: &HsvBand, v: &mut Validator<'_>) {
    v.require(
        b.h_deg.iter().all(|h| (0.0..=360.0).contains(h)),
        &format!("perception.pyramid.{name}.h_deg"),
        || format!("expected hues in [0, 360] degrees, got {:?}", b.h_deg),
    );
    for (axis, r) in [("s", b.s), ("v", b.v)] {
        v.require(
            r.iter().all(|x| (0.0..=1.0).contains(x)) && r[0] <= r[1],
            &format!("perception.pyramid.{name}.{axis}"),
            || format!("expected [lo, hi] in [0, 1] with lo ≤ hi, got {r:?}"),
        );
    }
}

pub(crate) fn validate_pyramid_perception(p: &PyramidPerceptionSpec, v: &mut Validator<'_>) {
    validate_band("orange", &p.orange, v);
    validate_band("blue", &p.blue, v);
    v.require(p.min_ellipse_px >= 4, "perception.pyramid.min_ellipse_px", || {
        "expected at least 4 px".into()
    });
    v.require(p.max_axis_ratio >= 1.0, "perception.pyramid.max_axis_ratio", || {
        format!("expected a ratio ≥ 1, got {}", p.max_axis_ratio)
    });
    v.range("perception.pyramid.min_fill", p.min_fill, 0.0, 1.0);
    v.nonzero("perception.pyramid.min_blue_px", p.min_blue_px as usize);
    v.fraction("perception.pyramid.tighten", p.tighten);
    v.positive("perception.pyramid.max_size_dev", p.max_size_dev);
    v.positive("perception.pyramid.max_vertical_dev", p.max_vertical_dev);
    v.non_negative("perception.pyramid.max_horizontal_dev", p.max_horizontal_dev);
    v.require(
        p.area_ratio[0] > 0.0 && p.area_ratio[0] < p.area_ratio[1],
        "perception.pyramid.area_ratio",
        || format!("expected 0 < lo < hi, got {:?}", p.area_ratio),
    );
    v.positive("perception.pyramid.tracking_ball_px", p.tracking_ball_px);
    v.nonzero("perception.pyramid.max_candidates", p.max_candidates as usize);
    for (name, r, hi) in [("hue_sd_deg", p.hue_sd_deg, 180.0), ("sv_sd", p.sv_sd, 1.0)] {
        v.require(
            r[0] > 0.0 && r[0] <= r[1] && r[1] <= hi,
            &format!("perception.pyramid.{name}"),
            || format!("expected [floor, ceiling] with 0 < floor ≤ ceiling ≤ {hi}, got {r:?}"),
        );
    }
    v.range("perception.pyramid.min_s", p.min_s, 0.0, 1.0);
    v.range("perception.pyramid.min_v", p.min_v, 0.0, 1.0);
    v.positive("perception.pyramid.imprint_distance_m", p.imprint_distance_m);
    v.nonzero("perception.pyramid.imprint_frames", p.imprint_frames as usize);
    v.require(p.imprint_widen >= 1.0, "perception.pyramid.imprint_widen", || {
        format!("expected a factor ≥ 1, got {}", p.imprint_widen)
    });
}
