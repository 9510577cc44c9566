//! Parameters chosen by evidence (issue 29, item 4): a differential drive's
//! calibrated parameter replaces its nominal value only where the drive's
//! own GNSS, held back from the fit, says it dead-reckons better.
//!
//! The least-squares calibration ([`calibrate_diff_drive`]) treats the
//! fixes' errors as white, but an SBAS receiver's error wanders for minutes
//! (the filter's model: 3 m with a 180 s time constant). Its standard
//! errors are then far too small, and a scale fitted on a few minutes of
//! wandering fixes is a poor value held with false confidence: on the Husky
//! bag the gyro's scale came out 1.063 ± 0.012 on the first half and
//! 0.893 ± 0.006 on the second, and each half's calibration lost to the
//! nominal values on the other half (3.83 against 2.59 m, 4.41 against
//! 4.20 m, 30 s outages every 10 s). The same idea as the car's
//! `--corrections auto` ([`crate::held_back`]) decides per parameter:
//!
//! 1. Back-to-back windows of [`WINDOW_S`] start [`FIRST_WINDOW_S`] after
//!    the first odometry sample and end before the last fix. The earlier
//!    half of them is one fold, the later half the other: each fold's
//!    parameters are fitted mostly on the *other* part of the drive in
//!    time, as a calibration is used on a later drive. (The car's
//!    [`crate::held_back`] alternates its windows; here that was tried
//!    first and let through what does not last: on the Husky bag's first
//!    half the gyro bias, −0.0014 rad/s, won over alternate windows, t =
//!    −1.9, and lost on the second half, whose own fit is +0.0002 rad/s —
//!    alternate windows interleave in time, so a bias or a scale that
//!    drifts over minutes fits the hidden windows as well as the seen ones.)
//! 2. For a set of parameters `S` and each fold, the parameters in `S` are
//!    fitted with the fold's fixes hidden (the others at nominal), and the
//!    GNSS-aided filter ([`super::filter`], started as `evaluate` starts it,
//!    the fitted parameters' standard errors as its priors) dead-reckons
//!    through each of the fold's windows from the fixes before it; the
//!    distance at the window's end to the last hidden fix is the
//!    *held-back error*.
//! 3. Forward selection from the nominal values (`S` empty), paired over
//!    the same windows: each round adds the parameter that lowers the mean
//!    held-back error most, if its paired t statistic is at most −[`MIN_T`];
//!    it stops when none does. A parameter the whole drive's fit cannot
//!    determine is not a candidate.
//!
//! The calibration returned is the whole drive's fit of the chosen
//! parameters; every other parameter keeps its nominal value, with the
//! reason and both held-back figures ([`HeldBackParams`]). A drive with
//! fewer than [`MIN_WINDOWS`] windows cannot judge: its calibration is the
//! plain fit of every parameter, and the result says so.

use serde::{Deserialize, Serialize};

use super::calibration::{calibrate_diff_drive, DiffDriveOptions};
use super::filter::{DiffDriveFilter, FilterNoise};
use super::{DiffDriveDrive, NAMES, N_PARAMS};
use crate::kinematics::KinematicCalibration;
use crate::Error;

/// Length of a held-back window, s: 30, the length of the outages a
/// differential drive is reported with (README, `tests/husky_diff_drive.rs`):
/// the parameters are judged on the outage they are used for. A 200 s
/// drive holds five windows.
pub const WINDOW_S: f64 = 30.0;

/// Time from the first odometry sample to the first window's start, s:
/// 40 (the filter starts after 10 m, some 10 s at 1 m/s, and its heading
/// settles over the fixes of the next half minute).
pub const FIRST_WINDOW_S: f64 = 40.0;

/// Fewest windows (both folds) for a judgement: 4.
pub const MIN_WINDOWS: usize = 4;

