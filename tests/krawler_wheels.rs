//! The wheel stage of the AutoKrawler's estimator (`perception::krawler::rotation`, seed
//! 003 §V-C) on rendered belly-fisheye frames with sensor noise: each wheel's step
//! between frames against the simulator's truth at several speeds, both directions and
//! several roll, drop and steering states; and the white correction marker snapping θ
//! back after an error of either sign, whichever way the wheels turn.

use crate::common;

use common::krawler::{Rig, axles, draw};
use marsupial::perception::RgbImage;
use marsupial::perception::krawler::{WheelParams, WheelTracker};
use marsupial::sim::krawler::KrawlerState;
use marsupial::sim::render::SensorParams;
use marsupial::sim::rng::Rng;
use std::f64::consts::{PI, TAU};

fn tracker(rig: &Rig) -> WheelTracker {
    let cam = &rig.profile.cameras[0];
    WheelTracker::new(cam.width_px, cam.height_px, rig.layout, WheelParams::default())
}

/// Six frames per case; every wheel turns at its own speed (the case's speed times 1,
/// 0.9, 1.1, 0.95), from starting angles away from the white face. The steps measured
/// from the second frame on are compared with the truth. Prints the figures.
#[test]
fn wheel_steps_match_the_truth_at_several_speeds_directions_and_axle_states() {
    let mut rig = Rig::new(SensorParams::default(), 3);
    let rest = rig.rest;
    let states = [
        ("rest", rest),
        (
            "steered",
            KrawlerState {
                steer: [0.35, -0.25],
                ..rest
            },
        ),
        (
            "rolled, dropped and steered",
            KrawlerState {
                roll: [0.1, -0.08],
                drop: [rest.drop[0] - 0.02, rest.drop[1] + 0.015],
                steer: [-0.2, 0.3],
                ..rest
            },
        ),
    ];
    let mut rng = Rng::new(7);
    let mut image = RgbImage::default();
    let (mut sum, mut n, mut worst, mut lost) = (0.0, 0usize, 0.0f64, 0usize);
    for (name, base) in states {
        for speed in [0.04, 0.1, -0.07, -0.15] {
            let rate = [1.0, 0.9, 1.1, 0.95].map(|f| f * speed);
            let mut t = tracker(&rig);
            let (mut case_sum, mut case_n) = (0.0, 0);
            for frame in 0..6 {
                let state = KrawlerState {
                    wheel: [0, 1, 2, 3].map(|k| 1.0 + k as f64 + rate[k] * frame as f64),
                    ..base
                };
                rig.render(&state, &mut image);
                let steps = t.update(&image.view(), &rig.geometry, &axles(&state), draw(&mut rng));
                if frame == 0 {
                    assert!(steps.iter().all(|s| s.step.is_none()), "no step on the first frame");
                    continue;
                }
                for (k, s) in steps.iter().enumerate() {
                    let Some(step) = s.step else {
                        lost += 1;
                        continue;
                    };
                    let e = (step - rate[k]).abs();
                    assert!(
                        e < 0.015,
                        "{name}, speed {speed}, frame {frame}, wheel {k}: step {step:.4} vs {:.4} ({s:?})",
                        rate[k]
                    );
                    sum += e;
                    case_sum += e;
                    n += 1;
                    case_n += 1;
                    worst = worst.max(e);
                }
            }
            println!(
                "{name}, {speed:+.2} rad/frame: step MAE {:.4} rad over {case_n} steps",
                case_sum / case_n.max(1) as f64
            );
        }
    }
    let mae = sum / n as f64;
    println!("wheel steps: MAE {mae:.4} rad, worst {worst:.4} rad, {n} measured, {lost} lost");
    assert!(lost * 20 <= n, "{lost} steps lost of {}", n + lost);
    assert!(mae < 0.002, "MAE {mae:.4} rad");
}

