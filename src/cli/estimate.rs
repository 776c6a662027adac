//! `marsupial estimate`: runs the AutoKrawler's state estimator ([`KrawlerStateSchema`],
//! seed 003) over a rendered driving sequence with a known state, and measures it the
//! paper's way (Table I), plus the use the paper builds towards: double-Ackermann
//! odometry with the estimated steering against the commanded.
//!
//! For each frame of the sequence ([`crate::sim::krawler_sequence`]) the gear is built
//! from the true state, rendered by the belly fisheye with sensor noise (and the
//! sequence's error knobs: lost frames, mount vibration, mud on a marker, a light
//! change in level and colour, the body's shadow on the gear, the mount's plates in
//! view, the floor moving under the rover), and estimated. `--out DIR` gets:
//! * `frames.csv`: per delivered frame, the truth and estimate of each degree of freedom
//!   (roll and steering in degrees, drop in mm, θ in rad from the first frame) and the
//!   estimate's validity, and the commanded steering;
//! * `odometry.csv`: per frame, the dead-reckoned pose with the true, estimated and
//!   commanded steering;
//! * one SVG per degree of freedom (truth and estimate over time) and `odometry.svg`;
//! * `summary.json`: MAE per DOF (over every delivered frame, a held value counting as
//!   what a consumer reads; and over valid frames only), the wheel drift the paper's
//!   way (the mean of θ_RL and θ_RR against the rear motor encoder, which we take as the
//!   true mean rear rotation) and per wheel, the odometry drift, and the paper's row.
//!
//! Truth is exact here; the paper's came from IMUs, potentiometers and an encoder.

use super::estimate_frames::{SequenceFrames, steps_of, true_path};
use crate::perception::RgbImage;
use crate::perception::krawler::{
    AxleGeometry, GearGeometry, KrawlerEstimate, KrawlerParams, KrawlerStateSchema, SteeringPoly,
};
use crate::profile::Profile;
use crate::report::plot::{Series, paths_svg, time_series_svg};
use crate::sim::krawler_sequence::{SequenceSpec, TruthFrame, drive_of, generate, odometry};
use crate::sim::rng::Rng;
use std::fmt::Write as _;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Options of `marsupial estimate` (also its command-line arguments).
#[derive(Debug, Clone, clap::Args)]
pub struct EstimateOptions {
    /// A built-in sequence (dataset1, dataset2, dataset3: the paper's 82, 170 and 257 s)
    /// or a sequence file (TOML, see sequences/). `--scenario` is the same option: a
    /// sequence is the AutoKrawler's scenario.
    #[arg(long, visible_alias = "scenario", value_name = "NAME|FILE")]
    pub sequence: String,
    /// Write frames.csv, odometry.csv, the plots and summary.json here.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Seed (default: the sequence's).
    #[arg(long, value_name = "S")]
    pub seed: Option<u64>,
    /// The AutoKrawler profile (with its steering calibration).
    #[arg(long, value_name = "PROFILE", default_value = "profiles/autokrawler.toml")]
    pub profile: PathBuf,
    /// Print summary.json instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Turn off the mount-vibration compensation (every frame read with the nominal
    /// mount, as the paper does): for before/after figures.
    #[arg(long)]
    pub no_mount_compensation: bool,
    /// Also estimate through the robot's loop (the `krawler` robot's perceptual schema on
    /// its belly camera's frames, `estimate_runtime`): ticked in `lockstep` (the default;
    /// with the slip monitor's figures) or on the `threads` of the runtime in real time,
    /// and print its Table I row beside the offline one. `--out` gets the offline run's.
    #[arg(long, value_enum, value_name = "LOOP", num_args = 0..=1, default_missing_value = "lockstep")]
    pub runtime: Option<super::estimate_runtime::RuntimePath>,
}

/// The ten degrees of freedom's names, in [`KrawlerState`](crate::sim::krawler::KrawlerState) order.
pub const DOF_NAMES: [&str; 10] = [
    "roll_f", "roll_r", "drop_f", "drop_r", "steer_f", "steer_r", "theta_fl", "theta_fr", "theta_rl", "theta_rr",
];

