//! Coordination strategies: priority, vector summation and the sequencer with latching.

use marsupial::arbiter::{Next, Priority, Sequencer, VectorSum};
use marsupial::geometry::Twist;
use marsupial::schemas::{
    Auxiliary, Behavior, DriveCommand, FailureReason, Feedback, Inputs, Lights, MotionVector, MotorOutput, Outcome,
    Status, Step,
};

/// A scripted behavior: active when `now` is in `[from, to)`, proposing `output`, and
/// finishing with `outcome` after `done_after` ticks of activity.
struct Scripted {
    name: &'static str,
    from: f64,
    to: f64,
    output: MotorOutput,
    done_after: Option<(u32, Outcome)>,
    ticks: u32,
    resets: u32,
}

impl Scripted {
    fn new(name: &'static str, from: f64, to: f64, output: MotorOutput) -> Self {
        Self {
            name,
            from,
            to,
            output,
            done_after: None,
            ticks: 0,
            resets: 0,
        }
    }
    fn finishing(mut self, after: u32, outcome: Outcome) -> Self {
        self.done_after = Some((after, outcome));
        self
    }
}

impl Behavior for Scripted {
    fn name(&self) -> &str {
        self.name
    }
    fn tick(&mut self, _mem: &mut (), inputs: &Inputs<'_>) -> Option<Step> {
        if !(inputs.now >= self.from && inputs.now < self.to) {
            return None;
        }
        self.ticks += 1;
        let fb = Feedback::new("scripted", inputs.now);
        match self.done_after {
            Some((n, o)) if self.ticks >= n => Some(Step::done(o, self.output, fb)),
            _ => Some(Step::running(self.output, fb)),
        }
    }
    fn reset(&mut self) {
        self.ticks = 0;
        self.resets += 1;
    }
}

#[test]
fn priority_picks_first_active_and_ticks_everyone() {
    let hi = Scripted::new("hi", 5.0, 10.0, MotorOutput::twist(0.0, 1.0));
    let lo = Scripted::new("lo", 0.0, 100.0, MotorOutput::twist(0.1, 0.0));
    let mut p = Priority::new("p", vec![Box::new(hi), Box::new(lo)]);
    let s = p.tick(&mut (), &Inputs::empty(1.0)).unwrap();
    assert_eq!(s.output, MotorOutput::twist(0.1, 0.0));
    assert_eq!(p.decision().winner, Some(1));
    assert_eq!(p.decision().active().collect::<Vec<_>>(), vec![1]);
    let s = p.tick(&mut (), &Inputs::empty(6.0)).unwrap();
    assert_eq!(s.output, MotorOutput::twist(0.0, 1.0));
    assert_eq!(p.decision().winner, Some(0));
    assert_eq!(p.decision().active().collect::<Vec<_>>(), vec![0, 1]);
    // Both proposals are recorded even though only one won.
    assert_eq!(p.decision().candidates[1].proposal, Some(MotorOutput::twist(0.1, 0.0)));
    assert!(p.tick(&mut (), &Inputs::empty(200.0)).is_none());
    assert_eq!(p.decision().winner, None);
}

#[test]
fn vector_sum_weights_and_merges() {
    let a = Scripted::new(
        "attract",
        0.0,
        10.0,
        MotorOutput::drive(DriveCommand::Vector(MotionVector::new(1.0, 0.0))),
    );
    let mut b_out = MotorOutput::drive(DriveCommand::Vector(MotionVector::new(0.0, 1.0)));
    b_out.aux = Auxiliary::with(Lights(true));
    let b = Scripted::new("tangent", 0.0, 5.0, b_out);
    let c = Scripted::new("twist", 0.0, 10.0, MotorOutput::twist(0.0, 0.2));
    let mut s = VectorSum::new(
        "sum",
        vec![(0.5, Box::new(a)), (0.5, Box::new(b)), (1.0, Box::new(c))],
        10.0,
        1.0,
    );
    let step = s.tick(&mut (), &Inputs::empty(1.0)).unwrap();
    let DriveCommand::Twist(t) = step.output.drive else {
        panic!()
    };
    // Vector sum (0.5, 0.5): heading 45°, |V| = 0.707 → v = 0.5, ω = π/4; plus twist 0.2.
    assert!((t.v - 0.5).abs() < 1e-12, "{t:?}");
    assert!((t.omega - (std::f64::consts::FRAC_PI_4 + 0.2)).abs() < 1e-12, "{t:?}");
    assert_eq!(step.output.aux.get::<Lights>(), Some(Lights(true)));
    let step = s.tick(&mut (), &Inputs::empty(7.0)).unwrap();
    let DriveCommand::Twist(t) = step.output.drive else {
        panic!()
    };
    assert!((t.v - 0.5).abs() < 1e-12 && (t.omega - 0.2).abs() < 1e-12);
    assert!(s.tick(&mut (), &Inputs::empty(20.0)).is_none());
}

