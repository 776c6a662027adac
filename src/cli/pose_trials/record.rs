//! The records a campaign produces, one [`PoseRun`] a line of `runs.jsonl`: what each
//! camera saw, labelled and posed, and the stereo pose, each beside the truth. Their field
//! names are the JSON's, read by the tables and by whoever studies the runs afterwards.

use serde::Serialize;

/// A pose measured against the truth, or why there is none.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct PoseOutcome {
    /// A pose was computed.
    pub found: bool,
    /// Distance between the estimated and true module origin on the ground, m.
    pub position_err_m: Option<f64>,
    /// Error of the module's heading, degrees.
    pub heading_err_deg: Option<f64>,
    /// Angle of R̂ᵀR (all three axes), degrees.
    pub rotation_err_deg: Option<f64>,
    /// The pose's own reprojection error, px.
    pub reprojection_px: Option<f64>,
    /// Marks the pose used.
    pub marks: Option<usize>,
    /// The typed error's variant (`TooFewMarks`, `Collinear`, …) when there is no pose,
    /// or the correspondence's when there was no labelling to pose.
    pub error: Option<String>,
    /// Its message.
    pub message: Option<String>,
}

/// One camera's labelling against the truth.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct Labelling {
    /// A labelling was accepted.
    pub found: bool,
    /// Its inliers.
    pub inliers: usize,
    /// Inliers more than a mark radius (at least 3 px) from their mark's true image.
    pub mislabelled: usize,
    /// The homography's RMS reprojection error over the inliers, px.
    pub reprojection_px: Option<f64>,
    /// The correspondence's error variant when none was accepted.
    pub error: Option<String>,
}

/// One camera's part of a run.
#[derive(Debug, Clone, PartialEq, Default, Serialize)]
pub struct CameraRun {
    /// Model marks wholly in the image (their rim's four extremes), less the hidden ones.
    pub visible: usize,
    /// Marks the detector reported (decoys included).
    pub detected: usize,
    /// The labelling (≥ 5 marks).
    pub labelling: Labelling,
    /// The mono pose through the camera's lens model.
    pub mono: PoseOutcome,
    /// Ablation: the mono pose through a pin-hole of the lens's on-axis focal length.
    pub mono_pinhole: PoseOutcome,
    /// Ablation: the labelling that accepts 4 marks (seed 000's bug).
    pub labelling_four_point: Labelling,
    /// Ablation: the mono pose from that labelling.
    pub mono_four_point: PoseOutcome,
}

/// The record of one run (a line of `runs.jsonl`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PoseRun {
    /// Index in the campaign.
    pub index: usize,
    /// Distance from the face centre, m.
    pub distance_m: f64,
    /// α, degrees.
    pub alpha_deg: f64,
    /// Heading off facing the module, degrees.
    pub turn_deg: f64,
    /// Noise draw.
    pub noise: u32,
    /// JPEG quality of the stream (0: raw frames).
    pub jpeg_quality: u32,
    /// The run's seed.
    pub seed: u64,
    /// Model marks hidden behind panels.
    pub hidden: Vec<usize>,
    /// The false marks were placed.
    pub decoy: bool,
    /// Cameras 0 (left) and 1 (right).
    pub cameras: [CameraRun; 2],
    /// The stereo pose.
    pub stereo: PoseOutcome,
    /// Ablation: the stereo pose from the 4-mark labellings.
    pub stereo_four_point: PoseOutcome,
}

/// A pose so far off that a planner trusting it would go the wrong way: more than 10 %
/// of the distance or 10° of heading out (the paper's worst, 30 cm at 4 m, is 7.5 %).
pub fn is_wrong(o: &PoseOutcome, distance_m: f64) -> bool {
    o.found && (o.position_err_m.unwrap_or(0.0) > 0.1 * distance_m || o.heading_err_deg.unwrap_or(0.0) > 10.0)
}
