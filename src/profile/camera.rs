//! `[[cameras]]`: camera models, resolution and mounting.

use crate::config::{Validate, Validator};
use serde::{Deserialize, Serialize};

/// Projection model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CameraModelKind {
    /// Pin-hole (with optional radial distortion).
    Pinhole,
    /// Scaramuzza's unified omnidirectional (fisheye) model.
    Fisheye,
}

/// Pin-hole intrinsics in pixels.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Intrinsics {
    /// Focal length along x, px.
    pub fx: f64,
    /// Focal length along y, px.
    pub fy: f64,
    /// Principal point x, px.
    pub cx: f64,
    /// Principal point y, px.
    pub cy: f64,
    /// Radial distortion k1, k2 (Brown model); zero by default.
    #[serde(default)]
    pub k1: f64,
    /// Second radial coefficient.
    #[serde(default)]
    pub k2: f64,
}

/// Scaramuzza (OCamCalib) model. `poly` is the back-projection polynomial exactly as the
/// OCamCalib toolbox prints it (a0 < 0: its optical axis is −z); `center_px` is given in
/// (column, row) order, whereas OCamCalib prints (row, column), so swap them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FisheyeSpec {
    /// Coefficients a0, a1 (= 0), a2, a3, a4 … of f(ρ), ρ in pixels.
    pub poly: Vec<f64>,
    /// Distortion centre (column, row), px.
    pub center_px: [f64; 2],
    /// Affine correction (c, d, e); (1, 0, 0) for an ideal sensor.
    #[serde(default = "default_affine")]
    pub affine: [f64; 3],
}

fn default_affine() -> [f64; 3] {
    [1.0, 0.0, 0.0]
}

/// Where a camera sits on the body and where it looks.
///
/// Position in the body frame (+x forward, +y left, +z up, metres). Orientation as
/// yaw (about +z, 180 looks backwards), pitch (positive looks down) and roll about the
/// optical axis (180 turns the image upside down, like Bujold's camera), in degrees.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mount {
    /// Forward offset, m.
    #[serde(default)]
    pub x_m: f64,
    /// Leftward offset, m.
    #[serde(default)]
    pub y_m: f64,
    /// Height above ground, m.
    #[serde(default)]
    pub z_m: f64,
    /// Yaw, degrees (0 forward, 180 backward).
    #[serde(default)]
    pub yaw_deg: f64,
    /// Pitch, degrees (positive looks down).
    #[serde(default)]
    pub pitch_deg: f64,
    /// Roll about the optical axis, degrees.
    #[serde(default)]
    pub roll_deg: f64,
}

impl Mount {
    /// True when the image is upside down (roll near ±180°).
    pub fn is_flipped(&self) -> bool {
        let r = self.roll_deg.rem_euclid(360.0);
        (r - 180.0).abs() < 90.0
    }
}

/// One `[[cameras]]` entry.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSpec {
    /// Name, for logs (`"rear"`, `"left"`).
    pub name: String,
    /// Projection model.
    pub model: CameraModelKind,
    /// Image width, px.
    pub width_px: usize,
    /// Image height, px.
    pub height_px: usize,
    /// Pin-hole: horizontal full-angle field of view, degrees (alternative to intrinsics).
    #[serde(default)]
    pub hfov_deg: Option<f64>,
    /// Pin-hole: explicit intrinsics (alternative to `hfov_deg`).
    #[serde(default)]
    pub intrinsics: Option<Intrinsics>,
    /// Fisheye parameters (required when `model = "fisheye"`).
    #[serde(default)]
    pub fisheye: Option<FisheyeSpec>,
    /// Frame rate, Hz.
    #[serde(default = "default_fps")]
    pub fps: f64,
    /// Mounting pose.
    #[serde(default)]
    pub mount: Mount,
}

fn default_fps() -> f64 {
    30.0
}

