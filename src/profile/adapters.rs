//! From a profile's tables to perception's plain parameter structs.
//!
//! Perception knows nothing of profiles: every detector and tracker is built from plain
//! numbers, so an embedder without TOML files can use it. These adapters are the one
//! place where a profile's units (degrees, named colours, camera specs) become those
//! numbers. They are written as conversions and constructors on perception's types
//! (`CameraModel::from_spec`, `TwoBlockParams::from_profile` …) so existing callers keep
//! their names.

use super::{CameraModelKind, CameraSpec, FisheyeSpec, Intrinsics, Mount, PerceptionSpec, Profile};
use super::{PyramidPerceptionSpec, TwoBlockSpec};
use crate::perception::circles::{CircleModel, CircleParams, FixedThreshold, MarkRotation, RigCamera, Threshold};
use crate::perception::krawler::{AxleGeometry, GearGeometry, GearSpec, SteeringPoly};
use crate::perception::{
    CameraModel, CastParams, ColorModelParams, Fisheye, HsvLimits, MountAngles, PairLimits, Pinhole, PyramidGeometry,
    PyramidParams, PyramidTrackerParams, SegmentationMode, TwoBlockGeometry, TwoBlockParams, VisionError,
};

impl From<&Mount> for MountAngles {
    fn from(m: &Mount) -> Self {
        Self {
            yaw_deg: m.yaw_deg,
            pitch_deg: m.pitch_deg,
            roll_deg: m.roll_deg,
        }
    }
}

impl CameraModel {
    /// The model a profile's camera describes. A pin-hole camera without intrinsics or
    /// field of view gets a focal length of one image width; a fisheye without a
    /// `fisheye` table a one-term polynomial of half the width (validation rejects both,
    /// so only hand-built specs reach these).
    pub fn from_spec(spec: &CameraSpec) -> Self {
        match spec.model {
            CameraModelKind::Pinhole => {
                let k = spec.pinhole_intrinsics().unwrap_or(Intrinsics {
                    fx: spec.width_px as f64,
                    fy: spec.width_px as f64,
                    cx: spec.width_px as f64 / 2.0,
                    cy: spec.height_px as f64 / 2.0,
                    k1: 0.0,
                    k2: 0.0,
                });
                CameraModel::Pinhole(Pinhole {
                    fx: k.fx,
                    fy: k.fy,
                    cx: k.cx,
                    cy: k.cy,
                    k1: k.k1,
                    k2: k.k2,
                })
            }
            CameraModelKind::Fisheye => {
                let fe = spec.fisheye.clone().unwrap_or(FisheyeSpec {
                    poly: vec![-(spec.width_px as f64) / 2.0],
                    center_px: [spec.width_px as f64 / 2.0, spec.height_px as f64 / 2.0],
                    affine: [1.0, 0.0, 0.0],
                });
                let max_rho = (spec.width_px as f64).hypot(spec.height_px as f64);
                CameraModel::Fisheye(Fisheye::new(fe.poly, fe.center_px, fe.affine, max_rho))
            }
        }
    }
}

impl From<&PerceptionSpec> for ColorModelParams {
    fn from(p: &PerceptionSpec) -> Self {
        Self {
            n_sd: p.n_sd,
            sd_floor: p.sd_floor_deg.to_radians(),
            sd_ceiling: p.sd_ceiling_deg.to_radians(),
            min_l: p.min_brightness,
            min_chroma: p.min_chroma_deg.to_radians(),
            timeout1: p.timeout1_s,
            timeout2: p.timeout2_s,
            adaptive: p.mode == SegmentationMode::Adaptive,
            adapt_rate: p.adapt_rate,
        }
    }
}

impl ColorModelParams {
    /// The parameters a profile's `[perception]` table sets (adaptive only in
    /// `adaptive` mode; degrees become radians).
    pub fn from_spec(p: &PerceptionSpec) -> Self {
        Self::from(p)
    }
}

impl From<&PerceptionSpec> for PairLimits {
    fn from(p: &PerceptionSpec) -> Self {
        Self {
            min_component_px: p.min_component_px as u64,
            max_gap_frac: p.max_gap_frac,
            gap_slack_px: p.gap_slack_px,
            max_vertical_frac: p.max_vertical_frac,
            max_height_ratio: p.max_height_ratio,
            min_count_ratio: p.min_count_ratio,
            max_candidates: p.max_candidates as usize,
        }
    }
}

impl From<&PyramidPerceptionSpec> for PyramidParams {
    fn from(s: &PyramidPerceptionSpec) -> Self {
        Self {
            orange: s.orange.range(),
            blue: s.blue.range(),
            min_ellipse_px: s.min_ellipse_px,
            max_axis_ratio: s.max_axis_ratio,
            min_fill: s.min_fill,
            min_blue_px: s.min_blue_px,
            tighten: s.tighten,
            max_size_dev: s.max_size_dev,
            max_vertical_dev: s.max_vertical_dev,
            max_horizontal_dev: s.max_horizontal_dev,
            area_ratio: s.area_ratio,
            tracking_ball_px: s.tracking_ball_px,
            tracking_reset_frames: s.tracking_reset_frames,
            max_candidates: s.max_candidates,
        }
    }
}

