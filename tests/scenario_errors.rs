//! Malformed scenarios fail with the file, field path, line and expectation, like profiles,
//! and no mutant of a shipped scenario makes loading panic.

use marsupial::cli::check::check_file;
use marsupial::config::ConfigError;
use marsupial::sim::scenario::Scenario;
use std::path::{Path, PathBuf};

use crate::mutate;

fn write(name: &str, body: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("marsupial-scenario-errors-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let profile = Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/bujold.toml");
    let p = dir.join(name);
    std::fs::write(
        &p,
        format!("name = \"bad\"\nprofile = \"{}\"\n{body}", profile.display()),
    )
    .unwrap();
    p
}

fn problem(path: &Path) -> (String, Option<usize>, String) {
    match Scenario::load(path).unwrap_err() {
        ConfigError::Invalid { problems, .. } => {
            (problems[0].path.clone(), problems[0].line, problems[0].message.clone())
        }
        e => panic!("{e:?}"),
    }
}

#[test]
fn malformed_scenarios_are_reported_precisely() {
    let cases: &[(&str, &str, &str, Option<usize>, &str)] = &[
        (
            "no_starts.toml",
            "[starts]\n",
            "starts",
            Some(3),
            "expected a `grid`, at least one entry in `points`, or `random`",
        ),
        (
            "bad_random_starts.toml",
            "[starts]\nrandom = { count = 0, distance_m = [2.0, 1.0], angle_deg = [-60.0, 60.0] }\n",
            "starts.random.count",
            Some(4),
            "expected 1 to 10000 starts, got 0",
        ),
        (
            "bad_grid.toml",
            "[starts]\ngrid = \"paper17\"\n",
            "starts.grid",
            Some(4),
            "unknown variant `paper17`",
        ),
        (
            "bad_select.toml",
            "[starts]\ngrid = \"paper16\"\nselect = [1, 17]\n",
            "starts.select[1]",
            Some(5),
            "expected a grid position 1–16, got 17",
        ),
        (
            "both_coords.toml",
            "[starts]\npoints = [ { distance_m = 1.0, angle_deg = 3.0, x_m = 1.0, y_m = 0.0 } ]\n",
            "starts.points[0]",
            Some(4),
            "either distance_m and angle_deg, or x_m and y_m",
        ),
        (
            "unknown_light.toml",
            "[starts]\ngrid = \"paper16\"\n[axes]\nlighting = [\"disco\"]\n",
            "axes.lighting[0]",
            Some(6),
            "unknown lighting `disco`",
        ),
        (
            "bad_terrain.toml",
            "[starts]\ngrid = \"paper16\"\n[axes]\nterrain = [\"ice\"]\n",
            "axes.terrain[0]",
            Some(6),
            "unknown variant `ice`",
        ),
        (
            "unknown_colour.toml",
            "[starts]\ngrid = \"paper16\"\n[axes]\nfiducial_colors = [[\"cyan\", \"purple\"]]\n",
            "axes.fiducial_colors[0][1]",
            Some(6),
            "unknown variant `purple`",
        ),
        (
            "same_colour.toml",
            "[starts]\ngrid = \"paper16\"\n[axes]\nfiducial_colors = [[\"cyan\", \"magenta\"], [\"blue\", \"blue\"]]\n",
            "axes.fiducial_colors[1]",
            Some(6),
            "expected two different colours, got `blue` twice",
        ),
        (
            "no_colours.toml",
            "[starts]\ngrid = \"paper16\"\n[axes]\nfiducial_colors = []\n",
            "axes.fiducial_colors",
            Some(6),
            "expected at least one [left, right] pair",
        ),
        (
            "one_colour.toml",
            "[starts]\ngrid = \"paper16\"\n[axes]\nfiducial_colors = [[\"cyan\"]]\n",
            "axes.fiducial_colors[0]",
            Some(6),
            "expected an array of length 2",
        ),
        (
            "grey_colour.toml",
            "[starts]\ngrid = \"paper16\"\n[axes]\nfiducial_colors = [[\"white\", \"magenta\"]]\n",
            "axes.fiducial_colors[0][0]",
            Some(6),
            "`white` lies on SCT's grey axis",
        ),
        (
            "twice.toml",
            "[starts]\ngrid = \"paper16\"\n[axes]\nfiducial_colors = [[\"cyan\", \"red\"], [\"cyan\", \"red\"]]\n",
            "axes.fiducial_colors[1]",
            Some(6),
            "the pair cyan|red is already axes.fiducial_colors[0]",
        ),
        (
            "typo.toml",
            "trails = 3\n[starts]\ngrid = \"paper16\"\n",
            "trails",
            Some(3),
            "unknown field `trails`",
        ),
        (
            "neg_timeout.toml",
            "timeout_s = -1.0\n[starts]\ngrid = \"paper16\"\n",
            "timeout_s",
            Some(3),
            "expected a positive number",
        ),
        (
            "bad_shadow.toml",
            "[starts]\ngrid = \"paper16\"\n[lighting.x]\npreset = \"noon\"\nshadows = [ { strength = 2.0, angle_deg = 0.0, offset_m = 0.0, amplitude_m = 0.0, period_s = 1.0, softness_m = 0.0 } ]\n",
            "lighting.x.shadows[0].strength",
            Some(7),
            "expected a number in [0, 1], got 2",
        ),
        (
            "bad_highlight_clip.toml",
            "[starts]\ngrid = \"paper16\"\n[sensor]\nhighlight_clip_frac = 1.5\n",
            "sensor.highlight_clip_frac",
            Some(6),
            "expected a number in [0, 1], got 1.5",
        ),
        (
            "bad_readout.toml",
            "[starts]\ngrid = \"paper16\"\n[sensor]\nrolling_shutter_readout_s = -0.01\n",
            "sensor.rolling_shutter_readout_s",
            Some(6),
            "expected a number in [0, 1], got -0.01",
        ),
        (
            "nan_readout.toml",
            "[starts]\ngrid = \"paper16\"\n[sensor]\nrolling_shutter_readout_s = nan\n",
            "sensor.rolling_shutter_readout_s",
            Some(6),
            "expected a number in [0, 1], got NaN",
        ),
        (
            "long_readout.toml",
            "[starts]\ngrid = \"paper16\"\n[sensor]\nrolling_shutter_readout_s = 2.0\n",
            "sensor.rolling_shutter_readout_s",
            Some(6),
            "expected a number in [0, 1], got 2",
        ),
        (
            "dark_corner.toml",
            "[starts]\ngrid = \"paper16\"\n[sensor]\nvignetting_corner = 0.0\n",
            "sensor.vignetting_corner",
            Some(6),
            "expected a number in (0, 1], got 0",
        ),
        (
            "bright_corner.toml",
            "[starts]\ngrid = \"paper16\"\n[sensor]\nvignetting_corner = 1.5\n",
            "sensor.vignetting_corner",
            Some(6),
            "expected a number in (0, 1], got 1.5",
        ),
        (
            "nan_corner.toml",
            "[starts]\ngrid = \"paper16\"\n[sensor]\nvignetting_corner = nan\n",
            "sensor.vignetting_corner",
            Some(6),
            "expected a number in (0, 1], got NaN",
        ),
        (
            "negative_focus.toml",
            "[starts]\ngrid = \"paper16\"\n[sensor]\nfocus_m = -1.0\n",
            "sensor.focus_m",
            Some(6),
            "expected a positive number, got -1",
        ),
        (
            "focus_inside_lens.toml",
            "[starts]\ngrid = \"paper16\"\n[sensor]\nfocus_m = 0.002\n",
            "sensor.focus_m",
            Some(6),
            "expected a focus farther than the focal length (3.6 mm), got 0.002 m",
        ),
        (
            "bad_f_number.toml",
            "[starts]\ngrid = \"paper16\"\n[sensor]\nf_number = 0.0\n",
            "sensor.f_number",
            Some(6),
            "expected a number in [0.5, 64], got 0",
        ),
        (
            "nan_focal_length.toml",
            "[starts]\ngrid = \"paper16\"\n[sensor]\nfocal_length_mm = nan\n",
            "sensor.focal_length_mm",
            Some(6),
            "expected a number in [0.5, 300], got NaN",
        ),
        (
            "bad_jpeg.toml",
            "[starts]\ngrid = \"paper16\"\n[sensor]\njpeg_quality = 101\n",
            "sensor.jpeg_quality",
            Some(6),
            "expected 0 (off) or a quality 1–100, got 101",
        ),
        (
            "negative_jpeg.toml",
            "[starts]\ngrid = \"paper16\"\n[sensor]\njpeg_quality = -5\n",
            "sensor.jpeg_quality",
            Some(6),
            "invalid value: integer `-5`",
        ),
        (
            "bad_motion_blur.toml",
            "[starts]\ngrid = \"paper16\"\n[sensor]\nmotion_blur = \"yes\"\n",
            "sensor.motion_blur",
            Some(6),
            "invalid type: string \"yes\", expected a boolean",
        ),
        (
            "fault_without_lag.toml",
            "[starts]\ngrid = \"paper16\"\n[[faults]]\nname = \"a\"\nkind = \"camera_late\"\nat_s = 1.0\nduration_s = 2.0\nexpect = \"dock\"\n",
            "faults[0].lag_s",
            Some(5),
            "`camera_late` needs `lag_s`",
        ),
        (
            "fault_with_stray_side.toml",
            "[starts]\ngrid = \"paper16\"\n[[faults]]\nname = \"a\"\nkind = \"half_speed\"\nat_s = 1.0\nduration_s = 2.0\nexpect = \"dock\"\nside = \"left\"\n",
            "faults[0].side",
            Some(11),
            "`half_speed` takes no `side`",
        ),
        (
            "fault_negative_duration.toml",
            "[starts]\ngrid = \"paper16\"\n[[faults]]\nname = \"a\"\nkind = \"lights_out\"\nat_s = 1.0\nduration_s = -2.0\nexpect = \"dock\"\n",
            "faults[0].duration_s",
            Some(9),
            "positive",
        ),
        (
            "fault_unknown_kind.toml",
            "[starts]\ngrid = \"paper16\"\n[[faults]]\nname = \"a\"\nkind = \"gremlins\"\nat_s = 1.0\nduration_s = 2.0\nexpect = \"dock\"\n",
            "faults[0].kind",
            Some(7),
            "unknown variant `gremlins`",
        ),
        (
            "fault_twice.toml",
            "[starts]\ngrid = \"paper16\"\n[[faults]]\nname = \"a\"\nkind = \"lights_out\"\nat_s = 1.0\nduration_s = 2.0\nexpect = \"dock\"\n[[faults]]\nname = \"a\"\nkind = \"half_speed\"\nat_s = 1.0\nduration_s = 2.0\nexpect = \"dock\"\n",
            "faults[1].name",
            Some(12),
            "`a` names another fault too",
        ),
    ];
    for (file, body, path, line, text) in cases {
        let (p, l, m) = problem(&write(file, body));
        assert_eq!(&p, path, "{file}: {m}");
        assert_eq!(l, *line, "{file}");
        assert!(m.contains(text), "{file}: {m}");
    }
}

