//! `KrawlerStateSchema` (seed 003): all ten degrees of freedom from a short rendered
//! belly-fisheye sequence with sensor noise and a known state trajectory, each checked
//! against the truth; a marker hidden by mud is reported missing and its axle's values
//! are held and flagged, never guessed; and the same frames and seed give the same
//! estimates bit for bit; and the camera's shake on its mount is measured from the plate
//! markers and compensated.

use crate::common;

use common::krawler::{Rig, axles, draw};
use marsupial::perception::RgbImage;
use marsupial::perception::krawler::{
    KrawlerEstimate, KrawlerParams, KrawlerStateSchema, MountParams, SteeringPoly, fit_mount,
};
use marsupial::sim::krawler::{GearExtras, KrawlerState, build, build_with, expected_markers};
use marsupial::sim::krawler_sequence::shaken;
use marsupial::sim::lighting::LightState;
use marsupial::sim::render::{CameraPose, Renderer, SensorParams};
use marsupial::sim::rng::Rng;
use nalgebra::Rotation3;

fn schema(rig: &Rig) -> KrawlerStateSchema {
    schema_with(rig, KrawlerParams::default())
}

fn schema_with(rig: &Rig, params: KrawlerParams) -> KrawlerStateSchema {
    let cam = &rig.profile.cameras[0];
    KrawlerStateSchema::new(
        (cam.width_px, cam.height_px),
        rig.geometry.clone(),
        rig.layout,
        SteeringPoly::from_profile(&rig.profile).expect("calibrated"),
        params,
        expected_markers(&rig.profile, &rig.rest).unwrap(),
        axles(&rig.rest),
    )
}

/// A trajectory through every degree of freedom: both axles rolling and bobbing out of
/// phase, the two axles steering through ±23° and ±17°, the wheels turning at their own
/// speeds, two of them backwards.
fn trajectory(rest: &KrawlerState, t: f64) -> KrawlerState {
    KrawlerState {
        roll: [0.08 * (0.2 * t).sin(), -0.07 * (0.25 * t + 1.0).sin()],
        drop: [
            rest.drop[0] + 0.012 * (0.15 * t).sin(),
            rest.drop[1] - 0.01 * (0.18 * t + 0.5).sin(),
        ],
        steer: [0.4 * (0.1 * t).sin(), -0.3 * (0.12 * t).sin()],
        wheel: [0.08, 0.07, -0.06, -0.1].map(|w| 1.3 + w * t),
    }
}

fn run(rig: &Rig, frames: &[RgbImage], seed: u64) -> Vec<KrawlerEstimate> {
    let mut s = schema(rig);
    let mut rng = Rng::new(seed);
    frames
        .iter()
        .map(|f| s.estimate(&f.view(), draw(&mut rng)).unwrap())
        .collect()
}

