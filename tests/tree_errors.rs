//! A malformed `[behavior.tree]` fails with the file, the line, the field and what was
//! expected: when the profile loads (structure) or when the agent is built (schemas and
//! their params). Never a panic.

use marsupial::behaviors::{BuildError, agent_for};
use marsupial::config::ConfigError;
use marsupial::profile::Profile;
use std::path::Path;

fn shipped() -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/bujold.toml")).unwrap()
}

/// The shipped Bujold profile with `from` replaced by `to` (which must occur once).
fn edited(from: &str, to: &str) -> (String, usize) {
    let src = shipped();
    assert_eq!(src.matches(from).count(), 1, "`{from}` must occur once");
    let line = src[..src.find(from).unwrap()].matches('\n').count() + 1;
    (src.replacen(from, to, 1), line)
}

fn only_problem(e: &ConfigError) -> (&str, Option<usize>, &str) {
    assert_eq!(e.problems().len(), 1, "{e}");
    let p = &e.problems()[0];
    (p.path.as_str(), p.line, p.message.as_str())
}

fn load_error(src: &str) -> ConfigError {
    Profile::parse(src, Path::new("bujold-edited.toml")).expect_err("the profile must be refused")
}

fn build_error(src: &str) -> ConfigError {
    let p = Profile::parse(src, Path::new("bujold-edited.toml")).expect("the profile loads");
    match agent_for(&p).err().expect("the agent must not build") {
        BuildError::Tree(e) => e,
        other => panic!("expected a tree error, got {other}"),
    }
}

#[test]
fn the_shipped_tree_builds() {
    let p = Profile::parse(&shipped(), Path::new("bujold.toml")).unwrap();
    assert!(agent_for(&p).is_ok());
}

#[test]
fn an_unknown_schema_names_its_line_and_the_registered_ones() {
    let (src, line) = edited("schema = \"bujold.search\"", "schema = \"bujold.serch\"");
    let e = build_error(&src);
    let (path, at, msg) = only_problem(&e);
    assert_eq!(path, "behavior.tree.nodes.search.schema");
    assert_eq!(at, Some(line));
    assert!(
        msg.contains("unknown schema `bujold.serch`") && msg.contains("bujold.search"),
        "{msg}"
    );
    assert!(
        e.to_string().starts_with(&format!("bujold-edited.toml:{line}: ")),
        "{e}"
    );
}

#[test]
fn a_misspelt_param_is_refused_by_its_schema() {
    let (src, line) = edited("still_levels = 1.0", "still_level = 1.0");
    let e = build_error(&src);
    let (path, at, msg) = only_problem(&e);
    assert_eq!(path, "behavior.tree.nodes.search.params");
    assert_eq!(at, Some(line));
    assert!(msg.contains("unknown field `still_level`"), "{msg}");
}

#[test]
fn a_transition_to_a_missing_state_names_the_event() {
    let (src, line) = edited(
        "on = { acquired = \"approach\", jammed = \"unjam\" }",
        "on = { acquired = \"aproach\", jammed = \"unjam\" }",
    );
    let e = load_error(&src);
    let (path, at, msg) = only_problem(&e);
    assert_eq!(path, "behavior.tree.nodes.search.on.acquired");
    assert_eq!(at, Some(line));
    assert!(msg.contains("`aproach` is not a state of `close_dock`"), "{msg}");
}

#[test]
fn a_node_that_contains_itself_is_a_cycle() {
    let (src, _) = edited(
        "children = [\"dock_switch\", \"close_dock\"]",
        "children = [\"dock_switch\", \"close_dock\", \"bujold\"]",
    );
    let e = load_error(&src);
    let all = e.to_string();
    assert!(
        all.contains("contains itself") || all.contains("is a child of"),
        "{all}"
    );
    assert!(e.problems().iter().all(|p| p.line.is_some()), "{all}");
}

#[test]
fn a_child_that_does_not_exist_and_a_node_outside_the_tree_are_named() {
    let (src, line) = edited(
        "states = [\"undock\", \"drive_out\", \"imprint\"]",
        "states = [\"undock\", \"drive_out\", \"imprnt\"]",
    );
    let e = load_error(&src);
    let msgs: Vec<String> = e
        .problems()
        .iter()
        .map(|p| format!("{}|{:?}|{}", p.path, p.line, p.message))
        .collect();
    assert!(
        msgs.iter().any(|m| m.starts_with(&format!(
            "behavior.tree.nodes.departure.states[2]|Some({line})|no node named `imprnt`"
        ))),
        "{msgs:?}"
    );
    // `imprint` is now listed by no node (and `drive_out` still leads to it).
    assert!(
        msgs.iter().any(|m| m.contains("`imprint` is not part of the tree")),
        "{msgs:?}"
    );
}

