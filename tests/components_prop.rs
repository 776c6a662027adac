//! The run-based labeller against a simple flood-fill reference, on thousands of random
//! masks and the worst cases (checkerboards, spirals, one-pixel lines, all set, none set).

use marsupial::perception::{Component, Labeler, Mask};
use proptest::prelude::*;
use std::collections::VecDeque;

/// Reference: BFS flood fill, 8-connected, components numbered in raster order of their
/// first pixel, with the same integer statistics.
fn flood_fill(mask: &Mask) -> Vec<Component> {
    flood_fill_with(mask, true)
}

/// [`flood_fill`], 8-connected when `eight`, else 4-connected.
fn flood_fill_with(mask: &Mask, eight: bool) -> Vec<Component> {
    let (w, h) = mask.size();
    let mut seen = vec![false; w * h];
    let mut out = Vec::new();
    for y0 in 0..h {
        for x0 in 0..w {
            if !mask.get(x0, y0) || seen[y0 * w + x0] {
                continue;
            }
            let mut c = Component {
                bbox: [x0 as u32, y0 as u32, x0 as u32, y0 as u32],
                ..Default::default()
            };
            let mut q = VecDeque::from([(x0, y0)]);
            seen[y0 * w + x0] = true;
            while let Some((x, y)) = q.pop_front() {
                let (xu, yu) = (x as u64, y as u64);
                c.count += 1;
                c.sum_x += xu;
                c.sum_y += yu;
                c.sum_xx += xu * xu;
                c.sum_xy += xu * yu;
                c.sum_yy += yu * yu;
                c.bbox = [
                    c.bbox[0].min(x as u32),
                    c.bbox[1].min(y as u32),
                    c.bbox[2].max(x as u32),
                    c.bbox[3].max(y as u32),
                ];
                for dy in -1i64..=1 {
                    for dx in -1i64..=1 {
                        if !eight && dx != 0 && dy != 0 {
                            continue;
                        }
                        let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                        if nx < 0 || ny < 0 || nx >= w as i64 || ny >= h as i64 {
                            continue;
                        }
                        let (nx, ny) = (nx as usize, ny as usize);
                        if mask.get(nx, ny) && !seen[ny * w + nx] {
                            seen[ny * w + nx] = true;
                            q.push_back((nx, ny));
                        }
                    }
                }
            }
            out.push(c);
        }
    }
    out
}

fn check(mask: &Mask) {
    let mut l = Labeler::new(mask.width(), mask.height());
    let got = l.label(mask).unwrap().to_vec();
    let want = flood_fill(mask);
    assert_eq!(got, want, "mask {}×{}", mask.width(), mask.height());
    // Runs cover exactly the set pixels, each tagged with its component.
    let total: u64 = l.runs().iter().map(|r| (r.x1 - r.x0) as u64).sum();
    assert_eq!(total, mask.count() as u64);
    // Re-labelling with the same labeller gives the same answer (buffers reused).
    assert_eq!(l.label(mask).unwrap(), &want[..]);
}

fn mask_from(w: usize, h: usize, mut f: impl FnMut(usize, usize) -> bool) -> Mask {
    let mut m = Mask::new(w, h);
    for y in 0..h {
        for x in 0..w {
            m.set(x, y, f(x, y));
        }
    }
    m
}

fn spiral(n: usize) -> Mask {
    let mut m = Mask::new(n, n);
    let (mut x0, mut y0, mut x1, mut y1) = (0i64, 0i64, n as i64 - 1, n as i64 - 1);
    while x0 <= x1 && y0 <= y1 {
        for x in x0..=x1 {
            m.set(x as usize, y0 as usize, true);
        }
        for y in y0..=y1 {
            m.set(x1 as usize, y as usize, true);
        }
        for x in x0..=x1 {
            m.set(x as usize, y1 as usize, true);
        }
        for y in y0 + 2..=y1 {
            m.set(x0 as usize, y as usize, true);
        }
        if x0 + 2 <= x1 {
            m.set((x0 + 1) as usize, (y0 + 2) as usize, true);
        }
        x0 += 2;
        y0 += 2;
        x1 -= 2;
        y1 -= 2;
    }
    m
}

#[test]
fn worst_cases() {
    for (w, h) in [(1, 1), (1, 9), (9, 1), (8, 8), (17, 13), (64, 48)] {
        check(&mask_from(w, h, |x, y| (x + y) % 2 == 0)); // checkerboard: one 8-connected blob
        check(&mask_from(w, h, |x, y| (x % 2 == 0) && (y % 2 == 0))); // isolated dots
        check(&mask_from(w, h, |_, _| true));
        check(&mask_from(w, h, |_, _| false));
        check(&mask_from(w, h, |x, _| x % 2 == 0)); // one-pixel vertical lines
        check(&mask_from(w, h, |_, y| y % 2 == 0)); // one-pixel horizontal lines
        check(&mask_from(w, h, |x, y| x == y || x + y == w)); // diagonals crossing
        check(&mask_from(w, h, |x, y| (x / 3 + y) % 2 == 0)); // staircases
    }
    for n in [5, 12, 31, 40] {
        check(&spiral(n));
    }
    // All components of a checkerboard with 4-gaps: 8-connectivity must join diagonals.
    let m = mask_from(6, 6, |x, y| (x + y) % 2 == 0);
    let mut l = Labeler::new(6, 6);
    assert_eq!(l.label(&m).unwrap().len(), 1);
}

