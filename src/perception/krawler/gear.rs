//! The AutoKrawler's running gear as the estimator models it: the dimensions the paper
//! does not print ([`GearSpec`], read from the profile's `[robot.gear]`), and what the
//! estimator derives from them on its own, without the simulator: where the wheels sit
//! ([`GearLayout`]), the state the gear rests in on flat ground, and where its eight
//! markers project then, the estimator's first marker predictions.
//!
//! Seed 003 gives the wheel radius (11.5 cm), the steering range and the markers' roles,
//! not the gear's other dimensions; the defaults below are our estimates (the simulator
//! builds its gear from the same profile table, so a profile that changes one changes
//! both).

use super::axle::AxleGeometry;
use super::markers::ExpectedMarker;
use super::rotation::{AxleState, GearLayout};
use nalgebra::{Point3, Rotation3, Vector3};
use serde::{Deserialize, Serialize};

/// The gear's dimensions the profile carries in `[robot.gear]` (every field optional,
/// defaulting to the estimate documented on it).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GearSpec {
    /// Width of a wheel's tread, m. Default 0.08 (an estimate: the paper gives only the
    /// radius).
    pub tread_width_m: f64,
    /// Height of the axle plate's top (the markers' plane) above the wheels' centres, m.
    /// Default 0.021 (an estimate).
    pub hub_below_plate_m: f64,
    /// How far each marker sits either side of its axle's (or tie rod's) centre line, m.
    /// Default 0.1 (an estimate).
    pub plate_marker_y_m: f64,
    /// Steering-arm length from kingpin to tie-rod end, m. Default 0.09 (an estimate;
    /// the arms form the standard Ackermann trapezoid, each pointing at the other axle's
    /// centre).
    pub steering_arm_m: f64,
}

impl Default for GearSpec {
    fn default() -> Self {
        Self {
            tread_width_m: 0.08,
            hub_below_plate_m: 0.021,
            plate_marker_y_m: 0.1,
            steering_arm_m: 0.09,
        }
    }
}

/// The whole gear in plain numbers: the drive's track, wheelbase and wheel radius with
/// [`GearSpec`]'s dimensions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GearGeometry {
    /// Distance between an axle's two kingpins, m.
    pub track: f64,
    /// Distance between the axles, m.
    pub wheelbase: f64,
    /// Tread radius r, m.
    pub wheel_radius: f64,
    /// The profile's `[robot.gear]`.
    pub spec: GearSpec,
}

impl GearGeometry {
    /// Where the wheels sit on their axles, as the wheel stage takes it.
    pub fn layout(&self) -> GearLayout {
        GearLayout {
            track: self.track,
            wheel_radius: self.wheel_radius,
            tread_half_width: self.spec.tread_width_m / 2.0,
            hub_below_plate: self.spec.hub_below_plate_m,
            marker_half_spacing: self.spec.plate_marker_y_m,
        }
    }

    /// Level axles resting on flat ground under a camera at height `camera_z`, straight:
    /// the drop is the camera's height less the wheel radius and the hub's depth.
    pub fn rest(&self, camera_z: f64) -> [AxleState; 2] {
        let drop = camera_z - self.wheel_radius - self.spec.hub_below_plate_m;
        [AxleState {
            roll: 0.0,
            drop,
            steer: 0.0,
        }; 2]
    }

    /// The tie rod's ends (left, right) in the axle frame, on the markers' plane (z = 0),
    /// for the front axle (`inboard` = −1, its arms point back) or the rear (+1), both
    /// wheels steered by `steer` (rad, positive turns the fronts left). At `steer` = 0
    /// each arm points from its kingpin at (0, ±track/2) toward the other axle's centre.
    pub fn tie_rod_ends(&self, inboard: f64, steer: f64) -> [Point3<f64>; 2] {
        [1.0, -1.0].map(|side: f64| {
            let kingpin = Vector3::new(0.0, side * self.track / 2.0, 0.0);
            let toward = Vector3::new(inboard * self.wheelbase, 0.0, 0.0) - kingpin;
            let arm =
                Rotation3::from_axis_angle(&Vector3::z_axis(), steer) * toward.normalize() * self.spec.steering_arm_m;
            Point3::from(kingpin + arm)
        })
    }