/// The paper's Table I: (length s, roll F, roll R, steer F, steer R in degrees, max drift rad).
pub const PAPER_TABLE_I: [(f64, [f64; 4], f64); 3] = [
    (82.0, [1.65, 1.51, 2.49, 1.98], 0.86),
    (170.0, [1.41, 1.32, 2.40, 2.49], 3.70),
    (257.0, [2.41, 1.97, 1.86, 2.55], 1.78),
];

/// The targets for ours: roll ≤ 1.3°, steering ≤ 1.8°, wheel drift ≤ 0.5 rad.
pub const TARGETS: (f64, f64, f64) = (1.3, 1.8, 0.5);

/// Errors of one degree of freedom over a sequence, in its reporting unit (degrees, mm
/// or rad).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DofError {
    /// Mean absolute error over every delivered frame (held values included).
    pub mae: f64,
    /// Mean absolute error over the frames where the estimate is valid.
    pub mae_valid: f64,
    /// Largest absolute error.
    pub max: f64,
    /// Error at the last frame (signed).
    pub last: f64,
    /// Fraction of delivered frames with a valid estimate.
    pub valid: f64,
}

/// Odometry drift with one source of steering against the true path.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct OdometryDrift {
    /// Position error at the end, m.
    pub final_m: f64,
    /// Largest position error along the way, m.
    pub max_m: f64,
    /// Heading error at the end, degrees (signed).
    pub heading_deg: f64,
}

/// What a run measured.
#[derive(Debug, Clone, PartialEq)]
pub struct EstimateSummary {
    /// The sequence's name.
    pub sequence: String,
    /// Its length, s.
    pub duration_s: f64,
    /// Seed used.
    pub seed: u64,
    /// Frames in the sequence, and delivered to the estimator.
    pub frames: usize,
    /// Frames delivered (the rest were lost to the frame-drop knob).
    pub delivered: usize,
    /// Error per degree of freedom, in [`DOF_NAMES`] order (roll and steering in
    /// degrees, drop in mm, θ in rad).
    pub dof: [DofError; 10],
    /// The paper's wheel drift: max |mean(θ_RL, θ_RR) − rear encoder|, rad.
    pub drift_max: f64,
    /// The same at the last frame (signed), rad.
    pub drift_final: f64,
    /// Distance travelled, m.
    pub path_m: f64,
    /// Odometry drift with the estimated steering.
    pub odo_estimated: OdometryDrift,
    /// Odometry drift with the commanded steering.
    pub odo_commanded: OdometryDrift,
    /// The paper's Table I row this sequence stands beside.
    pub paper_dataset: Option<usize>,
    /// The error knobs that were on.
    pub errors: Vec<String>,
    /// Whether the estimator compensated the mount's vibration.
    pub mount_compensation: bool,
    /// The path that estimated the frames: `offline` (each frame straight into the
    /// estimator) or `lockstep` (the `krawler` robot's perceptual schema, each frame
    /// delivered by its camera to the loop's tick).
    pub via: &'static str,
}