#[test]
fn every_degree_of_freedom_tracks_a_rendered_sequence() {
    let mut rig = Rig::new(SensorParams::default(), 21);
    let truth: Vec<KrawlerState> = (0..30).map(|t| trajectory(&rig.rest, t as f64)).collect();
    let frames: Vec<RgbImage> = truth
        .iter()
        .map(|s| {
            let mut im = RgbImage::default();
            rig.render(s, &mut im);
            im
        })
        .collect();
    let est = run(&rig, &frames, 4);
    let mut err = [0.0f64; 10];
    let mut worst = [0.0f64; 10];
    let mut invalid = [0usize; 10];
    for (t, (e, s)) in est.iter().zip(&truth).enumerate() {
        let pairs = [
            (e.roll[0], s.roll[0]),
            (e.roll[1], s.roll[1]),
            (e.drop[0], s.drop[0]),
            (e.drop[1], s.drop[1]),
            (e.steer[0], s.steer[0]),
            (e.steer[1], s.steer[1]),
        ];
        for (i, (dof, want)) in pairs.into_iter().enumerate() {
            if !dof.valid {
                invalid[i] += 1;
                continue;
            }
            let d = (dof.value - want).abs();
            err[i] += d;
            worst[i] = worst[i].max(d);
        }
        for k in 0..4 {
            if t > 0 && !e.wheel[k].valid {
                invalid[6 + k] += 1;
            }
            // θ counts from the first frame.
            let d = (e.wheel[k].value - (s.wheel[k] - truth[0].wheel[k])).abs();
            err[6 + k] += d;
            worst[6 + k] = worst[6 + k].max(d);
        }
    }
    let n = est.len() as f64;
    let names = [
        "roll F", "roll R", "drop F", "drop R", "steer F", "steer R", "θ FL", "θ FR", "θ RL", "θ RR",
    ];
    for i in 0..10 {
        let (scale, unit) = match i {
            0 | 1 | 4 | 5 => (1f64.to_degrees(), "°"),
            2 | 3 => (1000.0, " mm"),
            _ => (1.0, " rad"),
        };
        println!(
            "{}: MAE {:.3}{unit}, worst {:.3}{unit}, {} invalid",
            names[i],
            err[i] / (n - invalid[i] as f64) * scale,
            worst[i] * scale,
            invalid[i]
        );
    }
    assert_eq!(invalid[..6], [0; 6], "roll, drop and steering measured in every frame");
    // A wheel may coast a frame while its white face fills the observation window.
    assert!(invalid[6..].iter().all(|&n| n <= 2), "{invalid:?}");
    for axle in 0..2 {
        assert!(err[axle] / n < 0.5f64.to_radians(), "roll {axle}");
        assert!(worst[axle] < 1.5f64.to_radians(), "roll {axle}");
        assert!(err[2 + axle] / n < 0.003, "drop {axle}");
        assert!(err[4 + axle] / n < 1.0f64.to_radians(), "steer {axle}");
        assert!(worst[4 + axle] < 3.0f64.to_radians(), "steer {axle}");
    }
    for k in 0..4 {
        assert!(worst[6 + k] < 0.08, "wheel {k}: θ drifted {:.3} rad", worst[6 + k]);
    }
    // Same frames, same seed: the same estimates, bit for bit.
    assert_eq!(run(&rig, &frames, 4), est);
}

/// Mud over the front-left plate marker for ten frames: that marker is missing, the front
/// axle's roll, drop and steering are flagged invalid and hold their last values, the
/// rear axle and the wheels carry on; the front axle is measured again once it clears.
#[test]
fn a_hidden_marker_is_missing_and_its_axle_held_never_guessed() {
    let mut rig = Rig::new(SensorParams::default(), 22);
    let mut s = schema(&rig);
    let mut rng = Rng::new(8);
    let predicted = expected_markers(&rig.profile, &rig.rest).unwrap()[0];
    let mut image = RgbImage::default();
    let mut held = None;
    for t in 0..24 {
        let state = trajectory(&rig.rest, t as f64 * 0.5);
        rig.render(&state, &mut image);
        let muddy = (8..18).contains(&t);
        if muddy {
            let (cx, cy) = (predicted.at[0] as i64, predicted.at[1] as i64);
            for y in cy - 14..=cy + 14 {
                for x in cx - 14..=cx + 14 {
                    image.put(x as usize, y as usize, [96, 80, 64]);
                }
            }
        }
        let e = s.estimate(&image.view(), draw(&mut rng)).unwrap();
        assert!(
            e.roll[1].valid && e.steer[1].valid,
            "frame {t}: the rear axle carries on"
        );
        if t > 0 {
            assert!(e.wheel.iter().all(|w| w.valid), "frame {t}: {:?}", e.wheels);
        }
        if muddy {
            assert!(e.markers.at[0].is_none(), "frame {t}: the hidden marker is missing");
            assert!(!e.roll[0].valid && !e.drop[0].valid && !e.steer[0].valid, "frame {t}");
            let h = held.expect("measured before the mud");
            assert_eq!(
                (e.roll[0].value, e.drop[0].value, e.steer[0].value),
                h,
                "frame {t}: held"
            );
        } else {
            assert!(e.roll[0].valid && e.drop[0].valid && e.steer[0].valid, "frame {t}");
            assert!(
                (e.roll[0].value - state.roll[0]).abs() < 1.5f64.to_radians(),
                "frame {t}"
            );
            held = Some((e.roll[0].value, e.drop[0].value, e.steer[0].value));
        }
    }
}

