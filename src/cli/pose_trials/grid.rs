//! The campaign's runs: every combination of its pose grid's axes (and the occlusion's),
//! in a fixed order, and where each puts the rover. A run's index in this order seeds it,
//! which is why the order is part of the records' bytes.

use super::PoseCampaign;
use crate::geometry::Pose2;

/// One run of the grid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunSpec {
    /// Index in the campaign.
    pub index: usize,
    /// Distance, m.
    pub distance_m: f64,
    /// α, degrees.
    pub alpha_deg: f64,
    /// Heading off facing the module, degrees.
    pub turn_deg: f64,
    /// Marks hidden.
    pub hidden: usize,
    /// The decoys are placed.
    pub decoy: bool,
    /// Noise draw, 0-based.
    pub noise: u32,
    /// JPEG quality of the stream (0: raw).
    pub jpeg_quality: u32,
}

/// Every run of a campaign, in order: JPEG quality, distance, α, turn, hidden, decoy,
/// noise.
pub fn runs(c: &PoseCampaign) -> Vec<RunSpec> {
    let hidden = c.occlusion.as_ref().map_or(vec![0], |o| o.hidden.clone());
    let decoys: &[bool] = match &c.occlusion {
        Some(o) if !o.decoys.is_empty() => &[false, true],
        _ => &[false],
    };
    let qualities = c
        .pose
        .jpeg_quality
        .clone()
        .unwrap_or_else(|| vec![c.sensor.jpeg_quality]);
    let mut out = Vec::new();
    for &jpeg_quality in &qualities {
        for &distance_m in &c.pose.distances_m {
            for &alpha_deg in &c.pose.alpha_deg {
                for &turn_deg in &c.pose.turn_deg {
                    for &h in &hidden {
                        for &decoy in decoys {
                            for noise in 0..c.pose.noise_seeds {
                                out.push(RunSpec {
                                    index: out.len(),
                                    distance_m,
                                    alpha_deg,
                                    turn_deg,
                                    hidden: h,
                                    decoy,
                                    noise,
                                    jpeg_quality,
                                });
                            }
                        }
                    }
                }
            }
        }
    }
    out
}

/// The rover's pose for a run: `distance_m` from the face centre, `alpha_deg` off the
/// axis, facing the module and then turned `turn_deg`.
pub fn rover_pose(spec: &RunSpec) -> Pose2 {
    let a = spec.alpha_deg.to_radians();
    Pose2::new(
        spec.distance_m * a.cos(),
        spec.distance_m * a.sin(),
        a + std::f64::consts::PI + spec.turn_deg.to_radians(),
    )
}