impl EstimateSummary {
    /// As JSON (what `summary.json` holds).
    pub fn to_json(&self) -> serde_json::Value {
        let dof: serde_json::Map<String, serde_json::Value> = DOF_NAMES
            .iter()
            .zip(&self.dof)
            .map(|(n, e)| {
                let unit = match *n {
                    "drop_f" | "drop_r" => "mm",
                    "theta_fl" | "theta_fr" | "theta_rl" | "theta_rr" => "rad",
                    _ => "deg",
                };
                (
                    n.to_string(),
                    serde_json::json!({
                        "unit": unit, "mae": e.mae, "mae_valid": e.mae_valid, "max": e.max,
                        "last": e.last, "valid_fraction": e.valid,
                    }),
                )
            })
            .collect();
        let odo = |o: &OdometryDrift| serde_json::json!({"final_m": o.final_m, "max_m": o.max_m, "heading_deg": o.heading_deg});
        let paper = self.paper_dataset.map(|d| {
            let (s, m, drift) = PAPER_TABLE_I[d - 1];
            serde_json::json!({"dataset": d, "s": s, "roll_f_deg": m[0], "roll_r_deg": m[1],
                "steer_f_deg": m[2], "steer_r_deg": m[3], "max_drift_rad": drift})
        });
        let (roll, steer, drift) = TARGETS;
        let per_wheel = [6, 7, 8, 9].map(|i| self.dof[i].max);
        let met = self.dof[0].mae <= roll
            && self.dof[1].mae <= roll
            && self.dof[4].mae <= steer
            && self.dof[5].mae <= steer
            && self.drift_max <= drift;
        serde_json::json!({
            "sequence": self.sequence,
            "duration_s": self.duration_s,
            "seed": self.seed,
            "frames": self.frames,
            "delivered": self.delivered,
            "dof": dof,
            "wheel_drift": {
                "paper_way": "mean of θ_RL and θ_RR against the rear motor encoder (the true mean rear rotation)",
                "max_rad": self.drift_max,
                "final_rad": self.drift_final,
                "per_wheel_max_rad": per_wheel,
            },
            "odometry": {
                "path_m": self.path_m,
                "estimated_steering": odo(&self.odo_estimated),
                "commanded_steering": odo(&self.odo_commanded),
            },
            "targets": {
                "roll_deg": roll, "steer_deg": steer, "drift_rad": drift,
                "met": met,
            },
            "paper": paper,
            "errors": self.errors,
            "mount_compensation": self.mount_compensation,
            "via": self.via,
        })
    }

    /// The table beside the paper's Table I, and the rest of the figures.
    pub fn table(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "Table I (MAE; drift in rad), ours beside the paper's");
        let _ = writeln!(
            s,
            "{:<26} {:>5}  {:>7} {:>7} {:>8} {:>8} {:>10}",
            "dataset", "s", "roll F", "roll R", "steer F", "steer R", "max drift"
        );
        if let Some(d) = self.paper_dataset {
            let (len, m, drift) = PAPER_TABLE_I[d - 1];
            let _ = writeln!(
                s,
                "{:<26} {:>5.0}  {:>6.2}° {:>6.2}° {:>7.2}° {:>7.2}° {:>10.2}",
                format!("paper {d}"),
                len,
                m[0],
                m[1],
                m[2],
                m[3],
                drift
            );
        }
        let _ = writeln!(
            s,
            "{:<26} {:>5.0}  {:>6.2}° {:>6.2}° {:>7.2}° {:>7.2}° {:>10.2}",
            format!("ours {} ({})", self.sequence, self.via),
            self.duration_s,
            self.dof[0].mae,
            self.dof[1].mae,
            self.dof[4].mae,
            self.dof[5].mae,
            self.drift_max
        );
        let (roll, steer, drift) = TARGETS;
        let _ = writeln!(
            s,
            "{:<26} {:>5}  {:>6.1}° {:>6.1}° {:>7.1}° {:>7.1}° {:>10.1}",
            "target (≤)", "", roll, roll, steer, steer, drift
        );
        let _ = writeln!(
            s,
            "frames {} delivered of {}; seed {}; errors: {}; mount compensation {}",
            self.delivered,
            self.frames,
            self.seed,
            if self.errors.is_empty() {
                "none".to_string()
            } else {
                self.errors.join(", ")
            },
            if self.mount_compensation { "on" } else { "off" }
        );
        let _ = writeln!(
            s,
            "drop MAE F/R {:.2}/{:.2} mm; valid roll F/R {:.1}/{:.1} %, steer F/R {:.1}/{:.1} %",
            self.dof[2].mae,
            self.dof[3].mae,
            self.dof[0].valid * 100.0,
            self.dof[1].valid * 100.0,
            self.dof[4].valid * 100.0,
            self.dof[5].valid * 100.0
        );
        let _ = writeln!(
            s,
            "wheel drift, paper's way (rear mean vs encoder): max {:.3} rad, final {:+.3} rad; per wheel max FL {:.3} FR {:.3} RL {:.3} RR {:.3}, final {:+.3} {:+.3} {:+.3} {:+.3} rad",
            self.drift_max,
            self.drift_final,
            self.dof[6].max,
            self.dof[7].max,
            self.dof[8].max,
            self.dof[9].max,
            self.dof[6].last,
            self.dof[7].last,
            self.dof[8].last,
            self.dof[9].last
        );
        for (name, o) in [("estimated", &self.odo_estimated), ("commanded", &self.odo_commanded)] {
            let _ = writeln!(
                s,
                "odometry over {:.2} m with {name} steering: final {:.3} m ({:.1} %), max {:.3} m, heading {:+.1}°",
                self.path_m,
                o.final_m,
                100.0 * o.final_m / self.path_m.max(1e-9),
                o.max_m,
                o.heading_deg
            );
        }
        s
    }
}

