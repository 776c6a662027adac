//! The legs every robot's manoeuvres are made of (`behaviors::common::motion`) and the
//! common search (`behaviors::common::search`), each driven alone with scripted inputs
//! on a scripted base that moves by what the leg commands.

use marsupial::behaviors::common::motion::*;
use marsupial::geometry::{Pose2, Twist, integrate_twist, wrap_angle};
use marsupial::schemas::{Behavior, DriveCommand, FailureReason, Feedback, Inputs, MotorOutput, Outcome, Status, Step};

/// A base driven by script: each tick the test moves it; it records what the legs
/// command.
#[derive(Default)]
pub struct Base {
    pub now: f64,
    pub odo: Pose2,
    pub ends: u32,
}

impl Motion for Base {
    fn now(&self) -> f64 {
        self.now
    }
    fn odo(&self) -> Pose2 {
        self.odo
    }
    fn hold(&mut self, phase: &'static str) -> Step {
        Step::running(MotorOutput::stop(), Feedback::new(phase, self.now))
    }
    fn turn_toward(&mut self, heading: f64, tolerance: Option<f64>, phase: &'static str) -> Option<Step> {
        let err = wrap_angle(heading - self.odo.theta);
        (err.abs() >= tolerance.unwrap_or(0.05)).then(|| {
            Step::running(
                MotorOutput::drive(DriveCommand::Turn { omega: err }),
                Feedback::new(phase, 0.0),
            )
        })
    }
    fn straight(&mut self, v: f64, phase: &'static str) -> Step {
        Step::running(
            MotorOutput::drive(DriveCommand::Straight { v }),
            Feedback::new(phase, 0.0),
        )
    }
    fn back_off(&mut self, speed: f64, phase: &'static str) -> Step {
        self.straight(-speed, phase)
    }
}

/// Runs `leaf` on `base` for up to `ticks` ticks of 0.1 s, moving the base by what
/// it commands; returns the status that ended it and the ticks it took.
pub fn run<B: Behavior<Base>>(leaf: &mut B, base: &mut Base, ticks: usize) -> (Status, usize) {
    leaf.enter(base, &Inputs::empty(base.now));
    for i in 0..ticks {
        base.now += 0.1;
        let step = leaf.tick(base, &Inputs::empty(base.now)).expect("a leg always steps");
        if step.status != Status::Running {
            return (step.status, i + 1);
        }
        let twist = match step.output.drive {
            DriveCommand::Turn { omega } => Twist::new(0.0, omega),
            DriveCommand::Straight { v } => Twist::new(v, 0.0),
            _ => Twist::new(0.0, 0.0),
        };
        base.odo = integrate_twist(&base.odo, &twist, 0.1);
    }
    (Status::Running, ticks)
}

#[test]
fn turn_to_reaches_the_heading_and_ends_with_its_event() {
    let mut base = Base::default();
    let aim: AimFn<Base> = Box::new(|_| Aim::Heading(1.0));
    let mut leg = TurnTo::new("turn", aim, Some(0.02), "turned").hooks(Hooks {
        end: |b: &mut Base| b.ends += 1,
        ..Hooks::default()
    });
    let (status, ticks) = run(&mut leg, &mut base, 200);
    assert_eq!(status, Status::Event("turned"));
    assert!((base.odo.theta - 1.0).abs() < 0.02, "{}", base.odo.theta);
    assert!(ticks > 5, "a proportional turn takes time: {ticks}");
    assert_eq!(base.ends, 1, "the end hook ran once");
}

#[test]
fn turn_to_gives_up_after_its_timeout_and_holds_without_an_aim() {
    // A heading it never reaches (the base does not move: run() is bypassed).
    let mut base = Base::default();
    let aim: AimFn<Base> = Box::new(|_| Aim::Heading(2.0));
    let mut leg = TurnTo::new("turn", aim, Some(0.01), "turned").timeout(0.5);
    leg.enter(&mut base, &Inputs::empty(0.0));
    let mut ended = None;
    for i in 1..20 {
        base.now = i as f64 * 0.1;
        let now = base.now;
        let step = leg.tick(&mut base, &Inputs::empty(now)).unwrap();
        if step.status != Status::Running {
            ended = Some((i, step.status));
            break;
        }
    }
    assert_eq!(
        ended,
        Some((6, Status::Event("turned"))),
        "ends on the first tick past 0.5 s"
    );
    let aim: AimFn<Base> = Box::new(|_| Aim::Hold);
    let mut idle = TurnTo::new("idle", aim, None, "turned");
    let (status, _) = run(&mut idle, &mut base, 30);
    assert_eq!(status, Status::Running, "no aim: it stands and waits");
}