/// Each wheel turns 1.4 turns at 0.1 rad a frame (1.7 times the top speed), either way, from just before its white
/// face reaches the observation window (the first pass sets c₀). Midway, each θ is
/// knocked off by ±0.5 rad (as a run of lost frames would); after the white face's
/// second pass θ is back within 0.06 rad of the truth, for both signs of the error and
/// both directions. Without the marker the error would stay.
#[test]
fn the_white_marker_snaps_theta_back_once_per_turn_whichever_way_it_turns() {
    let mut rig = Rig::new(SensorParams::default(), 5);
    let rest = rig.rest;
    let mut rng = Rng::new(9);
    let mut image = RgbImage::default();
    let step = 0.1;
    // The window sits 60° up the wheel on the side facing the camera: the front wheels'
    // back (φ = −30°), the rear wheels' front (+30°); the white face is centred on it
    // when θ ≡ φ.
    let window_phi = [-PI / 6.0, -PI / 6.0, PI / 6.0, PI / 6.0];
    let knock = [0.5, -0.5, -0.5, 0.5];
    let frames = (1.4 * TAU / step) as usize;
    for dir in [1.0, -1.0] {
        let start = window_phi.map(|p| p - dir * 0.7);
        let mut t = tracker(&rig);
        let mut corrections = [0usize; 4];
        let mut before = [0.0f64; 4];
        for frame in 0..frames {
            let state = KrawlerState {
                wheel: [0, 1, 2, 3].map(|k| start[k] + dir * step * frame as f64),
                steer: [0.1, -0.1],
                ..rest
            };
            if frame == frames / 2 {
                // The frame that follows has no predecessor: its step is added here.
                let theta = t.theta();
                t.restart([0, 1, 2, 3].map(|k| theta[k] + dir * step + knock[k]));
            }
            rig.render(&state, &mut image);
            let out = t.update(&image.view(), &rig.geometry, &axles(&state), draw(&mut rng));
            let theta = t.theta();
            for k in 0..4 {
                let err = theta[k] - dir * step * frame as f64;
                if out[k].correction != 0.0 {
                    corrections[k] += 1;
                    println!(
                        "dir {dir:+}, wheel {k}, frame {frame}: corrected by {:+.3} rad, error {before:+.3} → {err:+.3}",
                        out[k].correction,
                        before = before[k]
                    );
                }
                before[k] = err;
            }
        }
        for k in 0..4 {
            assert_eq!(corrections[k], 1, "dir {dir}, wheel {k}: one correction after c₀");
            assert!(
                before[k].abs() < 0.06,
                "dir {dir}, wheel {k}: final error {:.3} rad",
                before[k]
            );
        }
    }
}

/// Pyramids built only around the observation windows (the default) give bit for bit
/// the steps, features, tracks and θ of pyramids over the whole frame, at the fastest
/// speed of the tests above in both directions, with the axles rolling, dropping and
/// steering from frame to frame so that the windows move.
#[test]
fn pyramids_around_the_windows_give_the_whole_frames_results() {
    let mut rig = Rig::new(SensorParams::default(), 11);
    let rest = rig.rest;
    let cam = &rig.profile.cameras[0];
    let (w, h) = (cam.width_px, cam.height_px);
    let whole_params = WheelParams {
        pyramid_margin_px: None,
        ..WheelParams::default()
    };
    assert!(WheelParams::default().pyramid_margin_px.is_some());
    let mut image = RgbImage::default();
    for speed in [0.15, -0.15] {
        let mut windowed = tracker(&rig);
        let mut whole = WheelTracker::new(w, h, rig.layout, whole_params);
        let (mut rng_a, mut rng_b) = (Rng::new(3), Rng::new(3));
        let mut measured = 0;
        for frame in 0..6 {
            let f = frame as f64;
            let state = KrawlerState {
                wheel: [0, 1, 2, 3].map(|k| 0.5 + k as f64 + speed * f),
                roll: [0.02 * f, -0.015 * f],
                drop: [rest.drop[0] - 0.003 * f, rest.drop[1] + 0.002 * f],
                steer: [0.05 * f, -0.04 * f],
            };
            rig.render(&state, &mut image);
            let a = windowed.update(&image.view(), &rig.geometry, &axles(&state), draw(&mut rng_a));
            let b = whole.update(&image.view(), &rig.geometry, &axles(&state), draw(&mut rng_b));
            assert_eq!(a, b, "speed {speed}, frame {frame}");
            assert_eq!(windowed.theta(), whole.theta());
            measured += a.iter().filter(|s| s.step.is_some()).count();
        }
        assert!(measured >= 16, "speed {speed}: only {measured} steps measured");
    }
}