#[test]
fn vector_sum_clips_to_max_speed() {
    let a = Scripted::new(
        "a",
        0.0,
        10.0,
        MotorOutput::drive(DriveCommand::Vector(MotionVector::new(3.0, 0.0))),
    );
    let mut s = VectorSum::new("sum", vec![(1.0, Box::new(a))], 0.2, 1.0);
    assert_eq!(
        s.tick(&mut (), &Inputs::empty(0.0)).unwrap().output.drive,
        DriveCommand::Twist(Twist::new(0.2, 0.0))
    );
}

#[test]
fn sequencer_follows_transitions_and_finishes() {
    let search = Scripted::new(
        "search",
        0.0,
        1e9,
        MotorOutput::drive(DriveCommand::Turn { omega: 0.3 }),
    )
    .finishing(3, Outcome::Completed);
    let approach = Scripted::new(
        "approach",
        0.0,
        1e9,
        MotorOutput::drive(DriveCommand::Straight { v: 0.1 }),
    )
    .finishing(2, Outcome::Docked);
    let mut seq = Sequencer::new("dock");
    seq.state(Box::new(search), false);
    seq.state(Box::new(approach), false);
    let mut phases = Vec::new();
    let mut t = 0.0;
    let outcome = loop {
        let s = seq.tick(&mut (), &Inputs::empty(t)).unwrap();
        phases.push(seq.current());
        t += 0.1;
        if let Status::Done(o) = s.status {
            break o;
        }
        assert!(t < 10.0);
    };
    assert_eq!(outcome, Outcome::Docked);
    // search runs 3 ticks (the third finishes it), approach 2 ticks.
    assert_eq!(phases, vec![0, 0, 1, 1, 1]);
    assert_eq!(seq.transition_count(), 1);
}

#[test]
fn sequencer_failure_goes_to_recovery_state() {
    let attempt = Scripted::new("attempt", 0.0, 1e9, MotorOutput::twist(0.1, 0.0))
        .finishing(1, Outcome::Failed(FailureReason::FailedToControl));
    let back_off = Scripted::new("back_off", 0.0, 1e9, MotorOutput::twist(-0.1, 0.0))
        .finishing(1, Outcome::Failed(FailureReason::RetriesExhausted));
    let mut seq = Sequencer::new("retry");
    let a = seq.state(Box::new(attempt), false);
    let b = seq.state(Box::new(back_off), false);
    seq.transitions(a, Next::Goto(b + 1), Next::Goto(b));
    let s = seq.tick(&mut (), &Inputs::empty(0.0)).unwrap();
    assert_eq!(s.status, Status::Running);
    assert_eq!(s.output.drive, DriveCommand::Stop, "a finishing state stops the base");
    assert_eq!(seq.current(), b);
    let s = seq.tick(&mut (), &Inputs::empty(0.1)).unwrap();
    assert_eq!(s.status, Status::Done(Outcome::Failed(FailureReason::RetriesExhausted)));
}

#[test]
fn latched_state_ignores_the_selector_until_done() {
    let normal = Scripted::new("normal", 0.0, 1e9, MotorOutput::twist(0.1, 0.0));
    let latched = Scripted::new("latched", 0.0, 1e9, MotorOutput::twist(0.0, 0.5)).finishing(4, Outcome::Completed);
    let after = Scripted::new("after", 0.0, 1e9, MotorOutput::twist(0.2, 0.0));
    // The selector wants "latched" at t ≥ 1 and "normal" at t ≥ 1.2.
    let mut seq = Sequencer::new("s").with_selector(|_: &mut (), inp: &Inputs<'_>, _cur: usize| {
        if inp.now >= 1.2 {
            Some(0)
        } else if inp.now >= 1.0 {
            Some(1)
        } else {
            None
        }
    });
    seq.state(Box::new(normal), false);
    let l = seq.state(Box::new(latched), true);
    seq.state(Box::new(after), false);
    seq.transitions(l, Next::Goto(2), Next::Finish);
    let mut visited = Vec::new();
    for k in 0..16 {
        let t = 0.9 + 0.1 * k as f64;
        seq.tick(&mut (), &Inputs::empty(t)).unwrap();
        visited.push(seq.current());
    }
    // 0.9: normal; 1.0..1.3: latched (4 ticks, selector ignored at 1.2 and 1.3), then the
    // transition table moves to "after", and the selector takes over again (→ normal).
    assert_eq!(&visited[..5], &[0, 1, 1, 1, 2]);
    assert_eq!(visited[5], 0);
}

/// Ends with a named event after `after` ticks.
struct Emits {
    name: &'static str,
    event: &'static str,
    after: u32,
    ticks: u32,
}

impl Behavior for Emits {
    fn name(&self) -> &str {
        self.name
    }
    fn tick(&mut self, _mem: &mut (), inputs: &Inputs<'_>) -> Option<Step> {
        self.ticks += 1;
        let fb = Feedback::new(self.name, inputs.now);
        let out = MotorOutput::twist(0.0, 0.3);
        Some(if self.ticks >= self.after {
            Step::event(self.event, out, fb)
        } else {
            Step::running(out, fb)
        })
    }
    fn reset(&mut self) {
        self.ticks = 0;
    }
}

