//! Calibration history per vehicle: are a vehicle's parameters consistent
//! across its drives, and on which drive did one move?
//!
//! For one parameter of one vehicle, drive `j` gives an estimate `x_j` with
//! standard error `s_j`. With a tolerance `τ` (the drive-to-drive variation
//! the parameter may have without counting as a change), each drive weighs
//! `w_j = 1 / (s_j² + τ²)`.
//!
//! - **Consistency**: with the weighted mean `x̄ = Σ w_j x_j / Σ w_j`, the
//!   statistic `χ² = Σ w_j (x_j − x̄)²` follows χ²(n − 1) when the parameter
//!   did not change; its p-value is `P(χ²(n − 1) ≥ χ²)`. Overall, the
//!   parameters' χ² and degrees of freedom add up (the parameters' estimates
//!   are taken as independent: `params.toml` carries no covariances).
//! - **Change points** (binary segmentation): for the drives in time order,
//!   splitting before drive `k` into two runs with weighted means `x̄_L`,
//!   `x̄_R` and weights `W_L`, `W_R` removes
//!   `Δ_k = (x̄_L − x̄_R)² / (1/W_L + 1/W_R)` from the χ²; under no change
//!   `Δ_k` is χ²(1). The largest `Δ_k` is a change when its p-value,
//!   Bonferroni-corrected for the `n − 1` splits and the parameters tested,
//!   is below `alpha`; then both runs are searched again. The change is
//!   reported at the first drive after it, with the shift `x̄_R − x̄_L` and its
//!   standard error `√(1/W_L + 1/W_R)`.

use std::cmp::Ordering;
use std::path::PathBuf;

use deadreckon_core::Params;
use statrs::distribution::{ChiSquared, ContinuousCDF};

use crate::batch::{DriveResult, ParamStatus};
use crate::FleetError;

/// The default tolerances `τ`, in [`Params::to_array`] order (rad/s, –, m ×4).
///
/// Measured on 20 simulated 300 s `calibration` drives of one car (seeds
/// 1–20, true parameters unchanged): the spread of the estimates over the
/// drives against their mean standard error is 1.06× for the gyro bias, 1.56×
/// for the speed scale (its standard error is too small: the GNSS error is
/// correlated in time, the least squares take it as white), 0.12–0.13× for the
/// circumferences (theirs are too large). The speed scale's excess spread is
/// √(9.2e-5² − 5.9e-5²) = 7e-5; τ = 1e-4 covers it. The others are set where a
/// change stops mattering for dead reckoning: 1e-5 rad/s of gyro bias
/// (0.2 m of lateral drift per minute at 30 km/h) and 0.2 mm of circumference
/// (0.01 %); a tyre change or a pressure drop moves a circumference by 0.3–2 %.
pub const DEFAULT_TOLERANCE: [f64; 6] = [1e-5, 1e-4, 2e-4, 2e-4, 2e-4, 2e-4];

/// Settings of the history tests.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HistoryOptions {
    /// Significance level of the consistency and change-point tests.
    pub alpha: f64,
    /// Tolerance `τ` per parameter, [`Params::to_array`] order, in the
    /// parameter's unit (0: the standard errors alone).
    pub tolerance: [f64; 6],
}

impl Default for HistoryOptions {
    fn default() -> Self {
        HistoryOptions {
            alpha: 1e-3,
            tolerance: DEFAULT_TOLERANCE,
        }
    }
}

impl HistoryOptions {
    /// Checks `0 < alpha < 1` and finite non-negative tolerances.
    pub fn validate(&self) -> Result<(), FleetError> {
        if !(self.alpha > 0.0 && self.alpha < 1.0) {
            return Err(FleetError::Options(format!(
                "alpha must be between 0 and 1, got {}",
                self.alpha
            )));
        }
        for (name, t) in Params::NAMES.iter().zip(self.tolerance) {
            if !(t.is_finite() && t >= 0.0) {
                return Err(FleetError::Options(format!(
                    "tolerance of {name} must be finite and non-negative, got {t}"
                )));
            }
        }
        Ok(())
    }
}

/// One successful drive of a vehicle, as the history sees it.
#[derive(Debug, Clone, PartialEq)]
pub struct HistoryDrive {
    /// The drive.
    pub path: PathBuf,
    /// Its `recorded_at`.
    pub recorded_at: Option<String>,
    /// Estimates, [`Params::to_array`] order.
    pub value: [f64; 6],
    /// Standard errors.
    pub std: [f64; 6],
    /// Whether each parameter was estimated (the others are left out).
    pub estimated: [bool; 6],
}