impl CameraSpec {
    /// Pin-hole intrinsics: the explicit ones, or square pixels and a centred principal
    /// point derived from `hfov_deg`.
    pub fn pinhole_intrinsics(&self) -> Option<Intrinsics> {
        if let Some(k) = self.intrinsics {
            return Some(k);
        }
        let fov = self.hfov_deg?.to_radians();
        let fx = self.width_px as f64 / 2.0 / (fov / 2.0).tan();
        Some(Intrinsics {
            fx,
            fy: fx,
            cx: self.width_px as f64 / 2.0,
            cy: self.height_px as f64 / 2.0,
            k1: 0.0,
            k2: 0.0,
        })
    }

    pub(crate) fn validate_at(&self, v: &mut Validator<'_>, base: &str) {
        let p = |f: &str| format!("{base}.{f}");
        v.require(!self.name.trim().is_empty(), &p("name"), || {
            "expected a non-empty camera name".into()
        });
        v.nonzero(&p("width_px"), self.width_px);
        v.nonzero(&p("height_px"), self.height_px);
        v.require(
            self.width_px <= 16384 && self.height_px <= 16384,
            &p("width_px"),
            || {
                format!(
                    "expected at most 16384×16384 pixels, got {}×{}",
                    self.width_px, self.height_px
                )
            },
        );
        v.positive(&p("fps"), self.fps);
        for (f, x) in [
            ("mount.x_m", self.mount.x_m),
            ("mount.y_m", self.mount.y_m),
            ("mount.z_m", self.mount.z_m),
            ("mount.yaw_deg", self.mount.yaw_deg),
            ("mount.pitch_deg", self.mount.pitch_deg),
            ("mount.roll_deg", self.mount.roll_deg),
        ] {
            v.finite(&p(f), x);
        }
        match self.model {
            CameraModelKind::Pinhole => {
                match (self.hfov_deg, &self.intrinsics) {
                    (None, None) => v.problem(base, "a pinhole camera needs `hfov_deg` or an `intrinsics` table"),
                    (Some(_), Some(_)) => v.problem(&p("hfov_deg"), "give `hfov_deg` or `intrinsics`, not both"),
                    (Some(f), None) => v.require(f.is_finite() && f > 0.0 && f < 180.0, &p("hfov_deg"), || {
                        format!("expected a field of view in (0, 180) degrees, got {f}")
                    }),
                    (None, Some(k)) => {
                        v.positive(&p("intrinsics.fx"), k.fx);
                        v.positive(&p("intrinsics.fy"), k.fy);
                        v.finite(&p("intrinsics.cx"), k.cx);
                        v.finite(&p("intrinsics.cy"), k.cy);
                        v.finite(&p("intrinsics.k1"), k.k1);
                        v.finite(&p("intrinsics.k2"), k.k2);
                    }
                }
                if self.fisheye.is_some() {
                    v.problem(&p("fisheye"), "a `fisheye` table needs `model = \"fisheye\"`");
                }
            }
            CameraModelKind::Fisheye => match &self.fisheye {
                None => v.problem(base, "a fisheye camera needs a `fisheye` table (poly, center_px)"),
                Some(fe) => {
                    v.require((2..=8).contains(&fe.poly.len()), &p("fisheye.poly"), || {
                        format!("expected 2 to 8 polynomial coefficients, got {}", fe.poly.len())
                    });
                    v.require(fe.poly.iter().all(|c| c.is_finite()), &p("fisheye.poly"), || {
                        "expected finite coefficients".into()
                    });
                    v.require(fe.poly.first().is_some_and(|a0| *a0 != 0.0), &p("fisheye.poly"), || {
                        "expected a0 ≠ 0 (it is the focal term)".into()
                    });
                    v.finite(&p("fisheye.center_px"), fe.center_px[0] + fe.center_px[1]);
                    let [c, d, e] = fe.affine;
                    v.require((c - d * e).abs() > 1e-9, &p("fisheye.affine"), || {
                        format!("expected an invertible affine correction, got c={c}, d={d}, e={e}")
                    });
                }
            },
        }
    }
}

impl Validate for CameraSpec {
    fn validate(&self, v: &mut Validator<'_>) {
        self.validate_at(v, "camera");
    }
}
