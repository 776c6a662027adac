//! Contact with the mother's body and the docking judge.
//!
//! The body is a rectangle at x ∈ [−body_length, 0], |y| ≤ body_half_width, with a pouch
//! (channel) |y| ≤ entrance_half, x ∈ [−depth, 0]. A robot backs in: when its footprint
//! first crosses the entrance plane x = 0 inside the opening, the judge compares its
//! lateral and heading errors with the profile's tolerances (Bujold: ±2 cm, ±5°) and, for
//! robots that must, its posture. Within tolerance it enters and slides down the channel
//! to the contact plates; outside it catches the entrance edge and is stuck (the paper's
//! failure mode). Elsewhere the body simply blocks motion.
//!
//! A docking cone ([`Cone`], Axel's central module, seed 000) is judged differently: only
//! the rover's leading arm enters it. The body (the wheels) is blocked by the module's
//! face; the arm's tip meets the cone's mouth, is guided by its walls, and docks when it
//! reaches the throat lying close enough to the cone's axis to slide into the seat. No
//! tolerance on the rover's pose is checked: what reaches the throat, and how, is the
//! tether's and the walls' doing ([`super::tether`]).

use super::world::DockGeometry;
use crate::geometry::{Pose2, wrap_angle};

/// Friction between the arm's tip and the cone's flat face (our estimate): a tip that
/// meets the face outside the mouth slides to the mouth only if the tether's pull along
/// the face beats this share of its push into it.
pub const FACE_FRICTION: f64 = 0.75;

/// A docking cone entered by a tether-pulled leading arm, in the dock frame (mouth at
/// x = 0 on the axis, throat at x = −depth), with the arm that enters it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cone {
    /// Half-width of the round mouth, m.
    pub mouth_half: f64,
    /// From the mouth to the throat, m.
    pub depth: f64,
    /// Half-width of the throat, m.
    pub throat_half: f64,
    /// Height of the cone's axis above the ground, m.
    pub axis_height: f64,
    /// The station tipped forward, rad.
    pub tilt: f64,
    /// Length of the seat's bore behind the throat, m.
    pub seat_length: f64,
    /// Where the tether is anchored, behind the mouth on the axis, m.
    pub anchor_depth: f64,
    /// The rover's arm, from its axle to its tip, m.
    pub arm: f64,
    /// Radius of the arm's tip, m.
    pub tip_radius: f64,
    /// Height of the arm's tip above the ground, m.
    pub tip_height: f64,
}

impl Cone {
    /// The arm's tip of a rover at `pose`, in the world.
    pub fn tip(&self, pose: &Pose2) -> (f64, f64) {
        pose.to_world(self.arm, 0.0)
    }

    /// The largest angle between the arm and the cone's axis at which its tip still
    /// slides into the seat: the throat's clearance around the tip over the seat's length.
    pub fn seat_clearance(&self) -> f64 {
        ((self.throat_half - self.tip_radius) / self.seat_length).atan()
    }

    /// Half-width of the cone's opening at depth `x` (x ≤ 0), m.
    fn half_width(&self, x: f64) -> f64 {
        let slope = (self.mouth_half - self.throat_half) / self.depth;
        self.mouth_half + x.clamp(-self.depth, 0.0) * slope
    }

    /// The arm's angle to the cone's axis (its tip pointing in, −x) at `pose`, rad.
    pub fn arm_angle(pose: &Pose2) -> f64 {
        wrap_angle(pose.theta - std::f64::consts::PI)
    }

    /// Whether a tip meeting the face plane outside the mouth's height slides into the
    /// mouth: the tether pulls the tip from its height toward the anchor on the axis, and
    /// the station's forward tilt turns the face so the pull along it grows for a tip
    /// above the mouth (and shrinks for one below).
    fn slides_in(&self) -> bool {
        let above = self.tip_height - self.axis_height;
        let reach = self.mouth_half - self.tip_radius;
        if above.abs() <= reach {
            return true;
        }
        let descent = (above.abs() / self.anchor_depth.max(1e-3)).atan();
        let along = if above > 0.0 {
            descent + self.tilt
        } else {
            descent - self.tilt
        };
        along.tan() > FACE_FRICTION
    }
}

/// Result of moving the robot one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Contact {
    /// Moved freely.
    Free,
    /// The body blocked the move (the pose is unchanged).
    Blocked,
    /// In the pouch, within tolerance.
    Inside,
    /// Reached the contact plates (a cone: the arm's tip seated in the throat).
    Docked,
    /// A cone's wall guided the arm's tip: the rover is at this pose instead.
    Guided(Pose2),
    /// Caught the entrance edge.
    Stuck {
        /// Lateral error at the entrance, m.
        lateral: f64,
        /// Heading error at the entrance, rad.
        heading: f64,
    },
}

