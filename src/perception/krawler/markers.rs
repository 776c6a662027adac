//! The eight magenta markers (seed 003 §IV-B): HSV segmentation, erosion then dilation (a
//! 3×3 opening), 8-connected components, and each blob's centre (the mean of its pixels,
//! which for a convex marker is the centre of the area its contour encloses).
//!
//! **Identity.** A blob is given a marker's identity from where that marker is expected
//! to project ([`ExpectedMarker`]: a pixel position and an area, which the caller predicts
//! from the previous estimate or the rest state through the camera model). Candidate
//! (marker, blob) pairs are those within [`MarkerParams::gate_px`] of the prediction whose
//! area is within [`MarkerParams::area_ratio`] of the expected area; they are taken
//! greedily, nearest first, each marker and each blob used at most once. Blobs nowhere
//! near a predicted marker, or of the wrong size, are never assigned: that is what keeps
//! magenta clutter out.
//!
//! **Corroboration.** A matched marker is reported only when another visible marker of
//! the same axle lies where the prediction puts it relative to the first (within
//! [`MarkerParams::consistency_px`]). A single magenta blob that happens to fall near a
//! prediction is not enough; an axle showing only one marker reports none (one marker
//! gives neither roll nor steering anyway).
//!
//! **Missing, never guessed.** A marker whose best blob touches the image border or has
//! less than [`MarkerParams::min_visible`] of the expected area (partly hidden by a wheel,
//! a shadow, or the frame's edge) is reported missing (`None`), as is one with no blob
//! within the gate. Its blob is still consumed, so it cannot be handed to a neighbour.
//!
//! Every buffer is sized in [`MarkerFinder::new`]; [`MarkerFinder::find`] does not
//! allocate.

use crate::perception::components::Labeler;
use crate::perception::hsv::Hsv;
use crate::perception::image::RgbView;
use crate::perception::segment::Mask;
use crate::perception::{VisionError, check_same_size};

/// Thresholds of the marker finder.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MarkerParams {
    /// Hue band of magenta, degrees (low, high), low < high.
    pub hue_deg: (f32, f32),
    /// Minimum saturation, 0–1.
    pub min_saturation: f32,
    /// Minimum value (brightness), 0–1.
    pub min_value: f32,
    /// Blobs smaller than this after the opening are noise, pixels.
    pub min_area_px: u64,
    /// Largest distance from a marker's predicted position to its blob's centre, px.
    pub gate_px: f64,
    /// A blob's area over the expected area must lie in (1 / this, this) to be a
    /// candidate for that marker at all.
    pub area_ratio: f64,
    /// A candidate with less than this fraction of the expected area is partly hidden:
    /// its marker is reported missing.
    pub min_visible: f64,
    /// Corroboration: a marker is reported only if another visible marker of its axle
    /// lies within this distance of where the prediction puts it relative to the first,
    /// px. A lone blob near a prediction (clutter) is not a marker.
    pub consistency_px: f64,
    /// Refine each reported marker's centre to sub-pixel precision with a
    /// magenta-weighted centroid ([`MarkerFinder::find`]); off gives the binary blob's
    /// mean pixel position, the paper's contour centre.
    pub refine: bool,
    /// Segment only in a window around each prediction (± the gate, 1.5 √area and 2 px),
    /// as the paper restricts every stage to regions of interest from the kinematic
    /// constraints; off segments the whole frame. A marker farther than the gate from its
    /// prediction is not matched either way, so on and off find the same markers; off
    /// also reports the clutter elsewhere in [`MarkerFinder::blobs`].
    pub windows: bool,
}

impl Default for MarkerParams {
    /// Magenta 270–330°, saturation ≥ 0.45, value ≥ 0.15; blobs of 4 px or more; a 25 px
    /// gate; areas within a factor 3, at least 60 % of the expected area visible, a
    /// 15 px corroboration tolerance, sub-pixel refinement and search windows on.
    fn default() -> Self {
        Self {
            hue_deg: (270.0, 330.0),
            min_saturation: 0.45,
            min_value: 0.15,
            min_area_px: 4,
            gate_px: 25.0,
            area_ratio: 3.0,
            min_visible: 0.6,
            consistency_px: 15.0,
            refine: true,
            windows: true,
        }
    }
}

