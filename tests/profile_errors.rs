//! Every malformed profile fails with the file, field path, line and expectation, and
//! never panics (nor does any mutant of a shipped profile); the shipped profiles pass.

use marsupial::behaviors::Catalog;
use marsupial::config::ConfigError;
use marsupial::profile::{DriveKind, Profile};
use std::path::Path;
use std::process::Command;

use crate::mutate;

/// (fixture, expected field path, expected line (None when the parser cannot give one),
/// text the message must contain)
const CASES: &[(&str, &str, Option<usize>, &str)] = &[
    ("syntax_error.toml", "", Some(37), "TOML syntax error"),
    (
        "unknown_field.toml",
        "drive.top_speed_mps",
        Some(14),
        "unknown field `top_speed_mps`",
    ),
    (
        "wrong_type.toml",
        "cameras[0].width_px",
        Some(26),
        "invalid type: string \"256\", expected usize",
    ),
    ("missing_field.toml", "", None, "missing field `success`"),
    (
        "negative_fov.toml",
        "cameras[0].hfov_deg",
        Some(28),
        "expected a field of view in (0, 180) degrees, got -70",
    ),
    (
        "dmin_gt_dmax.toml",
        "drive.d_min_m",
        Some(11),
        "expected d_min_m ≤ d_max_m, got 0.4 > 0.3",
    ),
    (
        "zero_resolution.toml",
        "cameras[0].height_px",
        Some(27),
        "expected an integer ≥ 1, got 0",
    ),
    ("skid_without_bounds.toml", "drive", Some(8), "missing field `d_max_m`"),
    (
        "unknown_drive_kind.toml",
        "drive.kind",
        Some(9),
        "unknown variant `hovercraft`",
    ),
    (
        "unknown_fiducial_kind.toml",
        "fiducial.kind",
        Some(45),
        "unknown fiducial kind `two_blocks` (registered: circles, markers, pyramid, two_block)",
    ),
    (
        "approach_without_gains.toml",
        "robot",
        Some(57),
        "missing field `ratio_steering`",
    ),
    (
        "bad_circle_rotation.toml",
        "fiducial.placements[2].rotation_deg",
        Some(58),
        "expected one of −45, 0, 45, 90, got 30",
    ),
    (
        "bad_fixed_threshold.toml",
        "fiducial.fixed_threshold",
        Some(84),
        "black_below ≤ white_above, got [150, 70]",
    ),
    (
        "stale_below_tick.toml",
        "loop.camera_stale_s",
        Some(71),
        "at least one tick",
    ),
    (
        "dock_narrower_than_body.toml",
        "dock.entrance_width_m",
        Some(38),
        "at least as wide as the body",
    ),
    (
        "pinhole_without_fov.toml",
        "cameras[0]",
        Some(23),
        "needs `hfov_deg` or an `intrinsics` table",
    ),
    (
        "chroma_gate_too_wide.toml",
        "perception.min_chroma_deg",
        Some(74),
        "expected a number in [0, 30], got 45",
    ),
    (
        "pairing_limits_out_of_range.toml",
        "perception.max_height_ratio",
        Some(74),
        "expected a number in [1, ",
    ),
    (
        "cast_out_of_range.toml",
        "perception.cast_tau_s",
        Some(74),
        "expected a number ≥ 0, got -1",
    ),
    (
        "cast_out_of_range.toml",
        "perception.cast_dead_band",
        Some(75),
        "expected a number in [0, 0.5], got 0.8",
    ),
    (
        "pairing_limits_out_of_range.toml",
        "perception.min_count_ratio",
        Some(75),
        "expected a number in [0, 1], got 1.5",
    ),
    (
        "steering_poly_wrong_length.toml",
        "fiducial.steering_poly_deg[1]",
        Some(43),
        "expected 3 coefficients (second order) or 4 (third order), got 5",
    ),
    ("empty.toml", "", None, "missing field `name`"),
];

fn fixture(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/profiles")
        .join(name)
}

#[test]
fn shipped_profiles_are_valid() {
    for (name, kind) in [
        ("bujold", DriveKind::TurnOrDrive),
        ("raposa", DriveKind::SkidSteer),
        ("axel", DriveKind::Differential),
        ("autokrawler", DriveKind::DoubleAckermann),
    ] {
        let p = Profile::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("profiles/{name}.toml")))
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(p.name, name);
        assert_eq!(p.drive.kind, kind);
    }
}