/// How a vehicle's drives were put in order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DriveOrder {
    /// By `recorded_at` (every drive has one), ties by path.
    RecordedAt,
    /// By path (some drive has no `recorded_at`).
    Path,
}

/// A χ² test of "no change".
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Consistency {
    /// Drives tested.
    pub drives: usize,
    /// The statistic.
    pub chi2: f64,
    /// Its degrees of freedom.
    pub dof: usize,
    /// `P(χ²(dof) ≥ chi2)`; 1 with no degree of freedom.
    pub p_value: f64,
    /// `p_value ≥ alpha`.
    pub consistent: bool,
}

/// A drive from which on a parameter differs.
#[derive(Debug, Clone, PartialEq)]
pub struct Change {
    /// Index of the first drive after the change in [`VehicleHistory::drives`].
    pub index: usize,
    /// Weighted mean of the run before.
    pub before: f64,
    /// Weighted mean of the run after (up to the next change).
    pub after: f64,
    /// `after − before`.
    pub shift: f64,
    /// Standard error of the shift.
    pub shift_std: f64,
    /// The χ² removed by the split (`Δ`).
    pub chi2: f64,
    /// Its p-value, Bonferroni-corrected.
    pub p_value: f64,
}

/// One parameter across a vehicle's drives.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamHistory {
    /// The parameter's name (`params.toml` key).
    pub name: &'static str,
    /// Weighted mean over the drives that estimated it (NaN with none).
    pub mean: f64,
    /// The consistency test.
    pub consistency: Consistency,
    /// Changes, in drive order.
    pub changes: Vec<Change>,
}

/// A vehicle's drives, tests and changes.
#[derive(Debug, Clone, PartialEq)]
pub struct VehicleHistory {
    /// The `vehicle_id`.
    pub vehicle_id: String,
    /// How the drives were ordered.
    pub order: DriveOrder,
    /// The successful drives, in order.
    pub drives: Vec<HistoryDrive>,
    /// Failed drives of this vehicle (left out).
    pub failed: usize,
    /// Per parameter, [`Params::to_array`] order.
    pub params: Vec<ParamHistory>,
    /// All estimated parameters together.
    pub overall: Consistency,
}

fn sf(chi2: f64, dof: usize) -> f64 {
    if dof == 0 {
        return 1.0;
    }
    match ChiSquared::new(dof as f64) {
        Ok(d) => d.sf(chi2.max(0.0)),
        Err(_) => f64::NAN,
    }
}

/// Weighted mean and total weight of `(x, w)` pairs.
fn mean(points: &[(usize, f64, f64)]) -> (f64, f64) {
    let w: f64 = points.iter().map(|p| p.2).sum();
    (points.iter().map(|p| p.1 * p.2).sum::<f64>() / w, w)
}

fn chi2_about_mean(points: &[(usize, f64, f64)]) -> f64 {
    let (m, _) = mean(points);
    points.iter().map(|p| p.2 * (p.1 - m).powi(2)).sum()
}

/// Binary segmentation of `points` (drive index, value, weight); `tests` is
/// the number of parameters tested (Bonferroni).
fn segment(points: &[(usize, f64, f64)], tests: usize, alpha: f64, out: &mut Vec<Change>) {
    let n = points.len();
    if n < 2 {
        return;
    }
    let mut best: Option<(usize, f64, f64, f64, f64)> = None;
    for k in 1..n {
        let (ml, wl) = mean(&points[..k]);
        let (mr, wr) = mean(&points[k..]);
        let var = 1.0 / wl + 1.0 / wr;
        let delta = (mr - ml).powi(2) / var;
        if best.is_none_or(|b| delta > b.1) {
            best = Some((k, delta, ml, mr, var.sqrt()));
        }
    }
    let Some((k, delta, ml, mr, sd)) = best else {
        return;
    };
    let p = (sf(delta, 1) * ((n - 1) * tests) as f64).min(1.0);
    if p < alpha {
        out.push(Change {
            index: points[k].0,
            before: ml,
            after: mr,
            shift: mr - ml,
            shift_std: sd,
            chi2: delta,
            p_value: p,
        });
        segment(&points[..k], tests, alpha, out);
        segment(&points[k..], tests, alpha, out);
    }
}

