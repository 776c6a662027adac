//! Where a body-mounted camera is in the world.

use super::render::CameraPose;
use crate::geometry::Pose2;
use crate::perception::camera_model::body_from_camera;
use crate::profile::Mount;
use nalgebra::{Point3, Rotation3, Vector3};

/// The world pose of a camera on a robot at `robot` (planar pose; the body is level).
pub fn camera_pose(robot: &Pose2, mount: &Mount) -> CameraPose {
    let world_from_body = Rotation3::from_axis_angle(&Vector3::z_axis(), robot.theta);
    let rotation = world_from_body.matrix() * body_from_camera(mount);
    let offset = world_from_body * Vector3::new(mount.x_m, mount.y_m, 0.0);
    CameraPose {
        rotation,
        position: Point3::new(robot.x + offset.x, robot.y + offset.y, mount.z_m),
    }
}