/// The robot's footprint corners (rear-right, rear-left, front-left, front-right).
pub fn footprint(pose: &Pose2, length: f64, width: f64) -> [(f64, f64); 4] {
    let (l, w) = (length / 2.0, width / 2.0);
    [(-l, -w), (-l, w), (l, w), (l, -w)].map(|(a, b)| pose.to_world(a, b))
}

fn in_body(g: &DockGeometry, x: f64, y: f64) -> bool {
    x < 0.0 && x > -g.body_length && y.abs() < g.body_half_width
}

/// True when a robot of `length × width` at `pose` overlaps the mother's body (or, for an
/// open dock, touches the target other than by docking): a start no proctor could place.
pub fn overlaps(g: &DockGeometry, pose: &Pose2, length: f64, width: f64) -> bool {
    if g.open {
        return matches!(judge_open(g, pose, length, width), Contact::Stuck { .. });
    }
    let robot_in_body = footprint(pose, length, width).iter().any(|&(x, y)| in_body(g, x, y));
    let body_in_robot = [(0.0, g.body_half_width), (0.0, -g.body_half_width)]
        .iter()
        .any(|&(x, y)| {
            let (a, b) = pose.to_local(x, y);
            a.abs() < length / 2.0 && b.abs() < width / 2.0
        });
    robot_in_body || body_in_robot
}

/// `pose`, or, when it overlaps the body (a proctor's placement jittered into it), the
/// pose slid straight out from the entrance in 5 mm steps until it is clear: the
/// proctor's hand meets the body. Gives up after half a metre.
pub fn slid_clear(g: &DockGeometry, mut pose: Pose2, length: f64, width: f64) -> Pose2 {
    let (s, c) = pose.y.atan2(pose.x).sin_cos();
    for _ in 0..100 {
        if !overlaps(g, &pose, length, width) {
            break;
        }
        pose.x += 0.005 * c;
        pose.y += 0.005 * s;
    }
    pose
}

/// Judges a move from `from` to `to`.
pub fn judge(
    g: &DockGeometry,
    inside: bool,
    from: &Pose2,
    to: &Pose2,
    length: f64,
    width: f64,
    lowered: bool,
) -> Contact {
    if g.open {
        return judge_open(g, to, length, width);
    }
    if let Some(c) = &g.cone {
        return judge_cone(g, c, from, to, length, width);
    }
    let rear = to.to_world(-length / 2.0, 0.0);
    if inside {
        let backing = to.x < from.x;
        return if rear.0 > 0.0 {
            Contact::Free // drove out of the pouch
        } else if backing && rear.0 <= -g.depth + 0.005 {
            Contact::Docked
        } else {
            Contact::Inside
        };
    }
    let corners = footprint(to, length, width);
    let crosses = corners.iter().any(|&(x, y)| in_body(g, x, y));
    if !crosses {
        return Contact::Free;
    }
    // Reaching the entrance plane at the opening, rear first (a rear corner may touch the
    // edge a little before the rear centre crosses).
    let near_opening = rear.1.abs() < g.entrance_half + width / 2.0;
    let rear_first = rear.0 < 0.03 && rear.0 < to.x;
    if near_opening && rear_first {
        let lateral = rear.1;
        let heading = crate::geometry::wrap_angle(to.theta);
        let aligned = lateral.abs() <= g.tol_lateral && heading.abs() <= g.tol_heading;
        if aligned && (lowered || !g.needs_lowered) {
            return Contact::Inside;
        }
        return Contact::Stuck { lateral, heading };
    }
    Contact::Blocked
}

