//! `[perception]`: colour segmentation, imprinting/adaptation and fiducial pairing.

use super::pyramid_perception::{PyramidPerceptionSpec, validate_pyramid_perception};
use crate::config::Validator;
use serde::{Deserialize, Serialize};

pub use crate::perception::SegmentationMode;

/// Where the two blocks appear in the image as the daughter leaves the dock.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ImprintSpec {
    /// Image-left block: (x0, y0, x1, y1) as fractions of width and height.
    pub left_rect: [f64; 4],
    /// Image-right block, same convention.
    pub right_rect: [f64; 4],
    /// Fraction of each rectangle (per side, centred) that is sampled.
    pub sample_frac: f64,
    /// Frames averaged.
    pub frames: u32,
    /// Camera-to-fiducial distance at which the departing robot imprints, m (the
    /// rectangles are where the blocks appear from there).
    pub at_distance_m: f64,
}

/// The `[perception]` table. Every field is optional; missing ones take the defaults of
/// [`PerceptionSpec::default`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PerceptionSpec {
    /// Adaptive or static segmentation.
    pub mode: SegmentationMode,
    /// Components smaller than this are dropped, px (paper: 20).
    pub min_component_px: u32,
    /// Pixels darker than this L (0–441.7) are not classified.
    pub min_brightness: f64,
    /// Pixels whose colour lies within this angle of the grey axis (r = g = b) are not
    /// classified, degrees: they carry no usable hue (SCT's B is undefined on the axis).
    /// Keeps a range that adapted toward a washed-out fiducial off grey walls and floor.
    pub min_chroma_deg: f64,
    /// Gap allowed between the blocks, as a fraction of their mean height (allows roll).
    pub max_gap_frac: f64,
    /// Extra gap allowed in pixels (for tiny, distant blocks).
    pub gap_slack_px: f64,
    /// Largest vertical offset of the block centroids, fraction of their mean height.
    pub max_vertical_frac: f64,
    /// Largest ratio of the blocks' heights in the image (≥ 1; perspective alone gives at
    /// most 1.35 for Bujold's flap, 2 leaves room for a block partly lost to shadow or
    /// clipped at the image edge).
    pub max_height_ratio: f64,
    /// Smallest ratio of the blocks' pixel counts, in [0, 1] (perspective alone gives at
    /// least 0.45 for Bujold's flap; 0.2 leaves room for a block half lost to shadow).
    pub min_count_ratio: f64,
    /// Range half-width in SDs (paper: 4).
    pub n_sd: f64,
    /// Smallest SD used for a range, degrees.
    pub sd_floor_deg: f64,
    /// Largest SD used for a range, degrees.
    pub sd_ceiling_deg: f64,
    /// SD of the table defaults, degrees.
    pub table_sd_deg: f64,
    /// Adaptation blend rate in (0, 1]; 1 replaces the statistics every frame (paper).
    pub adapt_rate: f64,
    /// Compensation of fast colour casts before segmentation: the time constant with
    /// which a measured cast fades into the light the colour model adapts to, s; 0 (the
    /// default) turns it off. Ours, not the paper's, and off by default because it did
    /// not raise the randomized-light success rate (README, "Colour casts").
    pub cast_tau_s: f64,
    /// Cast gains within this fraction of 1 are not applied (0.02 moves an SCT angle by
    /// under 0.6°, inside the narrowest range).
    pub cast_dead_band: f64,
    /// Adapted → imprinted after this long without a detection, s.
    pub timeout1_s: f64,
    /// Imprinted → table after this long without a detection, s.
    pub timeout2_s: f64,
    /// At most this many components per colour are paired (the largest), bounding time
    /// in clutter.
    pub max_candidates: u32,
    /// Imprint geometry.
    pub imprint: ImprintSpec,
    /// RAPOSA's pyramid detector (HSV bands, shape and pair filters).
    pub pyramid: PyramidPerceptionSpec,
}