#[test]
fn an_event_a_nested_sequence_finishes_on_is_routed_by_its_parent() {
    let emits = |name, event, after| {
        Box::new(Emits {
            name,
            event,
            after,
            ticks: 0,
        })
    };
    // inner: turn → (turned) → look → (seen: finish); the parent routes `seen` to approach.
    let mut inner = Sequencer::new("manoeuvre");
    let turn = inner.state(emits("turn", "turned", 2), false);
    let look = inner.state(emits("look", "seen", 1), false);
    inner.on_event(turn, "turned", Next::Goto(look));
    inner.on_event(look, "seen", Next::Finish);
    let mut outer = Sequencer::new("servo");
    let m = outer.state(Box::new(inner), true);
    let approach = outer.state(
        Box::new(Scripted::new("approach", 0.0, 1e9, MotorOutput::twist(0.1, 0.0))),
        false,
    );
    outer.transitions(m, Next::Finish, Next::Finish);
    outer.on_event(m, "seen", Next::Goto(approach));
    let mut at = Vec::new();
    for k in 0..5 {
        let s = outer.tick(&mut (), &Inputs::empty(0.1 * k as f64)).unwrap();
        assert_eq!(s.status, Status::Running, "tick {k}");
        at.push(outer.current());
    }
    // turn, turn (turned), look (seen, leaves the manoeuvre), approach, approach.
    assert_eq!(at, vec![m, m, approach, approach, approach]);
    assert_eq!(outer.last_event(), Some("seen"));

    // An event the table does not declare still ends the sequence as failing to control.
    let mut lone = Sequencer::new("lone");
    lone.state(emits("turn", "turned", 1), false);
    let s = lone.tick(&mut (), &Inputs::empty(0.0)).unwrap();
    assert_eq!(s.status, Status::Done(Outcome::Failed(FailureReason::FailedToControl)));
    assert!(lone.is_finished());
}

#[test]
fn a_sum_ends_with_its_first_childs_event_so_it_can_be_a_sequencer_state() {
    let near = Emits {
        name: "field",
        event: "near",
        after: 3,
        ticks: 0,
    };
    let push = Scripted::new("avoid", 0.0, 100.0, MotorOutput::twist(0.0, 0.1));
    let mut s = VectorSum::new("sum", vec![(1.0, Box::new(near)), (1.0, Box::new(push))], 1.0, 1.0);
    for now in [0.0, 0.1] {
        assert_eq!(s.tick(&mut (), &Inputs::empty(now)).unwrap().status, Status::Running);
    }
    let step = s.tick(&mut (), &Inputs::empty(0.2)).unwrap();
    assert_eq!(step.status, Status::Event("near"));
    // The sum's command that tick still adds both children's turns.
    let DriveCommand::Twist(t) = step.output.drive else {
        panic!()
    };
    assert!((t.omega - 0.4).abs() < 1e-12, "{t:?}");
}

#[test]
fn a_rear_first_sum_backs_along_the_vector() {
    let vector = |x, y| MotorOutput::drive(DriveCommand::Vector(MotionVector::new(x, y)));
    let twist = |s: &mut VectorSum| match s.tick(&mut (), &Inputs::empty(0.0)).unwrap().output.drive {
        DriveCommand::Twist(t) => t,
        other => panic!("{other:?}"),
    };
    // Straight behind: back straight at full speed, no turn.
    let mut s = VectorSum::new(
        "sum",
        vec![(1.0, Box::new(Scripted::new("a", 0.0, 1.0, vector(-0.2, 0.0))))],
        1.0,
        1.0,
    )
    .rear_first();
    let t = twist(&mut s);
    assert!((t.v + 0.2).abs() < 1e-12 && t.omega.abs() < 1e-12, "{t:?}");
    // The same vector leading with the front turns the robot round instead.
    let mut s = VectorSum::new(
        "sum",
        vec![(1.0, Box::new(Scripted::new("a", 0.0, 1.0, vector(-0.2, 0.0))))],
        1.0,
        1.0,
    );
    let t = twist(&mut s);
    assert!(
        t.v.abs() < 1e-12 && (t.omega.abs() - std::f64::consts::PI).abs() < 1e-12,
        "{t:?}"
    );
    // Behind and to the left: backing, the rear swings left, so the body turns right
    // (clockwise, ω < 0), by the vector's 45° off the rear axis.
    let mut s = VectorSum::new(
        "sum",
        vec![(1.0, Box::new(Scripted::new("a", 0.0, 1.0, vector(-0.1, 0.1))))],
        1.0,
        1.0,
    )
    .rear_first();
    let t = twist(&mut s);
    assert!(t.v < 0.0, "{t:?}");
    assert!((t.omega + std::f64::consts::FRAC_PI_4).abs() < 1e-12, "{t:?}");
}
