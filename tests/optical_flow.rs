//! Sparse optical flow (`perception::flow`): Shi–Tomasi's response against a direct
//! per-pixel reference; pyramidal Lucas–Kanade against known sub-pixel shifts and
//! rotations of a synthetic texture and of a real photograph; and on a real frame pair
//! (Middlebury RubberWhale), where no ground truth ships with the photos, the
//! forward–backward consistency of the tracks.

use marsupial::image_io::load_rgb;
use marsupial::perception::flow::{CornerParams, GreyImage, GreyPyramid, LkParams, LucasKanade, Roi, ShiTomasi};
use proptest::prelude::*;
use std::path::Path;

/// λ_min of the structure tensor at (x, y), directly: Sobel gradients summed over the
/// (2b + 1)² box, in f64.
fn reference_eigen(im: &GreyImage, x: usize, y: usize, b: usize) -> f64 {
    let p = |x: usize, y: usize| im.at(x, y) as f64;
    let (mut a, mut bb, mut c) = (0.0, 0.0, 0.0);
    for v in y - b..=y + b {
        for u in x - b..=x + b {
            let ix = ((p(u + 1, v - 1) + 2.0 * p(u + 1, v) + p(u + 1, v + 1))
                - (p(u - 1, v - 1) + 2.0 * p(u - 1, v) + p(u - 1, v + 1)))
                / 8.0;
            let iy = ((p(u - 1, v + 1) + 2.0 * p(u, v + 1) + p(u + 1, v + 1))
                - (p(u - 1, v - 1) + 2.0 * p(u, v - 1) + p(u + 1, v - 1)))
                / 8.0;
            a += ix * ix;
            bb += ix * iy;
            c += iy * iy;
        }
    }
    (a + c) / 2.0 - (((a - c) / 2.0).powi(2) + bb * bb).sqrt()
}

/// A smooth texture with corners everywhere, sampled at (u, v) (continuous).
fn texture(u: f64, v: f64) -> f32 {
    (128.0
        + 50.0 * (u * 0.13).sin() * (v * 0.09).cos()
        + 35.0 * ((u - v) * 0.07).sin()
        + 25.0 * (u * 0.031 + v * 0.045).cos() * (v * 0.21).sin()) as f32
}

fn render(w: usize, h: usize, map: impl Fn(f64, f64) -> (f64, f64)) -> GreyImage {
    let mut data = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            let (u, v) = map(x as f64, y as f64);
            data.push(texture(u, v));
        }
    }
    GreyImage::from_vec(w, h, data).unwrap()
}

