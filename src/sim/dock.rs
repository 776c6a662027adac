//! Contact with the mother's body and the docking judge.
//!
//! The body is a rectangle at x ∈ [−body_length, 0], |y| ≤ body_half_width, with a pouch
//! (channel) |y| ≤ entrance_half, x ∈ [−depth, 0]. A robot backs in: when its footprint
//! first crosses the entrance plane x = 0 inside the opening, the judge compares its
//! lateral and heading errors with the profile's tolerances (Bujold: ±2 cm, ±5°) and, for
//! robots that must, its posture. Within tolerance it enters and slides down the channel
//! to the contact plates; outside it catches the entrance edge and is stuck (the paper's
//! failure mode). Elsewhere the body simply blocks motion.

use super::world::DockGeometry;
use crate::geometry::Pose2;

/// Result of moving the robot one step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Contact {
    /// Moved freely.
    Free,
    /// The body blocked the move (the pose is unchanged).
    Blocked,
    /// In the pouch, within tolerance.
    Inside,
    /// Reached the contact plates.
    Docked,
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
        // A target lying on the ground: "docked" when the robot's rear reaches it aligned.
        let rear = to.to_world(-length / 2.0, 0.0);
        let heading = crate::geometry::wrap_angle(to.theta);
        if rear.0 <= 0.02 && rear.0 > -0.1 && rear.1.abs() <= g.entrance_half {
            return if rear.1.abs() <= g.tol_lateral && heading.abs() <= g.tol_heading {
                Contact::Docked
            } else {
                Contact::Stuck {
                    lateral: rear.1,
                    heading,
                }
            };
        }
        return Contact::Free;
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
        }
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

    #[test]
    fn body_blocks_elsewhere() {
        let to = Pose2::new(0.15, 0.35, 0.0);
        assert_eq!(judge(&g(), false, &to, &to, 0.4, 0.18, true), Contact::Blocked);
        assert_eq!(
            judge(&g(), false, &to, &Pose2::new(1.0, 0.0, 0.0), 0.4, 0.18, true),
            Contact::Free
        );
    }
}
