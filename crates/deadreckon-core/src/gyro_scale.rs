//! The gyro's scale factor (ESP and phone gyros read a few per cent off)
//! from the heading changes of turns.
//!
//! Between two moments of straight driving (the gyro, bias removed, below
//! [`STRAIGHT_RPS`] over ±1 s, speed above [`MIN_SPEED_MPS`], a GNSS course at
//! both) the GNSS course changes by exactly the heading change (no slip and no
//! lever-arm term on a straight), and the gyro integrates `(1 + s)` times it.
//! Each turn (consecutive straight fixes more than [`MIN_TURN_DEG`] apart
//! in integrated heading) gives one pair; the course change is regressed on the
//! integrated gyro through the origin, `Δcourse = c·∫(gyro − b)`, and
//! `s = 1/c − 1`, with the standard error from the residual scatter.
//!
//! **Observability rule**: not estimated with fewer than [`MIN_TURNS`] turns,
//! a standard error above [`MAX_STD`] (too little turning), without GNSS
//! course, or with |s| above [`MAX_SCALE_ERROR`] (rejected, never clamped).

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
/// Fewest turns for an estimate.
pub const MIN_TURNS: usize = 3;
/// Largest standard error of an accepted scale error.
pub const MAX_STD: f64 = 0.005;
/// Largest scale error accepted (a physical gyro is within a few per cent).
pub const MAX_SCALE_ERROR: f64 = 0.1;

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
    // One pair per turn: consecutive straight moments far apart in heading.
    let mut pairs: Vec<(f64, f64)> = Vec::new();
    for w in straight.windows(2) {
        let (a, b) = (w[0], w[1]);
        let dg = b.2 - a.2;
        if dg.abs() < MIN_TURN_DEG.to_radians() {
            continue;
        }
        // The course change, unwrapped to the turn the gyro saw.
        let dc = dg + angle::wrap(b.1 - a.1 - dg);
        pairs.push((dg, dc));
    }
    let n = pairs.len();
    if n < MIN_TURNS {
        return GyroScale::not_estimated(
            n,
            format!("{n} turns of more than {MIN_TURN_DEG}° between straights, need {MIN_TURNS}"),
        );
    }
    let sxx: f64 = pairs.iter().map(|p| p.0 * p.0).sum();
    let sxy: f64 = pairs.iter().map(|p| p.0 * p.1).sum();
    let c = sxy / sxx;
    let s2 = pairs.iter().map(|p| (p.1 - c * p.0).powi(2)).sum::<f64>() / (n - 1) as f64;
    let std_c = (s2 / sxx).sqrt();
    let scale_error = 1.0 / c - 1.0;
    let std = std_c / (c * c);
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
        turns: n,
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