#[test]
fn label_order_is_raster_order_of_first_pixel() {
    // A "U": its right arm starts a run before the join, but its first pixel is top-left.
    let m = mask_from(7, 4, |x, y| x == 0 || x == 6 || y == 3 || (x == 3 && y == 0));
    let mut l = Labeler::new(7, 4);
    let comps = l.label(&m).unwrap();
    assert_eq!(comps.len(), 2);
    assert_eq!(comps[0].bbox, [0, 0, 6, 3]);
    assert_eq!(comps[1].bbox, [3, 0, 3, 0]);
}

#[test]
fn sizes_are_checked() {
    let mut l = Labeler::new(4, 4);
    assert!(l.label(&Mask::new(4, 5)).is_err());
}

#[test]
fn moments_of_a_filled_rectangle() {
    let m = mask_from(20, 10, |x, y| (4..14).contains(&x) && (2..6).contains(&y));
    let mut l = Labeler::new(20, 10);
    let c = l.label(&m).unwrap()[0];
    assert_eq!(c.count, 40);
    assert_eq!(c.centroid(), (8.5, 3.5));
    let (mu20, mu02, mu11) = c.central_moments();
    assert!(
        (mu20 - (100.0 - 1.0) / 12.0).abs() < 1e-9 && (mu02 - (16.0 - 1.0) / 12.0).abs() < 1e-9 && mu11.abs() < 1e-9
    );
    assert_eq!((c.width(), c.height()), (10, 4));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 3000, ..ProptestConfig::default() })]

    #[test]
    fn random_masks_match_flood_fill(
        w in 1usize..40,
        h in 1usize..40,
        density in 0.0f64..1.0,
        seed in any::<u64>(),
    ) {
        let m = random_mask(w, h, density, seed);
        check(&m);
    }
}

/// A `w` × `h` mask with each pixel set with probability `density` (xorshift from `seed`).
fn random_mask(w: usize, h: usize, density: f64, seed: u64) -> Mask {
    let mut s = seed | 1;
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        s
    };
    let threshold = (density * u64::MAX as f64) as u64;
    mask_from(w, h, |_, _| next() < threshold)
}

/// `mask` with every pixel outside the inclusive box `b` cleared.
fn cropped(mask: &Mask, b: [u32; 4]) -> Mask {
    let inside = |x: usize, y: usize| {
        (b[0] as usize..=b[2] as usize).contains(&x) && (b[1] as usize..=b[3] as usize).contains(&y)
    };
    mask_from(mask.width(), mask.height(), |x, y| inside(x, y) && mask.get(x, y))
}

/// `label_box` against the flood fill of the mask cleared outside the box, both
/// connectivities; and every box component clear of the box's border is one of the whole
/// frame's components, statistics and all (what the circle detector relies on).
fn check_box(mask: &Mask, b: [u32; 4]) {
    let (w, h) = mask.size();
    for eight in [true, false] {
        let new = |w, h| {
            if eight {
                Labeler::new(w, h)
            } else {
                Labeler::new_four_connected(w, h)
            }
        };
        let mut l = new(w, h);
        let got = l.label_box(mask, b).unwrap().to_vec();
        assert_eq!(
            got,
            flood_fill_with(&cropped(mask, b), eight),
            "eight {eight} box {b:?}"
        );
        for r in l.runs() {
            assert!(
                r.x0 >= b[0] && r.x1 <= b[2] + 1 && r.y >= b[1] && r.y <= b[3],
                "{r:?} outside {b:?}"
            );
        }
        let mut whole = new(w, h);
        let all = whole.label(mask).unwrap();
        for c in &got {
            if c.bbox[0] > b[0] && c.bbox[1] > b[1] && c.bbox[2] < b[2] && c.bbox[3] < b[3] {
                assert!(
                    all.contains(c),
                    "eight {eight}: {c:?} of box {b:?} is no whole-frame component"
                );
            }
        }
        for c in all {
            if c.bbox[0] > b[0] && c.bbox[1] > b[1] && c.bbox[2] < b[2] && c.bbox[3] < b[3] {
                assert!(
                    got.contains(c),
                    "eight {eight}: {c:?} inside {b:?} was not found in the box"
                );
            }
        }
    }
}

#[test]
fn boxes_at_the_edges_and_beyond() {
    let m = mask_from(17, 13, |x, y| (x / 3 + y) % 2 == 0 || x == y);
    for b in [
        [0, 0, 16, 12],
        [0, 0, 0, 0],
        [16, 12, 16, 12],
        [3, 2, 40, 40],
        [5, 5, 4, 9],
        [2, 3, 9, 3],
    ] {
        check_box(&m, b);
    }
    let mut l = Labeler::new(17, 13);
    assert!(
        l.label_box(&m, [20, 0, 30, 5]).unwrap().is_empty(),
        "a box off the mask"
    );
    assert!(l.label_box(&Mask::new(4, 4), [0, 0, 3, 3]).is_err());
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1500, ..ProptestConfig::default() })]

    #[test]
    fn boxes_match_the_flood_fill_of_the_cropped_mask(
        w in 1usize..40,
        h in 1usize..30,
        density in 0.0f64..1.0,
        seed in any::<u64>(),
        corners in any::<[u8; 4]>(),
    ) {
        let m = random_mask(w, h, density, seed);
        let (xa, xb) = (corners[0] as u32 % w as u32, corners[1] as u32 % w as u32);
        let (ya, yb) = (corners[2] as u32 % h as u32, corners[3] as u32 % h as u32);
        check_box(&m, [xa.min(xb), ya.min(yb), xa.max(xb), ya.max(yb)]);
    }
}
