//! Ratio steering (seed 004 §V), in aim-point form.
//!
//! The paper maps the left/right pixel-count ratio to a steering command, with a dead band
//! around straight ahead and deliberate understeer; the robot turns OR drives. Here the
//! ratio (with the aspect cue of [`FiducialView`]) places an aim point on the dock axis
//! halfway between the robot and the dock, and the schema keeps the fiducial where it
//! must appear in the image for the robot's motion to head at that aim point. So the
//! robot curves onto the axis as it closes in, and a balanced ratio with a centred
//! fiducial means "on the axis, facing it": the paper's docking condition.
//!
//! * error e = (offset − desired offset) / (half image width);
//! * |e| ≤ dead band: drive (toward the dock) at a speed that falls with the summed pixel
//!   count; otherwise turn in place by `understeer` × the angle error this tick, capped at
//!   the turn rate. Drives that can do both get one twist instead.

use super::motor_output::{DriveCommand, MotorOutput};
use crate::geometry::Twist;
use crate::perception::{FiducialView, TwoBlockGeometry};

/// Largest aim angle, rad (25°).
pub const MAX_AIM_RAD: f64 = 25.0 * std::f64::consts::PI / 180.0;

/// The ratio-steering motor schema.
///
/// # Example
///
/// Bujold's rear camera, rolled 180° (f = 182.8 px, 256 px wide), on a turn-or-drive
/// base. Centred on the axis, a fiducial 3 px off centre is inside the 5 % dead band: the
/// robot backs straight in, at a speed reduced by the pixel count (1000 of the 9000 at
/// the dock). 30 px off centre it turns in place, counter-clockwise for a fiducial on the
/// image's right, by 0.6 of the angle error per 0.1 s tick, capped at 0.5 rad/s.
///
/// ```
/// use marsupial::perception::{FiducialView, TwoBlockGeometry};
/// use marsupial::schemas::{DriveCommand, MotorSchema, RatioSteering};
///
/// let s = RatioSteering {
///     geometry: TwoBlockGeometry { fx: 182.8, size: (0.18, 0.11), image_right_sign: 1.0, drive_dir: -1.0 },
///     image_width: 256.0,
///     dead_band: 0.05,
///     understeer: 0.6,
///     turn_rate: 0.5,
///     speed: 0.06,
///     dock_total_px: 9000.0,
///     aim_fraction: 0.5,
///     tick_s: 0.1,
///     restricted: true,
/// };
/// let view = |alpha: f64, offset_px: f64| FiducialView {
///     distance: 1.0,
///     alpha,
///     asym: 0.0,
///     offset_px,
///     bearing: 0.0,
///     heading: 0.0,
///     total_px: 1000,
///     height_px: 30.0,
/// };
/// let DriveCommand::Straight { v } = s.act(&view(0.0, 3.0)).drive else { panic!() };
/// assert!((v - -0.06 * (1.0 - 1000.0 / 9000.0)).abs() < 1e-12);
///
/// let DriveCommand::Turn { omega } = s.act(&view(0.0, 30.0)).drive else { panic!() };
/// let full = (30.0f64 / 182.8).atan() / 0.1; // the whole angle error in one tick
/// assert!(omega > 0.0 && (omega - (0.6 * full).min(0.5)).abs() < 1e-9);
/// let DriveCommand::Turn { omega } = s.act(&view(0.0, -30.0)).drive else { panic!() };
/// assert!(omega < 0.0);
///
/// // 40° off the axis the aim point wants the fiducial off centre: centred is an error.
/// assert!(s.aim_angle(&view(40f64.to_radians(), 0.0)) > 0.1);
/// assert!(s.error(&view(40f64.to_radians(), 0.0)) > s.dead_band);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RatioSteering {
    /// Camera and fiducial geometry.
    pub geometry: TwoBlockGeometry,
    /// Image width, px.
    pub image_width: f64,
    /// Dead band on the normalised steering error.
    pub dead_band: f64,
    /// Fraction of the angle error turned per tick (< 1 understeers).
    pub understeer: f64,
    /// Turn rate cap, rad/s.
    pub turn_rate: f64,
    /// Drive speed far from the dock, m/s.
    pub speed: f64,
    /// Summed pixel count at the dock.
    pub dock_total_px: f64,
    /// The aim point's place on the dock axis, as a fraction of the robot's distance
    /// along it (0.5: halfway in; see [`RatioSteering::aim_angle`]).
    pub aim_fraction: f64,
    /// Loop period, s.
    pub tick_s: f64,
    /// Turn OR drive (true), or both at once.
    pub restricted: bool,
}

