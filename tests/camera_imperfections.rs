//! The camera's imperfections measured on rendered frames against their stated models: a
//! turning camera blurs a vertical edge by f·ω·T (T following the exposure), a rolling
//! shutter skews it by f·ω·readout over the frame, a near edge is defocused by the thin
//! lens's circle of confusion and a far one is not, the corner of a flat field receives
//! the stated vignetting (before auto-exposure, which then brightens the centre), and the
//! whole chain is deterministic.

use marsupial::perception::RgbImage;
use marsupial::perception::camera_model::{CameraModel, Pinhole};
use marsupial::sim::lighting::LightState;
use marsupial::sim::render::{CameraMotion, CameraPose, Defocus, Renderer, SensorParams};
use marsupial::sim::scene::{Material, Prim, Scene, Shape, Tag, srgb_to_linear};
use nalgebra::{Matrix3, Point3, Vector3};

const W: usize = 160;
const H: usize = 120;
const F: f64 = 200.0;

fn renderer() -> Renderer {
    let model = CameraModel::Pinhole(Pinhole {
        fx: F,
        fy: F,
        cx: W as f64 / 2.0,
        cy: H as f64 / 2.0,
        k1: 0.0,
        k2: 0.0,
    });
    Renderer::new(model, W, H, 3)
}

/// A camera 1 m above the ground at the origin, looking along world +x: its right is
/// world −y, its down world −z.
fn pose() -> CameraPose {
    CameraPose {
        rotation: Matrix3::from_columns(&[-Vector3::y(), -Vector3::z(), Vector3::x()]),
        position: Point3::new(0.0, 0.0, 1.0),
    }
}

/// A wall facing the camera at distance `d`, light (albedo `bright`) on the image's left
/// half and dark on its right: a vertical edge through the image centre, at one depth.
fn edge_wall(d: f64, bright: f32) -> Scene {
    let half = |y: f64, albedo: f32| {
        Prim::new(
            Shape::Rect {
                centre: Point3::new(d, y, 1.0),
                u: Vector3::z(),
                v: Vector3::y(),
                half: [5.0, 5.0],
            },
            Material::Solid([albedo; 3]),
            Tag::Target,
        )
    };
    Scene {
        prims: vec![half(5.0, bright), half(-5.0, 0.02)],
        ground: Material::Solid([0.0; 3]),
        sky: [0.0; 3],
    }
}

/// A fixed exposure `k` without noise or white balance.
fn sensor(k: f32) -> SensorParams {
    SensorParams {
        exposure: k,
        ..SensorParams::noiseless()
    }
}

fn render(r: &mut Renderer, scene: &Scene, s: &SensorParams, frames: u64) -> RgbImage {
    let mut out = RgbImage::default();
    for k in 0..frames {
        r.render(scene, &pose(), &LightState::uniform(1.0), s, k, &mut out);
    }
    out
}

/// Linear level of the green channel at (x, y).
fn lin(im: &RgbImage, x: usize, y: usize) -> f64 {
    srgb_to_linear(im.view().get(x, y).unwrap()[1] as f32 / 255.0) as f64
}

/// (10 %–90 % width, 50 % position) of the bright-to-dark edge along row `y`, px.
fn edge(im: &RgbImage, y: usize) -> (f64, f64) {
    let (hi, lo) = (lin(im, 2, y), lin(im, W - 3, y));
    let level = |x: usize| (lin(im, x, y) - lo) / (hi - lo);
    // Where the normalised level first falls below `t`, interpolated, at pixel centres.
    let cross = |t: f64| {
        (1..W)
            .find(|&x| level(x) < t)
            .map(|x| {
                let (a, b) = (level(x - 1), level(x));
                x as f64 - 0.5 + (a - t) / (a - b)
            })
            .unwrap()
    };
    (cross(0.1) - cross(0.9), cross(0.5))
}

/// A camera turning left (counter-clockwise seen from above) at `omega` rad/s.
fn yawing(omega: f32) -> CameraMotion {
    // World z is the camera's −y.
    CameraMotion {
        omega: [0.0, -omega, 0.0],
        velocity: [0.0; 3],
    }
}

#[test]
fn a_turning_camera_blurs_a_vertical_edge_by_f_omega_t() {
    let scene = edge_wall(1.0, 0.4);
    let mut r = renderer();
    let still = render(&mut r, &scene, &sensor(1.0), 1);
    let (sharp, centre) = edge(&still, H / 2);
    assert!(sharp < 1.5, "a still camera's edge is sharp: {sharp:.2} px");
    assert!((centre - W as f64 / 2.0).abs() < 0.5, "edge at {centre:.2}");
    let omega = 2.0f32;
    r.set_motion(yawing(omega));
    for k in [1.0f32, 2.0] {
        let s = SensorParams {
            motion_blur: true,
            ..sensor(k)
        };
        // Exposure multiplier k of max_integration 4 at 10 frames a second: T = k/4 × 0.1 s.
        let t = s.exposure_time_s(k);
        assert!((t - k / 40.0).abs() < 1e-6);
        let blurred = render(&mut r, &scene, &s, 1);
        let length = F * omega as f64 * t as f64; // 10 px at k = 1, 20 at k = 2
        let (width, centre) = edge(&blurred, H / 2);
        // A box of length L turns a step into a ramp 0.8·L wide between 10 % and 90 %.
        assert!(
            (width - 0.8 * length).abs() < 1.2,
            "k {k}: edge {width:.2} px wide, predicted {:.2}",
            0.8 * length
        );
        assert!((centre - W as f64 / 2.0).abs() < 0.6, "blur is centred: {centre:.2}");
    }
    // Off, the same motion leaves the frame alone.
    let off = render(&mut r, &scene, &sensor(1.0), 1);
    assert_eq!(off.as_bytes(), still.as_bytes());
}