/// Where a marker is expected in the image, and how large.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExpectedMarker {
    /// Predicted centre, px (x = column, y = row).
    pub at: [f64; 2],
    /// Predicted area, px².
    pub area: f64,
}

impl ExpectedMarker {
    /// The prediction for a square marker of side `side` centred at `centre` with edge
    /// directions `u` and `v` (unit vectors), through `project` (a 3-D point in whatever
    /// frame the closure expects to a pixel). The area is the parallelogram spanned by the
    /// projected half-side steps, times four. `None` when any point does not project.
    pub fn from_square<F>(project: F, centre: [f64; 3], u: [f64; 3], v: [f64; 3], side: f64) -> Option<Self>
    where
        F: Fn([f64; 3]) -> Option<[f64; 2]>,
    {
        let at = project(centre)?;
        let step = |d: [f64; 3]| {
            let q = project([
                centre[0] + d[0] * side / 2.0,
                centre[1] + d[1] * side / 2.0,
                centre[2] + d[2] * side / 2.0,
            ])?;
            Some([q[0] - at[0], q[1] - at[1]])
        };
        let (a, b) = (step(u)?, step(v)?);
        Some(Self {
            at,
            area: 4.0 * (a[0] * b[1] - a[1] * b[0]).abs(),
        })
    }
}

/// One magenta blob after the opening.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Blob {
    /// Centre (mean pixel position), px, with pixel centres at integer + 0.5 as in
    /// [`crate::perception::camera_model`].
    pub centre: [f64; 2],
    /// Area, px.
    pub area: u64,
    /// Whether the blob touches the image border (so it may be cut off).
    pub on_border: bool,
    /// Which marker it was matched to, if any (index into the eight).
    pub marker: Option<usize>,
    /// Matched, but not reported: partly hidden, or not corroborated by its axle.
    pub rejected: bool,
}

/// The eight markers found in one frame, in the simulator's order: front plate left,
/// right; front tie rod left, right; then the rear axle's (the paper's A1, A2, B1, B2,
/// C1, C2, D1, D2, 1 on the left).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Markers {
    /// Each marker's centre, px, or `None` when missing.
    pub at: [Option<[f64; 2]>; 8],
}

impl Markers {
    /// How many of the eight were found.
    pub fn found(&self) -> usize {
        self.at.iter().filter(|m| m.is_some()).count()
    }
}

/// Finds and identifies the eight markers in frames of one size; owns every buffer.
#[derive(Debug, Clone)]
pub struct MarkerFinder {
    params: MarkerParams,
    mask: Mask,
    scratch: Mask,
    line: Mask,
    labeler: Labeler,
    blobs: Vec<Blob>,
    pairs: Vec<(f64, u8, u16)>,
    /// sRGB byte → linear light, for the refinement's weights.
    linear: [f32; 256],
}

/// At most this many blobs are kept per frame (the largest first is not guaranteed:
/// raster order); more than this is clutter, not a rover.
pub const MAX_BLOBS: usize = 512;

impl MarkerFinder {
    /// A finder for `width × height` frames.
    pub fn new(width: usize, height: usize, params: MarkerParams) -> Self {
        Self {
            params,
            mask: Mask::new(width, height),
            scratch: Mask::new(width, height),
            line: Mask::new(width, height),
            labeler: Labeler::new(width, height),
            blobs: Vec::with_capacity(MAX_BLOBS),
            pairs: Vec::with_capacity(8 * MAX_BLOBS),
            linear: std::array::from_fn(|i| crate::perception::image::srgb_to_linear(i as f32 / 255.0)),
        }
    }

    /// The thresholds in use.
    pub fn params(&self) -> &MarkerParams {
        &self.params
    }

    /// The blobs of the last frame (at most [`MAX_BLOBS`]), each with the marker it was
    /// given, if any.
    pub fn blobs(&self) -> &[Blob] {
        &self.blobs
    }

    /// The opened magenta mask of the last frame.
    pub fn mask(&self) -> &Mask {
        &self.mask
    }

