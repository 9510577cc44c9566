//! The held-back folds ([`super`]'s module docs): the windows, and the
//! dead reckoning through them with each fold's calibration blind to its
//! fixes.

use super::{MIN_WINDOW_S, PERIOD_WINDOWS, WINDOW_S};
use crate::calibrate::{self, CalibrationOptions};
use crate::drive::Drive;
use crate::outage;
use crate::vehicle::Params;
use crate::Error;
use rayon::prelude::*;

/// The two folds of held-back windows (module docs): alternate windows
/// every [`PERIOD_WINDOWS`] window lengths, the first as long after the
/// vehicle first moves, each ending a second before the last fix and the
/// last wheel row; the windows [`WINDOW_S`] long, or a sixth of the moving
/// span where that is shorter (not under [`MIN_WINDOW_S`]).
pub fn windows(drive: &Drive) -> [Vec<(f64, f64)>; 2] {
    let mut folds = [Vec::new(), Vec::new()];
    let n = drive.wheels.len();
    let (Some(first), Some(last)) = (drive.gnss.first(), drive.gnss.last()) else {
        return folds;
    };
    if n == 0 {
        return folds;
    }
    let (w0, w1) = (drive.wheels.t_s(0), drive.wheels.t_s(n - 1));
    // The first fix moving faster than a walk.
    let moving = drive
        .gnss
        .windows(2)
        .find(|p| {
            let dt = p[1].t_s - p[0].t_s;
            dt > 0.0
                && ((p[1].east_m - p[0].east_m).hypot(p[1].north_m - p[0].north_m) / dt)
                    > outage::MOVING_MPS
        })
        .map(|p| p[0].t_s)
        .unwrap_or(first.t_s)
        .max(w0);
    let end = last.t_s.min(w1) - 1.0;
    let window_s = ((end - moving) / 6.0).clamp(MIN_WINDOW_S, WINDOW_S);
    let period_s = PERIOD_WINDOWS * window_s;
    let mut a = moving + period_s;
    let mut k = 0;
    while a + window_s <= end {
        folds[k % 2].push((a, a + window_s));
        a += period_s;
        k += 1;
    }
    folds
}

/// The error at each window's end against its hidden fix, m, with the
/// window's start, s.
type WindowErrors = Vec<(f64, f64)>;

/// One held-back judgement of a drive: the error at each window's end
/// against its hidden fix, the parameters each fold was calibrated to, and
/// how many GNSS recoveries the dead reckoning's filter made.
pub(super) struct HeldBackRun {
    pub(super) errors: WindowErrors,
    /// The log-likelihood of each window's last hidden fix under the dead
    /// reckoning's prediction of it
    /// ([`crate::compared::OutageResult::fix_log_likelihood`]), keyed by
    /// the window's start as `errors`.
    pub(super) scores: WindowErrors,
    /// Per fold, the parameters dead-reckoned with (`None`: the fold was
    /// skipped).
    pub(super) params: [Option<Params>; 2],
    pub(super) recoveries: u64,
}

/// The error at each window's end against the hidden fix, m, keyed by the
/// window's start: for each fold `k`, the car calibrated with the fold's
/// fixes hidden (its passes started from `start[k]`; or the parameters
/// `calibrated` gives, from a drive that differs only in what the
/// calibration does not use), then dead-reckoned through the fold's
/// windows.
pub(super) fn held_back_errors(
    drive: &Drive,
    copts: &CalibrationOptions,
    start: [Option<Params>; 2],
    folds: &[Vec<(f64, f64)>; 2],
    calibrated: Option<&[Option<Params>; 2]>,
) -> Result<HeldBackRun, Error> {
    // The two folds are independent: run in parallel, merged in fold order
    // (the same numbers as one after the other).
    let per_fold: Vec<Result<Option<FoldRun>, Error>> = folds
        .par_iter()
        .enumerate()
        .map(|(k, fold)| fold_run(drive, copts, start[k], k, fold, calibrated))
        .collect();
    let mut out = HeldBackRun {
        errors: Vec::new(),
        scores: Vec::new(),
        params: [None, None],
        recoveries: 0,
    };
    for (k, run) in per_fold.into_iter().enumerate() {
        let Some(run) = run? else {
            continue;
        };
        out.params[k] = Some(run.params);
        out.recoveries += run.recoveries;
        out.errors.extend(run.errors);
        out.scores.extend(run.scores);
    }
    Ok(out)
}

/// One fold of [`held_back_errors`]: the parameters dead-reckoned with, the
/// error at each window's end and the GNSS recoveries.
struct FoldRun {
    params: Params,
    errors: WindowErrors,
    scores: WindowErrors,
    recoveries: u64,
}

/// Fold `k` of [`held_back_errors`] (`None`: skipped, being empty or
/// without parameters to judge with).
fn fold_run(
    drive: &Drive,
    copts: &CalibrationOptions,
    start: Option<Params>,
    k: usize,
    fold: &[(f64, f64)],
    calibrated: Option<&[Option<Params>; 2]>,
) -> Result<Option<FoldRun>, Error> {
    if fold.is_empty() {
        return Ok(None);
    }
    let params = match calibrated {
        Some(c) => match c[k] {
            Some(p) => p,
            None => return Ok(None),
        },
        None => {
            let mut o = copts.clone();
            o.filter.gnss_outages.extend_from_slice(fold);
            if start.is_some() {
                o.initial = start;
            }
            match calibrate::calibrate_parameters(drive, &o) {
                Ok(c) => c.estimate.params,
                // A fold the calibration cannot take: judge with the start.
                Err(_) => match start {
                    Some(p) => p,
                    None => return Ok(None),
                },
            }
        }
    };
    let ev = outage::through_windows_against_fixes(drive, &params, fold, &copts.filter)?;
    Ok(Some(FoldRun {
        params,
        recoveries: ev.gates.recovered(crate::filter::SensorKind::Gnss),
        errors: ev
            .windows
            .iter()
            .map(|w| (w.start_s, w.final_m()))
            .collect(),
        scores: ev
            .windows
            .iter()
            .filter_map(|w| w.fix_log_likelihood.map(|s| (w.start_s, s)))
            .collect(),
    }))
}

/// The mean of `errors`, m (NaN when empty).
pub(super) fn mean(errors: &[(f64, f64)]) -> f64 {
    errors.iter().map(|e| e.1).sum::<f64>() / errors.len() as f64
}

/// The paired comparison of `with` against `without` over the windows both
/// have: the mean difference, m, and its t statistic (NaN with fewer than
/// two windows or no spread). The car's and the differential drive's
/// held-back choices both judge with it.
pub(crate) fn paired(with: &[(f64, f64)], without: &[(f64, f64)]) -> (f64, f64) {
    let d: Vec<f64> = with
        .iter()
        .filter_map(|&(t, e)| {
            without
                .iter()
                .find(|w| (w.0 - t).abs() < 1e-9)
                .map(|w| e - w.1)
        })
        .collect();
    let n = d.len() as f64;
    if d.len() < 2 {
        return (f64::NAN, f64::NAN);
    }
    let m = d.iter().sum::<f64>() / n;
    let var = d.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0);
    (m, m / (var / n).sqrt())
}
