//! `marsupial calibrate-odometry`: fit a skid-steer log and compare with a profile.

use crate::kinematics::{calibrate, parse_log};
use crate::profile::Profile;
use std::io::Write;
use std::path::Path;

/// Fits `log` and prints the result (JSON with `json`); with a profile, also whether the
/// fitted track lies in its `[d_min, d_max]`.
///
/// # Errors
/// A message naming the file for unreadable logs, bad lines or unfittable logs.
pub fn run(log: &Path, profile: Option<&Path>, json: bool, out: &mut dyn Write) -> Result<(), String> {
    let text = std::fs::read_to_string(log).map_err(|e| format!("{}: {e}", log.display()))?;
    let samples = parse_log(&text).map_err(|e| format!("{}: {e}", log.display()))?;
    let c = calibrate(&samples).map_err(|e| format!("{}: {e}", log.display()))?;
    let bounds = match profile {
        Some(p) => {
            let p = Profile::load(p).map_err(|e| e.to_string())?;
            Some((p.drive.d_min_m, p.drive.d_max_m))
        }
        None => None,
    };
    let within = bounds.and_then(|(lo, hi)| Some((lo?..=hi?).contains(&c.effective_track_m)));
    let w = |e: std::io::Error| e.to_string();
    if json {
        let v = serde_json::json!({ "calibration": c, "within_profile_bounds": within });
        writeln!(out, "{v}").map_err(w)?;
    } else {
        writeln!(
            out,
            "effective track {:.3} m, wheel scale {:.3} ({} steps; RMS error {:.2}° heading, {:.1} mm travel per step)",
            c.effective_track_m,
            c.wheel_scale,
            c.steps,
            c.rms_heading_error_rad.to_degrees(),
            c.rms_travel_error_m * 1000.0
        )
        .map_err(w)?;
        if let (Some(ok), Some((lo, hi))) = (within, bounds) {
            writeln!(
                out,
                "{} the profile's [d_min, d_max] = [{:?}, {:?}] m",
                if ok { "within" } else { "OUTSIDE" },
                lo,
                hi
            )
            .map_err(w)?;
        }
    }
    Ok(())
}