    /// Finds the markers in `frame`, given where each is expected.
    ///
    /// # Errors
    /// [`VisionError::SizeMismatch`] when `frame` is not the finder's size.
    pub fn find(&mut self, frame: &RgbView<'_>, expected: &[ExpectedMarker; 8]) -> Result<Markers, VisionError> {
        check_same_size(self.mask.size(), (frame.width(), frame.height()))?;
        let (w, h) = self.mask.size();
        if self.params.windows {
            self.mask.data_mut().fill(0);
            let rects = expected.map(|e| Rect::around(&e, self.params.gate_px, w, h));
            // Each row's stretches covered by the windows, merged, so a pixel of
            // overlapping windows is segmented once.
            let (y0, y1) = rects
                .iter()
                .filter(|r| r.x0 < r.x1 && r.y0 < r.y1)
                .fold((usize::MAX, 0), |(a, b), r| (a.min(r.y0), b.max(r.y1)));
            for y in y0..y1 {
                let mut spans = [(0usize, 0usize); 8];
                let mut n = 0;
                for r in rects.iter().filter(|r| r.x0 < r.x1 && r.y0 <= y && y < r.y1) {
                    spans[n] = (r.x0, r.x1);
                    n += 1;
                }
                spans[..n].sort_unstable();
                let mut open: Option<(usize, usize)> = None;
                for &(a, b) in &spans[..n] {
                    open = match open {
                        Some((oa, ob)) if a <= ob => Some((oa, ob.max(b))),
                        Some((oa, ob)) => {
                            self.segment(frame, y, oa, ob);
                            Some((a, b))
                        }
                        None => Some((a, b)),
                    };
                }
                if let Some((a, b)) = open {
                    self.segment(frame, y, a, b);
                }
            }
            open3(&mut self.mask, &mut self.scratch, &mut self.line, &rects);
        } else {
            for y in 0..h {
                self.segment(frame, y, 0, w);
            }
            open3(&mut self.mask, &mut self.scratch, &mut self.line, &[Rect::full(w, h)]);
        }
        self.collect_blobs()?;
        let mut found = self.assign(expected);
        if self.params.refine {
            for blob in self.blobs.iter().filter(|b| !b.rejected) {
                if let Some(m) = blob.marker
                    && found.at[m].is_some()
                {
                    found.at[m] = Some(self.refine(frame, blob));
                }
            }
        }
        Ok(found)
    }

    /// A marker's centre to sub-pixel precision: the centroid of the window around its
    /// blob, each pixel weighted by how much of it is marker.
    ///
    /// Why: the binary blob's centre moves in whole-pixel steps as a 10–15 px marker's
    /// edge pixels cross the threshold, which is a few tenths of a pixel, and the steering
    /// ratio turns 0.2 px into about 1°. An edge pixel's colour is the mix of marker and
    /// background in proportion to its coverage (in linear light), so its magenta chroma
    /// (R + B)/2 − G, over the blob interior's, is its coverage; the coverage-weighted
    /// centroid is the centre of the marker's area in the image. Chroma below a tenth of
    /// the interior's (a tinted grey background, noise) weighs nothing.
    fn refine(&self, frame: &RgbView<'_>, blob: &Blob) -> [f64; 2] {
        let (w, h) = (frame.width(), frame.height());
        let r = ((blob.area as f64).sqrt() * 0.75).ceil() as usize + 2;
        let (cx, cy) = (blob.centre[0] as usize, blob.centre[1] as usize);
        let (x0, x1) = (cx.saturating_sub(r), (cx + r).min(w - 1));
        let (y0, y1) = (cy.saturating_sub(r), (cy + r).min(h - 1));
        let bytes = frame.as_bytes();
        let chroma = |x: usize, y: usize| {
            let i = (y * w + x) * 3;
            let (r, g, b) = (
                self.linear[bytes[i] as usize],
                self.linear[bytes[i + 1] as usize],
                self.linear[bytes[i + 2] as usize],
            );
            (r + b) / 2.0 - g
        };
        // The interior's chroma: the mean over the blob's own (opened) mask pixels.
        let (mut sum, mut n) = (0.0f64, 0u32);
        for y in y0..=y1 {
            for x in x0..=x1 {
                if self.mask.get(x, y) {
                    sum += chroma(x, y) as f64;
                    n += 1;
                }
            }
        }
        if n == 0 || sum <= 0.0 {
            return blob.centre;
        }
        let full = sum / n as f64;
        let low = 0.1 * full;
        let (mut sw, mut sx, mut sy) = (0.0, 0.0, 0.0);
        for y in y0..=y1 {
            for x in x0..=x1 {
                let wgt = ((chroma(x, y) as f64 - low) / (full - low)).clamp(0.0, 1.0);
                sw += wgt;
                sx += wgt * x as f64;
                sy += wgt * y as f64;
            }
        }
        if sw <= 0.0 {
            blob.centre
        } else {
            [sx / sw + 0.5, sy / sw + 0.5]
        }
    }