fn err(path: &Path, e: impl std::fmt::Display) -> String {
    format!("{}: {e}", path.display())
}

/// Per delivered frame: its index in the sequence, the estimate.
pub(super) struct Record {
    pub(super) index: usize,
    pub(super) estimate: KrawlerEstimate,
}

/// Runs the estimator over the sequence's frames, offline: each frame straight into
/// [`KrawlerStateSchema::estimate`].
fn run_frames(
    spec: &SequenceSpec,
    profile: &Profile,
    truth: &[TruthFrame],
    seed: u64,
    params: KrawlerParams,
) -> Result<Vec<Record>, String> {
    let pe = |e: &dyn std::fmt::Display| format!("profile `{}`: {e}", profile.name);
    let cam = profile.cameras.first().ok_or_else(|| pe(&"no camera"))?;
    let geometry = AxleGeometry::from_profile(profile, 0).map_err(|e| pe(&e))?;
    let gear_spec = crate::behaviors::krawler::gear_spec(profile).map_err(|e| pe(&e))?;
    let gear = GearGeometry::from_profile(profile, gear_spec).map_err(|e| pe(&e))?;
    let polys = SteeringPoly::from_profile(profile)
        .ok_or_else(|| pe(&"no `markers` fiducial steering_poly_deg: run `marsupial calibrate-steering --write`"))?;
    let side = profile
        .fiducial
        .get::<crate::profile::MarkersSpec>()
        .map_or(0.03, |m| m.side_m);
    // The estimator starts from its own model of the gear at rest, not the simulator's.
    let (start, axles) = gear
        .start(&geometry, side)
        .ok_or_else(|| pe(&"a marker of the gear at rest does not project into the camera"))?;
    let size = (cam.width_px, cam.height_px);
    let mut schema = KrawlerStateSchema::new(size, geometry, gear.layout(), polys, params, start, axles);
    let mut frames = SequenceFrames::new(spec, profile, truth, seed)?;
    let mut ransac = Rng::named(seed, "krawler-ransac");
    let mut image = RgbImage::default();
    let mut out = Vec::with_capacity(truth.len());
    for i in 0..truth.len() {
        if !frames.render(i, &mut image)? {
            continue;
        }
        let estimate = schema
            .estimate(&image.view(), |n| (ransac.next_u64() % n as u64) as usize)
            .map_err(|e| format!("frame {i}: {e}"))?;
        out.push(Record { index: i, estimate });
    }
    Ok(out)
}

/// The truth of DOF `k` at `f`, in its reporting unit, θ from the sequence's start.
fn truth_value(f: &TruthFrame, first: &TruthFrame, k: usize) -> f64 {
    let s = &f.state;
    match k {
        0 | 1 => s.roll[k].to_degrees(),
        2 | 3 => s.drop[k - 2] * 1000.0,
        4 | 5 => s.steer[k - 4].to_degrees(),
        _ => s.wheel[k - 6] - first.state.wheel[k - 6],
    }
}

/// The estimate of DOF `k`, in its reporting unit, and its validity.
fn estimate_value(e: &KrawlerEstimate, k: usize) -> (f64, bool) {
    let d = match k {
        0 | 1 => e.roll[k],
        2 | 3 => e.drop[k - 2],
        4 | 5 => e.steer[k - 4],
        _ => e.wheel[k - 6],
    };
    let v = match k {
        0 | 1 | 4 | 5 => d.value.to_degrees(),
        2 | 3 => d.value * 1000.0,
        _ => d.value,
    };
    (v, d.valid)
}