/// The plate markers of a gear in `state`, projected by a camera at `pose`: front left,
/// front right, rear left, rear right.
fn plate_pixels(rig: &Rig, state: &KrawlerState, pose: &CameraPose) -> [Option<[f64; 2]>; 4] {
    let gear = build(&rig.profile, state).unwrap();
    [0, 1, 4, 5].map(|i| rig.geometry.model.project(&pose.to_camera(&gear.markers[i])))
}

/// The mount fit on exact marker positions, over shakes drawn at random and states across
/// the trajectory: the measurable parts of the shake (yaw, pitch, the forward and the
/// sideways shift) come back, and with them each axle's roll and drop as seen by the
/// shaken camera, far better than reading the same pixels with the nominal mount.
#[test]
fn the_mount_fit_recovers_the_measurable_shake_from_exact_markers() {
    let rig = Rig::new(SensorParams::default(), 23);
    let mut rng = Rng::new(31);
    let params = MountParams::default();
    let (mut yaw, mut pitch, mut tx) = (0.0f64, 0.0f64, 0.0f64);
    let (mut fitted_roll, mut nominal_roll) = (0.0f64, 0.0f64);
    let mut frame_geometry = rig.geometry.clone();
    let n = 40;
    for i in 0..n {
        let state = trajectory(&rig.rest, i as f64 * 2.0);
        let pose = shaken(&rig.pose, 0.5, 2.0, &mut rng);
        let truth = Rotation3::from_matrix(&(pose.rotation * rig.pose.rotation.transpose())).scaled_axis();
        let shift = pose.position - rig.pose.position;
        let px = plate_pixels(&rig, &state, &pose);
        let fit = fit_mount(
            &rig.geometry,
            px,
            [(0.0, rig.rest.drop[0]), (0.0, rig.rest.drop[1])],
            rig.layout.marker_half_spacing,
            &params,
        )
        .expect("four markers");
        yaw = yaw.max((fit.rotation.z - truth.z).abs());
        pitch = pitch.max((fit.rotation.y - truth.y).abs());
        tx = tx.max((fit.translation.x - shift.x).abs());
        fit.apply(&rig.geometry, &mut frame_geometry);
        let [fl, fr, _, _] = px.map(Option::unwrap);
        let with = frame_geometry.axle_pose(0, fl, fr).unwrap();
        let without = rig.geometry.axle_pose(0, fl, fr).unwrap();
        fitted_roll += (with.roll - state.roll[0]).abs();
        nominal_roll += (without.roll - state.roll[0]).abs();
    }
    println!(
        "worst yaw {:.3}°, pitch {:.3}°, forward shift {:.2} mm; front roll MAE {:.3}° fitted, {:.3}° nominal",
        yaw.to_degrees(),
        pitch.to_degrees(),
        tx * 1000.0,
        (fitted_roll / n as f64).to_degrees(),
        (nominal_roll / n as f64).to_degrees()
    );
    assert!(yaw < 0.05f64.to_radians(), "yaw {}", yaw.to_degrees());
    assert!(fitted_roll < 0.7 * nominal_roll, "{fitted_roll} vs {nominal_roll}");
    // Compensation off: no offset.
    let off = MountParams {
        enabled: false,
        ..params
    };
    let px = plate_pixels(&rig, &rig.rest, &rig.pose);
    assert!(fit_mount(&rig.geometry, px, [(0.0, 0.2); 2], 0.1, &off).is_none());
}