    /// Segments the pixels x0..x1 of row y into the mask.
    fn segment(&mut self, frame: &RgbView<'_>, y: usize, x0: usize, x1: usize) {
        let p = &self.params;
        let w = frame.width();
        let bytes = frame.as_bytes();
        let data = self.mask.data_mut();
        // A hue above 240° needs green to be the strictly smallest channel (see
        // `magenta_needs_green_least`): for such a band, every other pixel is rejected
        // before the conversion, with the same result.
        let green_least = p.hue_deg.0 > 240.0;
        let out = &mut data[y * w + x0..y * w + x1];
        let px = &bytes[3 * (y * w + x0)..3 * (y * w + x1)];
        for (o, rgb) in out.iter_mut().zip(px.chunks_exact(3)) {
            let rgb = [rgb[0], rgb[1], rgb[2]];
            *o = if green_least && (rgb[1] >= rgb[0] || rgb[1] >= rgb[2]) {
                0
            } else {
                in_band(p, rgb) as u8
            };
        }
    }

    fn collect_blobs(&mut self) -> Result<(), VisionError> {
        let (w, h) = self.mask.size();
        self.blobs.clear();
        for c in self.labeler.label(&self.mask)? {
            if c.count < self.params.min_area_px {
                continue;
            }
            if self.blobs.len() == MAX_BLOBS {
                break;
            }
            // Pixel centres at integer + 0.5, the camera model's convention.
            let (x, y) = c.centroid();
            self.blobs.push(Blob {
                centre: [x + 0.5, y + 0.5],
                area: c.count,
                on_border: c.bbox[0] == 0
                    || c.bbox[1] == 0
                    || c.bbox[2] as usize + 1 >= w
                    || c.bbox[3] as usize + 1 >= h,
                marker: None,
                rejected: false,
            });
        }
        Ok(())
    }

    fn assign(&mut self, expected: &[ExpectedMarker; 8]) -> Markers {
        let p = self.params;
        self.pairs.clear();
        for (m, e) in expected.iter().enumerate() {
            for (b, blob) in self.blobs.iter().enumerate() {
                let d = (blob.centre[0] - e.at[0]).hypot(blob.centre[1] - e.at[1]);
                let ratio = blob.area as f64 / e.area.max(1.0);
                if d <= p.gate_px && ratio < p.area_ratio && ratio > 1.0 / p.area_ratio {
                    self.pairs.push((d, m as u8, b as u16));
                }
            }
        }
        self.pairs.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        let mut out = Markers::default();
        let mut taken = [false; 8];
        for &(_, m, b) in &self.pairs {
            let (m, b) = (m as usize, b as usize);
            if taken[m] || self.blobs[b].marker.is_some() {
                continue;
            }
            taken[m] = true;
            let blob = &mut self.blobs[b];
            blob.marker = Some(m);
            let hidden = blob.on_border || (blob.area as f64) < p.min_visible * expected[m].area;
            blob.rejected = hidden;
            if !hidden {
                out.at[m] = Some(blob.centre);
            }
        }
        // Corroboration: a marker stands only if another visible marker of its axle sits
        // where the prediction puts it relative to this one.
        let mut keep = [false; 8];
        for m in 0..8 {
            let Some(c) = out.at[m] else { continue };
            let axle = m / 4 * 4;
            keep[m] = (axle..axle + 4).any(|n| {
                n != m
                    && out.at[n].is_some_and(|d| {
                        let seen = [c[0] - d[0], c[1] - d[1]];
                        let want = [
                            expected[m].at[0] - expected[n].at[0],
                            expected[m].at[1] - expected[n].at[1],
                        ];
                        (seen[0] - want[0]).hypot(seen[1] - want[1]) <= p.consistency_px
                    })
            });
        }
        for (at, keep) in out.at.iter_mut().zip(keep) {
            if !keep {
                *at = None;
            }
        }
        for blob in &mut self.blobs {
            if blob.marker.is_some_and(|m| !keep[m]) {
                blob.rejected = true;
            }
        }
        out
    }
}

