//! `krawler.slip_monitor`: the optical wheel rotation against the commanded one.
//!
//! Over consecutive windows of `window_s`, the monitor sums the rotation the wheels were
//! told to make (the drive leaf's commanded rate, or with `reference = "odometry"` the
//! encoders' speed, over the wheel radius, times each tick's length) and compares it with
//! the rotation the estimator saw: the change of the four wheels' mean θ between the
//! window's first and last fresh frames. The mean over both sides cancels a turn's
//! differential (its residue on a double-Ackermann axle is under 2 % at full lock). When
//! they differ by more than `threshold_rad` the leaf is released for one tick: it stops
//! the base and ends its state with the event `slip`; otherwise it stays inactive and the
//! figures are in [`KrawlerMemory::slip`] for whoever reads them. A window in which the
//! wheel stage measured fewer than `min_measured` of the frames (the white face, a
//! shadow, lost frames) is not judged: coasting would otherwise read as agreement.

use super::KrawlerMemory;
use crate::schemas::{Behavior, Feedback, Inputs, MotorOutput, Step};
use serde::{Deserialize, Serialize};

/// What the reference rotation is read from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Reference {
    /// The drive leaf's commanded rate ([`KrawlerMemory::commanded_rate`]).
    #[default]
    Command,
    /// The odometry's forward speed (the encoders) over the wheel radius.
    Odometry,
}

/// The monitor's `params`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SlipParams {
    /// Largest disagreement over one window that is not a slip, rad.
    pub threshold_rad: f64,
    /// Length of a window, s.
    pub window_s: f64,
    /// Where the reference rotation comes from (default `command`).
    #[serde(default)]
    pub reference: Reference,
    /// Fewest frames of a window whose four wheel steps were all measured, as a
    /// fraction, for the window to be judged (default 0.5).
    #[serde(default = "half")]
    pub min_measured: f64,
}

fn half() -> f64 {
    0.5
}

/// One judged window.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct SlipReading {
    /// When the window closed, s.
    pub t: f64,
    /// The estimator's mean wheel rotation over it, rad.
    pub optical_rad: f64,
    /// The reference rotation over it, rad.
    pub reference_rad: f64,
    /// Fraction of its frames whose wheel steps were all measured.
    pub measured: f64,
    /// Whether it was judged a slip.
    pub slip: bool,
}

/// The window being summed.
#[derive(Debug, Clone, Copy)]
struct Window {
    start: f64,
    theta0: f64,
    reference: f64,
    frames: u32,
    measured: u32,
}

/// `krawler.slip_monitor` (see the module docs).
pub struct SlipMonitor {
    params: SlipParams,
    window: Option<Window>,
    last_tick: Option<f64>,
}

impl SlipMonitor {
    /// The monitor with `params`.
    ///
    /// # Errors
    /// Names the field of a threshold, window or fraction out of range.
    pub fn new(params: SlipParams) -> Result<Self, String> {
        let p = &params;
        if !(p.threshold_rad.is_finite() && p.threshold_rad > 0.0) {
            return Err(format!(
                "params.threshold_rad: expected a positive number of rad, got {}",
                p.threshold_rad
            ));
        }
        if !(p.window_s.is_finite() && p.window_s > 0.0) {
            return Err(format!(
                "params.window_s: expected a positive number of s, got {}",
                p.window_s
            ));
        }
        if !(0.0..=1.0).contains(&p.min_measured) {
            return Err(format!(
                "params.min_measured: expected a fraction in [0, 1], got {}",
                p.min_measured
            ));
        }
        Ok(Self {
            params,
            window: None,
            last_tick: None,
        })
    }
}

/// The four wheels' mean θ of `m`'s estimate.
fn mean_theta(m: &KrawlerMemory) -> f64 {
    m.percept.estimate.wheel.iter().map(|d| d.value).sum::<f64>() / 4.0
}

impl Behavior<KrawlerMemory> for SlipMonitor {
    fn reset(&mut self) {
        self.window = None;
        self.last_tick = None;
    }

    fn tick(&mut self, m: &mut KrawlerMemory, inputs: &Inputs<'_>) -> Option<Step> {
        let now = inputs.now;
        let rate = match self.params.reference {
            Reference::Command => m.commanded_rate,
            Reference::Odometry => inputs.odometry.map_or(0.0, |o| o.value.twist.v) / m.wheel_radius,
        };
        let dt = self.last_tick.map_or(0.0, |t| (now - t).max(0.0));
        self.last_tick = Some(now);
        if !m.percept.fresh {
            if let Some(w) = self.window.as_mut() {
                w.reference += rate * dt;
            }
            return None;
        }
        let theta = mean_theta(m);
        let Some(w) = self.window.as_mut() else {
            self.window = Some(Window {
                start: now,
                theta0: theta,
                reference: 0.0,
                frames: 0,
                measured: 0,
            });
            return None;
        };
        w.reference += rate * dt;
        w.frames += 1;
        w.measured += u32::from(m.percept.estimate.wheel.iter().all(|d| d.valid));
        if now - w.start < self.params.window_s {
            return None;
        }
        let measured = f64::from(w.measured) / f64::from(w.frames.max(1));
        let optical = theta - w.theta0;
        let slip = measured >= self.params.min_measured && (optical - w.reference).abs() > self.params.threshold_rad;
        m.slip = SlipReading {
            t: now,
            optical_rad: optical,
            reference_rad: w.reference,
            measured,
            slip,
        };
        *w = Window {
            start: now,
            theta0: theta,
            reference: 0.0,
            frames: 0,
            measured: 0,
        };
        slip.then(|| Step::event("slip", MotorOutput::stop(), Feedback::new("slip", now)))
    }
}
