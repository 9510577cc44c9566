//! The gyro's scale factor (ESP and phone gyros read a few per cent off)
//! from the heading changes of turns.
//!
//! On a straight (the gyro, bias removed, below [`STRAIGHT_RPS`] over ±1 s,
//! speed above [`MIN_SPEED_MPS`], a GNSS course) the GNSS course is the
//! heading (no slip and no lever-arm term). Consecutive straight fixes form
//! runs; for each run the mean of `o = course − ∫(gyro − b)` is taken. With
//! the gyro reading `(1 + s)` times the rate plus a bias `δb` off the
//! removed `b`, `∫(gyro − b) = h = (1 + s)ψ + δb·t`, so across the runs
//! `o = a·h + β·t + const` with `a = 1/(1 + s) − 1`: a weighted linear fit
//! over the runs gives `s` and its standard error from the residual
//! scatter. The time term matters: on a drive that turns more one way than
//! the other the calibrated bias holds `s` times the mean yaw rate, and the
//! first version, a regression of each turn's course change on its
//! integrated gyro, read that as scale (on the dynamic family's
//! development cars 1–25 with a ±1 % scale error: RMS error 0.53 %, up to
//! 1.4 %, and through `calibrate`'s corrections cars 12 and 22 5.0 and 4.4
//! standard errors off; now RMS 0.12 %, none beyond 3:
//! `deadreckon-sim/tests/gyro_scale_family.rs`).
//!
//! **Observability rule**: not estimated with fewer than [`MIN_TURNS`] turns
//! (consecutive runs more than [`MIN_TURN_DEG`] apart) or [`MIN_RUNS`] runs,
//! a standard error above [`MAX_STD`] (too little turning), without GNSS
//! course, or with |s| above [`MAX_SCALE_ERROR`] (rejected, never clamped).

use nalgebra::{DMatrix, DVector};

use crate::angle;
use crate::drive::Drive;
use crate::series::interp;
use crate::status::Status;

/// Largest mean yaw rate over ±1 s of a straight moment, rad/s.
pub const STRAIGHT_RPS: f64 = 0.01;
/// Slowest speed of a straight moment used, m/s (the GNSS course is noisy below).
pub const MIN_SPEED_MPS: f64 = 3.0;
/// Smallest heading change counted as a turn, degrees.
pub const MIN_TURN_DEG: f64 = 20.0;
/// Fewest turns for an estimate: 2 (3 before the runs' fit; development
/// car 5, two turns, −0.96 % ± 0.10 % for a true −0.90 %).
pub const MIN_TURNS: usize = 2;
/// Largest standard error of an accepted scale error.
pub const MAX_STD: f64 = 0.005;
/// Largest scale error accepted (a physical gyro is within a few per cent).
pub const MAX_SCALE_ERROR: f64 = 0.1;

/// `--corrections auto` applies the gyro scale error when it lowers the
/// held-back error at all (paired t below 0), not by
/// [`crate::held_back::MIN_T`]: a scale error turns the heading only in the
/// turns inside a window, so the 20 s windows' end errors see it weakly,
/// while its estimate is a candidate only at [`crate::held_back::MIN_Z`]
/// standard errors and is checked against the truth on the family
/// (`deadreckon-sim/tests/gyro_scale_family.rs`). Chosen on the dynamic
/// family's development cars 1–6 with the scale effect alone: cars 3 and 6,
/// estimated within 0.05 % of the truth, were judged at t = −0.3 and −0.9
/// and left out. Checked on the held-out cars 101–110
/// (`deadreckon-api/tests/dynamic_family_defaults.rs`): cars 103, 105 and
/// 106 were applied at t = −0.5, −0.8 and −0.3; mean final error of 30 s
/// outages with the scale effect 0.671 → 0.514 m with the new estimator
/// (0.465 m without the effect).
pub const HELD_BACK_MIN_T: f64 = 0.0;

/// Longest gap between two fixes of one straight run, s.
pub const MAX_RUN_GAP_S: f64 = 1.0;
/// Most fixes a run's weight counts: 10 (a second of a 10 Hz receiver). A
/// run's mean course is not better than a second's: the course errors are
/// correlated, and the gyro bias drifts within a long straight. Chosen on
/// the dynamic family's development cars 1–25 with the gyro scale error
/// alone (`deadreckon-sim/tests/gyro_scale_family.rs`): the estimate's
/// error in its standard errors had an RMS of 0.85 capped at 10, 0.91 at
/// 5, 0.88 at 20, and three cars beyond 3 standard errors uncapped (RMS
/// 1.37 unweighted); checked on cars 101–125 (RMS z 0.76, RMS error
/// 0.16 %).
pub const MAX_RUN_WEIGHT_FIXES: f64 = 10.0;
/// Fewest runs of straight moments for a fit: 5 (three coefficients and
/// two degrees of freedom for the scatter).
pub const MIN_RUNS: usize = 5;