impl TwoBlockGeometry {
    /// From the profile's camera and fiducial.
    pub fn new(camera: &CameraSpec, fiducial: &TwoBlockSpec) -> Self {
        Self::from_camera(
            &CameraModel::from_spec(camera),
            camera.width_px,
            MountAngles::from(&camera.mount),
            (fiducial.width_m, fiducial.height_m),
        )
    }
}

fn missing(what: String) -> VisionError {
    VisionError::Profile { what }
}

fn camera(profile: &Profile, camera: usize) -> Result<&CameraSpec, VisionError> {
    profile
        .cameras
        .get(camera)
        .ok_or_else(|| missing(format!("profile `{}` has no camera {camera}", profile.name)))
}

impl PyramidGeometry {
    /// From camera `camera` of a profile and its `pyramid` fiducial.
    ///
    /// # Errors
    /// [`VisionError::Profile`] without a pin-hole camera or a pyramid fiducial.
    pub fn from_profile(profile: &Profile, camera_index: usize) -> Result<Self, VisionError> {
        let pyr = *profile
            .fiducial
            .require::<super::PyramidSpec>()
            .map_err(|e| missing(format!("profile `{}` {e}", profile.name)))?;
        let cam = camera(profile, camera_index)?;
        let k = cam
            .pinhole_intrinsics()
            .ok_or_else(|| missing(format!("camera `{}` is not a pin-hole camera", cam.name)))?;
        Ok(Self {
            f_px: k.fx,
            principal: [k.cx, k.cy],
            h: pyr.blue_edge_length_m,
            m: pyr.edge_to_ball_m,
            ball_diameter: pyr.ball_diameter_m,
        })
    }
}

impl TwoBlockParams {
    /// The two-block tracker of camera `camera` of a profile with a
    /// `two_block` fiducial: table defaults from the fiducial's paint colours as painted
    /// ([`NamedColor::paint_srgb`](crate::profile::NamedColor::paint_srgb)), in the
    /// order they appear in this camera's image, and everything else from `[perception]`.
    ///
    /// # Errors
    /// [`VisionError::Profile`] when the profile has no two-block fiducial or no such camera.
    pub fn from_profile(profile: &Profile, camera_index: usize) -> Result<Self, VisionError> {
        let fid = *profile
            .fiducial
            .require::<super::TwoBlockSpec>()
            .map_err(|e| missing(format!("profile `{}` {e}", profile.name)))?;
        let cam = camera(profile, camera_index)?;
        let p = &profile.perception;
        let (img_left, img_right) = if cam.mount.is_flipped() {
            (fid.right_color, fid.left_color)
        } else {
            (fid.left_color, fid.right_color)
        };
        Ok(Self {
            width: cam.width_px,
            height: cam.height_px,
            colours: [img_left.paint_srgb(), img_right.paint_srgb()],
            table_sd: p.table_sd_deg.to_radians(),
            limits: PairLimits::from(p),
            colour: ColorModelParams::from(p),
            mode: p.mode,
            imprint_rects: [p.imprint.left_rect, p.imprint.right_rect],
            imprint_sample_frac: p.imprint.sample_frac,
            imprint_frames: p.imprint.frames,
            cast: CastParams {
                tau_s: p.cast_tau_s,
                dead_band: p.cast_dead_band,
            },
        })
    }
}

impl CircleModel {
    /// The correspondence model of a profile's `circles` fiducial: each placement's
    /// (y_m, z_m) as face coordinates (u, v) (the module's face looks along +x, so +y is
    /// to the right seen from in front), its rotation, and half the diameter as radius.
    ///
    /// # Errors
    /// [`VisionError::Profile`] without circles, or with placements the model refuses
    /// (fewer than 5, overlapping, a rotation other than −45, 0, 45 or 90).
    pub fn from_profile(profile: &Profile) -> Result<Self, VisionError> {
        let c = profile
            .fiducial
            .require::<super::CirclesSpec>()
            .map_err(|e| missing(format!("profile `{}` {e}", profile.name)))?;
        let mut marks = Vec::with_capacity(c.placements.len());
        for (i, p) in c.placements.iter().enumerate() {
            let r = MarkRotation::from_degrees(p.rotation_deg).ok_or_else(|| {
                missing(format!(
                    "fiducial.circles.placements[{i}].rotation_deg: expected one of −45, 0, 45, 90, got {}",
                    p.rotation_deg
                ))
            })?;
            marks.push(([p.y_m, p.z_m], r));
        }
        CircleModel::new(c.diameter_m / 2.0, &marks)
            .map_err(|e| missing(format!("profile `{}`: `circles` fiducial: {e}", profile.name)))
    }
}

impl CircleParams {
    /// The detector's parameters for frames `width_px` wide ([`CircleParams::for_image`]),
    /// with the fixed threshold of the profile's `circles` fiducial when it sets one.
    pub fn from_profile(profile: &Profile, width_px: usize) -> Self {
        let mut p = CircleParams::for_image(width_px);
        let levels = profile
            .fiducial
            .get::<crate::profile::CirclesSpec>()
            .and_then(|c| c.fixed_threshold);
        if let Some([black_below, white_above]) = levels {
            p.threshold = Threshold::Fixed(FixedThreshold {
                black_below,
                white_above,
            });
        }
        p
    }
}

