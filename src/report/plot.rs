//! SVG plots of a campaign: trajectories on a top view of the dock with the starts
//! marked (like seed 004 Fig. 8/9), and a success map.

use crate::profile::Profile;
use crate::sim::campaign::RunRecord;
use crate::sim::world::World;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

struct View {
    x0: f64,
    y0: f64,
    scale: f64,
    w: f64,
    h: f64,
}

impl View {
    fn fit(records: &[RunRecord], world: &World) -> Self {
        let (mut x0, mut x1, mut y0, mut y1) = (-world.dock.body_length.max(0.3) - 0.1, 0.5f64, -0.6f64, 0.6f64);
        for r in records {
            let (sx, sy) = (
                r.distance_m * r.angle_deg.to_radians().cos(),
                r.distance_m * r.angle_deg.to_radians().sin(),
            );
            x1 = x1.max(sx + 0.3);
            y0 = y0.min(sy - 0.3);
            y1 = y1.max(sy + 0.3);
            x0 = x0.min(sx - 0.3);
        }
        let scale = 700.0 / (x1 - x0).max(y1 - y0);
        // The approach zone is drawn with +x up the page, +y to the left (a map seen from above).
        Self {
            x0,
            y0,
            scale,
            w: (y1 - y0) * scale + 40.0,
            h: (x1 - x0) * scale + 40.0,
        }
    }
    /// Page coordinates of world (x, y): +x up the page, +y to the left.
    fn px(&self, x: f64, y: f64) -> (f64, f64) {
        let y1 = self.y0 + (self.w - 40.0) / self.scale;
        (
            20.0 + (y1 - y) * self.scale,
            20.0 + (self.h - 40.0) - (x - self.x0) * self.scale,
        )
    }
}

fn dock_outline(svg: &mut String, v: &View, world: &World) {
    let d = &world.dock;
    if d.body_length > 0.0 {
        let (ax, ay) = v.px(0.0, d.body_half_width);
        let (bx, by) = v.px(-d.body_length, -d.body_half_width);
        let _ = writeln!(
            svg,
            r##"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="#555" />"##,
            ax.min(bx),
            ay.min(by),
            (bx - ax).abs(),
            (by - ay).abs()
        );
        let (cx, cy) = v.px(0.0, d.entrance_half);
        let (ex, ey) = v.px(-d.depth, -d.entrance_half);
        let _ = writeln!(
            svg,
            r##"<rect x="{:.1}" y="{:.1}" width="{:.1}" height="{:.1}" fill="#222" />"##,
            cx.min(ex),
            cy.min(ey),
            (ex - cx).abs(),
            (ey - cy).abs()
        );
    } else {
        let (cx, cy) = v.px(0.0, 0.0);
        let _ = writeln!(svg, r##"<circle cx="{cx:.1}" cy="{cy:.1}" r="6" fill="#f80" />"##);
    }
}

/// Writes `trajectories.svg` and `success_map.svg` into `dir`.
///
/// # Errors
/// When a file cannot be written.
pub fn write_plots(dir: &Path, world: &World, profile: &Profile, records: &[RunRecord]) -> std::io::Result<()> {
    let v = View::fit(records, world);
    let head = |title: &str| {
        format!(
            r##"<svg xmlns="http://www.w3.org/2000/svg" width="{:.0}" height="{:.0}" font-family="sans-serif" font-size="12"><rect width="100%" height="100%" fill="white"/><text x="10" y="14">{title}</text>"##,
            v.w,
            v.h + 10.0
        )
    };
    let mut svg = head(&format!(
        "{}: trajectories (green docked, red failed), top view, dock at the bottom",
        profile.name
    ));
    dock_outline(&mut svg, &v, world);
    for r in records {
        let pts: Vec<String> = r
            .track
            .iter()
            .map(|p| {
                let (x, y) = v.px(p[0] as f64 / 1000.0, p[1] as f64 / 1000.0);
                format!("{x:.1},{y:.1}")
            })
            .collect();
        let colour = if r.success { "#2a2" } else { "#d22" };
        let _ = writeln!(
            svg,
            r##"<polyline points="{}" fill="none" stroke="{colour}" stroke-width="1" opacity="0.6"/>"##,
            pts.join(" ")
        );
    }
    let mut starts: BTreeMap<String, (f64, f64, usize, usize)> = BTreeMap::new();
    for r in records {
        let e = starts
            .entry(r.start.clone())
            .or_insert((r.distance_m, r.angle_deg, 0, 0));
        e.2 += 1;
        e.3 += r.success as usize;
    }
    for (label, (d, a, _, _)) in &starts {
        let (x, y) = v.px(d * a.to_radians().cos(), d * a.to_radians().sin());
        let _ = writeln!(
            svg,
            r##"<circle cx="{x:.1}" cy="{y:.1}" r="4" fill="black"/><text x="{:.1}" y="{:.1}">{label}</text>"##,
            x + 6.0,
            y - 4.0
        );
    }
    svg.push_str("</svg>\n");
    std::fs::write(dir.join("trajectories.svg"), svg)?;
    let mut svg = head(&format!("{}: success rate per start", profile.name));
    dock_outline(&mut svg, &v, world);
    for (label, (d, a, n, ok)) in &starts {
        let (x, y) = v.px(d * a.to_radians().cos(), d * a.to_radians().sin());
        let rate = *ok as f64 / (*n).max(1) as f64;
        let (r, g) = ((255.0 * (1.0 - rate)) as u8, (200.0 * rate) as u8);
        let _ = writeln!(
            svg,
            r##"<circle cx="{x:.1}" cy="{y:.1}" r="14" fill="rgb({r},{g},40)"/><text x="{:.1}" y="{:.1}" text-anchor="middle">{label}: {ok}/{n}</text>"##,
            x,
            y + 28.0
        );
    }
    svg.push_str("</svg>\n");
    std::fs::write(dir.join("success_map.svg"), svg)
}

/// One line of a time-series plot: its label, colour (SVG), and a value per time (NaN
/// leaves a gap).
#[derive(Debug, Clone, Copy)]
pub struct Series<'a> {
    /// Legend text.
    pub label: &'a str,
    /// SVG colour.
    pub colour: &'a str,
    /// One value per entry of the plot's times.
    pub values: &'a [f64],
}