/// One run of straight moments: the mean integrated gyro `h` and the mean
/// of `o = c − h` (course minus integrated gyro, unwrapped about the run's
/// first), radians.
#[derive(Debug, Clone, Copy)]
struct Run {
    t: f64,
    h: f64,
    o: f64,
    n: f64,
    /// Sum of the squared deviations of `o` about its mean in the run.
    ss: f64,
}

impl Run {
    /// The run's weight in the fit: its fixes, at most
    /// [`MAX_RUN_WEIGHT_FIXES`].
    fn weight(&self) -> f64 {
        self.n.min(MAX_RUN_WEIGHT_FIXES)
    }
}

/// Groups the straight moments `(t, course, integrated gyro)` into runs.
fn straight_runs(straight: &[(f64, f64, f64)]) -> Vec<Run> {
    let mut runs = Vec::new();
    let mut start = 0;
    for i in 1..=straight.len() {
        if i < straight.len() && straight[i].0 - straight[i - 1].0 <= MAX_RUN_GAP_S {
            continue;
        }
        let run = &straight[start..i];
        let o0 = angle::wrap(run[0].1 - run[0].2);
        let n = run.len() as f64;
        // `o` of each fix, unwrapped about the run's first.
        let os: Vec<f64> = run
            .iter()
            .map(|m| o0 + angle::wrap(m.1 - m.2 - o0))
            .collect();
        let o = os.iter().sum::<f64>() / n;
        let h = run.iter().map(|m| m.2).sum::<f64>() / n;
        let t = run.iter().map(|m| m.0).sum::<f64>() / n;
        let ss = os.iter().map(|x| (x - o).powi(2)).sum::<f64>();
        runs.push(Run { t, h, o, n, ss });
        start = i;
    }
    runs
}

/// Fits `o = a·h + β·t + γ` over the runs (weighted by their fixes; `o`
/// unwrapped from run to run), giving `a` and its standard error from the
/// weighted residual scatter (at least the course noise within the runs
/// implies). With the gyro reading `(1 + s)` times the
/// rate plus a bias `δb` off the one removed, the integrated gyro is
/// `h = (1 + s)ψ + δb·t`, so `o = c − h = (1/(1+s) − 1)·h − δb·t/(1+s) +
/// const`: the time term takes the bias error (on a drive that turns more
/// one way than the other, the calibrated bias holds `s` times the mean
/// yaw rate), which a regression on the turns alone reads as scale.
fn fit_runs(runs: &[Run]) -> Result<(f64, f64), String> {
    let k = runs.len();
    if k < MIN_RUNS {
        return Err(format!(
            "{k} stretches of straight driving with a GNSS course, need {MIN_RUNS}"
        ));
    }
    let o = angle::unwrap(&runs.iter().map(|r| r.o).collect::<Vec<_>>());
    let t0 = runs[0].t;
    let x = DMatrix::from_fn(k, 3, |i, j| {
        runs[i].weight().sqrt()
            * match j {
                0 => runs[i].h,
                1 => runs[i].t - t0,
                _ => 1.0,
            }
    });
    let y = DVector::from_fn(k, |i, _| runs[i].weight().sqrt() * o[i]);
    let xtx = x.transpose() * &x;
    let inv = xtx
        .try_inverse()
        .ok_or("the stretches of straight driving do not determine a scale")?;
    let theta = &inv * (x.transpose() * &y);
    let r = &y - &x * &theta;
    // The residual variance, at least what the fixes' course noise within
    // the runs implies for the weighted run means (with few runs the
    // scatter of a few residuals can come out near zero by chance).
    let within_dof: f64 = runs.iter().map(|r| r.n - 1.0).sum();
    let floor = if within_dof > 0.0 {
        let var_c = runs.iter().map(|r| r.ss).sum::<f64>() / within_dof;
        var_c * runs.iter().map(|r| r.weight() / r.n).sum::<f64>() / k as f64
    } else {
        0.0
    };
    let s2 = (r.norm_squared() / (k - 3) as f64).max(floor);
    let std = (s2 * inv[(0, 0)]).sqrt();
    Ok((theta[0], std))
}

