//! The pipeline's results measured against the simulator's truth: a pose's errors from
//! the module's true pose, a labelling's mislabelled marks from their true images, and a
//! failure's typed error named as the records spell it. Apart from the run so what a
//! record's numbers mean is read in one place.

use super::{Labelling, PoseOutcome};
use crate::geometry::Pose2;
use crate::perception::circles::{
    CircleModel, CorrespondenceError, CorrespondenceParams, DetectedMark, LensPlane, ModelFit, ModulePose, PoseError,
    correspond_through,
};
use nalgebra::{Matrix3, Rotation3, Vector3};

/// An angle wrapped into [−π, π).
fn wrap(a: f64) -> f64 {
    (a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
}

/// The module's true pose in the rover frame at `robot` (the module frame is the world's).
pub(super) fn truth(robot: &Pose2) -> (Matrix3<f64>, Vector3<f64>) {
    let r = *Rotation3::from_axis_angle(&Vector3::z_axis(), -robot.theta).matrix();
    (r, r * Vector3::new(-robot.x, -robot.y, 0.0))
}

/// A pose's errors from the module's true pose with the rover at `robot`, or the typed
/// error when there is no pose.
pub(super) fn outcome(res: Result<ModulePose, PoseError>, robot: &Pose2) -> PoseOutcome {
    match res {
        Ok(p) => {
            let (r, t) = truth(robot);
            let c = ((r.transpose() * p.rotation).trace() - 1.0) / 2.0;
            PoseOutcome {
                found: true,
                position_err_m: Some((p.x() - t.x).hypot(p.y() - t.y)),
                heading_err_deg: Some(wrap(p.heading() + robot.theta).to_degrees().abs()),
                rotation_err_deg: Some(c.clamp(-1.0, 1.0).acos().to_degrees()),
                reprojection_px: Some(p.reprojection_px),
                marks: Some(p.marks_used),
                error: None,
                message: None,
            }
        }
        Err(e) => PoseOutcome {
            error: Some(pose_error_kind(&e).into()),
            message: Some(e.to_string()),
            ..Default::default()
        },
    }
}

/// The pose error's variant, as the records name it.
fn pose_error_kind(e: &PoseError) -> &'static str {
    match e {
        PoseError::TooFewMarks { .. } => "TooFewMarks",
        PoseError::Collinear { .. } => "Collinear",
        PoseError::BadInput { .. } => "BadInput",
        PoseError::Degenerate { .. } => "Degenerate",
    }
}

/// The correspondence error's variant, as the records name it.
fn correspondence_kind(e: &CorrespondenceError) -> &'static str {
    match e {
        CorrespondenceError::TooFewMarks { .. } => "TooFewMarks",
        CorrespondenceError::NoConsistentFit { .. } => "NoConsistentFit",
    }
}

/// A pose outcome standing for "no labelling to pose".
pub(super) fn unlabelled(e: &CorrespondenceError) -> PoseOutcome {
    PoseOutcome {
        error: Some(correspondence_kind(e).into()),
        message: Some(e.to_string()),
        ..Default::default()
    }
}

/// Labels `marks` with `params` through the camera's `lens`, as the robot does, and checks
/// each label against the true image of its mark.
pub(super) fn label(
    model: &CircleModel,
    marks: &[DetectedMark],
    lens: &mut LensPlane,
    params: &CorrespondenceParams,
    true_px: &[Option<[f64; 2]>],
) -> (Result<ModelFit, CorrespondenceError>, Labelling) {
    let res = correspond_through(model, marks, lens, params);
    let l = match &res {
        Ok(fit) => Labelling {
            found: true,
            inliers: fit.inliers,
            mislabelled: (0..model.len())
                .filter(|&j| {
                    fit.detection_of(j).and_then(|i| marks.get(i)).is_some_and(|m| {
                        let tol = m.ellipse.semi_major.max(3.0);
                        true_px[j].is_none_or(|t| (m.centre[0] - t[0]).hypot(m.centre[1] - t[1]) > tol)
                    })
                })
                .count(),
            reprojection_px: Some(fit.rms_px),
            error: None,
        },
        Err(e) => Labelling {
            error: Some(correspondence_kind(e).into()),
            ..Default::default()
        },
    };
    (res, l)
}
