//! The papers' evaluation metrics for dead reckoning against a reference.
//!
//! - [`drift`] (table IV, figure 4): dead reckoning without GNSS from the truth;
//!   every `segment_m` (100 m) of travelled distance the horizontal error is
//!   recorded and the pose reset to the truth. Travelled distance is measured on
//!   the reference trajectory, so every method is cut into the same segments.
//! - [`reset_on_error`] (figure 5): the pose is reset only when the horizontal
//!   error reaches `threshold_m` (1 m); the distances travelled between resets are
//!   recorded. The last, unfinished stretch is not counted.
//!
//! On reset, the position and yaw are set to the reference and their covariance
//! to a small value; speed and yaw rate stay the filter's (they are measured).

use crate::drive::Drive;
use crate::ekf::{self, EpochHook, FilterOptions, Init, SensorSet, Timing};
use crate::filter::GateCounts;
use crate::model::{Mat, State, X, Y, YAW};
use crate::reference::Reference;
use crate::vehicle::Params;
use crate::{Error, Input, Need, Task};

/// Summary statistics of a sample.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Summary {
    /// Sample size.
    pub n: usize,
    /// Mean.
    pub mean: f64,
    /// Standard deviation (n − 1).
    pub std: f64,
    /// Median.
    pub median: f64,
    /// 95th percentile (linear interpolation).
    pub p95: f64,
    /// Minimum.
    pub min: f64,
    /// Maximum.
    pub max: f64,
}

impl Summary {
    /// Summarises `values` (NaN-free); all zeros for an empty sample.
    pub fn of(values: &[f64]) -> Summary {
        let n = values.len();
        if n == 0 {
            return Summary::default();
        }
        let mut s = values.to_vec();
        s.sort_by(|a, b| a.total_cmp(b));
        let mean = s.iter().sum::<f64>() / n as f64;
        let std = if n > 1 {
            (s.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt()
        } else {
            0.0
        };
        Summary {
            n,
            mean,
            std,
            median: quantile(&s, 0.5),
            p95: quantile(&s, 0.95),
            min: s[0],
            max: s[n - 1],
        }
    }
}

/// Arithmetic mean (NaN for an empty slice).
pub fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

/// Median (NaN for an empty slice); the mean of the two middle values for
/// even lengths.
pub fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    quantile(&s, 0.5)
}

/// Quantile `q` of sorted values, with linear interpolation.
pub fn quantile(sorted: &[f64], q: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let pos = q.clamp(0.0, 1.0) * (sorted.len() - 1) as f64;
    let i = pos.floor() as usize;
    let j = (i + 1).min(sorted.len() - 1);
    sorted[i] + (pos - i as f64) * (sorted[j] - sorted[i])
}

/// The result of a drift evaluation.
#[derive(Debug, Clone, PartialEq)]
pub struct DriftResult {
    /// Segment length, m.
    pub segment_m: f64,
    /// Horizontal error at the end of each segment, m.
    pub errors_m: Vec<f64>,
    /// Time of the end of each segment, s.
    pub times_s: Vec<f64>,
    /// The χ² gate counters of the dead-reckoning run.
    pub gates: GateCounts,
}

impl DriftResult {
    /// Errors as a percentage of the segment length.
    pub fn errors_pct(&self) -> Vec<f64> {
        self.errors_m
            .iter()
            .map(|e| 100.0 * e / self.segment_m)
            .collect()
    }
}

/// The result of a reset-on-error evaluation.
#[derive(Debug, Clone, PartialEq)]
pub struct ResetResult {
    /// Error threshold, m.
    pub threshold_m: f64,
    /// Distance travelled before each reset, m.
    pub distances_m: Vec<f64>,
    /// Time of each reset, s.
    pub times_s: Vec<f64>,
    /// The χ² gate counters of the dead-reckoning run.
    pub gates: GateCounts,
}

enum Rule {
    Every(f64),
    OnError(f64),
}

struct ResetHook<'a> {
    reference: &'a Reference,
    distance: Vec<f64>,
    rule: Rule,
    last_reset_m: f64,
    values: Vec<f64>,
    times: Vec<f64>,
}

impl ResetHook<'_> {
    fn distance_at(&self, t: f64) -> Option<f64> {
        let r = self.reference;
        let n = r.t.len();
        if n == 0 || t < r.t[0] || t > r.t[n - 1] {
            return None;
        }
        let i = r.t.partition_point(|&ti| ti <= t).clamp(1, n - 1);
        let (t0, t1) = (r.t[i - 1], r.t[i]);
        let a = if t1 > t0 { (t - t0) / (t1 - t0) } else { 0.0 };
        Some(self.distance[i - 1] + a * (self.distance[i] - self.distance[i - 1]))
    }
}

