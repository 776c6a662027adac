//! The `krawler` robot kind from its profile, without the simulator: the shipped
//! AutoKrawler builds, its gear is read from `[robot.gear]` strictly (a misspelt or
//! out-of-range field names its line, never a panic), the tree's leaves refuse bad params
//! by field, and a scripted tick runs the estimator as the memory's perceptual schema.

use marsupial::behaviors::BuildError;
use marsupial::behaviors::catalog::shipped;
use marsupial::behaviors::krawler::{Krawler, gear_spec};
use marsupial::perception::{GearSpec, RgbImage};
use marsupial::profile::Profile;
use marsupial::schemas::{Agent, Behavior, CameraInput, Inputs, Mission};
use std::path::Path;

fn source() -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/autokrawler.toml")).unwrap()
}

fn profile(src: &str) -> Profile {
    Profile::parse(src, Path::new("autokrawler.toml")).unwrap()
}

/// The first problem of a robot that must not build: (path, line, message).
fn refused(src: &str) -> (String, Option<usize>, String) {
    let e = match shipped().agent(&profile(src)) {
        Ok(_) => panic!("must not build"),
        Err(BuildError::Invalid(e) | BuildError::Tree(e)) => e,
        Err(e) => panic!("{e}"),
    };
    let p = &e.problems()[0];
    (p.path.clone(), p.line, p.message.clone())
}

#[test]
fn the_shipped_autokrawler_builds_with_its_profiles_gear() {
    let src = source();
    assert!(shipped().agent(&profile(&src)).is_ok());
    assert_eq!(gear_spec(&profile(&src)).unwrap(), GearSpec::default());
    let wider = src.replace("tread_width_m = 0.08", "tread_width_m = 0.1");
    assert_eq!(gear_spec(&profile(&wider)).unwrap().tread_width_m, 0.1);
    // Without [robot.gear] at all, the documented defaults.
    let start = src.find("[robot.gear]").unwrap();
    let end = src[start..].find("\n\n").unwrap() + start;
    let bare = format!("{}{}", &src[..start], &src[end..]);
    assert_eq!(gear_spec(&profile(&bare)).unwrap(), GearSpec::default());
}

#[test]
fn a_bad_gear_field_names_its_line() {
    let src = source();
    let line_of = |needle: &str| src.lines().position(|l| l.starts_with(needle)).unwrap() + 1;
    let (path, line, _) = refused(&src.replace("tread_width_m = 0.08", "tread_widht_m = 0.08"));
    assert_eq!(path, "robot.gear.tread_widht_m");
    assert_eq!(line, Some(line_of("tread_width_m")));
    let (path, line, message) = refused(&src.replace("steering_arm_m = 0.09", "steering_arm_m = -0.09"));
    assert_eq!(
        (path.as_str(), line),
        ("robot.gear.steering_arm_m", Some(line_of("steering_arm_m")))
    );
    assert!(message.contains("positive"), "{message}");
    let (path, _, _) = refused(&src.replace("hub_below_plate_m = 0.021", "hub_below_plate_m = \"deep\""));
    assert_eq!(path, "robot.gear.hub_below_plate_m");
    // Another kind's gear is no gear.
    let e = gear_spec(&profile(&src.replace("kind = \"krawler\"", "kind = \"axel\""))).unwrap_err();
    assert!(
        e.to_string().contains("robot kind `axel` has no AutoKrawler gear"),
        "{e}"
    );
}

#[test]
fn the_leaves_refuse_bad_params_by_field() {
    let src = source();
    for (from, to, field) in [
        ("threshold_rad = 0.35", "threshold_rad = 0.0", "threshold_rad"),
        ("reference = \"command\"", "reference = \"gps\"", "reference"),
        ("window_s = 1.0", "window_s = -1.0", "window_s"),
        ("speed_mps = 0.05", "speed_mps = nan", "speed_mps"),
    ] {
        let (path, line, message) = refused(&src.replace(from, to));
        assert!(path.starts_with("behavior.tree.nodes."), "{path}");
        assert!(line.is_some(), "{path}: {message}");
        assert!(message.contains(field) || message.contains("gps"), "{field}: {message}");
    }
}

#[test]
fn a_tick_runs_the_estimator_on_the_belly_camera_once_per_frame() {
    let p = profile(&source());
    let mut robot = shipped().compose(&Krawler, &p).unwrap();
    robot.begin(&Mission::docking()).unwrap();
    let cam = &p.cameras[0];
    let frame = RgbImage::new(cam.width_px, cam.height_px);
    let cameras = [Some(CameraInput {
        stamp: 0.0,
        image: frame.view(),
    })];
    let inputs = Inputs {
        cameras: &cameras,
        ..Inputs::empty(0.0)
    };
    // A blank frame: estimated (no markers found), and the traverse drives.
    let step = robot.tick(&mut (), &inputs).unwrap();
    assert!(robot.memory().percept.fresh);
    assert_eq!(robot.memory().percept.frames, 1);
    assert_eq!(robot.memory().percept.estimate.markers.found(), 0);
    assert!(step.output.drive.to_twist().v > 0.0);
    // The same frame again (a repeat): not estimated twice.
    let later = Inputs {
        cameras: &cameras,
        ..Inputs::empty(0.1)
    };
    robot.tick(&mut (), &later).unwrap();
    assert!(!robot.memory().percept.fresh);
    assert_eq!(robot.memory().percept.frames, 1);
    // A frame of another size is refused and counted, never a panic.
    let small = RgbImage::new(8, 8);
    let cameras = [Some(CameraInput {
        stamp: 0.2,
        image: small.view(),
    })];
    let inputs = Inputs {
        cameras: &cameras,
        ..Inputs::empty(0.2)
    };
    robot.tick(&mut (), &inputs).unwrap();
    assert_eq!((robot.memory().percept.frames, robot.memory().percept.refused), (1, 1));
}