/// Pixel bounds `[x0, x1) × [y0, y1)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Rect {
    x0: usize,
    y0: usize,
    x1: usize,
    y1: usize,
}

impl Rect {
    fn full(w: usize, h: usize) -> Self {
        Self {
            x0: 0,
            y0: 0,
            x1: w,
            y1: h,
        }
    }

    /// The search window of a prediction, clipped to a `w × h` image.
    fn around(e: &ExpectedMarker, gate: f64, w: usize, h: usize) -> Self {
        let r = gate + 1.5 * e.area.max(0.0).sqrt() + 2.0;
        let clip = |v: f64, n: usize| {
            if v.is_finite() {
                v.clamp(0.0, n as f64) as usize
            } else {
                0
            }
        };
        Self {
            x0: clip(e.at[0] - r, w),
            y0: clip(e.at[1] - r, h),
            x1: clip(e.at[0] + r + 1.0, w),
            y1: clip(e.at[1] + r + 1.0, h),
        }
    }
}

/// A 3×3 opening of `mask` (erosion, then dilation), through `scratch` and `line` (same
/// size), for a mask that is unset outside `rects`. Pixels outside the image count as
/// unset, so erosion clears the border ring. Both are separable (a row pass, then a
/// column pass over whole row slices, which the compiler vectorises); the test below
/// checks it against the plain 3×3 reference.
fn open3(mask: &mut Mask, scratch: &mut Mask, line: &mut Mask, rects: &[Rect]) {
    let (w, h) = mask.size();
    if w < 3 || h < 3 {
        // Every pixel is on the border ring, which erosion clears.
        mask.data_mut().fill(0);
        return;
    }
    let live = |r: &&Rect| r.x0 < r.x1 && r.y0 < r.y1;
    // Erosion of every rectangle first (a pixel of two overlapping rectangles gets the
    // same value twice), so the dilation reads the finished erosion everywhere.
    scratch.data_mut().fill(0);
    for r in rects.iter().filter(live) {
        let (x0, x1) = (r.x0.max(1), r.x1.min(w - 1));
        let (y0, y1) = (r.y0.max(1), r.y1.min(h - 1));
        if x0 >= x1 || y0 >= y1 {
            continue;
        }
        let (src, tmp) = (mask.data(), line.data_mut());
        for y in y0 - 1..y1 + 1 {
            let row = &src[y * w..(y + 1) * w];
            let out = &mut tmp[y * w + x0..y * w + x1];
            for (((o, a), b), c) in out.iter_mut().zip(&row[x0 - 1..]).zip(&row[x0..]).zip(&row[x0 + 1..]) {
                *o = a & b & c;
            }
        }
        let (tmp, dst) = (line.data(), scratch.data_mut());
        for y in y0..y1 {
            let out = &mut dst[y * w + x0..y * w + x1];
            let (a, b, c) = (&tmp[(y - 1) * w + x0..], &tmp[y * w + x0..], &tmp[(y + 1) * w + x0..]);
            for (((o, a), b), c) in out.iter_mut().zip(a).zip(b).zip(c) {
                *o = a & b & c;
            }
        }
    }
    // Eroded pixels lie inside the rectangles, so the dilation reaches at most one
    // pixel beyond them; the mask outside is unset and stays so.
    for r in rects.iter().filter(live) {
        let (x0, x1) = (r.x0.saturating_sub(1), (r.x1 + 1).min(w));
        let (y0, y1) = (r.y0.saturating_sub(1), (r.y1 + 1).min(h));
        let (src, tmp) = (scratch.data(), line.data_mut());
        for y in y0.saturating_sub(1)..(y1 + 1).min(h) {
            let row = &src[y * w..(y + 1) * w];
            let out = &mut tmp[y * w + x0..y * w + x1];
            out.copy_from_slice(&row[x0..x1]);
            let left = usize::from(x0 == 0);
            for (o, a) in out[left..].iter_mut().zip(&row[x0 + left - 1..]) {
                *o |= a;
            }
            let n = out.len() - usize::from(x1 == w);
            for (o, c) in out[..n].iter_mut().zip(&row[x0 + 1..]) {
                *o |= c;
            }
        }
        let (tmp, dst) = (line.data(), mask.data_mut());
        for y in y0..y1 {
            let out = &mut dst[y * w + x0..y * w + x1];
            out.copy_from_slice(&tmp[y * w + x0..y * w + x1]);
            if y > 0 {
                for (o, a) in out.iter_mut().zip(&tmp[(y - 1) * w + x0..]) {
                    *o |= a;
                }
            }
            if y + 1 < h {
                for (o, c) in out.iter_mut().zip(&tmp[(y + 1) * w + x0..]) {
                    *o |= c;
                }
            }
        }
    }
}