#[test]
fn a_colour_axis_needs_a_two_block_flap() {
    let dir = std::env::temp_dir().join(format!("marsupial-scenario-errors-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("raposa_colours.toml");
    let profile = Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/raposa.toml");
    std::fs::write(
        &p,
        format!(
            "name = \"x\"\nprofile = \"{}\"\n[starts]\ngrid = \"paper16\"\n[axes]\nfiducial_colors = [[\"cyan\", \"magenta\"]]\n",
            profile.display()
        ),
    )
    .unwrap();
    let (path, line, message) = problem(&p);
    assert_eq!(path, "axes.fiducial_colors");
    assert_eq!(line, None);
    assert!(
        message.contains("profile `raposa` has no `two_block` fiducial"),
        "{message}"
    );
}

#[test]
fn missing_profile_and_backdrop_name_the_files() {
    let dir = std::env::temp_dir().join(format!("marsupial-scenario-errors-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("no_profile.toml");
    std::fs::write(
        &p,
        "name = \"x\"\nprofile = \"nowhere.toml\"\n[starts]\ngrid = \"paper16\"\n",
    )
    .unwrap();
    assert!(
        Scenario::load(&p)
            .unwrap_err()
            .to_string()
            .contains("nowhere.toml: cannot read file")
    );
    let p = write(
        "no_backdrop.toml",
        "backgrounds = [\"missing.jpg\"]\n[starts]\ngrid = \"paper16\"\n",
    );
    let e = Scenario::load(&p).unwrap_err().to_string();
    assert!(e.contains("backgrounds[0]") && e.contains("missing.jpg"), "{e}");
}

#[test]
fn profile_patches_apply_and_bad_ones_name_the_patch() {
    let starts = "[starts]\ngrid = \"paper16\"\n";
    let ok = write(
        "patch_ok.toml",
        &format!("{starts}[profile_patch.fiducial]\nright_color = \"yellow\"\n"),
    );
    let loaded = Scenario::load(&ok).unwrap();
    let fid = loaded
        .profile
        .fiducial
        .get::<marsupial::profile::TwoBlockSpec>()
        .copied()
        .unwrap();
    assert_eq!(format!("{:?}", fid.right_color), "Yellow");
    assert_eq!(
        format!("{:?}", fid.left_color),
        "Cyan",
        "unpatched keys follow the profile"
    );
    let cases: &[(&str, &str, &str, &str)] = &[
        (
            "patch_typo.toml",
            "[profile_patch.behavior]\naproach = \"potential_field\"\n",
            "behavior",
            "unknown field `aproach`",
        ),
        (
            "patch_range.toml",
            "[profile_patch.success]\nlateral_tolerance_m = -0.02\n",
            "success.lateral_tolerance_m",
            "expected a positive number",
        ),
        (
            "patch_shape.toml",
            "[profile_patch.name]\nx = 1\n",
            "profile_patch",
            "`name` is not a table",
        ),
    ];
    for (file, body, path, text) in cases {
        let e = Scenario::load(&write(file, &format!("{starts}{body}"))).unwrap_err();
        let shown = e.to_string();
        assert!(shown.contains("as patched by [profile_patch]"), "{file}: {shown}");
        let ConfigError::Invalid { problems, .. } = e else {
            panic!("{file}: {e:?}")
        };
        assert!(problems[0].path.starts_with(path), "{file}: {:?}", problems[0]);
        assert_eq!(problems[0].line, None, "{file}: lines of the merged text would mislead");
        assert!(problems[0].message.contains(text), "{file}: {}", problems[0].message);
    }
}

#[test]
fn shipped_scenarios_are_valid_and_check_accepts_them() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
    let mut n = 0;
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "toml") {
            marsupial::cli::check::check_file(&p).unwrap_or_else(|e| panic!("{e}"));
            n += 1;
        }
    }
    assert!(n >= 5);
}

#[test]
fn mutated_scenarios_never_panic() {
    // Every shipped scenario (and perception campaign), truncated, with bytes flipped, values swapped for other types
    // and lines deleted, loaded from a folder beside a copy of the shipped profiles (so
    // `profile = "../profiles/…"` resolves and the `[profile_patch]` is merged): loading
    // each (parse, validate, its profile's too) must return, Ok or Err. Loading runs no
    // campaign.
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let work = std::env::temp_dir().join(format!("marsupial-scenario-mutants-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&work);
    std::fs::create_dir_all(work.join("scenarios")).unwrap();
    std::fs::create_dir_all(work.join("profiles")).unwrap();
    for e in std::fs::read_dir(root.join("profiles")).unwrap() {
        let p = e.unwrap().path();
        std::fs::copy(&p, work.join("profiles").join(p.file_name().unwrap())).unwrap();
    }
    let mut files: Vec<PathBuf> = std::fs::read_dir(root.join("scenarios"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    assert!(files.len() >= 18, "{files:?}");
    let mutant = work.join("scenarios/mutant.toml");
    let mut bad = Vec::new();
    let mut tried = 0;
    for (k, file) in files.iter().enumerate() {
        let src = std::fs::read_to_string(file).unwrap();
        // The original loads from there.
        std::fs::write(&mutant, &src).unwrap();
        // `check_file` loads each file as its kind: a docking scenario, or a perception
        // campaign (`pose-trials`, a `[pose]` table); a mutant may change its kind.
        check_file(&mutant).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        let mutants = mutate::mutants(&src, 0x5CE7_0000 + k as u64, 30, 11, 3);
        tried += mutants.len();
        for what in mutate::panicking(&mutants, |m| {
            std::fs::write(&mutant, &m.bytes).unwrap();
            let _ = check_file(&mutant);
        }) {
            bad.push(format!("{}: {what}", file.display()));
        }
    }
    let _ = std::fs::remove_dir_all(&work);
    assert!(tried > 3000, "{tried} mutants");
    assert!(
        bad.is_empty(),
        "{} of {tried} mutants panicked:\n{}",
        bad.len(),
        bad.join("\n")
    );
}

/// A file, the text of a valid outing to replace and its replacement, and the expected
/// problem: path, line, part of the message.
type Case<'a> = (&'a str, &'a str, &'a str, &'a str, Option<usize>, &'a str);

#[test]
fn bad_endurance_tables_are_reported_precisely() {
    // A valid outing (lines 3–8 after the name and profile), then one change each.
    let base =
        "[starts]\ngrid = \"paper16\"\n[endurance]\ncycles = 3\nlighting = [\"dawn\", \"dusk\"]\nday_s = 100.0\n";
    Scenario::load(&write("endurance_ok.toml", base)).unwrap();
    let cases: &[Case] = &[
        (
            "e_cycles.toml",
            "cycles = 3",
            "cycles = 0",
            "endurance.cycles",
            Some(6),
            "expected 1 to 10000 cycles, got 0",
        ),
        (
            "e_day.toml",
            "day_s = 100.0",
            "day_s = 0.0",
            "endurance.day_s",
            Some(8),
            "expected a positive number, got 0",
        ),
        (
            "e_speed.toml",
            "day_s = 100.0",
            "day_s = 100.0\nexcursion_speed_mps = -0.1",
            "endurance.excursion_speed_mps",
            Some(9),
            "expected a positive number, got -0.1",
        ),
        (
            "e_timeout.toml",
            "day_s = 100.0",
            "day_s = 100.0\nexcursion_timeout_s = nan",
            "endurance.excursion_timeout_s",
            Some(9),
            "expected a positive number, got NaN",
        ),
        (
            "e_nolight.toml",
            "[\"dawn\", \"dusk\"]",
            "[]",
            "endurance.lighting",
            Some(7),
            "expected at least one lighting programme",
        ),
        (
            "e_unknown_light.toml",
            "\"dusk\"]",
            "\"sunset\"]",
            "endurance.lighting[1]",
            Some(7),
            "unknown lighting `sunset`",
        ),
        (
            "e_flashers.toml",
            "\"dusk\"]",
            "\"flashers\"]",
            "endurance.lighting[1]",
            Some(7),
            "`flashers` has flashers or clouds",
        ),
        (
            "e_missing.toml",
            "day_s = 100.0\n",
            "",
            "endurance",
            Some(5),
            "missing field `day_s`",
        ),
        (
            "e_trials.toml",
            "[starts]",
            "trials = 2\n[starts]",
            "trials",
            Some(3),
            "expected trials = 1, got 2",
        ),
        (
            "e_axes_lighting.toml",
            "[starts]",
            "[axes]\nlighting = [\"noon\"]\n[starts]",
            "axes.lighting",
            Some(4),
            "leave axes.lighting out",
        ),
        (
            "e_segmentation.toml",
            "[starts]",
            "[axes]\nsegmentation = [\"adaptive\", \"static\"]\n[starts]",
            "axes.segmentation",
            Some(4),
            "expected one value, got 2",
        ),
        (
            "e_terrain.toml",
            "[starts]",
            "[axes]\nterrain = [\"lab_floor\", \"grass\"]\n[starts]",
            "axes.terrain",
            Some(4),
            "expected one value, got 2",
        ),
        (
            "e_colours.toml",
            "[starts]",
            "[axes]\nfiducial_colors = [[\"cyan\", \"magenta\"]]\n[starts]",
            "axes.fiducial_colors",
            Some(4),
            "leave axes.fiducial_colors out",
        ),
        (
            "e_faults.toml",
            "[starts]",
            "[[faults]]\nname = \"x\"\nkind = \"camera_silent\"\nat_s = 1.0\nduration_s = 1.0\nexpect = \"dock\"\n[starts]",
            "faults",
            Some(3),
            "faults are not injected into endurance outings",
        ),
        (
            "e_ballistic.toml",
            "[starts]",
            "[ballistic]\nenabled = true\n[starts]",
            "ballistic.enabled",
            Some(4),
            "without an a-priori dock pose",
        ),
        (
            "e_imprint.toml",
            "[starts]",
            "[imprint]\nenabled = false\n[starts]",
            "imprint.enabled",
            Some(4),
            "each endurance cycle starts with the departure",
        ),
        (
            "e_imprint_light.toml",
            "[starts]",
            "[imprint]\nlighting = \"lab\"\n[starts]",
            "imprint.lighting",
            Some(4),
            "departs under the outing's light",
        ),
        (
            "e_sleep.toml",
            "[starts]",
            "[imprint]\nsleep_s = 60.0\n[starts]",
            "imprint.sleep_s",
            Some(4),
            "expected 0",
        ),
    ];
    for (file, from, to, path, line, text) in cases {
        assert!(base.contains(from), "{file}");
        let (p, l, m) = problem(&write(file, &base.replacen(from, to, 1)));
        assert_eq!(&p, path, "{file}: {m}");
        assert_eq!(l, *line, "{file}: {m}");
        assert!(m.contains(text), "{file}: {m}");
    }
}
