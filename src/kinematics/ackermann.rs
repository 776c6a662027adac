//! Double-Ackermann (four-wheel steering) kinematics, as on the AutoKrawler.
//!
//! Both axles steer. With the body reference point midway between the axles, front
//! steering angle λ_F and rear λ_R (the equivalent "bicycle" angles at each axle centre,
//! positive to the left), the instantaneous centre of rotation lies where the two axle
//! normals cross. For body speed `v` along the velocity direction β:
//!
//! tan β = (tan λ_F + tan λ_R)/2 ,  ω = v·cos β·(tan λ_F − tan λ_R)/L
//!
//! with L the wheelbase. λ_R = −λ_F gives the tightest turn with no side-slip (β = 0);
//! λ_R = λ_F is pure crab motion (ω = 0).

/// Double-Ackermann geometry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DoubleAckermann {
    /// Distance between front and rear axles, m.
    pub wheelbase: f64,
    /// Distance between left and right wheels, m.
    pub track: f64,
    /// Steering limit per axle, rad.
    pub max_steer: f64,
}

/// Body velocity of a double-Ackermann vehicle at its centre.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyVelocity {
    /// Forward component, m/s.
    pub vx: f64,
    /// Leftward component, m/s.
    pub vy: f64,
    /// Yaw rate, rad/s.
    pub omega: f64,
}

impl DoubleAckermann {
    /// Body velocity for speed `v` (m/s along the direction of travel) and axle angles.
    pub fn body_velocity(&self, v: f64, steer_front: f64, steer_rear: f64) -> BodyVelocity {
        let (tf, tr) = (steer_front.tan(), steer_rear.tan());
        let beta = ((tf + tr) / 2.0).atan();
        BodyVelocity {
            vx: v * beta.cos(),
            vy: v * beta.sin(),
            omega: v * beta.cos() * (tf - tr) / self.wheelbase,
        }
    }

    /// Symmetric steering (λ_R = −λ_F) realising forward speed `v` and yaw rate `omega`,
    /// clamped to `max_steer`. Returns (λ_F, λ_R). With v = 0 the vehicle cannot turn, so
    /// the angles are zero.
    pub fn steering_for(&self, v: f64, omega: f64) -> (f64, f64) {
        if v == 0.0 {
            return (0.0, 0.0);
        }
        let lf = (omega * self.wheelbase / (2.0 * v))
            .atan()
            .clamp(-self.max_steer, self.max_steer);
        (lf, -lf)
    }

    /// Largest yaw rate reachable at forward speed `v` with symmetric steering.
    pub fn max_yaw_rate(&self, v: f64) -> f64 {
        2.0 * v.abs() * self.max_steer.tan() / self.wheelbase
    }

    /// Individual wheel steering angles (left, right) on an axle whose equivalent centre
    /// angle is `lambda`, so that all four wheels share one ICR (true Ackermann geometry).
    pub fn wheel_angles(&self, lambda: f64) -> (f64, f64) {
        if lambda == 0.0 {
            return (0.0, 0.0);
        }
        // Axle centre sits at L/2 from the ICR line; the ICR is at lateral distance R.
        let half_l = self.wheelbase / 2.0;
        let r = half_l / lambda.tan();
        let w = self.track / 2.0;
        ((half_l / (r - w)).atan(), (half_l / (r + w)).atan())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn car() -> DoubleAckermann {
        DoubleAckermann {
            wheelbase: 0.6,
            track: 0.5,
            max_steer: 30f64.to_radians(),
        }
    }

    #[test]
    fn symmetric_turn_radius() {
        let c = car();
        let l = 0.2f64;
        let b = c.body_velocity(1.0, l, -l);
        assert!(b.vy.abs() < 1e-12);
        // R = (L/2)/tan λ.
        let r = 0.3 / l.tan();
        assert!((b.omega - 1.0 / r).abs() < 1e-12);
        let (f, rr) = c.steering_for(1.0, b.omega);
        assert!((f - l).abs() < 1e-12 && (rr + l).abs() < 1e-12);
    }

    #[test]
    fn crab_has_no_rotation() {
        let b = car().body_velocity(0.5, 0.3, 0.3);
        assert_eq!(b.omega, 0.0);
        assert!((b.vy / b.vx - 0.3f64.tan()).abs() < 1e-12);
    }

    #[test]
    fn inner_wheel_steers_more() {
        let (l, r) = car().wheel_angles(0.2);
        assert!(l > 0.2 && r < 0.2 && r > 0.0);
        assert!(car().steering_for(1.0, 100.0).0 <= 30f64.to_radians() + 1e-12);
    }
}