impl RatioSteering {
    /// The aim-point angle δ (rad): how far the motion direction should point away from the
    /// fiducial so that it heads at the point on the axis `aim_fraction` of the way in
    /// from the dock (halfway for 0.5). Heading at it, the lateral offset shrinks as
    /// (x/x₀)^(1/(1−f)) with the distance x along the axis. Capped at [`MAX_AIM_RAD`] so
    /// the fiducial stays well inside the image; larger offsets are the repositioning
    /// manoeuvre's job.
    pub fn aim_angle(&self, view: &FiducialView) -> f64 {
        let (d, a) = (view.distance, view.alpha);
        let (px, py) = (d * a.cos(), d * a.sin());
        let aim = self.aim_fraction * px;
        let to_dock = (-py).atan2(-px);
        let to_aim = (-py).atan2(aim - px);
        crate::geometry::wrap_angle(to_aim - to_dock).clamp(-MAX_AIM_RAD, MAX_AIM_RAD)
    }

    /// Normalised steering error in [−∞, ∞]; positive means "turn counter-clockwise" for the
    /// mount in `geometry`.
    pub fn error(&self, view: &FiducialView) -> f64 {
        let g = &self.geometry;
        let desired = g.fx * self.aim_angle(view).tan() * g.image_right_sign * g.drive_dir;
        let e = (view.offset_px - desired) / (self.image_width / 2.0);
        e * -g.drive_dir * g.image_right_sign
    }

    /// Forward speed (signed toward the dock) for a summed pixel count.
    pub fn speed_for(&self, total_px: f64) -> f64 {
        let k = (1.0 - total_px / self.dock_total_px).clamp(0.3, 1.0);
        self.speed * k * self.geometry.drive_dir
    }

    /// The dead band as a heading error, rad: the angle a steering error of `dead_band`
    /// (a fraction of the half image) stands for.
    pub fn dead_band_angle(&self) -> f64 {
        (self.dead_band * self.image_width / 2.0 / self.geometry.fx).atan()
    }