/// A cone: the body meeting the module is blocked; the arm's tip crossing the mouth's
/// plane outside the mouth (beside it, or above or below it without sliding in) catches
/// on the flat face; inside, the walls hold the tip (the rover pivots about its axle on
/// its free wheels); at the throat the arm seats if it lies within the seat's clearance
/// of the axis, and otherwise pushes against the cone (seed 000 §V-C: stuck).
fn judge_cone(g: &DockGeometry, c: &Cone, from: &Pose2, to: &Pose2, length: f64, width: f64) -> Contact {
    let body_hits = footprint(to, length, width).iter().any(|&(x, y)| in_body(g, x, y))
        || [(0.0, g.body_half_width), (0.0, -g.body_half_width)]
            .iter()
            .any(|&(x, y)| {
                let (a, b) = to.to_local(x, y);
                a.abs() < length / 2.0 && b.abs() < width / 2.0
            });
    if body_hits {
        return Contact::Blocked;
    }
    let (was, tip) = (c.tip(from), c.tip(to));
    let psi = Cone::arm_angle(to);
    if tip.0 > 0.0 {
        return Contact::Free;
    }
    if was.0 > 0.0 {
        // Crossing the mouth's plane: beside the mouth, or at a height the pull cannot
        // slide into it, the tip catches on the flat face.
        let y = was.1 + (tip.1 - was.1) * was.0 / (was.0 - tip.0);
        if y.abs() > c.mouth_half - c.tip_radius || !c.slides_in() {
            return Contact::Stuck {
                lateral: y,
                heading: psi,
            };
        }
    }
    if tip.0 <= -c.depth {
        return if psi.abs() <= c.seat_clearance() && tip.1.abs() <= c.throat_half - c.tip_radius {
            Contact::Docked
        } else {
            Contact::Stuck {
                lateral: tip.1,
                heading: psi,
            }
        };
    }
    // Inside the cone: a wall holds the tip, the rover pivoting about its axle.
    let room = c.half_width(tip.0) - c.tip_radius;
    if tip.1.abs() <= room {
        return Contact::Free;
    }
    let want = room.copysign(tip.1);
    let s = ((want - to.y) / c.arm).clamp(-1.0, 1.0);
    let theta = if to.theta.cos() < 0.0 {
        std::f64::consts::PI - s.asin()
    } else {
        s.asin()
    };
    Contact::Guided(Pose2::new(to.x, to.y, theta))
}

/// An open dock (a target on the ground at the origin, entering the robot's rear): docked
/// when the target reaches the rear within the socket's mouth and the robot is within
/// tolerance; reaching it out of tolerance, or touching the target with any other part of
/// the body, is a collision.
fn judge_open(g: &DockGeometry, to: &Pose2, length: f64, width: f64) -> Contact {
    let (lx, ly) = to.to_local(0.0, 0.0);
    let rear = -length / 2.0;
    let heading = crate::geometry::wrap_angle(to.theta);
    // The target meets the socket's mouth (DockGeometry::mouth_reach).
    if lx >= rear - g.mouth_reach(heading) && lx <= rear + g.depth && ly.abs() <= g.entrance_half {
        return if ly.abs() <= g.tol_lateral && heading.abs() <= g.tol_heading {
            Contact::Docked
        } else {
            Contact::Stuck { lateral: ly, heading }
        };
    }
    if let Some([x0, x1, y0, y1]) = g.target_extent {
        // The target's footprint corners inside the robot, or the robot's corners inside
        // the target's footprint.
        let target_in_robot = [(x0, y0), (x0, y1), (x1, y0), (x1, y1), (0.0, 0.0)]
            .iter()
            .any(|&(x, y)| {
                let (a, b) = to.to_local(x, y);
                a.abs() < length / 2.0 && b.abs() < width / 2.0
            });
        let robot_in_target = footprint(to, length, width)
            .iter()
            .any(|&(x, y)| x > x0 && x < x1 && y > y0 && y < y1);
        if target_in_robot || robot_in_target {
            return Contact::Stuck {
                lateral: ly,
                heading: crate::geometry::wrap_angle(to.theta),
            };
        }
    }
    Contact::Free
}

#[cfg(test)]
mod tests {
    use super::*;

    fn g() -> DockGeometry {
        DockGeometry {
            body_length: 1.2,
            body_half_width: 0.45,
            entrance_half: 0.10,
            depth: 0.45,
            tol_lateral: 0.02,
            tol_heading: 5f64.to_radians(),
            needs_lowered: true,
            open: false,
            target_extent: None,
            cone: None,
        }
    }