#[test]
fn back_off_covers_its_distance_or_its_time() {
    let mut base = Base::default();
    let mut leg = BackOff::new("away", Distance::Fixed(0.3), 0.1, End::Event("done"));
    let (status, ticks) = run(&mut leg, &mut base, 100);
    assert_eq!(status, Status::Event("done"));
    assert!((base.odo.x + 0.3).abs() < 1e-9, "backed 0.3 m: {}", base.odo.x);
    assert_eq!(ticks, 31, "30 ticks of 1 cm, then the end");
    // The same leg bounded by 1 s ends short, failed for the memory's reason.
    let mut base = Base::default();
    let why: fn(&Base) -> FailureReason = |_| FailureReason::TargetLost;
    let mut leg = BackOff::new("give_up", Distance::AtEntry(Box::new(|_| 0.3)), 0.1, End::Fail(why)).timeout(1.0);
    let (status, _) = run(&mut leg, &mut base, 100);
    assert_eq!(status, Status::Done(Outcome::Failed(FailureReason::TargetLost)));
    assert!(base.odo.x > -0.15, "stopped by the time limit: {}", base.odo.x);
}

#[test]
fn turn_drive_turn_reaches_a_staging_pose_from_many_starts() {
    // The three legs in sequence, as a profile's sequencer runs them.
    let target = Pose2::new(1.0, 0.5, 0.3);
    for (x, y, th) in [(0.0, 0.0, 0.0), (2.0, -1.0, 2.5), (1.5, 1.5, -2.0), (-0.5, 0.4, 3.0)] {
        let mut base = Base {
            odo: Pose2::new(x, y, th),
            ..Base::default()
        };
        let face_aim: AimFn<Base> = Box::new(move |b| face(&b.odo, &target, 0.03));
        let (s, _) = run(&mut TurnTo::new("f", face_aim, Some(0.01), "faced"), &mut base, 400);
        assert!(matches!(s, Status::Event("faced" | "arrived")), "{s:?}");
        let mut drive = DriveAbeam::new("d", Box::new(move |_| Some(target)), 0.1, 0.1, 0.03, 0.005);
        let (s, _) = run(&mut drive, &mut base, 400);
        assert!(matches!(s, Status::Event("abeam" | "arrived")), "{s:?}");
        let align: AimFn<Base> = Box::new(move |_| Aim::Heading(target.theta));
        let (s, _) = run(&mut TurnTo::new("a", align, Some(0.01), "aligned"), &mut base, 400);
        assert_eq!(s, Status::Event("aligned"));
        let off = base.odo.distance(&target);
        assert!(off < 0.03, "from ({x}, {y}, {th}) ended {off} m off");
        assert!(wrap_angle(base.odo.theta - target.theta).abs() < 0.01);
    }
}

/// The common search on a scripted robot.
mod search {
    use super::Base;
    use marsupial::behaviors::common::motion::Motion;
    use marsupial::behaviors::common::search::*;
    use marsupial::geometry::Pose2;
    use marsupial::schemas::{Behavior, DriveCommand, FailureReason, Inputs, MotorOutput, Outcome, Status, Step};

    /// A scripted robot: the target appears at `seen_at`.
    #[derive(Default)]
    struct Robot {
        base: Base,
        seen_at: Option<f64>,
        unseen: u32,
        clock: Option<f64>,
    }

    impl Motion for Robot {
        fn now(&self) -> f64 {
            self.base.now
        }
        fn odo(&self) -> Pose2 {
            self.base.odo
        }
        fn hold(&mut self, phase: &'static str) -> Step {
            self.base.hold(phase)
        }
        fn turn_toward(&mut self, h: f64, tol: Option<f64>, phase: &'static str) -> Option<Step> {
            self.base.turn_toward(h, tol, phase)
        }
        fn straight(&mut self, v: f64, phase: &'static str) -> Step {
            self.base.straight(v, phase)
        }
        fn back_off(&mut self, speed: f64, phase: &'static str) -> Step {
            self.base.back_off(speed, phase)
        }
    }