/// The result of a run: the summary, and the per-frame tables and plots.
pub struct EstimateRun {
    /// The figures.
    pub summary: EstimateSummary,
    truth: Vec<TruthFrame>,
    records: Vec<Record>,
    paths: [Vec<[f64; 3]>; 3],
}

/// Generates the sequence, renders and estimates every frame with the estimator's
/// default settings, and measures.
///
/// # Errors
/// A message naming the field for a bad sequence file, or the profile's problem.
pub fn estimate(spec: &SequenceSpec, profile: &Profile, seed: u64) -> Result<EstimateRun, String> {
    estimate_with(spec, profile, seed, KrawlerParams::default())
}

/// As [`estimate`], with the estimator's settings `params`.
///
/// # Errors
/// As [`estimate`].
pub fn estimate_with(
    spec: &SequenceSpec,
    profile: &Profile,
    seed: u64,
    params: KrawlerParams,
) -> Result<EstimateRun, String> {
    let truth = generate(spec, profile, seed)?;
    let records = run_frames(spec, profile, &truth, seed, params)?;
    measure(spec, profile, seed, params, truth, records, "offline")
}

/// Measures `records`, estimates of the frames of `truth`, the paper's way; `via` names
/// the path that estimated them.
pub(super) fn measure(
    spec: &SequenceSpec,
    profile: &Profile,
    seed: u64,
    params: KrawlerParams,
    truth: Vec<TruthFrame>,
    records: Vec<Record>,
    via: &'static str,
) -> Result<EstimateRun, String> {
    let drive = drive_of(profile).ok_or_else(|| format!("profile `{}` has no double-Ackermann drive", profile.name))?;
    let first = &truth[0];
    let mut dof = [DofError::default(); 10];
    let mut valid_sum = [0.0f64; 10];
    let mut drift_max = 0.0f64;
    let mut drift_final = 0.0;
    for r in &records {
        let f = &truth[r.index];
        for (k, d) in dof.iter_mut().enumerate() {
            let (v, valid) = estimate_value(&r.estimate, k);
            let e = v - truth_value(f, first, k);
            d.mae += e.abs();
            d.max = d.max.max(e.abs());
            d.last = e;
            if valid {
                d.valid += 1.0;
                valid_sum[k] += e.abs();
            }
        }
        let rear_est = (r.estimate.wheel[2].value + r.estimate.wheel[3].value) / 2.0;
        let encoder = (truth_value(f, first, 8) + truth_value(f, first, 9)) / 2.0;
        drift_final = rear_est - encoder;
        drift_max = drift_max.max(drift_final.abs());
    }
    let n = records.len().max(1) as f64;
    for (d, s) in dof.iter_mut().zip(valid_sum) {
        d.mae /= n;
        d.mae_valid = if d.valid > 0.0 { s / d.valid } else { f64::NAN };
        d.valid /= n;
    }
    // Odometry: every frame, speed from the truth; the estimated steering held between
    // delivered frames.
    let (dts, speed) = steps_of(&truth);
    let cmd_steer: Vec<[f64; 2]> = truth.iter().map(|f| f.steer_cmd).collect();
    let mut est_steer = Vec::with_capacity(truth.len());
    let mut held = [0.0f64; 2];
    let mut next = records.iter().peekable();
    for i in 0..truth.len() {
        if let Some(r) = next.next_if(|r| r.index == i) {
            held = [r.estimate.steer[0].value, r.estimate.steer[1].value];
        }
        est_steer.push(held);
    }
    let p_true = true_path(&drive, &truth);
    let p_est = odometry(&drive, &dts, &speed, &est_steer);
    let p_cmd = odometry(&drive, &dts, &speed, &cmd_steer);
    let drift = |p: &[[f64; 3]]| {
        let mut o = OdometryDrift::default();
        for (a, b) in p.iter().zip(&p_true) {
            let e = (a[0] - b[0]).hypot(a[1] - b[1]);
            o.max_m = o.max_m.max(e);
            o.final_m = e;
            o.heading_deg = (a[2] - b[2]).to_degrees();
        }
        o
    };
    let path_m = speed.iter().zip(&dts).map(|(v, dt)| v.abs() * dt).sum();
    let summary = EstimateSummary {
        sequence: spec.name.clone(),
        duration_s: spec.duration_s,
        seed,
        frames: truth.len(),
        delivered: records.len(),
        dof,
        drift_max,
        drift_final,
        path_m,
        odo_estimated: drift(&p_est),
        odo_commanded: drift(&p_cmd),
        paper_dataset: spec.paper_dataset,
        errors: spec.errors.active(),
        mount_compensation: params.mount.enabled,
        via,
    };
    Ok(EstimateRun {
        summary,
        truth,
        records,
        paths: [p_true, p_est, p_cmd],
    })
}