    #[test]
    fn starts_overlapping_the_body_are_recognised() {
        let (l, w) = (0.4, 0.18);
        // Paper position 1 (0.33 m from the rear, 70° off the axis) facing the flap: clear.
        assert!(!overlaps(&g(), &Pose2::new(0.27, -0.50, 110f64.to_radians()), l, w));
        assert!(!overlaps(&g(), &Pose2::new(1.0, 0.0, 0.0), l, w));
        // Beside the gate turned 45°: a rear corner is inside the body.
        assert!(overlaps(&g(), &Pose2::new(0.2, -0.524, -44.5f64.to_radians()), l, w));
        // Straddling the body's corner diagonally: no robot corner inside the body, the
        // body's corner inside the robot.
        let diagonal = Pose2::new(0.0, -0.45, 45f64.to_radians());
        assert!(!footprint(&diagonal, 0.4, 0.1).iter().any(|&(x, y)| in_body(&g(), x, y)));
        assert!(overlaps(&g(), &diagonal, 0.4, 0.1));
        // Inside the body outright.
        assert!(overlaps(&g(), &Pose2::new(-0.6, 0.0, 0.0), l, w));
        // A jittered start just inside is slid out radially, by less than 5 mm past contact;
        // a clear one is left alone.
        let jittered = Pose2::new(0.2, -0.524, -44.5f64.to_radians());
        let slid = slid_clear(&g(), jittered, l, w);
        assert!(!overlaps(&g(), &slid, l, w) && slid.theta == jittered.theta);
        let r = jittered.x.hypot(jittered.y);
        let back = Pose2::new(
            slid.x - 0.005 * jittered.x / r,
            slid.y - 0.005 * jittered.y / r,
            slid.theta,
        );
        assert!(overlaps(&g(), &back, l, w), "one step back still overlaps");
        let clear = Pose2::new(1.0, 0.0, 0.0);
        assert_eq!(slid_clear(&g(), clear, l, w), clear);
    }

    #[test]
    fn aligned_backing_enters_and_docks() {
        let from = Pose2::new(0.21, 0.01, 0.02);
        let to = Pose2::new(0.195, 0.01, 0.02);
        assert_eq!(judge(&g(), false, &from, &to, 0.4, 0.18, true), Contact::Inside);
        assert_eq!(
            judge(&g(), true, &to, &Pose2::new(-0.26, 0.01, 0.02), 0.4, 0.18, true),
            Contact::Docked
        );
        // Leaving: driving forward out of the pouch never "docks", and exits at the entrance.
        let deep = Pose2::new(-0.26, 0.0, 0.0);
        assert_eq!(
            judge(&g(), true, &deep, &Pose2::new(-0.25, 0.0, 0.0), 0.4, 0.18, true),
            Contact::Inside
        );
        assert_eq!(
            judge(&g(), true, &deep, &Pose2::new(0.21, 0.0, 0.0), 0.4, 0.18, true),
            Contact::Free
        );
    }

    #[test]
    fn misaligned_or_raised_gets_stuck() {
        let from = Pose2::new(0.21, 0.04, 0.0);
        let to = Pose2::new(0.195, 0.04, 0.0);
        assert!(matches!(
            judge(&g(), false, &from, &to, 0.4, 0.18, true),
            Contact::Stuck { .. }
        ));
        let to = Pose2::new(0.195, 0.0, 0.2);
        assert!(matches!(
            judge(&g(), false, &from, &to, 0.4, 0.18, true),
            Contact::Stuck { .. }
        ));
        let to = Pose2::new(0.195, 0.0, 0.0);
        assert!(
            matches!(judge(&g(), false, &from, &to, 0.4, 0.18, false), Contact::Stuck { .. }),
            "must lower first"
        );
    }

    fn open() -> DockGeometry {
        DockGeometry {
            body_length: 0.0,
            body_half_width: 0.0,
            entrance_half: 0.06,
            depth: 0.1,
            tol_lateral: 0.04,
            tol_heading: 20f64.to_radians(),
            needs_lowered: false,
            open: true,
            target_extent: Some([-0.2, 0.035, -0.06, 0.06]),
            cone: None,
        }
    }

    #[test]
    fn open_dock_docks_aligned_and_collides_otherwise() {
        // Rear 0.4 m behind the centre of a 0.8 m robot, the ball at the origin.
        let at = |x: f64, y: f64, theta: f64| {
            judge(
                &open(),
                false,
                &Pose2::default(),
                &Pose2::new(x, y, theta),
                0.8,
                0.4,
                false,
            )
        };
        assert_eq!(at(0.405, 0.01, 0.1), Contact::Docked, "reaching the ball, aligned");
        assert!(
            matches!(at(0.405, 0.0, 0.52), Contact::Stuck { .. }),
            "same place, heading 30°"
        );
        assert!(
            matches!(at(-0.1, 0.1, 1.57), Contact::Stuck { .. }),
            "driving over the pyramid sideways"
        );
        assert_eq!(at(1.0, 0.0, 0.0), Contact::Free, "far away");
    }

