//! Arkin's avoid-static-obstacle motor schema over a range finder's beams.
//!
//! Each beam that returns at distance d inside the sphere of influence S repels along the
//! beam, back toward the sensor, with magnitude
//!
//! ```text
//! |O| = 0                       d > S
//! |O| = G · (S − d) / (S − R)   R < d ≤ S
//! |O| = G · cap                 d ≤ R   (Arkin's "infinite", capped)
//! ```
//!
//! Summing one vector per beam would make a wall (many returns) far more repulsive than a
//! post (one return), so, as TeamBots' `v_Avoid_va` does, the direction is the sum of the
//! beams' repulsions and the magnitude the largest single one. The result is a body-frame
//! [`MotionVector`] (m/s) for a vector-sum arbiter to add to the robot's other schemas.
//!
//! Pure repulsion has the local minimum every potential-field text warns of: an obstacle
//! straight between the robot and its goal pushes straight back, and the robot stops in
//! front of it. With `swirl` > 0 each repulsion turns toward a tangent of the obstacle
//! (TeamBots' swirl schemas), so the robot slides round it instead. Of a return's two
//! tangents the schema takes the one that carries on the way the robot travels (its
//! leading end, `lead`): a return beside the robot slides it past, not back. A return
//! dead ahead has no such preference; it slides to the side away from where the returns
//! lie, and the caller keeps that side while the obstacle is in range
//! ([`AvoidObstacles::side`]) so a symmetric obstacle cannot make it dither.

use super::vector::MotionVector;

/// See the module docs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AvoidObstacles {
    /// Sphere of influence S, m: returns farther away are ignored.
    pub sphere: f64,
    /// Safety radius R, m: returns this close repel at the cap.
    pub safety: f64,
    /// Gain G, m/s at the safety radius.
    pub gain: f64,
    /// Multiple of G that stands for Arkin's "infinite" inside R.
    pub cap: f64,
    /// Share of each repulsion turned to the tangent, 0 (Arkin's pure repulsion) to 1.
    pub swirl: f64,
    /// The end the robot travels with: +1 its front, −1 its rear (backing).
    pub lead: f64,
}

/// A return this close to dead ahead (sine of 10°) has no tangent that carries on.
const DEAD_AHEAD: f64 = 0.17;

impl AvoidObstacles {
    /// Magnitude of one return at distance `d`, m/s.
    pub fn magnitude(&self, d: f64) -> f64 {
        if !(d.is_finite() && d >= 0.0) || d > self.sphere {
            0.0
        } else if d <= self.safety {
            self.gain * self.cap
        } else {
            self.gain * (self.sphere - d) / (self.sphere - self.safety).max(1e-9)
        }
    }

    /// The side to slide round the returns on: +1 toward +y (left), −1 right: away from
    /// the side the returns' repulsion-weighted bearings lie on (left when balanced).
    pub fn side(&self, beams: impl IntoIterator<Item = (f64, f64)>) -> f64 {
        let lateral: f64 = beams
            .into_iter()
            .map(|(angle, range)| self.magnitude(range) * angle.sin())
            .sum();
        if lateral > 0.0 { -1.0 } else { 1.0 }
    }