/// A parameter is taken when it lowers the held-back error with a paired t
/// statistic of at most minus this: 1, the car's rule
/// ([`crate::held_back::MIN_T`]), checked on simulated robots
/// (`held_back_tests::min_t_family`: twelve robots with drawn errors, a
/// gyro bias that moves between drives; mean of the second drive's 30 s
/// outages 1.078 / 1.093 / 1.226 / 1.305 / 1.369 m for thresholds 0.5 / 1
/// / 1.5 / 2 / 3, every parameter fitted 1.030 m, nominal 1.371 m). On
/// those robots, whose errors stay put, fitting everything is best; the
/// threshold costs 6 % there and is what keeps the Husky's drifting
/// parameters nominal.
pub const MIN_T: f64 = 1.0;

/// One parameter's judgement.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JudgedParam {
    /// The parameter's name ([`NAMES`]).
    pub name: String,
    /// The whole drive's fit of every parameter: the value.
    pub calibrated: f64,
    /// Its standard error (least squares, fixes taken as white).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub calibrated_std: Option<f64>,
    /// Mean held-back error with it fitted (added to those chosen before
    /// it, the last round it was tried in), m.
    pub with_m: f64,
    /// Mean held-back error of those without it, m.
    pub without_m: f64,
    /// The paired t statistic of the difference (negative: it helps).
    pub t: f64,
    /// Whether the calibrated value is used (else the nominal is kept).
    pub applied: bool,
}

/// What the held-back GNSS said about a differential drive's parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HeldBackParams {
    /// Held-back windows (both folds).
    pub windows: usize,
    /// Window length, s.
    pub window_s: f64,
    /// Mean held-back error with every parameter nominal, m (`None` when
    /// not judged).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nominal_m: Option<f64>,
    /// Mean held-back error with the chosen parameters, m (`None` when
    /// nothing was chosen or nothing judged).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub chosen_m: Option<f64>,
    /// Every candidate (determined by the whole drive's fit).
    pub judged: Vec<JudgedParam>,
    /// Why nothing was judged (a drive too short), if so.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub not_judged: Option<String>,
}

impl HeldBackParams {
    /// The judgement of parameter `name`, if it was a candidate.
    pub fn decision(&self, name: &str) -> Option<&JudgedParam> {
        self.judged.iter().find(|j| j.name == name)
    }
}

/// The two folds of held-back windows `(start, end)`, s (module docs).
pub fn windows(d: &DiffDriveDrive) -> [Vec<(f64, f64)>; 2] {
    let mut folds = [Vec::new(), Vec::new()];
    let (Some(first), Some(last_fix)) = (d.samples.first(), d.fixes.last()) else {
        return folds;
    };
    let end = last_fix
        .0
        .min(d.samples.last().map_or(first.t_s, |s| s.t_s));
    let mut all = Vec::new();
    let mut a = first.t_s + FIRST_WINDOW_S;
    while a + WINDOW_S <= end {
        all.push((a, a + WINDOW_S));
        a += WINDOW_S;
    }
    let h = all.len().div_ceil(2);
    folds[1] = all.split_off(h);
    folds[0] = all;
    folds
}

/// The drive with the fixes inside `fold`'s windows removed.
fn hidden(d: &DiffDriveDrive, fold: &[(f64, f64)]) -> DiffDriveDrive {
    DiffDriveDrive {
        samples: d.samples.clone(),
        fixes: d
            .fixes
            .iter()
            .filter(|f| !fold.iter().any(|w| f.0 >= w.0 && f.0 <= w.1))
            .copied()
            .collect(),
        yaw_source: d.yaw_source,
    }
}

/// The error at each window's end against its hidden fix, m, keyed by the
/// window's start, s.
type WindowErrors = Vec<(f64, f64)>;

/// One fold's fit: every candidate fitted with the fold's fixes hidden.
struct FoldFit {
    values: Vec<f64>,
    std: Vec<Option<f64>>,
}

/// The fits of the candidates `fit`, one per fold, blind to the fold.
fn fold_fits(
    d: &DiffDriveDrive,
    o: &DiffDriveOptions,
    folds: &[Vec<(f64, f64)>; 2],
    fit: &[usize],
) -> Result<Vec<FoldFit>, Error> {
    let mut fo = *o;
    fo.fit = [false; N_PARAMS];
    for &k in fit {
        fo.fit[k] = true;
    }
    folds
        .iter()
        .map(|fold| {
            let c = calibrate_diff_drive(&hidden(d, fold), &fo)?;
            Ok(FoldFit {
                values: c.values(),
                std: c
                    .params
                    .iter()
                    .map(|p| if p.estimated { p.std } else { None })
                    .collect(),
            })
        })
        .collect()
}