#[test]
fn a_rolling_shutter_skews_a_vertical_edge_by_the_predicted_slope() {
    let scene = edge_wall(1.0, 0.4);
    let mut r = renderer();
    let (omega, readout) = (2.0f32, 0.03f32);
    r.set_motion(yawing(omega));
    let s = SensorParams {
        rolling_shutter_readout_s: readout,
        ..sensor(1.0)
    };
    let im = render(&mut r, &scene, &s, 1);
    let (top, bottom) = (edge(&im, 10).1, edge(&im, 110).1);
    // Turning left moves the scene right in the image; later (lower) rows see it moved
    // further: f·ω·readout = 12 px over the frame, 10 px over these 100 rows.
    let want = F * omega as f64 * readout as f64 * 100.0 / H as f64;
    assert!(
        (bottom - top - want).abs() < 0.5,
        "skew {:.2} px over 100 rows, predicted {want:.2}",
        bottom - top
    );
    // The middle row is the rendered instant; each row stays sharp without motion blur.
    assert!((edge(&im, H / 2).1 - W as f64 / 2.0).abs() < 0.6);
    assert!(edge(&im, 10).0 < 1.5);
}

#[test]
fn defocus_blurs_a_near_edge_by_the_circle_of_confusion_and_not_a_focused_one() {
    // An 8 mm f/1 lens focused at 1 m (a large aperture, so the test's numbers are well
    // above a pixel): at 0.15 m the circle of confusion is
    // A·f_px·s/(s − F)·|1/s − 1/Z| = 8 mm × 200 × 1.008 × 5.67 ≈ 9.1 px.
    let lens = Defocus {
        focus_m: 1.0,
        f_number: 1.0,
        focal_length_mm: 8.0,
    };
    let s = SensorParams {
        defocus: Some(lens),
        ..sensor(1.0)
    };
    let mut r = renderer();
    let near = render(&mut r, &edge_wall(0.15, 0.4), &s, 1);
    let coc = 0.008 * F * (1.0 / (1.0 - 0.008)) * (1.0 / 0.15 - 1.0);
    // The box standing for the disc is √12/4 of its diameter; its 10–90 ramp 0.8 of that.
    let want = 0.8 * 0.866 * coc;
    let (width, _) = edge(&near, H / 2);
    assert!(
        (width - want).abs() < 1.2,
        "near edge {width:.2} px, predicted {want:.2}"
    );
    let focused = render(&mut r, &edge_wall(1.0, 0.4), &s, 1);
    let (width, _) = edge(&focused, H / 2);
    assert!(width < 1.5, "the focused edge stays sharp: {width:.2} px");
}

/// A flat wall filling the view.
fn flat_wall(albedo: f32) -> Scene {
    let mut s = edge_wall(1.0, albedo);
    s.prims[1].material = Material::Solid([albedo; 3]);
    s
}

#[test]
fn the_corner_of_a_flat_field_is_darker_by_the_stated_vignetting() {
    let scene = flat_wall(0.5);
    let mut r = renderer();
    let s = SensorParams {
        vignetting_corner: 0.6,
        ..sensor(1.0)
    };
    let im = render(&mut r, &scene, &s, 1);
    let centre = lin(&im, W / 2, H / 2);
    let corner = lin(&im, 0, 0);
    // The corner pixel's centre is half a pixel in from the corner: 0.6 to within 1 %,
    // plus the 8-bit output's rounding.
    assert!(
        (corner / centre - 0.6).abs() < 0.015,
        "corner/centre {:.3}",
        corner / centre
    );
    assert!((centre - 0.5).abs() < 0.01, "centre {centre:.3}");
    // The falloff is applied before auto-exposure: metering the darkened field, the
    // exposure rises and the centre comes out brighter than without vignetting.
    let auto = |corner: f32| {
        let s = SensorParams {
            auto_exposure: true,
            vignetting_corner: corner,
            ..SensorParams::noiseless()
        };
        let mut r = renderer();
        let im = render(&mut r, &scene, &s, 30);
        lin(&im, W / 2, H / 2)
    };
    let (plain, vignetted) = (auto(1.0), auto(0.6));
    assert!(vignetted > plain * 1.15, "centre {vignetted:.3} vs {plain:.3}");
}

#[test]
fn every_effect_at_once_is_deterministic_and_changes_the_frame() {
    let all = SensorParams {
        motion_blur: true,
        rolling_shutter_readout_s: 0.03,
        vignetting_corner: 0.65,
        defocus: Some(Defocus {
            focus_m: 1.0,
            f_number: 2.0,
            focal_length_mm: 3.6,
        }),
        jpeg_quality: 80,
        ..SensorParams::default()
    };
    let scene = edge_wall(0.3, 0.4);
    let motion = CameraMotion {
        omega: [0.0, -0.8, 0.02],
        velocity: [0.03, 0.0, -0.1],
    };
    let run = |s: &SensorParams| {
        let mut r = renderer();
        r.set_motion(motion);
        render(&mut r, &scene, s, 5)
    };
    let a = run(&all);
    assert_eq!(a.as_bytes(), run(&all).as_bytes());
    let plain = run(&SensorParams::default());
    assert_ne!(a.as_bytes(), plain.as_bytes());
}
