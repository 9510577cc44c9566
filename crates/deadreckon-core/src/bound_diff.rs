//! The 95 % bound ([`crate::bound`]) for the differential drive's filter
//! (`kinematics::diff_drive`): the same construction as the four-wheel
//! filter's, on its own covariance and its own held-back fixes.
//!
//! The differential drive's filter carries the fixes' wander in its state
//! (the wander estimated at an outage's start is carried into it), so the
//! covariance of the fix it predicts at a window's end already holds the
//! receiver's offset: no declared-accuracy floor is added (the four-wheel
//! filter's `σ² I`). Per window, `P` is that covariance and `R` the fixes'
//! white noise (`FilterNoise::fix_white_m` per axis); the score, the
//! conformal rank and `k` are [`crate::bound::fit`]'s, on sliding windows
//! of the calibration drive ([`crate::bound::fit_windows`]) started from
//! the GNSS-aided filter, as `evaluate` starts them. Windows started from
//! the alignment (`--start align`) have no covariance, so no bound.

use crate::bound::{fit, fit_windows, BoundFit, Cov2, Sample};
use crate::kinematics::diff_drive::{
    evaluate_diff_drive, DiffDriveDrive, DiffDriveOutages, FilterNoise, OutageStart,
};

/// Each window's end of `o` as a [`Sample`] (none without the filter's
/// covariances: windows started from the alignment).
pub fn samples(o: &DiffDriveOutages) -> Vec<Sample> {
    let OutageStart::Filter(noise) = o.start else {
        return Vec::new();
    };
    if o.predicted_cov_m2.len() != o.outages.windows.len() {
        return Vec::new();
    }
    o.outages
        .windows
        .iter()
        .zip(&o.predicted_cov_m2)
        .map(|(w, c)| Sample {
            error_m: w.final_error_m,
            cov: *c,
            reference: Cov2::circular(noise.fix_white_m),
        })
        .collect()
}

/// Fits the bound's factor on the differential drive `d` with `params`
/// and the filter's `noise`: sliding windows ([`fit_windows`] over the
/// fixes' span after `warmup_s`) started from the GNSS-aided filter,
/// scored against the hidden fix at each end. [`BoundFit::FILTER`] when
/// too few windows fit.
pub fn fit_diff_drive(
    d: &DiffDriveDrive,
    params: &[f64],
    noise: &FilterNoise,
    warmup_s: f64,
) -> BoundFit {
    let (Some(first), Some(last)) = (d.samples.first(), d.fixes.last()) else {
        return BoundFit::FILTER;
    };
    let (length, step) = fit_windows(last.0 - first.t_s - warmup_s);
    match evaluate_diff_drive(
        d,
        params,
        length,
        step,
        warmup_s,
        &OutageStart::Filter(*noise),
    ) {
        Ok(o) => fit(&samples(&o), length, step),
        Err(_) => BoundFit::FILTER,
    }
}

/// The bound of each window of `o` and whether its final error is within
/// the bound of what was compared (`k² P + R`), or `None` without the
/// filter's covariances.
pub fn window_bounds(o: &DiffDriveOutages, fit: &BoundFit) -> Option<Vec<(f64, bool)>> {
    let s = samples(o);
    if s.is_empty() {
        return None;
    }
    Some(
        s.iter()
            .map(|x| {
                (
                    fit.bound_m(&x.cov),
                    x.error_m <= fit.compared_bound_m(&x.cov, &x.reference),
                )
            })
            .collect(),
    )
}

/// The share of windows of `o` within the bound, and the median bound over
/// the median final error (sharpness); `None` without covariances.
pub fn coverage_and_sharpness(o: &DiffDriveOutages, fit: &BoundFit) -> Option<(f64, f64)> {
    let b = window_bounds(o, fit)?;
    let within = b.iter().filter(|x| x.1).count() as f64 / b.len() as f64;
    let bounds: Vec<f64> = b.iter().map(|x| x.0).collect();
    let median = crate::metrics::Summary::of(&bounds).median;
    let errors: Vec<f64> = o.outages.windows.iter().map(|w| w.final_error_m).collect();
    Some((within, median / crate::metrics::Summary::of(&errors).median))
}