impl Default for PerceptionSpec {
    fn default() -> Self {
        Self {
            mode: SegmentationMode::Adaptive,
            min_component_px: 20,
            min_brightness: 30.0,
            min_chroma_deg: 5.0,
            max_gap_frac: 0.5,
            gap_slack_px: 3.0,
            max_vertical_frac: 0.5,
            max_height_ratio: 2.0,
            min_count_ratio: 0.2,
            n_sd: 4.0,
            sd_floor_deg: 0.5,
            sd_ceiling_deg: 10.0,
            table_sd_deg: 6.0,
            adapt_rate: 1.0,
            cast_tau_s: 0.0,
            cast_dead_band: 0.02,
            timeout1_s: 2.0,
            timeout2_s: 6.0,
            max_candidates: 64,
            imprint: ImprintSpec::default(),
            pyramid: PyramidPerceptionSpec::default(),
        }
    }
}

impl Default for ImprintSpec {
    fn default() -> Self {
        Self {
            left_rect: [0.38, 0.40, 0.50, 0.60],
            right_rect: [0.50, 0.40, 0.62, 0.60],
            sample_frac: 0.5,
            frames: 5,
            at_distance_m: 0.6,
        }
    }
}

pub(crate) fn validate_perception(p: &PerceptionSpec, v: &mut Validator<'_>) {
    v.nonzero("perception.min_component_px", p.min_component_px as usize);
    v.range("perception.min_brightness", p.min_brightness, 0.0, 441.0);
    v.range("perception.min_chroma_deg", p.min_chroma_deg, 0.0, 30.0);
    v.non_negative("perception.max_gap_frac", p.max_gap_frac);
    v.non_negative("perception.gap_slack_px", p.gap_slack_px);
    v.positive("perception.max_vertical_frac", p.max_vertical_frac);
    v.range("perception.max_height_ratio", p.max_height_ratio, 1.0, f64::MAX);
    v.range("perception.min_count_ratio", p.min_count_ratio, 0.0, 1.0);
    v.positive("perception.n_sd", p.n_sd);
    v.positive("perception.sd_floor_deg", p.sd_floor_deg);
    v.positive("perception.sd_ceiling_deg", p.sd_ceiling_deg);
    if p.sd_floor_deg > p.sd_ceiling_deg {
        v.problem(
            "perception.sd_floor_deg",
            format!(
                "expected sd_floor_deg ≤ sd_ceiling_deg, got {} > {}",
                p.sd_floor_deg, p.sd_ceiling_deg
            ),
        );
    }
    v.positive("perception.table_sd_deg", p.table_sd_deg);
    v.fraction("perception.adapt_rate", p.adapt_rate);
    v.non_negative("perception.cast_tau_s", p.cast_tau_s);
    v.range("perception.cast_dead_band", p.cast_dead_band, 0.0, 0.5);
    v.positive("perception.timeout1_s", p.timeout1_s);
    v.positive("perception.timeout2_s", p.timeout2_s);
    if p.timeout1_s > 0.0 && p.timeout2_s <= p.timeout1_s {
        v.problem(
            "perception.timeout2_s",
            format!(
                "expected timeout2_s > timeout1_s, got {} ≤ {}",
                p.timeout2_s, p.timeout1_s
            ),
        );
    }
    v.nonzero("perception.max_candidates", p.max_candidates as usize);
    for (name, r) in [("left_rect", p.imprint.left_rect), ("right_rect", p.imprint.right_rect)] {
        let path = format!("perception.imprint.{name}");
        v.require(
            r.iter().all(|x| (0.0..=1.0).contains(x)) && r[0] < r[2] && r[1] < r[3],
            &path,
            || format!("expected (x0, y0, x1, y1) fractions in [0, 1] with x0 < x1 and y0 < y1, got {r:?}"),
        );
    }
    v.fraction("perception.imprint.sample_frac", p.imprint.sample_frac);
    v.nonzero("perception.imprint.frames", p.imprint.frames as usize);
    validate_pyramid_perception(&p.pyramid, v);
}