impl RigCamera {
    /// Camera `camera_index` of a profile as a rig camera: its model from the spec, its
    /// mount's angles and its offset (x_m, y_m, z_m) in the rover frame.
    ///
    /// # Errors
    /// [`VisionError::Profile`] when the profile has no such camera.
    pub fn from_profile(profile: &Profile, camera_index: usize) -> Result<Self, VisionError> {
        let cam = camera(profile, camera_index)?;
        let m = &cam.mount;
        Ok(Self::new(
            CameraModel::from_spec(cam),
            MountAngles::from(m),
            [m.x_m, m.y_m, m.z_m],
        ))
    }
}

impl AxleGeometry {
    /// The back-projection geometry of a double-Ackermann profile's belly camera
    /// (`camera_index`): its model, mount rotation and position, and the axles' planes at
    /// ± half the wheelbase.
    ///
    /// # Errors
    /// [`VisionError::Profile`] without the camera or a wheelbase.
    pub fn from_profile(profile: &Profile, camera_index: usize) -> Result<Self, VisionError> {
        let cam = camera(profile, camera_index)?;
        let half = profile
            .drive
            .wheelbase_m
            .ok_or_else(|| missing(format!("profile `{}` has no drive.wheelbase_m", profile.name)))?
            / 2.0;
        let m = &cam.mount;
        Ok(Self {
            model: CameraModel::from_spec(cam),
            body_from_camera: crate::perception::body_from_camera(m),
            camera: nalgebra::Point3::new(m.x_m, m.y_m, m.z_m),
            axle_x: [half, -half],
        })
    }
}

impl GearGeometry {
    /// The gear of a double-Ackermann profile: its track, wheelbase and wheel radius,
    /// with `spec`'s dimensions (the profile's `[robot.gear]`, which the `krawler` robot
    /// kind reads: `behaviors::krawler::gear_spec`).
    ///
    /// # Errors
    /// [`VisionError::Profile`] without `drive.wheel_radius_m` or `drive.wheelbase_m`.
    pub fn from_profile(profile: &Profile, spec: GearSpec) -> Result<Self, VisionError> {
        let d = &profile.drive;
        let need = |v: Option<f64>, what: &str| {
            v.ok_or_else(|| missing(format!("profile `{}` has no drive.{what}", profile.name)))
        };
        Ok(Self {
            track: d.track_m,
            wheelbase: need(d.wheelbase_m, "wheelbase_m")?,
            wheel_radius: need(d.wheel_radius_m, "wheel_radius_m")?,
            spec,
        })
    }
}

impl SteeringPoly {
    /// The steering calibrations (front, rear) of a profile's `markers` fiducial, or
    /// `None` when it has none yet (`marsupial calibrate-steering` writes them).
    pub fn from_profile(profile: &Profile) -> Option<[Self; 2]> {
        let polys = profile
            .fiducial
            .get::<crate::profile::MarkersSpec>()?
            .steering_poly_deg?;
        Some(polys.map(|c| Self { deg: c.deg }))
    }
}

impl PyramidTrackerParams {
    /// The pyramid tracker of camera `camera` of a profile with a `pyramid` fiducial:
    /// bands, filters and imprint/adapt settings from `[perception]` and
    /// `[perception.pyramid]`.
    ///
    /// # Errors
    /// [`VisionError::Profile`] when the profile lacks the fiducial or the (pin-hole) camera.
    pub fn from_profile(profile: &Profile, camera_index: usize) -> Result<Self, VisionError> {
        let geometry = PyramidGeometry::from_profile(profile, camera_index)?;
        let cam = camera(profile, camera_index)?;
        let p = &profile.perception;
        let spec = &p.pyramid;
        Ok(Self {
            width: cam.width_px,
            height: cam.height_px,
            detector: PyramidParams::from(spec),
            geometry,
            mode: p.mode,
            colour: ColorModelParams::from(p),
            limits: HsvLimits {
                n_sd: p.n_sd,
                hue_sd_deg: spec.hue_sd_deg,
                sv_sd: spec.sv_sd,
                min_s: spec.min_s,
                min_v: spec.min_v,
            },
            imprint_distance_m: spec.imprint_distance_m,
            imprint_widen: spec.imprint_widen,
            imprint_frames: spec.imprint_frames,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pyramid_defaults_agree_with_the_profile_defaults() {
        assert_eq!(
            PyramidParams::from(&PyramidPerceptionSpec::default()),
            PyramidParams::default()
        );
    }

    #[test]
    fn mount_angles_keep_the_flip() {
        let m = Mount {
            roll_deg: 180.0,
            ..Mount::default()
        };
        assert!(MountAngles::from(&m).is_flipped() && m.is_flipped());
        assert!(!MountAngles::from(&Mount::default()).is_flipped());
    }
}
