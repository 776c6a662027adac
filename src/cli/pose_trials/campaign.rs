//! The campaign file (`[pose]`, `[occlusion]`, `[lighting]`, `[sensor]`): its types, their
//! validation, and loading it with the profile it names. Kept apart from the runs so
//! `marsupial check` can validate a campaign without touching the renderer or detector.

use crate::config::{self, ConfigError, Validate, Validator};
use crate::profile::Profile;
use crate::sim::lighting::LightingSpec;
use crate::sim::scenario::SensorSpec;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// `[pose]`: the grid of rover poses. Every combination is a run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PoseGrid {
    /// Distances from the module's face centre to the rover's origin, m.
    pub distances_m: Vec<f64>,
    /// Angles off the module's axis, degrees.
    pub alpha_deg: Vec<f64>,
    /// The rover's heading turned off facing the module, degrees (default `[0]`).
    #[serde(default = "zero_list")]
    pub turn_deg: Vec<f64>,
    /// Independent draws of the sensor noise per pose (default 1).
    #[serde(default = "one")]
    pub noise_seeds: u32,
    /// Frames rendered per camera before the one measured, so auto-exposure settles
    /// (default 3).
    #[serde(default = "three")]
    pub settle_frames: u32,
    /// JPEG qualities of the cameras' stream, an axis (0: raw frames); absent: the
    /// `[sensor]`'s `jpeg_quality` alone.
    #[serde(default)]
    pub jpeg_quality: Option<Vec<u32>>,
}

/// `[occlusion]`: marks hidden behind panels, and false marks near the module.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OcclusionSpec {
    /// How many marks each run hides (an axis): which ones is drawn per run. A hidden
    /// mark is covered flush with a patch of the face's grey
    /// ([`world::build_face`](crate::sim::world::build_face)). A panel held in
    /// front of it would be more physical, but the renderer draws front to back by each
    /// primitive's centre distance, so a small panel before the large face is lost
    /// wherever its centre lies farther from the camera than the face's.
    pub hidden: Vec<usize>,
    /// False marks placed near the module; when any are given every run is made both
    /// without and with them (an axis).
    #[serde(default)]
    pub decoys: Vec<DecoySpec>,
}

/// One false mark: a circle mark of the module's pattern, either on a panel of the
/// module's grey standing near the module, or painted on the face among the real marks
/// (`painted`). A panel must stand clear of the face in the image (beside the module):
/// for the reason given at [`OcclusionSpec::hidden`], a panel overlapping the face would
/// be drawn behind it. A painted one is drawn by the face itself
/// ([`world::build_face`](crate::sim::world::build_face)), so it can sit among the marks:
/// seed 000 §V-D's four true marks and one false one.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DecoySpec {
    /// Position of its centre in the module frame (x forward of the face, y, height), m.
    /// A painted decoy lies on the face: x must be 0.
    pub at_m: [f64; 3],
    /// Its bar's rotation, degrees.
    pub rotation_deg: f64,
    /// Side of its square panel, m (default 0.14); unused when painted.
    #[serde(default = "decoy_side")]
    pub panel_m: f64,
    /// Painted on the module's face instead of standing on a panel (default false).
    #[serde(default)]
    pub painted: bool,
}

fn zero_list() -> Vec<f64> {
    vec![0.0]
}
fn one() -> u32 {
    1
}
fn three() -> u32 {
    3
}
fn decoy_side() -> f64 {
    0.14
}

/// A perception campaign file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PoseCampaign {
    /// Name.
    pub name: String,
    /// Description.
    #[serde(default)]
    pub description: String,
    /// Profile path (relative to the file); it must have `circles` fiducial.
    pub profile: PathBuf,
    /// Campaign seed.
    #[serde(default)]
    pub seed: u64,
    /// The pose grid.
    pub pose: PoseGrid,
    /// Hidden marks and false ones (absent: none).
    #[serde(default)]
    pub occlusion: Option<OcclusionSpec>,
    /// The light (default: the lab's uniform light).
    #[serde(default)]
    pub lighting: LightingSpec,
    /// The cameras' sensor.
    #[serde(default)]
    pub sensor: SensorSpec,
}