/// The tests of one vehicle's drives, ordered as given.
pub fn vehicle_history(
    vehicle_id: &str,
    order: DriveOrder,
    drives: Vec<HistoryDrive>,
    failed: usize,
    options: &HistoryOptions,
) -> VehicleHistory {
    let columns: Vec<Vec<(usize, f64, f64)>> = (0..6)
        .map(|i| {
            drives
                .iter()
                .enumerate()
                .filter(|(_, d)| d.estimated[i])
                .map(|(j, d)| {
                    let var = d.std[i].powi(2) + options.tolerance[i].powi(2);
                    (j, d.value[i], 1.0 / var)
                })
                .filter(|p| p.2.is_finite() && p.2 > 0.0)
                .collect()
        })
        .collect();
    let tests = columns.iter().filter(|c| c.len() >= 2).count().max(1);
    let mut params = Vec::with_capacity(6);
    let (mut chi2_all, mut dof_all) = (0.0, 0);
    for (i, points) in columns.iter().enumerate() {
        let n = points.len();
        let (m, chi2) = if n == 0 {
            (f64::NAN, 0.0)
        } else {
            (mean(points).0, chi2_about_mean(points))
        };
        let dof = n.saturating_sub(1);
        let p_value = sf(chi2, dof);
        chi2_all += chi2;
        dof_all += dof;
        let mut changes = Vec::new();
        segment(points, tests, options.alpha, &mut changes);
        changes.sort_by_key(|c| c.index);
        params.push(ParamHistory {
            name: Params::NAMES[i],
            mean: m,
            consistency: Consistency {
                drives: n,
                chi2,
                dof,
                p_value,
                consistent: p_value >= options.alpha,
            },
            changes,
        });
    }
    let p_all = sf(chi2_all, dof_all);
    VehicleHistory {
        vehicle_id: vehicle_id.to_string(),
        order,
        overall: Consistency {
            drives: drives.len(),
            chi2: chi2_all,
            dof: dof_all,
            p_value: p_all,
            consistent: p_all >= options.alpha,
        },
        drives,
        failed,
        params,
    }
}

/// Groups a batch's results by `vehicle_id` (drives without one are left
/// out), orders each vehicle's drives (by `recorded_at` when all have one,
/// else by path) and tests them. Vehicles come sorted by id.
pub fn histories(
    results: &[DriveResult],
    options: &HistoryOptions,
) -> Result<Vec<VehicleHistory>, FleetError> {
    options.validate()?;
    let mut ids: Vec<&str> = results
        .iter()
        .filter_map(|r| r.vehicle_id.as_deref())
        .collect();
    ids.sort_unstable();
    ids.dedup();
    let mut out = Vec::new();
    for id in ids {
        let mine: Vec<&DriveResult> = results
            .iter()
            .filter(|r| r.vehicle_id.as_deref() == Some(id))
            .collect();
        let failed = mine.iter().filter(|r| r.outcome.is_err()).count();
        let mut drives: Vec<HistoryDrive> = mine
            .iter()
            .filter_map(|r| {
                let c = r.outcome.as_ref().ok()?;
                Some(HistoryDrive {
                    path: r.path.clone(),
                    recorded_at: r.recorded_at.clone(),
                    value: c.car.calibration.estimate.params.to_array(),
                    std: c.car.calibration.estimate.std.to_array(),
                    estimated: c.car.status().map(|s| s == ParamStatus::Estimated),
                })
            })
            .collect();
        let keys: Option<Vec<String>> = drives
            .iter()
            .map(|d| {
                d.recorded_at
                    .as_deref()
                    .and_then(|t| deadreckon_core::vehicle::recorded_at_key(t).ok())
            })
            .collect();
        let order = match keys {
            Some(keys) => {
                let mut keyed: Vec<(String, HistoryDrive)> = keys.into_iter().zip(drives).collect();
                keyed.sort_by(|a, b| match a.0.cmp(&b.0) {
                    Ordering::Equal => a.1.path.cmp(&b.1.path),
                    o => o,
                });
                drives = keyed.into_iter().map(|k| k.1).collect();
                DriveOrder::RecordedAt
            }
            None => {
                drives.sort_by(|a, b| a.path.cmp(&b.path));
                DriveOrder::Path
            }
        };
        out.push(vehicle_history(id, order, drives, failed, options));
    }
    Ok(out)
}

#[cfg(test)]
#[path = "history_tests.rs"]
mod tests;
