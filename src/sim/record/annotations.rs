//! A percept drawn over its frame: [`Observation`] → `foxglove.ImageAnnotations`.
//!
//! Two-block flap: each block's box (green for the image-left colour, yellow for the
//! right, the paints of [`crate::perception::overlay`]), its centroid, and a white box
//! around the pair. Pyramid: the blue region's box, the orange ellipse's outline and
//! centre, and a white box around the pair when both were found. A caption gives the
//! percept's headline figures; nothing but the caption is drawn when the fiducial was
//! not found.

use super::messages::{CircleAnnotation, Color, ImageAnnotations, Point2, PointsAnnotation, TextAnnotation, Time};
use crate::perception::overlay::{LEFT_PAINT, RIGHT_PAINT};
use crate::schemas::{Observation, ObservedPercept};

/// `foxglove.PointsAnnotation` types.
const LINE_LOOP: u8 = 2;

/// White, for pair boxes and captions.
const WHITE: Color = Color {
    r: 1.0,
    g: 1.0,
    b: 1.0,
    a: 1.0,
};

/// The outline of an inclusive pixel box `[x_min, y_min, x_max, y_max]`, grown by
/// `margin` px, along pixel edges.
fn bbox_loop(t: Time, b: [u32; 4], margin: f64, color: Color) -> PointsAnnotation {
    let (x0, y0) = (b[0] as f64 - margin, b[1] as f64 - margin);
    let (x1, y1) = (b[2] as f64 + 1.0 + margin, b[3] as f64 + 1.0 + margin);
    PointsAnnotation {
        timestamp: t,
        kind: LINE_LOOP,
        points: vec![
            Point2 { x: x0, y: y0 },
            Point2 { x: x1, y: y0 },
            Point2 { x: x1, y: y1 },
            Point2 { x: x0, y: y1 },
        ],
        outline_color: color,
        outline_colors: Vec::new(),
        fill_color: Color::CLEAR,
        thickness: 1.0,
    }
}

/// A small filled dot at pixel centre `c` (pixel coordinates of the pixel's centre).
fn dot(t: Time, c: [f64; 2], color: Color) -> CircleAnnotation {
    CircleAnnotation {
        timestamp: t,
        position: Point2 {
            x: c[0] + 0.5,
            y: c[1] + 0.5,
        },
        diameter: 4.0,
        thickness: 1.0,
        fill_color: color,
        outline_color: WHITE,
    }
}

/// The union of two inclusive boxes.
fn union(a: [u32; 4], b: [u32; 4]) -> [u32; 4] {
    [a[0].min(b[0]), a[1].min(b[1]), a[2].max(b[2]), a[3].max(b[3])]
}

/// A caption in the frame's top-left corner.
fn caption(t: Time, text: String) -> TextAnnotation {
    TextAnnotation {
        timestamp: t,
        position: Point2 { x: 4.0, y: 12.0 },
        text,
        font_size: 10.0,
        text_color: WHITE,
        background_color: Color {
            r: 0.0,
            g: 0.0,
            b: 0.0,
            a: 0.5,
        },
    }
}

/// The annotations of `obs` for the image stamped `t`.
pub fn annotate(t: Time, obs: &Observation) -> ImageAnnotations {
    let mut a = ImageAnnotations::default();
    match &obs.percept {
        ObservedPercept::TwoBlock(p) => {
            if p.found {
                let (l, r) = (Color::rgb8(LEFT_PAINT.0), Color::rgb8(RIGHT_PAINT.0));
                a.points.push(bbox_loop(t, p.left_bbox, 0.0, l));
                a.points.push(bbox_loop(t, p.right_bbox, 0.0, r));
                a.points
                    .push(bbox_loop(t, union(p.left_bbox, p.right_bbox), 2.0, WHITE));
                a.circles.push(dot(t, p.left_centroid, l));
                a.circles.push(dot(t, p.right_centroid, r));
                a.texts.push(caption(
                    t,
                    format!(
                        "{} + {} px, ratio {:.2}, offset {:+.1} px",
                        p.left_px, p.right_px, p.ratio, p.offset_px
                    ),
                ));
            } else {
                a.texts.push(caption(t, "not found".into()));
            }
        }
        ObservedPercept::Krawler(k) => {
            let magenta = Color::rgb8([255, 0, 255]);
            // Marker centres count pixel centres at +0.5 already.
            for at in k.markers.iter().flatten() {
                a.circles.push(dot(t, [at[0] - 0.5, at[1] - 0.5], magenta));
            }
            let found = k.markers.iter().flatten().count();
            let theta = k.wheel_rad.iter().sum::<f64>() / 4.0;
            a.texts
                .push(caption(t, format!("markers {found}/8, mean θ {theta:.2} rad")));
        }
        ObservedPercept::Pyramid(p) => {
            let d = &p.detection;
            let blue = Color::rgb8([40, 120, 255]);
            let orange = Color::rgb8([255, 140, 0]);
            if let Some(b) = &d.blue {
                a.points.push(bbox_loop(t, b.bbox, 0.0, blue));
            }
            if let Some(e) = &d.ellipse {
                let (s, c) = e.angle.sin_cos();
                let points = (0..24)
                    .map(|k| {
                        let u = k as f64 / 24.0 * std::f64::consts::TAU;
                        let (x, y) = (e.semi_major * u.cos(), e.semi_minor * u.sin());
                        Point2 {
                            x: e.centre[0] + 0.5 + c * x - s * y,
                            y: e.centre[1] + 0.5 + s * x + c * y,
                        }
                    })
                    .collect();
                a.points.push(PointsAnnotation {
                    timestamp: t,
                    kind: LINE_LOOP,
                    points,
                    outline_color: orange,
                    outline_colors: Vec::new(),
                    fill_color: Color::CLEAR,
                    thickness: 1.0,
                });
                a.circles.push(dot(t, e.centre, orange));
            }
            if let Some(pair) = &d.pair {
                a.points
                    .push(bbox_loop(t, union(pair.blue.bbox, pair.ellipse.bbox), 2.0, WHITE));
            }
            a.texts.push(caption(
                t,
                match &p.view {
                    Some(v) => format!(
                        "ball {:.2} m, bearing {:+.1}°{}",
                        v.ball_distance_m,
                        v.bearing.to_degrees(),
                        v.alpha
                            .map(|x| format!(", α {:+.1}°", x.to_degrees()))
                            .unwrap_or_default()
                    ),
                    None => "not found".into(),
                },
            ));
        }
    }
    a
}