    /// Realises a heading error `angle` (rad, counter-clockwise positive) and a speed `v`
    /// the schema's way: within the dead band drive at `v`; outside it turn by
    /// `understeer` × the error this tick (capped at the turn rate), in place on a
    /// turn-or-drive base, or as one twist on a base that can do both. Any approach that
    /// yields a heading error (the potential field does) can drive through this.
    pub fn steer(&self, angle: f64, v: f64) -> MotorOutput {
        let within = angle.abs() <= self.dead_band_angle();
        let omega = (self.understeer * angle / self.tick_s).clamp(-self.turn_rate, self.turn_rate);
        let cmd = match (self.restricted, within) {
            (false, _) => DriveCommand::Twist(Twist::new(v, if within { 0.0 } else { omega })),
            (true, true) => DriveCommand::Straight { v },
            (true, false) => DriveCommand::Turn { omega },
        };
        MotorOutput::drive(cmd)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::schemas::MotorSchema;

    fn rear_flipped() -> TwoBlockGeometry {
        TwoBlockGeometry {
            fx: 182.8,
            size: (0.18, 0.11),
            image_right_sign: 1.0,
            drive_dir: -1.0,
        }
    }

    fn schema() -> RatioSteering {
        RatioSteering {
            geometry: rear_flipped(),
            image_width: 256.0,
            dead_band: 0.05,
            understeer: 0.6,
            turn_rate: 0.5,
            speed: 0.06,
            dock_total_px: 9000.0,
            aim_fraction: 0.5,
            tick_s: 0.1,
            restricted: true,
        }
    }

    fn view(alpha_deg: f64, offset_px: f64) -> FiducialView {
        FiducialView {
            distance: 1.0,
            alpha: alpha_deg.to_radians(),
            asym: 0.0,
            offset_px,
            bearing: 0.0,
            heading: 0.0,
            total_px: 1000,
            height_px: 30.0,
        }
    }

    #[test]
    fn dead_band_drives_straight_backwards() {
        let c = schema().act(&view(0.0, 3.0));
        assert_eq!(
            c.drive,
            DriveCommand::Straight {
                v: -0.06 * (1.0 - 1000.0 / 9000.0)
            }
        );
    }

    #[test]
    fn turns_toward_the_fiducial_with_understeer() {
        // Flipped rear camera: fiducial right of centre → rotate counter-clockwise.
        let s = schema();
        let DriveCommand::Turn { omega } = s.act(&view(0.0, 30.0)).drive else {
            panic!()
        };
        let full = (30.0f64 / 182.8).atan() / 0.1;
        assert!(omega > 0.0 && (omega - (0.6 * full).min(0.5)).abs() < 1e-9, "{omega}");
        let DriveCommand::Turn { omega } = s.act(&view(0.0, -30.0)).drive else {
            panic!()
        };
        assert!(omega < 0.0);
    }

    /// A point heading at the aim point closes on the axis as (x/x₀)^(1/(1−f)): the
    /// square law halfway in, the cube law at two thirds.
    #[test]
    fn the_aim_fraction_sets_how_fast_the_robot_closes_on_the_axis() {
        for (f, power) in [(0.5, 2.0), (2.0 / 3.0, 3.0)] {
            let s = RatioSteering {
                aim_fraction: f,
                ..schema()
            };
            let (mut x, mut y) = (2.0f64, 0.1f64);
            while x > 0.5 {
                let v = FiducialView {
                    distance: x.hypot(y),
                    alpha: y.atan2(x),
                    ..view(0.0, 0.0)
                };
                // Motion toward the dock, turned by the aim angle toward the axis.
                let dir = (-y).atan2(-x) + s.aim_angle(&v);
                let step = 1e-3;
                x += step * dir.cos();
                y += step * dir.sin();
            }
            let expected = 0.1 * (x / 2.0).powf(power);
            assert!(
                (y - expected).abs() < 0.15 * expected,
                "f {f}: y {y:.5} against {expected:.5}"
            );
        }
    }

    #[test]
    fn off_axis_the_fiducial_is_held_off_centre_toward_the_axis() {
        // At α = +40°, the aim point asks for the fiducial on the image's left: centred is wrong.
        let s = schema();
        assert!(s.aim_angle(&view(40.0, 0.0)) > 0.1);
        let e_centred = s.error(&view(40.0, 0.0));
        assert!(e_centred > s.dead_band, "{e_centred}");
        let desired = -182.8 * s.aim_angle(&view(40.0, 0.0)).tan();
        assert!(s.error(&view(40.0, desired)).abs() < 1e-9);
        // Symmetric on the other side.
        assert!((s.error(&view(-40.0, 0.0)) + e_centred).abs() < 1e-9);
    }

    #[test]
    fn steer_realises_any_heading_error_with_the_same_dead_band() {
        let s = schema();
        let db = s.dead_band_angle();
        // The dead band in pixels and in angle are the same boundary.
        assert!((db - (0.05f64 * 128.0 / 182.8).atan()).abs() < 1e-12);
        assert_eq!(s.steer(0.99 * db, -0.04).drive, DriveCommand::Straight { v: -0.04 });
        assert_eq!(s.steer(-0.99 * db, -0.04).drive, DriveCommand::Straight { v: -0.04 });
        let DriveCommand::Turn { omega } = s.steer(1.01 * db, -0.04).drive else {
            panic!()
        };
        assert!((omega - 0.6 * 1.01 * db / 0.1).abs() < 1e-12, "understeered: {omega}");
        let DriveCommand::Turn { omega } = s.steer(-1.0, -0.04).drive else {
            panic!()
        };
        assert_eq!(omega, -0.5, "capped at the turn rate");
    }

    #[test]
    fn speed_falls_with_pixel_count_and_twist_for_free_drives() {
        let mut s = schema();
        assert!(s.speed_for(8000.0).abs() < s.speed_for(100.0).abs());
        assert!(s.speed_for(20000.0).abs() >= 0.3 * 0.06 - 1e-12);
        s.restricted = false;
        let DriveCommand::Twist(t) = s.act(&view(0.0, 30.0)).drive else {
            panic!()
        };
        assert!(t.v < 0.0 && t.omega > 0.0);
    }
}