    /// The repulsion for beams given as (direction in the body frame, rad; range, m),
    /// swirling toward `side` (see [`AvoidObstacles::side`]); `None` when no return lies
    /// inside the sphere of influence.
    ///
    /// ```
    /// use marsupial::schemas::AvoidObstacles;
    /// let avoid = AvoidObstacles { sphere: 0.5, safety: 0.1, gain: 0.1, cap: 3.0, swirl: 0.0, lead: 1.0 };
    /// // One return straight ahead at 0.3 m pushes straight back at half the gain.
    /// let v = avoid.vector([(0.0, 0.3), (1.0, 2.0)], 1.0).unwrap();
    /// assert!((v.x + 0.05).abs() < 1e-12 && v.y.abs() < 1e-12);
    /// assert!(avoid.vector([(0.0, 0.6)], 1.0).is_none());
    /// ```
    pub fn vector(&self, beams: impl IntoIterator<Item = (f64, f64)>, side: f64) -> Option<MotionVector> {
        let mut sum = MotionVector::ZERO;
        let mut largest = 0.0f64;
        let w = self.swirl.clamp(0.0, 1.0);
        for (angle, range) in beams {
            let m = self.magnitude(range);
            if m > 0.0 {
                let (s, c) = angle.sin_cos();
                let away = MotionVector::new(-c, -s);
                // The tangent on `side`: `away` turned a quarter turn, the way whose
                // lateral part points to `side`.
                let ccw = MotionVector::new(-away.y, away.x);
                let ahead = ccw.x * self.lead;
                let keep = if ahead.abs() > DEAD_AHEAD {
                    ahead > 0.0
                } else {
                    ccw.y * side >= 0.0
                };
                let tangent = if keep { ccw } else { ccw.scale(-1.0) };
                sum = sum + (away.scale(1.0 - w) + tangent.scale(w)).scale(m);
                largest = largest.max(m);
            }
        }
        if largest <= 0.0 {
            return None;
        }
        let norm = sum.norm();
        // Returns all round cancel: no way out is better than another; push nowhere.
        Some(if norm < 1e-12 {
            MotionVector::ZERO
        } else {
            sum.scale(largest / norm)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn avoid() -> AvoidObstacles {
        AvoidObstacles {
            sphere: 0.5,
            safety: 0.1,
            gain: 0.1,
            cap: 3.0,
            swirl: 0.0,
            lead: 1.0,
        }
    }

    #[test]
    fn magnitude_falls_linearly_from_the_safety_radius_to_the_sphere() {
        let a = avoid();
        // Inside and at R: the cap, G·3.
        assert!((a.magnitude(0.05) - 0.3).abs() < 1e-12);
        assert!((a.magnitude(0.1) - 0.3).abs() < 1e-12);
        // Just outside R: G, falling linearly to 0 at S.
        assert!((a.magnitude(0.1 + 1e-9) - 0.1).abs() < 1e-8);
        assert!((a.magnitude(0.3) - 0.05).abs() < 1e-12);
        assert_eq!(a.magnitude(0.5), 0.0);
        assert_eq!(a.magnitude(0.7), 0.0);
        assert_eq!(a.magnitude(f64::NAN), 0.0);
    }

    #[test]
    fn a_wall_repels_no_more_than_a_post_at_the_same_distance() {
        let a = avoid();
        let post = a.vector([(0.0, 0.3)], 1.0).unwrap();
        let wall = a
            .vector((-4..=4).map(|k| (k as f64 * 0.05, 0.3 / (k as f64 * 0.05).cos())), 1.0)
            .unwrap();
        assert!((post.x.hypot(post.y) - wall.x.hypot(wall.y)).abs() < 1e-12);
        assert!(wall.y.abs() < 1e-12 && wall.x < 0.0, "{wall:?}");
    }

    #[test]
    fn an_obstacle_to_the_left_pushes_right() {
        let v = avoid().vector([(std::f64::consts::FRAC_PI_2, 0.2)], 1.0).unwrap();
        assert!(v.y < 0.0 && v.x.abs() < 1e-12, "{v:?}");
    }

    #[test]
    fn swirl_slides_round_an_obstacle_on_the_far_side_of_its_returns() {
        let a = AvoidObstacles { swirl: 1.0, ..avoid() };
        // A box dead ahead, a little to the left: returns at 0.3 m, more of them left.
        let beams = [(-0.1, 0.32), (0.0, 0.3), (0.1, 0.3), (0.2, 0.32)];
        let side = a.side(beams);
        assert_eq!(side, -1.0);
        let v = a.vector(beams, side).unwrap();
        assert!(v.y < 0.0 && v.y.abs() > 5.0 * v.x.abs(), "{v:?}");
        // Half swirl: back off and slide.
        let half = AvoidObstacles { swirl: 0.5, ..avoid() }
            .vector([(0.0, 0.3)], 1.0)
            .unwrap();
        assert!(
            half.x < 0.0 && half.y > 0.0 && (half.x + half.y).abs() < 1e-12,
            "{half:?}"
        );
        // Beside the robot the tangent carries on the way it travels: forward, or, for a
        // robot that backs, backward.
        let beside = [(std::f64::consts::FRAC_PI_2, 0.3)];
        assert!(a.vector(beside, -1.0).unwrap().x > 0.0);
        let backing = AvoidObstacles { lead: -1.0, ..a };
        assert!(backing.vector(beside, -1.0).unwrap().x < 0.0);
        // Balanced returns pick the left, and the magnitude stays the largest return's.
        assert_eq!(a.side([(0.1, 0.3), (-0.1, 0.3)]), 1.0);
        assert!((v.x.hypot(v.y) - a.magnitude(0.3)).abs() < 1e-12);
    }
}