/// A rendered sequence with the camera shaken by 0.5° and 2 mm (SD) every frame: with
/// the compensation the wheels keep their count and roll and steering stay close; read
/// with the nominal mount (the paper's way) the shake between frames reads as wheel
/// rotation and θ runs away.
#[test]
fn mount_shake_is_compensated_on_rendered_frames() {
    let mut rig = Rig::new(SensorParams::default(), 24);
    let base = rig.pose;
    let mut rng = Rng::new(41);
    let truth: Vec<KrawlerState> = (0..40).map(|t| trajectory(&rig.rest, t as f64 * 0.3)).collect();
    let frames: Vec<RgbImage> = truth
        .iter()
        .map(|s| {
            rig.pose = shaken(&base, 0.5, 2.0, &mut rng);
            let mut im = RgbImage::default();
            rig.render(s, &mut im);
            im
        })
        .collect();
    let errors = |enabled: bool| {
        let mut params = KrawlerParams::default();
        params.mount.enabled = enabled;
        let mut s = schema_with(&rig, params);
        let mut rng = Rng::new(5);
        let (mut roll, mut steer, mut wheel) = (0.0f64, 0.0f64, 0.0f64);
        for (f, t) in frames.iter().zip(&truth) {
            let e = s.estimate(&f.view(), draw(&mut rng)).unwrap();
            roll += (e.roll[0].value - t.roll[0]).abs() + (e.roll[1].value - t.roll[1]).abs();
            steer += (e.steer[0].value - t.steer[0]).abs() + (e.steer[1].value - t.steer[1]).abs();
            for k in 0..4 {
                wheel = wheel.max((e.wheel[k].value - (t.wheel[k] - truth[0].wheel[k])).abs());
            }
        }
        let n = 2.0 * frames.len() as f64;
        (roll.to_degrees() / n, steer.to_degrees() / n, wheel)
    };
    let on = errors(true);
    let off = errors(false);
    println!(
        "compensated: roll {:.3}°, steer {:.3}°, worst θ {:.3} rad",
        on.0, on.1, on.2
    );
    println!(
        "nominal:     roll {:.3}°, steer {:.3}°, worst θ {:.3} rad",
        off.0, off.1, off.2
    );
    assert!(on.0 < 0.8 * off.0, "roll");
    assert!(on.1 < 0.6 * off.1, "steering");
    assert!(on.2 < 0.1 && on.2 < 0.3 * off.2, "wheels");
}

/// The camera mount's thin plates (seed 003 Fig. 3, the `mount_plates` knob) are in view,
/// as slivers toward the fisheye's rim, and cover none of the markers: a frame rendered
/// with them differs from one without (same noise) by a plain number of pixels, none of
/// them near a marker.
#[test]
fn the_mount_plates_are_in_view_but_off_the_markers() {
    let rig = Rig::new(SensorParams::default(), 25);
    let cam = &rig.profile.cameras[0];
    let state = trajectory(&rig.rest, 3.0);
    let render = |mount_plates: bool| {
        let gear = build_with(
            &rig.profile,
            &state,
            &GearExtras {
                mount_plates,
                ..GearExtras::default()
            },
        )
        .unwrap();
        let mut renderer = Renderer::new(rig.geometry.model.clone(), cam.width_px, cam.height_px, 7);
        let mut im = RgbImage::default();
        renderer.render(
            &gear.scene,
            &rig.pose,
            &LightState::uniform(1.0),
            &rig.sensor,
            0,
            &mut im,
        );
        im
    };
    let (plain, plates) = (render(false), render(true));
    let (plain, plates) = (plain.view(), plates.view());
    let markers = expected_markers(&rig.profile, &state).unwrap();
    let mut changed = 0;
    for y in 0..cam.height_px {
        for x in 0..cam.width_px {
            let (a, b) = (plain.get(x, y).unwrap(), plates.get(x, y).unwrap());
            if (0..3).any(|c| a[c].abs_diff(b[c]) > 40) {
                changed += 1;
                for m in &markers {
                    let d = (m.at[0] - x as f64).hypot(m.at[1] - y as f64);
                    assert!(d > 15.0, "a plate pixel ({x}, {y}) {d:.1} px from a marker");
                }
            }
        }
    }
    println!("the plates change {changed} pixels");
    assert!(changed > 200, "the plates are in view: {changed} pixels");
}
