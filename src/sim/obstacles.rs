//! What a robot can bump into and a range finder can see, in the world's ground plane.
//!
//! [`Obstacles`] holds the footprints of the scenario's boxes that stand low enough to hit
//! the robot's body (the robot cannot drive through them: a move into one ends the run as
//! a collision), and the outline every range beam is cast against: those boxes' sides and
//! the dock's own body (the mother's walls and pouch, or an open dock's target). A range
//! finder therefore sees the dock too, as a real one would; a composition that must not
//! be repelled by it hands over to a state without obstacle avoidance near the dock.

use super::dock::footprint;
use super::world::DockGeometry;
use crate::geometry::Pose2;

/// An axis-aligned footprint on the ground, m (x0, y0, x1, y1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Footprint {
    /// Smallest x.
    pub x0: f64,
    /// Smallest y.
    pub y0: f64,
    /// Largest x.
    pub x1: f64,
    /// Largest y.
    pub y1: f64,
}

impl Footprint {
    /// The footprint's outline as four segments.
    fn outline(&self) -> [[f64; 4]; 4] {
        let Footprint { x0, y0, x1, y1 } = *self;
        [[x0, y0, x1, y0], [x1, y0, x1, y1], [x1, y1, x0, y1], [x0, y1, x0, y0]]
    }

    /// Distance from the footprint's centre to `pose`'s position, m.
    fn distance(&self, pose: &Pose2) -> f64 {
        ((self.x0 + self.x1) / 2.0 - pose.x).hypot((self.y0 + self.y1) / 2.0 - pose.y)
    }

    /// True when a robot of `length × width` at `pose` overlaps the footprint
    /// (separating-axis test of the two rectangles).
    pub fn hits(&self, pose: &Pose2, length: f64, width: f64) -> bool {
        let corners = footprint(pose, length, width);
        // Axes of the box: the robot's extent along x and y.
        let (mut rx0, mut rx1, mut ry0, mut ry1) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
        for &(x, y) in &corners {
            rx0 = rx0.min(x);
            rx1 = rx1.max(x);
            ry0 = ry0.min(y);
            ry1 = ry1.max(y);
        }
        if rx1 <= self.x0 || rx0 >= self.x1 || ry1 <= self.y0 || ry0 >= self.y1 {
            return false;
        }
        // Axes of the robot: the box's corners in the robot's frame.
        let (l, w) = (length / 2.0, width / 2.0);
        let (mut a0, mut a1, mut b0, mut b1) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
        for (x, y) in [
            (self.x0, self.y0),
            (self.x1, self.y0),
            (self.x1, self.y1),
            (self.x0, self.y1),
        ] {
            let (a, b) = pose.to_local(x, y);
            a0 = a0.min(a);
            a1 = a1.max(a);
            b0 = b0.min(b);
            b1 = b1.max(b);
        }
        !(a1 <= -l || a0 >= l || b1 <= -w || b0 >= w)
    }
}

/// Obstacles and the outline range beams see (see the module docs).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Obstacles {
    /// Footprints the robot cannot enter.
    pub solid: Vec<Footprint>,
    /// Segments (x0, y0, x1, y1) range beams are cast against.
    walls: Vec<[f64; 4]>,
}

impl Obstacles {
    /// The solid footprints `solid` plus the outline of `dock`'s body.
    pub fn new(solid: Vec<Footprint>, dock: &DockGeometry) -> Self {
        let mut walls: Vec<[f64; 4]> = solid.iter().flat_map(Footprint::outline).collect();
        if dock.open {
            if let Some([x0, x1, y0, y1]) = dock.target_extent {
                walls.extend(Footprint { x0, y0, x1, y1 }.outline());
            }
        } else {
            let (l, w, e, d) = (dock.body_length, dock.body_half_width, dock.entrance_half, dock.depth);
            walls.extend([
                [0.0, e, 0.0, w],   // face, left of the entrance
                [0.0, -w, 0.0, -e], // face, right of it
                [0.0, e, -d, e],    // pouch walls and back
                [0.0, -e, -d, -e],
                [-d, -e, -d, e],
                [0.0, w, -l, w], // sides and back of the body
                [0.0, -w, -l, -w],
                [-l, -w, -l, w],
            ]);
        }
        Self { solid, walls }
    }