#[test]
fn every_malformed_profile_names_file_path_line_and_expectation() {
    for &(file, path, line, text) in CASES {
        // The catalog's check: the generic profile, its fiducial kind, its robot kind's
        // tuning and its tree.
        let err = Catalog::shipped().check_profile(&fixture(file)).expect_err(file);
        let ConfigError::Invalid { file: f, problems } = &err else {
            panic!("{file}: expected Invalid, got {err:?}");
        };
        assert!(f.ends_with(file), "{file}: error names {}", f.display());
        let p = problems
            .iter()
            .find(|p| p.message.contains(text))
            .unwrap_or_else(|| panic!("{file}: no problem mentions {text:?}: {problems:?}"));
        assert_eq!(p.path, path, "{file}");
        assert_eq!(p.line, line, "{file}");
        let shown = err.to_string();
        assert!(shown.contains(file), "{file}: {shown}");
        if let Some(l) = line {
            assert!(shown.contains(&format!("{file}:{l}: ")), "{file}: {shown}");
        }
    }
}

#[test]
fn unreadable_files_are_io_errors() {
    let err = Profile::load(&fixture("binary.toml")).unwrap_err();
    assert!(matches!(err, ConfigError::Io { .. }), "{err:?}");
    assert!(err.to_string().contains("binary.toml"));
    let err = Profile::load(&fixture("does-not-exist.toml")).unwrap_err();
    assert!(err.to_string().contains("does-not-exist.toml: cannot read file"));
}

#[test]
fn several_problems_are_reported_together() {
    let src = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/bujold.toml")).unwrap();
    let src = src
        .replace("hfov_deg = 70.0", "hfov_deg = 190.0")
        .replace("width_px = 256", "width_px = 0");
    let err = Profile::parse(&src, Path::new("mem.toml")).unwrap_err();
    let paths: Vec<_> = err.problems().iter().map(|p| p.path.as_str()).collect();
    assert!(
        paths.contains(&"cameras[0].hfov_deg") && paths.contains(&"cameras[0].width_px"),
        "{paths:?}"
    );
}

/// `robot.two_arc.max_arc_turn_deg` is optional (absent in the shipped profile: no
/// cap) and, when given, must be a finite number in (0, 180]; a bad one is reported by
/// its field path and line.
#[test]
fn the_arc_turn_cap_is_optional_and_checked() {
    let src = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/axel.toml")).unwrap();
    let gains = |p: &Profile| {
        marsupial::behaviors::catalog::tuning::<marsupial::behaviors::axel::Axel>(p)
            .expect("two-arc gains")
            .two_arc
    };
    // The tuning is the robot kind's: checked when the robot is built.
    let check = |src: &str| {
        let p = Profile::parse(src, Path::new("axel.toml")).expect("the profile loads");
        match marsupial::behaviors::catalog::tuning::<marsupial::behaviors::axel::Axel>(&p) {
            Err(marsupial::behaviors::BuildError::Invalid(e)) => e,
            other => panic!("expected the tuning refused, got {other:?}"),
        }
    };
    let shipped = Profile::parse(&src, Path::new("axel.toml")).expect("the shipped profile");
    assert_eq!(gains(&shipped).max_arc_turn_deg, None);
    let with = |cap: &str| {
        src.replace(
            "arc_speed_mps = 0.08",
            &format!("arc_speed_mps = 0.08\nmax_arc_turn_deg = {cap}"),
        )
    };
    assert!(with("1").len() > src.len(), "the profile's arc_speed_mps line moved");
    let capped = Profile::parse(&with("30.0"), Path::new("axel.toml")).expect("a 30° cap");
    assert_eq!(gains(&capped).max_arc_turn_deg, Some(30.0));
    let line = src.lines().position(|l| l.starts_with("arc_speed_mps")).unwrap() + 2;
    for bad in ["0.0", "-5.0", "180.5", "nan", "inf"] {
        let err = check(&with(bad));
        let p = err
            .problems()
            .iter()
            .find(|p| p.path == "robot.two_arc.max_arc_turn_deg")
            .unwrap_or_else(|| panic!("{bad}: {:?}", err.problems()));
        assert!(
            p.message.contains("expected a number in (0, 180]"),
            "{bad}: {}",
            p.message
        );
        assert_eq!(p.line, Some(line), "{bad}");
    }
}

/// The shipped profiles, sorted by name.
fn shipped_profiles() -> Vec<std::path::PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles");
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    files
}

#[test]
fn mutated_profiles_never_panic() {
    // Every shipped profile, truncated, with bytes flipped, values swapped for other types
    // and lines deleted: parsing and validating each must return, Ok or Err.
    let files = shipped_profiles();
    assert!(files.len() >= 6, "{files:?}");
    let mut bad = Vec::new();
    let mut tried = 0;
    for (k, file) in files.iter().enumerate() {
        let src = std::fs::read_to_string(file).unwrap();
        let mutants = mutate::mutants(&src, 0x5EED_0000 + k as u64, 40, 11, 3);
        tried += mutants.len();
        for what in mutate::panicking(&mutants, |m| {
            if let Ok(s) = std::str::from_utf8(&m.bytes) {
                let _ = Profile::parse(s, Path::new("mutant.toml"));
            }
        }) {
            bad.push(format!("{}: {what}", file.display()));
        }
    }
    assert!(tried > 5000, "{tried} mutants");
    assert!(
        bad.is_empty(),
        "{} of {tried} mutants panicked:\n{}",
        bad.len(),
        bad.join("\n")
    );
}