impl EpochHook for ResetHook<'_> {
    fn after_epoch(&mut self, t: f64, x: &mut State, p: &mut Mat) {
        let (Some(truth), Some(d)) = (self.reference.state_at(t), self.distance_at(t)) else {
            return;
        };
        let err = (x[X] - truth[X]).hypot(x[Y] - truth[Y]);
        let travelled = d - self.last_reset_m;
        let reset = match self.rule {
            Rule::Every(seg) if travelled >= seg => {
                self.values.push(err);
                true
            }
            Rule::OnError(thr) if err >= thr => {
                self.values.push(travelled);
                true
            }
            _ => false,
        };
        if reset {
            self.times.push(t);
            self.last_reset_m = d;
            x[X] = truth[X];
            x[Y] = truth[Y];
            // Keep the yaw continuous with the filter's own (unwrapped) value.
            x[YAW] += crate::angle::diff(truth[YAW], x[YAW]);
            for i in [X, Y, YAW] {
                for j in 0..5 {
                    p[(i, j)] = 0.0;
                    p[(j, i)] = 0.0;
                }
            }
            p[(X, X)] = 1e-4;
            p[(Y, Y)] = 1e-4;
            p[(YAW, YAW)] = 1e-6;
        }
    }
}

/// Refuses a length that is not a finite positive number (`--segment-m 0`,
/// `--threshold-m=-1` and NaN printed inf/NaN tables).
fn positive(what: &'static str, v: f64) -> Result<(), Error> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(Error::param(what, v, crate::Rule::Positive))
    }
}

fn run_with_resets(
    drive: &Drive,
    params: &Params,
    timing: Timing,
    rule: Rule,
) -> Result<(Vec<f64>, Vec<f64>, GateCounts), Error> {
    let reference = Reference::from_truth(&drive.truth)
        .ok_or_else(|| Error::needs(Task::Evaluation, Input::Truth { min_poses: 3 }))?;
    let mut hook = ResetHook {
        distance: reference.distance(),
        reference: &reference,
        rule,
        last_reset_m: 0.0,
        values: Vec::new(),
        times: Vec::new(),
    };
    let opts = FilterOptions {
        timing,
        init: Init::Truth,
        sensors: SensorSet::dead_reckoning(),
        record_epochs: false,
        ..Default::default()
    };
    let out = ekf::run(drive, params, &opts, &mut hook)?;
    Ok((hook.values, hook.times, out.stats.gates))
}

/// Table IV / figure 4: horizontal error after every `segment_m` of dead reckoning.
pub fn drift(
    drive: &Drive,
    params: &Params,
    segment_m: f64,
    timing: Timing,
) -> Result<DriftResult, Error> {
    positive("segment length (m)", segment_m)?;
    let (errors_m, times_s, gates) =
        run_with_resets(drive, params, timing, Rule::Every(segment_m))?;
    if errors_m.is_empty() {
        // "mean 0.000%" over no segment read as perfect dead reckoning.
        return Err(Need::DriftSegment { segment_m }.into());
    }
    Ok(DriftResult {
        segment_m,
        errors_m,
        times_s,
        gates,
    })
}

/// Figure 5: distances travelled before the error reaches `threshold_m`.
pub fn reset_on_error(
    drive: &Drive,
    params: &Params,
    threshold_m: f64,
    timing: Timing,
) -> Result<ResetResult, Error> {
    positive("error threshold (m)", threshold_m)?;
    let (distances_m, times_s, gates) =
        run_with_resets(drive, params, timing, Rule::OnError(threshold_m))?;
    Ok(ResetResult {
        threshold_m,
        distances_m,
        times_s,
        gates,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    /// Issue 12: `--segment-m 0`, `--threshold-m=-1` and NaN were accepted.
    #[test]
    fn a_zero_or_negative_length_was_accepted() {
        for v in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(positive("x", v).is_err(), "{v}");
        }
        assert!(positive("x", 100.0).is_ok());
    }

    #[test]
    fn summary_and_quantiles() {
        let s = Summary::of(&[4.0, 1.0, 3.0, 2.0]);
        assert_eq!(s.n, 4);
        assert!((s.mean - 2.5).abs() < 1e-12);
        assert!((s.median - 2.5).abs() < 1e-12);
        assert!((s.std - (5.0f64 / 3.0).sqrt()).abs() < 1e-12);
        assert_eq!((s.min, s.max), (1.0, 4.0));
        assert!((s.p95 - 3.85).abs() < 1e-12);
    }
}