#[test]
fn a_leaf_with_a_sequencers_field_is_refused_at_its_line() {
    let (src, line) = edited(
        "schema = \"bujold.unjam_turn\"",
        "schema = \"bujold.unjam_turn\"\nstates = []",
    );
    let e = load_error(&src);
    let (_, at, msg) = only_problem(&e);
    assert!(msg.contains("unknown field `states`"), "{msg}");
    assert!(at.is_some_and(|l| l >= line - 3 && l <= line + 1), "{at:?} vs {line}");
}

#[test]
fn an_unknown_selector_names_its_line() {
    let from = "states = [\"ballistic\", \"search\"";
    let (src, line) = edited(from, &format!("selector = \"bujold.nothing\"\n{from}"));
    let e = build_error(&src);
    let (path, at, msg) = only_problem(&e);
    assert_eq!(path, "behavior.tree.nodes.close_dock.selector");
    assert_eq!(at, Some(line));
    assert!(msg.contains("unknown selector `bujold.nothing`"), "{msg}");
}

fn raposa_shipped() -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/raposa.toml")).unwrap()
}

#[test]
fn raposas_tree_builds_and_a_transition_out_of_its_sequence_is_refused() {
    let p = Profile::parse(&raposa_shipped(), Path::new("raposa.toml")).unwrap();
    assert!(agent_for(&p).is_ok());
    // The region-II sequence hands `facing` up to the servo; `look` is the servo's state,
    // not region_2's.
    let src = raposa_shipped();
    let from = "on = { facing = \"finish\" }";
    assert_eq!(src.matches(from).count(), 1);
    let line = src[..src.find(from).unwrap()].matches('\n').count() + 1;
    let src = src.replacen(from, "on = { facing = \"look\" }", 1);
    let e = Profile::parse(&src, Path::new("raposa-edited.toml")).expect_err("the profile must be refused");
    let (path, at, msg) = only_problem(&e);
    assert_eq!(path, "behavior.tree.nodes.rotate_phi.on.facing");
    assert_eq!(at, Some(line));
    assert!(msg.contains("`look` is not a state of `region_2`"), "{msg}");
}

/// The problem reported at `path` (others may follow from it).
fn problem_at<'e>(e: &'e ConfigError, path: &str) -> (&'e str, Option<usize>, &'e str) {
    let p = e
        .problems()
        .iter()
        .find(|p| p.path == path)
        .unwrap_or_else(|| panic!("no problem at {path}: {e}"));
    (p.path.as_str(), p.line, p.message.as_str())
}

fn avoid_shipped() -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/bujold-avoid.toml")).unwrap()
}

/// `profiles/bujold-avoid.toml` with `from` replaced by `to` (which must occur once), and
/// the line `from` starts on.
fn avoid_edited(from: &str, to: &str) -> (String, usize) {
    let src = avoid_shipped();
    assert_eq!(src.matches(from).count(), 1, "`{from}` must occur once");
    let line = src[..src.find(from).unwrap()].matches('\n').count() + 1;
    (src.replacen(from, to, 1), line)
}

#[test]
fn an_unknown_sensor_kind_names_its_line_and_the_registered_kinds() {
    let (src, line) = avoid_edited("kind = \"range\"", "kind = \"lidar\"");
    let e = build_error(&src);
    // The avoid leaf, which needs a range finder, is refused too (at its own line).
    let (_, at, msg) = problem_at(&e, "sensors[0].kind");
    assert_eq!(at, Some(line));
    assert!(msg.contains("`lidar`") && msg.contains("range"), "{msg}");
}

#[test]
fn a_sensors_bad_params_are_refused_by_its_kind() {
    let (src, _) = avoid_edited("beams = 19,", "beams = 0,");
    let e = build_error(&src);
    let (_, _, msg) = problem_at(&e, "sensors[0].params");
    assert!(msg.contains("beams"), "{msg}");
}

#[test]
fn a_leaf_needing_a_sensor_the_profile_lacks_names_the_leaf() {
    let src = avoid_shipped();
    let cut = src.find("\n[[sensors]]\n").unwrap() + 1;
    let end = cut + src[cut..].find("\n\n").unwrap();
    let src = format!("{}{}", &src[..cut], &src[end + 2..]);
    let line = src[..src.find("schema = \"avoid_obstacles\"").unwrap()]
        .matches('\n')
        .count()
        + 1;
    let e = build_error(&src);
    let (path, at, msg) = only_problem(&e);
    assert_eq!(path, "behavior.tree.nodes.avoid.schema");
    assert_eq!(at, Some(line));
    assert!(msg.contains("[[sensors]]") && msg.contains("range"), "{msg}");
}