impl EstimateRun {
    /// Writes frames.csv, odometry.csv, the plots and summary.json into `dir`.
    ///
    /// # Errors
    /// A message naming the file that could not be written.
    pub fn write(&self, dir: &Path) -> Result<(), String> {
        std::fs::create_dir_all(dir).map_err(|e| err(dir, e))?;
        let first = &self.truth[0];
        let mut csv = String::from("frame,t_s");
        for n in DOF_NAMES {
            let _ = write!(csv, ",{n}_true,{n}_est,{n}_valid");
        }
        csv.push_str(",steer_f_cmd,steer_r_cmd\n");
        for r in &self.records {
            let f = &self.truth[r.index];
            let _ = write!(csv, "{},{:.4}", r.index, f.t);
            for k in 0..10 {
                let (v, valid) = estimate_value(&r.estimate, k);
                let _ = write!(csv, ",{:.5},{:.5},{}", truth_value(f, first, k), v, u8::from(valid));
            }
            let _ = writeln!(
                csv,
                ",{:.5},{:.5}",
                f.steer_cmd[0].to_degrees(),
                f.steer_cmd[1].to_degrees()
            );
        }
        let put = |name: &str, text: &str| {
            let p = dir.join(name);
            std::fs::write(&p, text).map_err(|e| err(&p, e))
        };
        put("frames.csv", &csv)?;
        let mut odo = String::from(
            "t_s,x_true,y_true,heading_true_deg,x_est,y_est,heading_est_deg,x_cmd,y_cmd,heading_cmd_deg\n",
        );
        for (i, f) in self.truth.iter().enumerate() {
            let _ = write!(odo, "{:.4}", f.t);
            for p in &self.paths {
                let _ = write!(odo, ",{:.5},{:.5},{:.4}", p[i][0], p[i][1], p[i][2].to_degrees());
            }
            odo.push('\n');
        }
        put("odometry.csv", &odo)?;
        let t: Vec<f64> = self.records.iter().map(|r| self.truth[r.index].t).collect();
        for (k, name) in DOF_NAMES.iter().enumerate() {
            let truth: Vec<f64> = self
                .records
                .iter()
                .map(|r| truth_value(&self.truth[r.index], first, k))
                .collect();
            let est: Vec<f64> = self.records.iter().map(|r| estimate_value(&r.estimate, k).0).collect();
            let unit = match k {
                2 | 3 => "mm",
                6..=9 => "rad",
                _ => "deg",
            };
            let cmd: Vec<f64>;
            let mut series = vec![
                Series {
                    label: "truth",
                    colour: "black",
                    values: &truth,
                },
                Series {
                    label: "estimate",
                    colour: "#d22",
                    values: &est,
                },
            ];
            if k == 4 || k == 5 {
                cmd = self
                    .records
                    .iter()
                    .map(|r| self.truth[r.index].steer_cmd[k - 4].to_degrees())
                    .collect();
                series.push(Series {
                    label: "commanded",
                    colour: "#28c",
                    values: &cmd,
                });
            }
            let title = format!("{}: {name}", self.summary.sequence);
            put(&format!("{name}.svg"), &time_series_svg(&title, unit, &t, &series))?;
        }
        put(
            "odometry.svg",
            &paths_svg(
                &format!("{}: double-Ackermann odometry", self.summary.sequence),
                &[
                    ("true steering", "black", &self.paths[0]),
                    ("estimated steering", "#d22", &self.paths[1]),
                    ("commanded steering", "#28c", &self.paths[2]),
                ],
            ),
        )?;
        let json = serde_json::to_string_pretty(&self.summary.to_json()).map_err(|e| e.to_string())?;
        put("summary.json", &(json + "\n"))
    }
}