/// Whether `rgb` lies in the finder's HSV band: the reference test of the segmentation.
fn in_band(p: &MarkerParams, rgb: [u8; 3]) -> bool {
    let c = Hsv::from_rgb(rgb);
    c.h >= p.hue_deg.0 && c.h <= p.hue_deg.1 && c.s >= p.min_saturation && c.v >= p.min_value
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn opening_removes_specks_and_keeps_squares() {
        let mut m = Mask::new(20, 20);
        for y in 5..11 {
            for x in 5..11 {
                m.set(x, y, true);
            }
        }
        m.set(15, 15, true);
        m.set(16, 15, true);
        let (mut s, mut l) = (Mask::new(20, 20), Mask::new(20, 20));
        open3(&mut m, &mut s, &mut l, &[Rect::full(20, 20)]);
        assert_eq!(m.count(), 36);
        assert!(!m.get(15, 15));
    }

    /// The reference opening: erosion then dilation of the whole mask, pixels outside
    /// the image unset.
    fn open_reference(m: &Mask) -> Mask {
        let (w, h) = m.size();
        let at = |m: &Mask, x: i64, y: i64| {
            x >= 0 && y >= 0 && x < w as i64 && y < h as i64 && m.get(x as usize, y as usize)
        };
        let mut eroded = Mask::new(w, h);
        let mut out = Mask::new(w, h);
        for y in 0..h as i64 {
            for x in 0..w as i64 {
                let all = (-1..=1).all(|dy| (-1..=1).all(|dx| at(m, x + dx, y + dy)));
                eroded.set(x as usize, y as usize, all);
            }
        }
        for y in 0..h as i64 {
            for x in 0..w as i64 {
                let any = (-1..=1).any(|dy| (-1..=1).any(|dx| at(&eroded, x + dx, y + dy)));
                out.set(x as usize, y as usize, any);
            }
        }
        out
    }

    proptest::proptest! {
        /// The opening over a few (overlapping, clipped) rectangles of a mask that is
        /// unset outside them equals the whole-mask reference.
        #[test]
        fn opening_in_rectangles_matches_the_whole_mask_reference(
            w in 1usize..40,
            h in 1usize..40,
            rects in proptest::collection::vec((0usize..45, 0usize..45, 0usize..20, 0usize..20), 0..5),
            seed in proptest::prelude::any::<u64>(),
        ) {
            let rects: Vec<Rect> = rects
                .iter()
                .map(|&(x, y, rw, rh)| Rect { x0: x.min(w), y0: y.min(h), x1: (x + rw).min(w), y1: (y + rh).min(h) })
                .collect();
            let mut s = seed | 1;
            let mut m = Mask::new(w, h);
            for r in &rects {
                for y in r.y0..r.y1 {
                    for x in r.x0..r.x1 {
                        s ^= s << 13;
                        s ^= s >> 7;
                        s ^= s << 17;
                        m.set(x, y, s % 4 != 0);
                    }
                }
            }
            let want = open_reference(&m);
            let (mut scratch, mut line) = (Mask::new(w, h), Mask::new(w, h));
            open3(&mut m, &mut scratch, &mut line, &rects);
            proptest::prop_assert_eq!(m.data(), want.data());
        }
    }

    /// Every colour: a hue band above 240° needs green strictly the smallest channel,
    /// which is what lets `segment` reject the other pixels before converting.
    #[test]
    fn magenta_needs_green_least() {
        let p = MarkerParams {
            hue_deg: (240.001, 360.0),
            min_saturation: 0.0,
            min_value: 0.0,
            ..MarkerParams::default()
        };
        for r in 0..=255u8 {
            for g in 0..=255u8 {
                for b in 0..=255u8 {
                    if g >= r || g >= b {
                        assert!(!in_band(&p, [r, g, b]), "{r} {g} {b}");
                    }
                }
            }
        }
    }
}