#[test]
fn cli_check_prints_ok_and_fails_on_bad_files() {
    let exe = env!("CARGO_BIN_EXE_marsupial");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let profiles: Vec<_> = ["bujold", "raposa", "axel", "autokrawler"]
        .iter()
        .map(|n| root.join(format!("profiles/{n}.toml")))
        .collect();
    let out = Command::new(exe).arg("check").args(&profiles).output().unwrap();
    assert!(out.status.success());
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert_eq!(stdout.lines().filter(|l| l.starts_with("ok ")).count(), 4, "{stdout}");

    let out = Command::new(exe)
        .arg("check")
        .arg(&profiles[0])
        .arg(fixture("dmin_gt_dmax.toml"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(
        stderr.contains("dmin_gt_dmax.toml:11: drive.d_min_m: expected d_min_m ≤ d_max_m"),
        "{stderr}"
    );
    assert!(!stderr.contains("panicked"));

    let out = Command::new(exe).arg("--help").output().unwrap();
    assert!(String::from_utf8(out.stdout).unwrap().contains("check"));
    let out = Command::new(exe).args(["check", "--help"]).output().unwrap();
    assert!(String::from_utf8(out.stdout).unwrap().contains("FILE:LINE"));
}

#[test]
fn a_docking_cone_names_the_field_that_cannot_work() {
    let src = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/axel.toml")).unwrap();
    let check = |from: &str, to: &str, field: &str| {
        assert!(src.contains(from), "{from}");
        let err = Profile::parse(&src.replace(from, to), Path::new("mem.toml")).unwrap_err();
        let paths: Vec<_> = err.problems().iter().map(|p| p.path.as_str()).collect();
        assert!(paths.contains(&field), "{to}: {paths:?}");
    };
    // Walls meeting before the throat; an arm too short to seat past the wheels; a tip
    // wider than the throat; a mouth below the ground; a negative seat.
    check(
        "funnel_half_angle_deg = 25.0",
        "funnel_half_angle_deg = 60.0",
        "dock.funnel_half_angle_deg",
    );
    check("arm_m = 0.55 ", "arm_m = 0.4 ", "tether.arm_m");
    check("tip_diameter_m = 0.06", "tip_diameter_m = 0.2", "tether.tip_diameter_m");
    check(
        "axis_height_m = 0.15",
        "axis_height_m = 0.05",
        "dock.cone.axis_height_m",
    );
    check(
        "seat_length_m = 0.27",
        "seat_length_m = -1.0",
        "dock.cone.seat_length_m",
    );
}

#[test]
fn docks_read_and_bad_ones_name_the_entry_and_line() {
    let src = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/bujold.toml")).unwrap();
    let with = |docks: &str| Profile::parse(&format!("{src}\n{docks}"), Path::new("mem.toml"));
    let p = with("[[docks]]\nid = \"home\"\npose = [1.5, 0.2, 3.0]\n\n[[docks]]\nid = \"shed\"\ntype = \"bujold\"\nframe = \"map\"\n").unwrap();
    assert_eq!(p.docks.len(), 2);
    assert_eq!(
        (p.docks[0].pose, p.docks[1].frame.as_deref()),
        (Some([1.5, 0.2, 3.0]), Some("map"))
    );
    let problem = |docks: &str| {
        let err = with(docks).unwrap_err();
        err.problems()
            .iter()
            .map(|p| (p.path.clone(), p.message.clone(), p.line))
            .collect::<Vec<_>>()
    };
    let twice = problem("[[docks]]\nid = \"home\"\n[[docks]]\nid = \"home\"\n");
    assert!(
        twice
            .iter()
            .any(|(path, m, line)| path == "docks[1].id" && m.contains("already docks[0]") && line.is_some()),
        "{twice:?}"
    );
    let nan = problem("[[docks]]\nid = \"home\"\npose = [1.0, nan, 0.0]\n");
    assert!(
        nan.iter()
            .any(|(path, m, _)| path == "docks[0].pose" && m.contains("finite")),
        "{nan:?}"
    );
    let blank = problem("[[docks]]\nid = \" \"\ntype = \"\"\n");
    let paths: Vec<&str> = blank.iter().map(|(p, ..)| p.as_str()).collect();
    assert!(
        paths.contains(&"docks[0].id") && paths.contains(&"docks[0].type"),
        "{blank:?}"
    );
    let unknown = problem("[[docks]]\nid = \"home\"\ncolour = \"red\"\n");
    assert!(
        unknown.iter().any(|(_, m, _)| m.contains("unknown field `colour`")),
        "{unknown:?}"
    );
}
