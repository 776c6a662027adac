//! SVG plots of a campaign: trajectories on a top view of the dock with the starts
//! marked (like seed 004 Fig. 8/9), and a success map.

use super::campaign::RunRecord;
use super::world::World;
use crate::profile::Profile;
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