/// The estimated gyro scale error.
#[derive(Debug, Clone, PartialEq)]
pub struct GyroScale {
    /// Relative scale error `s`: the gyro reads `(1 + s)` × the angular rate.
    pub scale_error: f64,
    /// Its standard error.
    pub std: f64,
    /// Turns used.
    pub turns: usize,
    /// Estimated, or why not.
    pub status: Status,
}

impl GyroScale {
    fn not_estimated(turns: usize, reason: String) -> GyroScale {
        GyroScale {
            scale_error: f64::NAN,
            std: f64::NAN,
            turns,
            status: Status::NotEstimated(reason),
        }
    }
    /// True when estimated (and so applied).
    pub fn is_estimated(&self) -> bool {
        self.status.is_estimated()
    }
}

/// Estimates the gyro's scale error on `drive` (time-corrected and levelled
/// already) with the gyro bias `bias_rps` removed.
pub fn estimate(drive: &Drive, bias_rps: f64) -> GyroScale {
    let g = &drive.yaw_rate;
    if g.len() < 3 {
        return GyroScale::not_estimated(0, "no gyro".into());
    }
    // Cumulative integral of (gyro − bias), trapezoids.
    let mut cum = Vec::with_capacity(g.len());
    let mut acc = 0.0;
    cum.push((g[0].t_s, 0.0));
    for w in g.windows(2) {
        acc += 0.5 * (w[0].value + w[1].value - 2.0 * bias_rps) * (w[1].t_s - w[0].t_s);
        cum.push((w[1].t_s, acc));
    }
    // Straight moments with a course.
    let straight: Vec<(f64, f64, f64)> = drive
        .gnss
        .iter()
        .filter_map(|f| {
            let c = f.course_yaw_rad()?;
            if f.speed_mps.is_some_and(|v| v < MIN_SPEED_MPS) {
                return None;
            }
            let h = interp(&cum, f.t_s)?;
            let rate = (interp(&cum, f.t_s + 1.0)? - interp(&cum, f.t_s - 1.0)?) / 2.0;
            (rate.abs() < STRAIGHT_RPS).then_some((f.t_s, c, h))
        })
        .collect();
    if straight.is_empty() {
        return GyroScale::not_estimated(0, "no GNSS course on straight driving".into());
    }
    // Runs of straight moments (consecutive fixes no more than
    // `MAX_RUN_GAP_S` apart): each run's course minus integrated gyro,
    // `o = c − h`, is one value up to the fixes' course noise, so its mean
    // over the run stands for the run.
    let runs = straight_runs(&straight);
    let turns = runs
        .windows(2)
        .filter(|w| (w[1].h - w[0].h).abs() >= MIN_TURN_DEG.to_radians())
        .count();
    if turns < MIN_TURNS {
        return GyroScale::not_estimated(
            turns,
            format!(
                "{turns} turns of more than {MIN_TURN_DEG}° between straights, need {MIN_TURNS}"
            ),
        );
    }
    let (a, std_a) = match fit_runs(&runs) {
        Ok(fit) => fit,
        Err(why) => return GyroScale::not_estimated(turns, why),
    };
    // o = a·h − δb·t/(1+s) + const with a = 1/(1+s) − 1.
    let scale_error = 1.0 / (1.0 + a) - 1.0;
    let std = std_a / (1.0 + a).powi(2);
    let status = if !(std.is_finite() && std <= MAX_STD) {
        Status::NotEstimated(format!(
            "too little turning: standard error {:.2}% above {:.1}%",
            100.0 * std,
            100.0 * MAX_STD
        ))
    } else if scale_error.abs() > MAX_SCALE_ERROR {
        Status::NotEstimated(format!(
            "scale error {:+.1}% beyond ±{:.0}%: not a gyro scale",
            100.0 * scale_error,
            100.0 * MAX_SCALE_ERROR
        ))
    } else {
        Status::Estimated
    };
    GyroScale {
        scale_error,
        std,
        turns,
        status,
    }
}

/// The drive with the gyro (one- and three-axis) divided by `1 + scale_error`.
pub fn apply(drive: &Drive, scale_error: f64) -> Drive {
    let mut d = drive.clone();
    apply_in_place(&mut d, scale_error);
    d
}

/// [`apply`] to a drive in place (no copy).
pub fn apply_in_place(d: &mut Drive, scale_error: f64) {
    let k = 1.0 + scale_error;
    d.yaw_rate.iter_mut().for_each(|s| s.value /= k);
    for a in &mut d.imu.gyro {
        a.x /= k;
        a.y /= k;
        a.z /= k;
    }
}
