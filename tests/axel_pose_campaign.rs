//! `marsupial pose-trials` on reduced grids of the shipped campaigns (issue 16): the
//! rendered, noisy stereo pose beats seed 000's figures at 1 and 2 m, the mono pose with
//! the lens model beats the one that ignores the distortion, and with marks covered a
//! camera with at least 5 visible marks is labelled and posed right while one with fewer
//! fails with a typed error and never gives a pose, with or without a false mark beside
//! the module (which may also cost a 5-mark labelling, but never makes a wrong one).
//! `cargo test --release --test cli axel_pose_campaign:: -- --nocapture` prints the tables.

use marsupial::cli::pose_trials::{self, PoseCampaign, PoseRun, is_wrong};
use std::path::Path;

fn load(name: &str) -> pose_trials::LoadedCampaign {
    PoseCampaign::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("scenarios/{name}.toml"))).expect(name)
}

fn tables(l: &pose_trials::LoadedCampaign, recs: &[PoseRun]) {
    let mut t = Vec::new();
    pose_trials::write_tables(&l.campaign, recs, &mut t).unwrap();
    eprintln!("{}", String::from_utf8_lossy(&t));
}

#[test]
fn stereo_beats_the_paper_at_1_and_2_m_and_the_lens_model_beats_the_pinhole() {
    let mut l = load("axel-pose");
    l.campaign.pose.distances_m = vec![1.0, 2.0];
    l.campaign.pose.alpha_deg = vec![-20.0];
    l.campaign.pose.turn_deg = vec![0.0];
    l.campaign.pose.noise_seeds = 1;
    assert_eq!(l.campaign.pose.jpeg_quality, Some(vec![0, 80]));
    let recs = pose_trials::run_campaign(&l, 2, None, &|_| {}).expect("campaign");
    tables(&l, &recs);
    assert_eq!(recs.len(), 4);
    let (mut lens, mut pin) = (0.0, 0.0);
    for r in &recs {
        let s = &r.stereo;
        // JPEG breaks the marks' detection at 1 m (README): there the pose may be missing,
        // but never wrong.
        if r.jpeg_quality > 0 && r.distance_m < 1.5 {
            assert!(!is_wrong(s, r.distance_m), "run {}: {s:?}", r.index);
            continue;
        }
        let (bound_m, bound_deg) = if r.distance_m < 1.5 {
            (0.0256, 2.5)
        } else {
            (0.0412, 4.58)
        };
        assert!(s.found, "run {}: no stereo pose: {:?}", r.index, s.message);
        let (e, h) = (s.position_err_m.unwrap(), s.heading_err_deg.unwrap());
        assert!(e < bound_m && h < bound_deg, "run {}: {e:.4} m, {h:.2}°", r.index);
        for k in &r.cameras {
            assert_eq!(k.labelling.mislabelled, 0, "run {}", r.index);
            if k.mono.found && k.mono_pinhole.found {
                lens += k.mono.position_err_m.unwrap();
                pin += k.mono_pinhole.position_err_m.unwrap();
            }
        }
    }
    assert!(
        lens > 0.0 && pin > 2.0 * lens,
        "mono position error summed: lens model {lens:.4} m, pin-hole {pin:.4} m"
    );
}

#[test]
fn fewer_than_5_visible_marks_never_give_a_pose_and_5_or_more_give_the_right_one() {
    let mut l = load("axel-occlusion");
    l.campaign.pose.distances_m = vec![3.0];
    l.campaign.pose.alpha_deg = vec![0.0];
    let o = l.campaign.occlusion.as_mut().expect("[occlusion]");
    o.hidden = vec![3, 4];
    let recs = pose_trials::run_campaign(&l, 2, None, &|_| {}).expect("campaign");
    tables(&l, &recs);
    assert_eq!(recs.len(), 4, "two hidden counts, without and with the false mark");
    for r in &recs {
        assert_eq!(r.hidden.len(), if r.index < 2 { 3 } else { 4 });
        assert_eq!(r.decoy, r.index % 2 == 1);
        for (c, k) in r.cameras.iter().enumerate() {
            let at = format!("run {} camera {c} ({} visible, decoy {})", r.index, k.visible, r.decoy);
            assert_eq!(k.visible, 8 - r.hidden.len(), "{at}");
            // Whatever is labelled is labelled right, and no pose is wrong.
            assert_eq!(k.labelling.mislabelled, 0, "{at}");
            assert!(!is_wrong(&k.mono, r.distance_m), "{at}: {:?}", k.mono);
            // From 5 marks, with or without the false mark beside them, it keeps working.
            if k.visible >= 5 {
                assert!(k.labelling.found, "{at}: {:?}", k.labelling);
                assert!(k.mono.found, "{at}: {:?}", k.mono);
            }
            if k.visible < 5 {
                assert!(!k.labelling.found, "{at}: labelled {:?}", k.labelling);
                assert!(!k.mono.found && k.mono.error.is_some(), "{at}: {:?}", k.mono);
            }
        }
        assert!(!is_wrong(&r.stereo, r.distance_m), "run {}: {:?}", r.index, r.stereo);
        if r.cameras.iter().any(|k| k.visible < 5) {
            assert!(
                !r.stereo.found && r.stereo.error.is_some(),
                "run {}: {:?}",
                r.index,
                r.stereo
            );
        } else {
            assert!(r.stereo.found, "run {}: {:?}", r.index, r.stereo);
        }
    }
}

/// The paper's hard case (seed 000 §V-D): a false mark painted among the marks
/// (`scenarios/axel-false-mark.toml`). Beside 5 true marks it is left unlabelled and the
/// pose is right; with 4 true marks ours refuses, never labelling the false one.
#[test]
fn a_false_mark_among_the_marks_is_never_labelled() {
    let mut l = load("axel-false-mark");
    l.campaign.pose.distances_m = vec![2.0];
    l.campaign.pose.alpha_deg = vec![0.0, 25.0];
    l.campaign.occlusion.as_mut().expect("[occlusion]").hidden = vec![3, 4];
    let recs = pose_trials::run_campaign(&l, 2, None, &|_| {}).expect("campaign");
    tables(&l, &recs);
    assert_eq!(recs.len(), 8);
    for r in recs.iter().filter(|r| r.decoy) {
        for (c, k) in r.cameras.iter().enumerate() {
            let at = format!("run {} camera {c} ({} visible)", r.index, k.visible);
            assert_eq!(k.detected, k.visible + 1, "{at}: the false mark is detected");
            assert_eq!(k.labelling.mislabelled, 0, "{at}");
            assert!(!is_wrong(&k.mono, r.distance_m), "{at}: {:?}", k.mono);
            if k.visible >= 5 {
                assert_eq!(k.labelling.inliers, k.visible, "{at}: {:?}", k.labelling);
            } else {
                assert!(!k.labelling.found, "{at}: {:?}", k.labelling);
            }
        }
    }
}

#[test]
fn the_records_are_the_same_bytes_whatever_the_jobs() {
    let mut l = load("axel-occlusion");
    l.campaign.pose.distances_m = vec![2.0];
    l.campaign.pose.alpha_deg = vec![25.0];
    l.campaign.occlusion.as_mut().unwrap().hidden = vec![1];
    let json = |jobs| {
        pose_trials::run_campaign(&l, jobs, None, &|_| {})
            .unwrap()
            .iter()
            .map(|r| serde_json::to_string(r).unwrap())
            .collect::<Vec<_>>()
    };
    let (a, b) = (json(1), json(2));
    assert_eq!(a.len(), 2);
    assert_eq!(a, b);
}