impl Validate for PoseCampaign {
    fn validate(&self, v: &mut Validator<'_>) {
        v.require(!self.name.trim().is_empty(), "name", || {
            "expected a non-empty name".into()
        });
        let g = &self.pose;
        for (field, list) in [
            ("pose.distances_m", &g.distances_m),
            ("pose.alpha_deg", &g.alpha_deg),
            ("pose.turn_deg", &g.turn_deg),
        ] {
            v.require(!list.is_empty(), field, || "expected at least one value".into());
        }
        for (i, d) in g.distances_m.iter().enumerate() {
            v.range(&format!("pose.distances_m[{i}]"), *d, 0.3, 50.0);
        }
        for (i, a) in g.alpha_deg.iter().enumerate() {
            v.range(&format!("pose.alpha_deg[{i}]"), *a, -89.0, 89.0);
        }
        for (i, a) in g.turn_deg.iter().enumerate() {
            v.range(&format!("pose.turn_deg[{i}]"), *a, -90.0, 90.0);
        }
        v.require((1..=1000).contains(&g.noise_seeds), "pose.noise_seeds", || {
            format!("expected 1 to 1000 noise seeds, got {}", g.noise_seeds)
        });
        if let Some(q) = &g.jpeg_quality {
            v.require(!q.is_empty(), "pose.jpeg_quality", || {
                "expected at least one value".into()
            });
            for (i, q) in q.iter().enumerate() {
                v.require(*q <= 100, &format!("pose.jpeg_quality[{i}]"), || {
                    format!("expected 0 (raw) or a quality 1–100, got {q}")
                });
            }
        }
        v.require(g.settle_frames <= 50, "pose.settle_frames", || {
            format!("expected at most 50 settling frames, got {}", g.settle_frames)
        });
        if let Some(o) = &self.occlusion {
            v.require(!o.hidden.is_empty(), "occlusion.hidden", || {
                "expected at least one value".into()
            });
            for (i, n) in o.hidden.iter().enumerate() {
                v.require(*n <= 8, &format!("occlusion.hidden[{i}]"), || {
                    format!("expected at most 8 hidden marks, got {n}")
                });
            }
            for (i, d) in o.decoys.iter().enumerate() {
                for (k, x) in d.at_m.iter().enumerate() {
                    v.finite(&format!("occlusion.decoys[{i}].at_m[{k}]"), *x);
                }
                v.finite(&format!("occlusion.decoys[{i}].rotation_deg"), d.rotation_deg);
                v.range(&format!("occlusion.decoys[{i}].panel_m"), d.panel_m, 0.01, 1.0);
                v.require(
                    !d.painted || d.at_m[0] == 0.0,
                    &format!("occlusion.decoys[{i}].at_m[0]"),
                    || format!("a painted decoy lies on the face (x = 0), got x = {}", d.at_m[0]),
                );
            }
        }
        self.lighting.validate_at("lighting", v);
        self.sensor.validate_at("sensor", v);
    }
}

/// A loaded campaign with its profile and the circle model.
#[derive(Debug, Clone)]
pub struct LoadedCampaign {
    /// The file's contents.
    pub campaign: PoseCampaign,
    /// The profile it names.
    pub profile: Profile,
}

impl PoseCampaign {
    /// Whether a parsed TOML file is a perception campaign (it has a `[pose]` table), so
    /// `marsupial check` validates it as one.
    pub fn is_campaign(table: &toml::Table) -> bool {
        table.get("pose").is_some_and(toml::Value::is_table)
    }

    /// Loads and validates a campaign and its profile, which must have two cameras and
    /// `circles` fiducial.
    ///
    /// # Errors
    /// [`ConfigError`] for the file or its profile.
    pub fn load(path: &Path) -> Result<LoadedCampaign, ConfigError> {
        let campaign: PoseCampaign = config::load(path)?;
        let profile = Profile::load(&path.parent().unwrap_or(Path::new(".")).join(&campaign.profile))?;
        if profile.fiducial.get::<crate::profile::CirclesSpec>().is_none() || profile.cameras.len() < 2 {
            return Err(ConfigError::Invalid {
                file: path.to_path_buf(),
                problems: vec![config::Problem {
                    path: "profile".into(),
                    line: None,
                    message: format!(
                        "a perception campaign needs a stereo pair and `circles` fiducial; profile `{}` has {} camera(s){}",
                        profile.name,
                        profile.cameras.len(),
                        if profile.fiducial.get::<crate::profile::CirclesSpec>().is_none() {
                            " and no circles"
                        } else {
                            ""
                        }
                    ),
                }],
            });
        }
        Ok(LoadedCampaign { campaign, profile })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A painted decoy off the face is refused with the field named; one on it is taken.
    #[test]
    fn a_painted_decoy_must_lie_on_the_face() {
        let text = |x: f64| {
            format!(
                "name = \"t\"\nprofile = \"p.toml\"\n[pose]\ndistances_m = [2.0]\nalpha_deg = [0.0]\n\
                 [occlusion]\nhidden = [0]\ndecoys = [ {{ at_m = [{x:?}, 0.1, 0.6], rotation_deg = 90.0, painted = true }} ]\n"
            )
        };
        let file = Path::new("campaign.toml");
        assert!(config::parse_str::<PoseCampaign>(&text(0.0), file).is_ok());
        match config::parse_str::<PoseCampaign>(&text(0.1), file) {
            Err(ConfigError::Invalid { problems, .. }) => {
                assert_eq!(problems.len(), 1, "{problems:?}");
                assert_eq!(problems[0].path, "occlusion.decoys[0].at_m[0]");
                assert!(
                    problems[0].message.contains("painted decoy lies on the face"),
                    "{problems:?}"
                );
            }
            other => panic!("{other:?}"),
        }
    }
}