fn pyramid(im: &GreyImage, levels: usize) -> GreyPyramid {
    let mut p = GreyPyramid::new(levels);
    p.build_from_grey(im);
    p
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(40))]

    /// The separable running-sum response equals the direct one wherever the box fits,
    /// over random images, box sizes and regions.
    #[test]
    fn the_response_matches_the_direct_reference(
        w in 12usize..40, h in 12usize..40, b in 1usize..4, seed in any::<u64>(),
        rx in 0usize..10, ry in 0usize..10, rw in 1usize..40, rh in 1usize..40,
    ) {
        let mut s = seed | 1;
        let data: Vec<f32> = (0..w * h)
            .map(|_| {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                (s % 256) as f32
            })
            .collect();
        let im = GreyImage::from_vec(w, h, data).unwrap();
        let mut st = ShiTomasi::new(w, h, CornerParams { block_radius: b, ..CornerParams::default() });
        st.response(&im, Roi { x0: rx, y0: ry, x1: rx + rw, y1: ry + rh });
        let r = st.region();
        let rw = r.x1 - r.x0;
        for y in r.y0..r.y1 {
            for x in r.x0..r.x1 {
                let got = st.eigen()[(y - r.y0) * rw + (x - r.x0)] as f64;
                let m = 1 + b;
                if x < m || y < m || x + m >= w || y + m >= h {
                    prop_assert_eq!(got, 0.0);
                } else {
                    let want = reference_eigen(&im, x, y, b);
                    prop_assert!((got - want).abs() <= 1e-3 * (1.0 + want.abs()) + 0.5, "({}, {}): {} vs {}", x, y, got, want);
                }
            }
        }
    }

    /// A sub-pixel shift of up to 6 px in any direction is recovered within 0.05 px at
    /// the corners found (three levels).
    #[test]
    fn shifts_are_recovered(dx in -6.0f64..6.0, dy in -6.0f64..6.0) {
        let a = render(160, 120, |x, y| (x, y));
        let b = render(160, 120, |x, y| (x - dx, y - dy));
        let (pa, pb) = (pyramid(&a, 3), pyramid(&b, 3));
        let mut st = ShiTomasi::new(160, 120, CornerParams::default());
        let pts: Vec<[f64; 2]> = st.detect(&a, Roi { x0: 30, y0: 30, x1: 130, y1: 90 }).to_vec();
        prop_assert!(pts.len() >= 10, "{} corners", pts.len());
        let mut lk = LucasKanade::new(LkParams::default(), pts.len());
        let mut out = vec![None; pts.len()];
        lk.track_checked(&pa, &pb, &pts, &mut out);
        let mut n = 0;
        for (p, o) in pts.iter().zip(&out) {
            if let Some(q) = o {
                n += 1;
                let e = (q[0] - p[0] - dx).hypot(q[1] - p[1] - dy);
                prop_assert!(e < 0.05, "{:?} → {:?}: error {} px", p, q, e);
            }
        }
        prop_assert!(n * 4 >= pts.len() * 3, "{} of {} tracked", n, pts.len());
    }

    /// A rotation of up to ±3° about the image centre (with a small shift) is followed
    /// within 0.3 px: the window deforms, which a translation-only tracker absorbs only
    /// approximately (0.30 px at 3.9° with a 15×15 window).
    #[test]
    fn small_rotations_are_followed(deg in -3.0f64..3.0, dx in -2.0f64..2.0) {
        let (c, s) = (deg.to_radians().cos(), deg.to_radians().sin());
        let (cx, cy) = (80.0, 60.0);
        // next(x) = prev(R⁻¹(x − c − t) + c): a point p of prev moves to R(p − c) + c + t.
        let a = render(160, 120, |x, y| (x, y));
        let b = render(160, 120, |x, y| {
            let (u, v) = (x - cx - dx, y - cy);
            (c * u + s * v + cx, -s * u + c * v + cy)
        });
        let (pa, pb) = (pyramid(&a, 3), pyramid(&b, 3));
        let mut st = ShiTomasi::new(160, 120, CornerParams::default());
        let pts: Vec<[f64; 2]> = st.detect(&a, Roi { x0: 40, y0: 30, x1: 120, y1: 90 }).to_vec();
        let mut lk = LucasKanade::new(LkParams::default(), pts.len());
        let mut out = vec![None; pts.len()];
        lk.track_checked(&pa, &pb, &pts, &mut out);
        let mut n = 0;
        for (p, o) in pts.iter().zip(&out) {
            if let Some(q) = o {
                n += 1;
                let (u, v) = (p[0] - cx, p[1] - cy);
                let want = [c * u - s * v + cx + dx, s * u + c * v + cy];
                let e = (q[0] - want[0]).hypot(q[1] - want[1]);
                prop_assert!(e < 0.3, "{:?} → {:?}, want {:?}: {} px", p, q, want, e);
            }
        }
        prop_assert!(n * 10 >= pts.len() * 8, "{} of {} tracked", n, pts.len());
    }
}

/// A featureless window is lost, not guessed; a point whose window leaves the image is
/// lost.
#[test]
fn flat_windows_and_the_border_lose_the_point() {
    let flat = GreyImage::from_vec(64, 48, vec![100.0; 64 * 48]).unwrap();
    let textured = render(64, 48, |x, y| (x, y));
    let mut lk = LucasKanade::new(LkParams::default(), 4);
    let mut out = [Some([0.0, 0.0]); 3];
    lk.track(
        &pyramid(&flat, 2),
        &pyramid(&flat, 2),
        &[[32.0, 24.0], [10.0, 10.0], [1.0, 1.0]],
        &mut out,
    );
    assert_eq!(out, [None; 3]);
    let mut out = [None; 2];
    let p = pyramid(&textured, 2);
    lk.track(&p, &p, &[[32.0, 24.0], [2.0, 24.0]], &mut out);
    assert!(out[0].is_some_and(|q| (q[0] - 32.0).abs() < 1e-6 && (q[1] - 24.0).abs() < 1e-6));
    assert_eq!(out[1], None);
}

fn photo(name: &str) -> Option<GreyImage> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data/photos/sequences")
        .join(name);
    if !path.exists() {
        eprintln!("skipping: {} is absent", path.display());
        return None;
    }
    let rgb = load_rgb(&path).unwrap();
    let mut g = GreyImage::default();
    g.set_from_rgb(&rgb.view());
    Some(g)
}