    impl Searching for Robot {
        fn acquired(&mut self, phase: &'static str) -> Option<Step> {
            let seen = self.seen_at.is_some_and(|t| self.base.now >= t);
            seen.then(|| self.base.hold(phase).with_event("acquired"))
        }
        fn search_side(&self) -> f64 {
            -1.0
        }
        fn lost_reason(&self) -> FailureReason {
            FailureReason::TargetNeverDetected
        }
        fn search_turn(&mut self, turn: DriveCommand, phase: &'static str) -> Step {
            Step::running(MotorOutput::drive(turn), marsupial::schemas::Feedback::new(phase, 0.0))
        }
        fn count_unseen(&mut self) -> u32 {
            self.unseen += 1;
            self.unseen
        }
        fn search_clock(&mut self) -> Option<&mut Option<f64>> {
            Some(&mut self.clock)
        }
    }

    fn params() -> SearchParams {
        SearchParams {
            rate: 0.5,
            first_sweep: 0.5,
            doubling: true,
            grace_frames: 0,
            settle_s: 0.0,
            resume_clock: false,
            timeout_s: 10.0,
        }
    }

    /// Ticks `leaf` at 0.1 s until it ends; returns each tick's turn rate and the end.
    fn run(leaf: &mut Search<Robot>, r: &mut Robot, ticks: usize) -> (Vec<f64>, Status) {
        leaf.enter(r, &Inputs::empty(r.base.now));
        let mut rates = Vec::new();
        for _ in 0..ticks {
            r.base.now += 0.1;
            let step = leaf.tick(r, &Inputs::empty(r.base.now)).unwrap();
            if step.status != Status::Running {
                return (rates, step.status);
            }
            rates.push(match step.output.drive {
                DriveCommand::Turn { omega } => omega,
                _ => 0.0,
            });
        }
        (rates, Status::Running)
    }

    #[test]
    fn doubling_search_alternates_from_the_side_asked_and_times_out() {
        let mut r = Robot::default();
        let (rates, end) = run(&mut Search::new("s", params(), ()), &mut r, 200);
        assert_eq!(end, Status::Done(Outcome::Failed(FailureReason::TargetNeverDetected)));
        assert_eq!(rates.len(), 100, "10 s of searching");
        assert!(
            rates[..9].iter().all(|&w| w == -0.5),
            "first sweep clockwise: {:?}",
            &rates[..9]
        );
        assert!(rates[11..29].iter().all(|&w| w == 0.5), "then back, twice as long");
    }

    #[test]
    fn acquisition_ends_it_and_grace_and_settle_hold_still_first() {
        let mut r = Robot {
            seen_at: Some(1.05),
            ..Robot::default()
        };
        let p = SearchParams {
            grace_frames: 3,
            settle_s: 0.45,
            ..params()
        };
        let (rates, end) = run(&mut Search::new("s", p, ()), &mut r, 200);
        assert_eq!(end, Status::Event("acquired"));
        assert_eq!(rates.len(), 10);
        // 3 grace ticks; then 0.45 s from entry has passed only at 0.5 s: one more hold.
        assert_eq!(&rates[..4], &[0.0; 4], "{rates:?}");
        assert!(rates[4..].iter().all(|&w| w == -0.5));
    }

    #[test]
    fn a_resumed_clock_keeps_counting_across_entries() {
        let mut r = Robot::default();
        let p = SearchParams {
            resume_clock: true,
            timeout_s: 0.95,
            ..params()
        };
        let mut leaf = Search::new("s", p, ());
        let (first, end) = run(&mut leaf, &mut r, 6);
        assert_eq!((first.len(), end), (6, Status::Running));
        // Re-entered (a glimpse came and went): the clock runs on from the first entry.
        let (second, end) = run(&mut leaf, &mut r, 20);
        assert_eq!(end, Status::Done(Outcome::Failed(FailureReason::TargetNeverDetected)));
        assert_eq!(second.len(), 4, "0.95 s from the first tick in all: {second:?}");
    }
}