    /// The first solid footprint the move `from` → `to` drives into: the robot overlaps it
    /// at `to`, and either did not at `from` or moved toward its centre. A robot the
    /// proctor placed against a box (overlapping it by a placement error) may drive out
    /// of it; pushing further in is a collision.
    pub fn entered(&self, from: &Pose2, to: &Pose2, length: f64, width: f64) -> Option<usize> {
        self.solid.iter().position(|f| {
            f.hits(to, length, width) && (!f.hits(from, length, width) || f.distance(to) < f.distance(from))
        })
    }

    /// Distance from `(x, y)` along direction `angle` (rad, world frame) to the nearest
    /// wall, or `max` when none is nearer.
    pub fn ray(&self, x: f64, y: f64, angle: f64, max: f64) -> f64 {
        let (dy, dx) = angle.sin_cos();
        let mut best = max;
        for &[x0, y0, x1, y1] in &self.walls {
            let (ex, ey) = (x1 - x0, y1 - y0);
            let denom = dx * ey - dy * ex;
            if denom.abs() < 1e-12 {
                continue;
            }
            // origin + t·d = p0 + u·e
            let (px, py) = (x0 - x, y0 - y);
            let t = (px * ey - py * ex) / denom;
            let u = (px * dy - py * dx) / denom;
            if t >= 0.0 && (0.0..=1.0).contains(&u) && t < best {
                best = t;
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dock() -> DockGeometry {
        DockGeometry {
            body_length: 1.2,
            body_half_width: 0.45,
            entrance_half: 0.1,
            depth: 0.45,
            tol_lateral: 0.02,
            tol_heading: 0.1,
            needs_lowered: false,
            open: false,
            target_extent: None,
            cone: None,
        }
    }

    #[test]
    fn beams_meet_boxes_and_the_mothers_face_and_enter_the_pouch() {
        let o = Obstacles::new(
            vec![Footprint {
                x0: 1.0,
                y0: -0.1,
                x1: 1.2,
                y1: 0.1,
            }],
            &dock(),
        );
        // From 2 m out on the axis, looking back toward the dock: the box's far side.
        assert!((o.ray(2.0, 0.0, std::f64::consts::PI, 5.0) - 0.8).abs() < 1e-9);
        // Beside the box: the mother's face at x = 0, 0.3 m to the left of the axis.
        assert!((o.ray(2.0, 0.3, std::f64::consts::PI, 5.0) - 2.0).abs() < 1e-9);
        // Through the entrance, to the back of the pouch.
        assert!((o.ray(0.5, 0.0, std::f64::consts::PI, 5.0) - 0.95).abs() < 1e-9);
        // Away from everything.
        assert_eq!(o.ray(2.0, 0.0, 0.0, 5.0), 5.0);
    }

    #[test]
    fn a_robot_overlapping_a_box_hits_it_even_turned() {
        let f = Footprint {
            x0: 1.0,
            y0: -0.1,
            x1: 1.2,
            y1: 0.1,
        };
        assert!(f.hits(&Pose2::new(1.4, 0.0, 0.0), 0.5, 0.2));
        assert!(!f.hits(&Pose2::new(1.5, 0.0, 0.0), 0.5, 0.2));
        // Turned 45°: the corner reaches in only when close enough.
        let q = std::f64::consts::FRAC_PI_4;
        assert!(!f.hits(&Pose2::new(1.45, 0.25, q), 0.4, 0.1));
        assert!(f.hits(&Pose2::new(1.25, 0.0, q), 0.4, 0.1));
        let o = Obstacles::new(vec![f], &dock());
        assert_eq!(
            o.entered(&Pose2::new(3.0, 0.0, 1.0), &Pose2::new(1.1, 0.0, 1.0), 0.2, 0.2),
            Some(0)
        );
    }

    #[test]
    fn driving_into_a_box_collides_and_driving_out_of_one_does_not() {
        let f = Footprint {
            x0: 1.0,
            y0: -0.1,
            x1: 1.2,
            y1: 0.1,
        };
        let o = Obstacles::new(vec![f], &dock());
        let at = |x| Pose2::new(x, 0.0, 0.0);
        // From clear into it.
        assert_eq!(o.entered(&at(1.46), &at(1.44), 0.5, 0.2), Some(0));
        assert_eq!(o.entered(&at(1.48), &at(1.46), 0.5, 0.2), None);
        // Placed against it (overlapping by 1 cm): backing away is free, pushing in is not.
        assert_eq!(o.entered(&at(1.44), &at(1.45), 0.5, 0.2), None);
        assert_eq!(o.entered(&at(1.44), &at(1.43), 0.5, 0.2), Some(0));
    }
}