/// Runs `marsupial estimate`: prints the table (or the summary's JSON) and writes the
/// output directory.
///
/// # Errors
/// As [`estimate`] and [`EstimateRun::write`], and for an unloadable profile or sequence.
pub fn run(opts: &EstimateOptions, out: &mut dyn Write) -> Result<EstimateSummary, String> {
    let spec = SequenceSpec::load(&opts.sequence).map_err(|e| e.to_string())?;
    let profile = Profile::load(&opts.profile).map_err(|e| e.to_string())?;
    let seed = opts.seed.unwrap_or(spec.seed);
    let started = std::time::Instant::now();
    let mut params = KrawlerParams::default();
    params.mount.enabled = !opts.no_mount_compensation;
    let result = estimate_with(&spec, &profile, seed, params)?;
    let elapsed = started.elapsed().as_secs_f64();
    if let Some(dir) = &opts.out {
        result.write(dir)?;
    }
    let w = |e: std::io::Error| e.to_string();
    if opts.json {
        writeln!(out, "{}", result.summary.to_json()).map_err(w)?;
    } else {
        write!(out, "{}", result.summary.table()).map_err(w)?;
        writeln!(
            out,
            "{} frames rendered and estimated in {:.1} s ({:.1} ms a frame)",
            result.summary.delivered,
            elapsed,
            1000.0 * elapsed / result.summary.delivered.max(1) as f64
        )
        .map_err(w)?;
    }
    if let Some(path) = opts.runtime {
        use super::estimate_runtime::{RuntimePath, estimate_runtime, estimate_threads};
        let started = std::time::Instant::now();
        let (rt, slip) = match path {
            RuntimePath::Lockstep => {
                let (rt, slip) = estimate_runtime(&spec, &profile, seed, params)?;
                (rt, Some(slip))
            }
            RuntimePath::Threads => (estimate_threads(&spec, &profile, seed, params)?, None),
        };
        let elapsed = started.elapsed().as_secs_f64();
        let (a, b) = (&result.summary, &rt.summary);
        // Bit for bit (a DOF never valid has a NaN valid-frame MAE on both paths).
        let bits = |d: &DofError| [d.mae, d.mae_valid, d.max, d.last, d.valid].map(f64::to_bits);
        let same = a.delivered == b.delivered
            && a.drift_max.to_bits() == b.drift_max.to_bits()
            && a.dof.iter().zip(&b.dof).all(|(x, y)| bits(x) == bits(y));
        if opts.json {
            let slip = slip.map(|s| {
                serde_json::json!({"windows": s.windows, "alarms": s.alarms,
                    "max_disagreement_rad": s.max_disagreement_rad})
            });
            let j = serde_json::json!({"runtime": b.to_json(), "slip": slip, "same_as_offline": same});
            writeln!(out, "{j}").map_err(w)?;
        } else {
            writeln!(
                out,
                "\nthrough the loop ({}, the krawler robot's perceptual schema):",
                b.via
            )
            .map_err(w)?;
            write!(out, "{}", b.table()).map_err(w)?;
            writeln!(
                out,
                "{} frames through the loop in {:.1} s ({:.1} ms a frame); same figures as offline: {}",
                b.delivered,
                elapsed,
                1000.0 * elapsed / b.delivered.max(1) as f64,
                if same { "yes" } else { "no" }
            )
            .map_err(w)?;
            if let Some(s) = slip {
                writeln!(
                    out,
                    "slip monitor (encoder reference): {} windows judged, {} alarms, largest disagreement {:.3} rad",
                    s.windows, s.alarms, s.max_disagreement_rad
                )
                .map_err(w)?;
            }
        }
    }
    Ok(result.summary)
}