/// An SVG line plot of `series` against time `t` (s), titled `title` with the values in
/// `unit`: the per-DOF plots of `marsupial estimate` (truth beside estimate over a
/// sequence). Lines break at NaN values.
pub fn time_series_svg(title: &str, unit: &str, t: &[f64], series: &[Series<'_>]) -> String {
    let (w, h, left, top, right, bottom) = (900.0, 260.0, 60.0, 30.0, 20.0, 30.0);
    let t0 = t.first().copied().unwrap_or(0.0);
    let t1 = t.last().copied().unwrap_or(1.0).max(t0 + 1e-9);
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for s in series {
        for v in s.values.iter().filter(|v| v.is_finite()) {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
    }
    if !lo.is_finite() {
        (lo, hi) = (0.0, 1.0);
    }
    let pad = ((hi - lo) * 0.05).max(1e-9);
    let (lo, hi) = (lo - pad, hi + pad);
    let px = |ti: f64| left + (ti - t0) / (t1 - t0) * (w - left - right);
    let py = |v: f64| top + (hi - v) / (hi - lo) * (h - top - bottom);
    let mut svg = format!(
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="{w:.0}" height="{h:.0}" font-family="sans-serif" font-size="12"><rect width="100%" height="100%" fill="white"/><text x="10" y="16">{title} ({unit})</text>"##
    );
    let _ = write!(
        svg,
        r##"<rect x="{left}" y="{top}" width="{:.0}" height="{:.0}" fill="none" stroke="#999"/>"##,
        w - left - right,
        h - top - bottom
    );
    for (v, anchor) in [(lo + pad, "end"), (hi - pad, "end")] {
        let _ = write!(
            svg,
            r##"<text x="{:.1}" y="{:.1}" text-anchor="{anchor}">{v:.3}</text>"##,
            left - 4.0,
            py(v) + 4.0
        );
    }
    let _ = write!(
        svg,
        r##"<text x="{left}" y="{:.0}">{t0:.0} s</text><text x="{:.0}" y="{:.0}" text-anchor="end">{t1:.0} s</text>"##,
        h - 10.0,
        w - right,
        h - 10.0
    );
    for (k, s) in series.iter().enumerate() {
        let mut runs: Vec<Vec<String>> = vec![Vec::new()];
        for (ti, v) in t.iter().zip(s.values) {
            if v.is_finite() {
                if let Some(run) = runs.last_mut() {
                    run.push(format!("{:.1},{:.1}", px(*ti), py(*v)));
                }
            } else if runs.last().is_some_and(|r| !r.is_empty()) {
                runs.push(Vec::new());
            }
        }
        for run in runs.iter().filter(|r| r.len() > 1) {
            let _ = write!(
                svg,
                r##"<polyline points="{}" fill="none" stroke="{}" stroke-width="1"/>"##,
                run.join(" "),
                s.colour
            );
        }
        let _ = write!(
            svg,
            r##"<text x="{:.0}" y="16" fill="{}">{}</text>"##,
            w - right - 150.0 * (series.len() - k) as f64,
            s.colour,
            s.label
        );
    }
    svg.push_str("</svg>\n");
    svg
}

/// An SVG top view of paths (x, y per point, m), each a [`Series`]-like (label, colour)
/// pair, with equal scales: the odometry plot of `marsupial estimate`.
pub fn paths_svg(title: &str, paths: &[(&str, &str, &[[f64; 3]])]) -> String {
    let (mut x0, mut x1, mut y0, mut y1) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
    for (_, _, p) in paths {
        for q in p.iter() {
            x0 = x0.min(q[0]);
            x1 = x1.max(q[0]);
            y0 = y0.min(q[1]);
            y1 = y1.max(q[1]);
        }
    }
    if !x0.is_finite() {
        (x0, x1, y0, y1) = (0.0, 1.0, 0.0, 1.0);
    }
    let span = (x1 - x0).max(y1 - y0).max(0.1) * 1.1;
    let (cx, cy) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
    let size = 600.0;
    // +x up the page, +y to the left, as the campaign plots.
    let px = |x: f64, y: f64| {
        (
            size / 2.0 - (y - cy) / span * size + 20.0,
            size / 2.0 - (x - cx) / span * size + 40.0,
        )
    };
    let mut svg = format!(
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="{:.0}" height="{:.0}" font-family="sans-serif" font-size="12"><rect width="100%" height="100%" fill="white"/><text x="10" y="16">{title} (top view, x up, {:.2} m across)</text>"##,
        size + 40.0,
        size + 60.0,
        span
    );
    for (k, (label, colour, p)) in paths.iter().enumerate() {
        let pts: Vec<String> = p
            .iter()
            .map(|q| {
                let (a, b) = px(q[0], q[1]);
                format!("{a:.1},{b:.1}")
            })
            .collect();
        let _ = write!(
            svg,
            r##"<polyline points="{}" fill="none" stroke="{colour}" stroke-width="1"/><text x="10" y="{}" fill="{colour}">{label}</text>"##,
            pts.join(" "),
            34 + 14 * k
        );
    }
    svg.push_str("</svg>\n");
    svg
}