    #[test]
    fn open_dock_mouth_reaches_further_for_angled_arrivals() {
        // The ball 6 cm behind the rear plane (rear 0.4 m behind the centre), on the axis.
        let at = |theta: f64| {
            let (c, s) = (theta.cos(), theta.sin());
            judge(
                &open(),
                false,
                &Pose2::default(),
                &Pose2::new(0.46 * c, 0.46 * s, theta),
                0.8,
                0.4,
                false,
            )
        };
        assert!((open().mouth_reach(0.0) - 0.05).abs() < 1e-12);
        // Aligned, the ball's front is still 2.5 cm short of the plane: free.
        assert_eq!(at(0.0), Contact::Free);
        // At 16° (within the 20° tolerance) the footprint's front corner reaches the plane
        // first: that is the target meeting the mouth, so it docks, not a collision.
        assert_eq!(at(-16f64.to_radians()), Contact::Docked);
    }

    #[test]
    fn body_blocks_elsewhere() {
        let to = Pose2::new(0.15, 0.35, 0.0);
        assert_eq!(judge(&g(), false, &to, &to, 0.4, 0.18, true), Contact::Blocked);
        assert_eq!(
            judge(&g(), false, &to, &Pose2::new(1.0, 0.0, 0.0), 0.4, 0.18, true),
            Contact::Free
        );
    }

    fn cone_dock(tilt_deg: f64) -> DockGeometry {
        DockGeometry {
            body_length: 1.0,
            body_half_width: 0.5,
            entrance_half: 0.10,
            depth: 0.10,
            tol_lateral: 0.1,
            tol_heading: 0.1,
            needs_lowered: false,
            open: false,
            target_extent: None,
            cone: Some(Cone {
                mouth_half: 0.10,
                depth: 0.10,
                throat_half: 0.0534,
                axis_height: 0.15,
                tilt: tilt_deg.to_radians(),
                seat_length: 0.27,
                anchor_depth: 0.25,
                arm: 0.55,
                tip_radius: 0.03,
                tip_height: 0.32,
            }),
        }
    }

    /// A rover whose arm's tip is at (`x`, `y`), its arm `psi_deg` off the cone's axis.
    fn tip_at(x: f64, y: f64, psi_deg: f64) -> Pose2 {
        let th = std::f64::consts::PI + psi_deg.to_radians();
        Pose2::new(x - 0.55 * th.cos(), y - 0.55 * th.sin(), th)
    }

    #[test]
    fn a_cone_seats_an_aligned_arm_and_refuses_a_slanted_one() {
        let g = cone_dock(5.0);
        let c = g.cone.unwrap();
        assert!((c.seat_clearance().to_degrees() - 4.95).abs() < 0.05);
        let at = |x: f64, y: f64, psi: f64| {
            judge(
                &g,
                false,
                &tip_at(x + 0.004, y, psi),
                &tip_at(x, y, psi),
                0.7,
                1.1,
                false,
            )
        };
        assert_eq!(at(0.05, 0.0, 0.0), Contact::Free, "approaching");
        assert_eq!(at(-0.05, 0.0, 2.0), Contact::Free, "in the cone, clear of its walls");
        assert_eq!(at(-0.101, 0.01, 4.0), Contact::Docked);
        assert!(
            matches!(at(-0.101, 0.01, 6.0), Contact::Stuck { .. }),
            "pushes on the cone"
        );
        // Near a wall: the wall turns the rover about its axle to hold the tip.
        match at(-0.05, 0.07, 0.0) {
            Contact::Guided(p) => {
                let tip = c.tip(&p);
                assert!(tip.1 <= c.half_width(tip.0) - c.tip_radius + 1e-3, "{tip:?}");
            }
            other => panic!("{other:?}"),
        }
        // The tip crossing the face plane beside the mouth catches on the face.
        assert!(matches!(at(-0.001, 0.2, 0.0), Contact::Stuck { .. }));
        // The wheels meet the face: blocked.
        assert_eq!(
            judge(
                &g,
                false,
                &Pose2::new(0.4, 0.0, 0.0),
                &Pose2::new(0.3, 0.0, 0.0),
                0.7,
                1.1,
                false
            ),
            Contact::Blocked
        );
    }

    #[test]
    fn an_upright_station_snags_the_tip_on_its_face() {
        let up = cone_dock(0.0);
        let tilted = cone_dock(5.0);
        let cross = |g: &DockGeometry| {
            judge(
                g,
                false,
                &tip_at(0.002, 0.0, 0.0),
                &tip_at(-0.002, 0.0, 0.0),
                0.7,
                1.1,
                false,
            )
        };
        assert!(matches!(cross(&up), Contact::Stuck { .. }));
        assert_eq!(cross(&tilted), Contact::Free);
    }
}