/// Held-back errors of the parameter set `set` (module docs, step 2): in
/// each fold, the parameters of `set` at that fold's fit (with its
/// standard errors as the filter's priors), the others nominal.
fn held_back_errors(
    d: &DiffDriveDrive,
    noise: &FilterNoise,
    folds: &[Vec<(f64, f64)>; 2],
    fits: &[FoldFit],
    set: &[usize],
) -> Result<WindowErrors, Error> {
    let mut errors = Vec::new();
    for (fold, fit) in folds.iter().zip(fits).filter(|(f, _)| !f.is_empty()) {
        let mut values = DiffDriveDrive::nominal();
        let mut std = vec![None; N_PARAMS];
        for &k in set {
            values[k] = fit.values[k];
            std[k] = fit.std[k];
        }
        errors.extend(through_windows(
            d,
            &values,
            &noise.with_param_std(&std),
            fold,
        )?);
    }
    Ok(errors)
}

/// The GNSS-aided filter with `params` through the drive, dead-reckoning
/// from each window's start (the fixes before it used) to the last fix in
/// the window: the distance to that fix.
fn through_windows(
    d: &DiffDriveDrive,
    params: &[f64],
    noise: &FilterNoise,
    fold: &[(f64, f64)],
) -> Result<WindowErrors, Error> {
    let Some(mut f) = DiffDriveFilter::start(d, params, noise)? else {
        return Ok(Vec::new());
    };
    let mut next_fix = d.fixes.partition_point(|x| x.0 <= f.t_s);
    let mut out = Vec::new();
    for &(a, b) in fold {
        let fm = d.fixes.partition_point(|x| x.0 < a);
        let fe = d.fixes.partition_point(|x| x.0 <= b);
        if f.t_s > a || fe <= fm {
            continue;
        }
        while next_fix < fm {
            let (t, e, n) = d.fixes[next_fix];
            f.predict_to(t);
            f.update_fix(e, n)?;
            next_fix += 1;
        }
        f.predict_to(a);
        let (tf, fx, fy) = d.fixes[fe - 1];
        let mut blind = f.clone();
        blind.predict_to(tf);
        let (z, _) = blind.predicted_fix();
        out.push((a, (z[0] - fx).hypot(z[1] - fy)));
    }
    Ok(out)
}

/// The mean of `errors`, m.
fn mean(errors: &[(f64, f64)]) -> f64 {
    errors.iter().map(|e| e.1).sum::<f64>() / errors.len().max(1) as f64
}

/// Calibrates the differential drive with each parameter chosen on
/// held-back GNSS (module docs): the fit of the chosen parameters, the
/// others nominal with the reason, and the judgement in
/// [`KinematicCalibration::held_back`]. `noise` is the filter the outages
/// are evaluated with.
pub fn calibrate_held_back(
    d: &DiffDriveDrive,
    o: &DiffDriveOptions,
    noise: &FilterNoise,
) -> Result<KinematicCalibration, Error> {
    calibrate_held_back_with(d, o, noise, MIN_T)
}