/// Warps `im` by x_next = R(x − c) + c + t (bilinear), the real texture moved by a known
/// motion.
fn warp(im: &GreyImage, deg: f64, t: [f64; 2]) -> GreyImage {
    let (w, h) = (im.width(), im.height());
    let (c, s) = (deg.to_radians().cos(), deg.to_radians().sin());
    let (cx, cy) = (w as f64 / 2.0, h as f64 / 2.0);
    let mut data = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            let (u, v) = (x as f64 - cx - t[0], y as f64 - cy - t[1]);
            data.push(im.sample(c * u + s * v + cx, -s * u + c * v + cy).unwrap_or(0.0));
        }
    }
    GreyImage::from_vec(w, h, data).unwrap()
}

/// On a real photograph moved by a known shift and rotation, the corners found are
/// tracked to where the motion puts them: median error under 0.05 px for a shift, under
/// 0.1 px with 2° of rotation, and 90 % of the tracks within 0.5 px.
#[test]
fn a_real_photo_moved_by_a_known_motion() {
    let Some(a) = photo("rubberwhale1.png") else { return };
    let (w, h) = (a.width(), a.height());
    for (deg, t, median_max) in [(0.0, [3.3, -2.7], 0.05), (2.0, [1.5, 0.8], 0.1)] {
        let b = warp(&a, deg, t);
        let (pa, pb) = (pyramid(&a, 3), pyramid(&b, 3));
        let mut st = ShiTomasi::new(
            w,
            h,
            CornerParams {
                max_corners: 200,
                ..CornerParams::default()
            },
        );
        let pts: Vec<[f64; 2]> = st
            .detect(
                &a,
                Roi {
                    x0: 60,
                    y0: 60,
                    x1: w - 60,
                    y1: h - 60,
                },
            )
            .to_vec();
        assert!(pts.len() >= 100, "{} corners", pts.len());
        let mut lk = LucasKanade::new(LkParams::default(), pts.len());
        let mut out = vec![None; pts.len()];
        lk.track_checked(&pa, &pb, &pts, &mut out);
        let (c, s) = (deg.to_radians().cos(), deg.to_radians().sin());
        let (cx, cy) = (w as f64 / 2.0, h as f64 / 2.0);
        let mut errors: Vec<f64> = pts
            .iter()
            .zip(&out)
            .filter_map(|(p, o)| {
                let q = (*o)?;
                let (u, v) = (p[0] - cx, p[1] - cy);
                Some((q[0] - (c * u - s * v + cx + t[0])).hypot(q[1] - (s * u + c * v + cy + t[1])))
            })
            .collect();
        errors.sort_by(f64::total_cmp);
        let median = errors[errors.len() / 2];
        let p90 = errors[errors.len() * 9 / 10];
        let within = errors.iter().filter(|&&e| e <= 0.5).count();
        println!(
            "rubberwhale1 moved {deg}°, {t:?}: {} of {} tracked, median {median:.3} px, 90 % {p90:.3} px, {within} within 0.5 px",
            errors.len(),
            pts.len()
        );
        assert!(errors.len() * 10 >= pts.len() * 8, "{} of {}", errors.len(), pts.len());
        assert!(
            median < median_max && within * 10 >= errors.len() * 9,
            "median {median}, {within} within 0.5 px"
        );
    }
}

/// On the real RubberWhale pair (its published flow does not ship with the photos), most
/// corners (88 % here) track forward and back to within 0.5 px, and those that do move by the few
/// pixels the scene moves.
#[test]
fn the_rubberwhale_pair_tracks_consistently() {
    let (Some(a), Some(b)) = (photo("rubberwhale1.png"), photo("rubberwhale2.png")) else {
        return;
    };
    let (w, h) = (a.width(), a.height());
    let (pa, pb) = (pyramid(&a, 3), pyramid(&b, 3));
    let mut st = ShiTomasi::new(
        w,
        h,
        CornerParams {
            max_corners: 300,
            ..CornerParams::default()
        },
    );
    let pts: Vec<[f64; 2]> = st.detect(&a, Roi::full(w, h)).to_vec();
    let mut lk = LucasKanade::new(LkParams::default(), pts.len());
    let mut out = vec![None; pts.len()];
    lk.track_checked(&pa, &pb, &pts, &mut out);
    let moves: Vec<f64> = pts
        .iter()
        .zip(&out)
        .filter_map(|(p, o)| o.map(|q| (q[0] - p[0]).hypot(q[1] - p[1])))
        .collect();
    let kept = moves.len() as f64 / pts.len() as f64;
    let largest = moves.iter().copied().fold(0.0, f64::max);
    println!(
        "rubberwhale: {} of {} corners consistent ({:.0} %), largest motion {largest:.2} px",
        moves.len(),
        pts.len(),
        kept * 100.0
    );
    assert!(pts.len() >= 200 && kept >= 0.8, "{kept}");
    assert!(largest < 10.0, "RubberWhale's motion is a few pixels: {largest}");
}
