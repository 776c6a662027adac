//! Decision traces name the leaf that ran, what the active children proposed, which won
//! and why each transition fired; and every arbiter choice a profile makes shows in them:
//! flip one and the trace changes.

use crate::common;

use marsupial::arbiter::{NodeTrace, Strategy};
use marsupial::behaviors::agent_for;
use marsupial::geometry::Pose2;
use marsupial::perception::RgbImage;
use marsupial::profile::Profile;
use marsupial::schemas::Agent;
use marsupial::schemas::{CameraInput, CameraInputs, DOCK_CONTACT_KIND, Inputs, OdometryReading, SensorInput, Stamped};
use std::path::Path;

fn shipped() -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("profiles/bujold.toml")).unwrap()
}

fn agent(src: &str) -> Box<dyn Agent> {
    agent_for(&Profile::parse(src, Path::new("bujold.toml")).unwrap()).unwrap()
}

/// Ticks `agent` at `t` on `frame` (dock switch as given) and returns its trace.
fn tick(agent: &mut Box<dyn Agent>, t: f64, frame: &RgbImage, contact: bool) -> Vec<NodeTrace> {
    let cams: CameraInputs<'_> = smallvec::smallvec![Some(CameraInput {
        stamp: t,
        image: frame.view()
    })];
    let mut inputs = Inputs::empty(t);
    inputs.cameras = &cams;
    let pose = Pose2::new(1.0, 0.0, 0.0);
    inputs.odometry = Some(Stamped::new(
        t,
        OdometryReading {
            pose,
            ..Default::default()
        },
    ));
    let plates = [f64::from(u8::from(contact))];
    let sensors = [Some(SensorInput {
        kind: DOCK_CONTACT_KIND,
        stamp: t,
        values: &plates,
    })];
    inputs.sensors = &sensors;
    agent.tick(&mut (), &inputs);
    let mut out = Vec::new();
    agent.explain(&mut out);
    out
}

fn node<'a>(trace: &'a [NodeTrace], name: &str) -> &'a NodeTrace {
    trace
        .iter()
        .find(|n| n.node == name)
        .unwrap_or_else(|| panic!("no `{name}` in {trace:#?}"))
}

#[test]
fn a_trace_names_the_leaf_the_proposals_the_winner_and_why_it_moved_on() {
    let mut a = agent(&shipped());
    a.begin(&marsupial::schemas::Mission::docking()).unwrap();
    let blank = common::background(256, 240);
    let seen = common::scene(256, 240, 0.25, 1);
    let first = tick(&mut a, 0.0, &blank, false);
    let names: Vec<&str> = first.iter().map(|n| n.node.as_str()).collect();
    assert_eq!(names, ["bujold", "docking", "close_dock"], "{first:#?}");
    assert_eq!(node(&first, "docking").strategy, Strategy::Priority);
    assert_eq!(node(&first, "docking").active, ["close_dock"]);
    let close = node(&first, "close_dock");
    assert_eq!(close.winner.as_deref(), Some("search"));
    assert_eq!(close.transitions[0].to, "search");
    assert_eq!(close.transitions[0].event, "started");
    // The fiducial comes into view: search ends with `acquired` and approach is entered.
    let t = tick(&mut a, 0.1, &seen, false);
    let close = node(&t, "close_dock");
    assert_eq!(close.winner.as_deref(), Some("search"));
    assert_eq!(close.proposals.len(), 1);
    assert_eq!(
        (
            close.transitions[0].from.as_str(),
            close.transitions[0].to.as_str(),
            close.transitions[0].event.as_str()
        ),
        ("search", "approach", "acquired")
    );
    let t = tick(&mut a, 0.2, &seen, false);
    assert_eq!(node(&t, "close_dock").winner.as_deref(), Some("approach"));
    assert!(node(&t, "close_dock").transitions.is_empty());
    // The plates close: the switch subsumes the approach.
    let t = tick(&mut a, 0.3, &seen, true);
    let docking = node(&t, "docking");
    assert_eq!(docking.active, ["dock_switch", "close_dock"]);
    assert_eq!(docking.winner.as_deref(), Some("dock_switch"));
}

/// The `close_dock` winner and `docking` node after the fiducial is acquired and the
/// plates close, for a profile text.
fn run(src: &str) -> (Vec<NodeTrace>, Vec<NodeTrace>) {
    let mut a = agent(src);
    a.begin(&marsupial::schemas::Mission::docking()).unwrap();
    let seen = common::scene(256, 240, 0.25, 1);
    tick(&mut a, 0.0, &common::background(256, 240), false);
    let acquired = tick(&mut a, 0.1, &seen, false);
    let contact = tick(&mut a, 0.2, &seen, true);
    (acquired, contact)
}

#[test]
fn flipping_each_arbiter_choice_changes_the_trace() {
    let base = shipped();
    let (_, contact) = run(&base);
    assert_eq!(node(&contact, "docking").winner.as_deref(), Some("dock_switch"));

    // Priority order: the close dock above the switch now wins while it runs.
    let swapped = base.replacen(
        "children = [\"dock_switch\", \"close_dock\"]",
        "children = [\"close_dock\", \"dock_switch\"]",
        1,
    );
    let (_, contact) = run(&swapped);
    assert_eq!(node(&contact, "docking").winner.as_deref(), Some("close_dock"));

    // Priority → vector sum: both proposals are summed, nobody wins.
    let summed = base.replacen(
        "kind = \"priority\"\nchildren = [\"dock_switch\", \"close_dock\"]",
        "kind = \"vector_sum\"\nchildren = [\"dock_switch\", \"close_dock\"]\ngains = [1.0, 1.0]\nmax_speed_mps = 0.08\nk_theta = 1.5",
        1,
    );
    assert_ne!(summed, base);
    let (_, contact) = run(&summed);
    let docking = node(&contact, "docking");
    assert_eq!(docking.strategy, Strategy::VectorSum);
    assert_eq!(docking.winner, None);
    assert_eq!(docking.proposals.len(), 2);

    // A transition's target: acquisition now leads to the decision.
    let rerouted = base.replacen("on = { acquired = \"approach\",", "on = { acquired = \"decide\",", 1);
    assert_ne!(rerouted, base);
    let (acquired, _) = run(&rerouted);
    assert_eq!(node(&acquired, "close_dock").transitions[0].to, "decide");

    // A state's timeout: a search limited to a tenth of a second times out at once.
    let hurried = base.replacen(
        "schema = \"bujold.search\"",
        "schema = \"bujold.search\"\ntimeout_s = 0.05",
        1,
    );
    let mut a = agent(&hurried);
    a.begin(&marsupial::schemas::Mission::docking()).unwrap();
    let blank = common::background(256, 240);
    tick(&mut a, 0.0, &blank, false);
    let t = tick(&mut a, 0.1, &blank, false);
    assert!(node(&t, "close_dock").proposals.is_empty(), "{t:#?}");
}