/// [`calibrate_held_back`] with the threshold `min_t` in place of
/// [`MIN_T`] (the family test that chose it).
pub(crate) fn calibrate_held_back_with(
    d: &DiffDriveDrive,
    o: &DiffDriveOptions,
    noise: &FilterNoise,
    min_t: f64,
) -> Result<KinematicCalibration, Error> {
    let full = calibrate_diff_drive(d, o)?;
    let folds = windows(d);
    let n_windows = folds[0].len() + folds[1].len();
    let candidates: Vec<usize> = (0..N_PARAMS)
        .filter(|&k| o.fit[k] && full.params[k].estimated)
        .collect();
    let mut held = HeldBackParams {
        windows: n_windows,
        window_s: WINDOW_S,
        nominal_m: None,
        chosen_m: None,
        judged: Vec::new(),
        not_judged: None,
    };
    if candidates.is_empty() {
        let mut c = full;
        c.held_back = Some(held);
        return Ok(c);
    }
    if n_windows < MIN_WINDOWS {
        held.not_judged = Some(format!(
            "{n_windows} held-back windows of {WINDOW_S:.0} s, at least {MIN_WINDOWS} needed: the drive is too short to judge its parameters on its own GNSS, so every determined one is fitted"
        ));
        let mut c = full;
        c.held_back = Some(held);
        return Ok(c);
    }
    let fits = fold_fits(d, o, &folds, &candidates)?;
    let mut current = held_back_errors(d, noise, &folds, &fits, &[])?;
    held.nominal_m = Some(mean(&current));
    let mut chosen: Vec<usize> = Vec::new();
    let mut left = candidates.clone();
    let mut tried: Vec<JudgedParam> = Vec::new();
    loop {
        let mut best: Option<(usize, WindowErrors, f64)> = None;
        for (i, &k) in left.iter().enumerate() {
            let set: Vec<usize> = chosen.iter().copied().chain([k]).collect();
            let errors = held_back_errors(d, noise, &folds, &fits, &set)?;
            let (diff_m, t) = crate::held_back::paired(&errors, &current);
            let j = JudgedParam {
                name: NAMES[k].to_string(),
                calibrated: full.params[k].value,
                calibrated_std: full.params[k].std,
                with_m: mean(&errors),
                without_m: mean(&current),
                t,
                applied: false,
            };
            match tried.iter_mut().find(|x| x.name == j.name) {
                Some(x) => *x = j,
                None => tried.push(j),
            }
            if t <= -min_t && best.as_ref().is_none_or(|b| diff_m < b.2) {
                best = Some((i, errors, diff_m));
            }
        }
        let Some((i, errors, _)) = best else { break };
        let k = left.remove(i);
        chosen.push(k);
        if let Some(x) = tried.iter_mut().find(|x| x.name == NAMES[k]) {
            x.applied = true;
        }
        current = errors;
        if left.is_empty() {
            break;
        }
    }
    if !chosen.is_empty() {
        held.chosen_m = Some(mean(&current));
    }
    held.judged = tried;
    // The whole drive's fit of every candidate (what was judged), the
    // parameters not chosen back at their nominal values.
    let mut c = full.clone();
    for (k, (p, v)) in c
        .params
        .iter_mut()
        .zip(DiffDriveDrive::nominal())
        .enumerate()
    {
        if !chosen.contains(&k) {
            p.value = v;
            p.std = None;
            p.estimated = false;
        }
    }
    let keep: Vec<usize> = (0..c.correlated.len())
        .filter(|&i| chosen.iter().any(|&k| NAMES[k] == c.correlated[i]))
        .collect();
    c.correlation = keep
        .iter()
        .map(|&i| keep.iter().map(|&j| c.correlation[i][j]).collect())
        .collect();
    c.correlated = keep.iter().map(|&i| c.correlated[i].clone()).collect();
    if chosen.is_empty() {
        c.converged = false;
        c.termination =
            "nothing fitted: held-back GNSS kept every parameter at its nominal value".into();
    }
    for p in c.params.iter_mut() {
        let Some(j) = held.decision(&p.name).filter(|j| !j.applied) else {
            continue;
        };
        let std = j
            .calibrated_std
            .map_or(String::new(), |s| format!(" ± {s:.6}"));
        let t = if j.t.is_finite() {
            format!("paired t {:+.1}", j.t)
        } else {
            "paired t not computed".to_string()
        };
        p.reason = Some(format!(
            "held-back GNSS prefers the nominal value: calibrated {:.6}{std} gave {:.3} m, {:.3} m without it ({t}, {} windows of {:.0} s)",
            j.calibrated, j.with_m, j.without_m, held.windows, held.window_s
        ));
    }
    for (p, f) in c.params.iter_mut().zip(&full.params) {
        // Not a candidate: the whole drive's reason stands.
        if held.decision(&p.name).is_none() && !f.estimated {
            p.reason = f.reason.clone();
        }
    }
    c.held_back = Some(held);
    Ok(c)
}