    /// The eight marker centres in the body frame (front plate left, right; front tie rod
    /// left, right; then the rear's), for axles in `axles` below a camera at `camera_z`:
    /// each axle's frame has its origin at the plate markers' midpoint, on x = ±wheelbase/2,
    /// rolled about x; the tie-rod markers sit on the rod, either side of its middle.
    pub fn marker_centres(&self, axles: &[AxleState; 2], camera_z: f64) -> [Point3<f64>; 8] {
        let mut out = [Point3::origin(); 8];
        let y = self.spec.plate_marker_y_m;
        for (axle, state) in axles.iter().enumerate() {
            let (x, inboard) = if axle == 0 {
                (self.wheelbase / 2.0, -1.0)
            } else {
                (-self.wheelbase / 2.0, 1.0)
            };
            let roll = Rotation3::from_axis_angle(&Vector3::x_axis(), state.roll);
            let origin = Point3::new(x, 0.0, camera_z - state.drop);
            let [l, r] = self.tie_rod_ends(inboard, state.steer);
            let mid = nalgebra::center(&l, &r);
            let along = (l - r).normalize();
            for (k, side) in [1.0, -1.0].into_iter().enumerate() {
                out[axle * 4 + k] = origin + roll * Vector3::new(0.0, side * y, 0.0);
                out[axle * 4 + 2 + k] = origin + roll * (mid.coords + along * side * y);
            }
        }
        out
    }

    /// Where square markers of side `side` centred at `centres` (body frame, facing up)
    /// project through `geometry`'s camera: the marker finder's predictions. `None` when
    /// one does not project.
    pub fn expected_markers(
        geometry: &AxleGeometry,
        centres: &[Point3<f64>; 8],
        side: f64,
    ) -> Option<[ExpectedMarker; 8]> {
        let camera_from_body = geometry.body_from_camera.transpose();
        let project = |q: [f64; 3]| {
            geometry
                .model
                .project(&(camera_from_body * (Point3::from(q) - geometry.camera)))
        };
        let mut out = [ExpectedMarker {
            at: [0.0; 2],
            area: 0.0,
        }; 8];
        for (o, c) in out.iter_mut().zip(centres) {
            *o = ExpectedMarker::from_square(project, c.coords.into(), [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], side)?;
        }
        Some(out)
    }

    /// The rest state ([`GearGeometry::rest`]) and its markers' projections
    /// ([`GearGeometry::expected_markers`]): what the estimator starts from.
    pub fn start(&self, geometry: &AxleGeometry, side: f64) -> Option<([ExpectedMarker; 8], [AxleState; 2])> {
        let axles = self.rest(geometry.camera.z);
        let centres = self.marker_centres(&axles, geometry.camera.z);
        Some((Self::expected_markers(geometry, &centres, side)?, axles))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gear() -> GearGeometry {
        GearGeometry {
            track: 0.56,
            wheelbase: 0.66,
            wheel_radius: 0.115,
            spec: GearSpec::default(),
        }
    }

    #[test]
    fn straight_tie_rods_sit_inboard_of_their_plates_and_steering_shifts_them() {
        let g = gear();
        let rest = g.rest(0.4);
        assert!((rest[0].drop - (0.4 - 0.115 - 0.021)).abs() < 1e-12);
        let m = g.marker_centres(&rest, 0.4);
        // Plate markers on the axle planes, ±0.1 m; the rods' between the axles.
        assert!((m[0].x - 0.33).abs() < 1e-12 && (m[0].y - 0.1).abs() < 1e-12 && (m[1].y + 0.1).abs() < 1e-12);
        assert!(m[2].x < 0.33 && m[6].x > -0.33, "{m:?}");
        assert!(
            (m[2].z - m[0].z).abs() < 1e-12,
            "the rod's markers lie in the plate's plane"
        );
        let mut steered = rest;
        steered[0].steer = 0.3;
        let s = g.marker_centres(&steered, 0.4);
        // The front arms point back from the kingpins: turning the wheels left swings the
        // rod right, both ends the same way.
        assert!(s[2].y < m[2].y - 0.01 && s[3].y < m[3].y - 0.01, "{s:?}");
    }
}