#[test]
fn the_avoid_profile_builds() {
    let p = Profile::parse(&avoid_shipped(), Path::new("bujold-avoid.toml")).unwrap();
    assert!(agent_for(&p).is_ok());
}

/// The toy robot of the examples with `[[actuators]]` entries `actuators` (TOML) and a
/// one-leaf tree whose leaf, `test.grip`, needs a `gripper`.
fn gripper_profile(actuators: &str) -> Profile {
    let src = format!(
        "name = \"gripper\"\n{}{actuators}\n\
         [behavior]\nmax_retries = 0\nsearch_timeout_s = 20.0\nphase_timeout_s = 20.0\n\
         [behavior.tree]\nroot = \"seek\"\ndocking = \"grip\"\n\
         [behavior.tree.nodes.seek]\nkind = \"sequencer\"\nstates = [\"grip\"]\n\
         [behavior.tree.nodes.grip]\nkind = \"leaf\"\nschema = \"test.grip\"\n\
         [success]\nlateral_tolerance_m = 0.1\nheading_tolerance_deg = 20.0\ntimeout_s = 30.0\n",
        include_str!("../examples/common/toy_robot.toml")
    );
    Profile::parse(&src, Path::new("gripper.toml")).expect("the profile loads")
}

/// A registry that knows the `gripper` actuator kind (params: `force_n` > 0) and a leaf
/// that finds it, reporting the index it found into `found`.
fn gripper_registry(
    found: std::sync::Arc<std::sync::Mutex<Option<usize>>>,
) -> marsupial::behaviors::registry::Registry<()> {
    use marsupial::behaviors::registry::{LeafArgs, Registry};
    use marsupial::schemas::{Behavior, Inputs, Step};
    // No `name`: the tree names it by its node.
    struct Grip;
    impl Behavior for Grip {
        fn tick(&mut self, _mem: &mut (), _: &Inputs<'_>) -> Option<Step> {
            None
        }
    }
    let mut r = Registry::new();
    r.register_actuator_kind("gripper", |p| match p.get("force_n").and_then(toml::Value::as_float) {
        Some(f) if f > 0.0 => Ok(()),
        _ => Err("params.force_n: expected a force > 0 N".into()),
    })
    .register("test.grip", move |_: &(), a: &LeafArgs<'_>| {
        *found.lock().unwrap() = Some(a.actuator("gripper")?);
        Ok(Box::new(Grip))
    });
    r
}

#[test]
fn a_registered_actuator_kind_is_checked_and_found_by_its_leaf() {
    let found = std::sync::Arc::default();
    let registry = gripper_registry(std::sync::Arc::clone(&found));
    let ok = "[[actuators]]\nname = \"beacon\"\nkind = \"gripper\"\nparams = { force_n = 5.0 }\n\
              [[actuators]]\nname = \"claw\"\nkind = \"gripper\"\nparams = { force_n = 20.0 }\n";
    assert!(registry.build(&gripper_profile(ok), &()).is_ok());
    assert_eq!(*found.lock().unwrap(), Some(0), "the first entry of the kind");
    let leaf = registry.build_node(&gripper_profile(ok), "grip", &()).unwrap();
    assert_eq!(leaf.name(), "grip", "a leaf is named by its node");
    // Params the kind refuses, at their entry.
    let weak = ok.replace("force_n = 20.0", "force_n = 0.0");
    let e = registry.build(&gripper_profile(&weak), &()).err().unwrap();
    let (_, _, msg) = problem_at(&e, "actuators[1].params");
    assert!(msg.contains("force_n"), "{msg}");
    // A kind nobody registered, named with the registered ones.
    let unknown = ok.replace("kind = \"gripper\"\nparams = { force_n = 5.0 }", "kind = \"winch\"");
    let e = registry.build(&gripper_profile(&unknown), &()).err().unwrap();
    let (_, _, msg) = problem_at(&e, "actuators[0].kind");
    assert!(msg.contains("`winch`") && msg.contains("gripper"), "{msg}");
    // No gripper at all: the leaf that needs one says so.
    let e = registry.build(&gripper_profile(""), &()).err().unwrap();
    let (_, _, msg) = problem_at(&e, "behavior.tree.nodes.grip.schema");
    assert!(msg.contains("[[actuators]]") && msg.contains("gripper"), "{msg}");
}
