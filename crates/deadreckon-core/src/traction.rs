//! The driven axle's longitudinal slip: a driven tyre turns faster than it
//! rolls, in proportion to the force it transmits, so its wheel speed reads
//! high while the car accelerates or climbs (and low while it brakes).
//!
//! **Model**: the driven axle's wheels read `v·(1 + s₀ + κ·f)` where the
//! free-rolling axle reads `v·(1 + s₀′)` and `f` is the forward specific
//! force (the accelerometer's x axis, m/s²): `f = a + g·sin(grade)`, what
//! the tyres push against besides drag. The constant parts are the
//! circumferences' business (calibration); [`estimate`] finds `κ` and
//! [`apply`] removes `κ·(f − f̄)`, with `f̄` the drive's mean forward specific
//! force while moving, from the driven axle's wheel speeds.
//!
//! **Estimate**: over one-second blocks while moving faster than
//! [`MIN_SPEED_MPS`], the ratio of the front axle's mean wheel speed to the
//! rear's, minus one, regressed on the block's mean `f`. The slope is `κ`
//! and its sign names the driven axle: positive, the front wheels read high
//! when pushed (front-wheel drive, and brakes biased to the front, as usual);
//! negative, the rear. Only the slip *difference* between the axles is seen:
//! on an all-wheel drive the correction leaves the smaller slip of the other
//! axle. Standard error from the residuals, inflated by `(1 + ρ)/(1 − ρ)` for
//! their lag-one autocorrelation `ρ`.
//!
//! Both the wheels and the GNSS delay depend on it: on the comma2k19 RAV4 the
//! front wheels read 0.325 % ± 0.024 % high against the rear per m/s² of
//! forward specific force (against the reference's horizontal speed: front
//! +0.316 %, rear −0.033 %), which made the four wheels' mean speed look
//! about 0.03 s early and the GNSS delay estimated against it 0.108 s; the
//! rear wheels alone give 0.084 s, the corrected four 0.087 s. One slope is
//! an approximation: braking loads both axles, and on that segment's first
//! half (pulling away) the slope is 0.40 % ± 0.02 %, on its second (mostly
//! braking) 0.26 % ± 0.03 %.
//!
//! **Status**: not estimated without an accelerometer, with wheel ticks (a
//! count cannot be corrected), without all four wheels, when gravity is not
//! within [`crate::imu::MAX_TILT_DEG`] of the accelerometer's z axis (its x
//! is then not forward), with fewer than
//! [`MIN_BLOCKS`] blocks, a standard error above [`MAX_STD_PER_MPS2`] (too
//! little acceleration or grade), or `|κ|` above [`MAX_SLIP_PER_MPS2`]
//! (rejected, never clamped).

use crate::drive::{Drive, Wheels};
use crate::status::Status;

/// Slowest speed of a block used, m/s (wheel speeds are coarse below).
pub const MIN_SPEED_MPS: f64 = 3.0;
/// Fewest one-second blocks for an estimate.
pub const MIN_BLOCKS: usize = 10;
/// Largest standard error of an accepted slip coefficient, per m/s².
pub const MAX_STD_PER_MPS2: f64 = 0.001;
/// Largest slip coefficient accepted, per m/s²: a tyre's longitudinal
/// stiffness is at least about 10 (force per unit slip, in units of its
/// load), so one driven axle carrying 60 % of the weight slips at most about
/// 1/(10 · 0.6 · 9.81) = 1.7 % per m/s²; beyond 2 % it is not slip.
pub const MAX_SLIP_PER_MPS2: f64 = 0.02;

/// The axle whose wheels carry the slip.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axle {
    /// Front wheels.
    Front,
    /// Rear wheels.
    Rear,
}

impl Axle {
    /// `front` or `rear`.
    pub fn name(self) -> &'static str {
        match self {
            Axle::Front => "front",
            Axle::Rear => "rear",
        }
    }
}

/// The estimated slip of the driven axle.
#[derive(Debug, Clone, PartialEq)]
pub struct TractionSlip {
    /// `κ`: the front axle's speed relative to the rear's rises by this per
    /// m/s² of forward specific force (negative: the rear's relative to the
    /// front's rises by `−κ`).
    pub slip_per_mps2: f64,
    /// Its standard error.
    pub std: f64,
    /// The axle corrected: front when `κ > 0`, rear otherwise.
    pub axle: Axle,
    /// One-second blocks used.
    pub blocks: usize,
    /// Estimated, or why not.
    pub status: Status,
    /// `f̄`: the mean forward specific force while moving, m/s², the level
    /// [`apply`] corrects the wheel speeds to ([`mean_force_mps2`]; NaN when
    /// not estimated). Stored in params.toml so that a live stream, which
    /// cannot know a drive's mean before its end, applies the same
    /// correction ([`apply_at`]).
    pub mean_force_mps2: f64,
}

impl TractionSlip {
    fn not_estimated(blocks: usize, reason: String) -> TractionSlip {
        TractionSlip {
            slip_per_mps2: f64::NAN,
            std: f64::NAN,
            axle: Axle::Front,
            blocks,
            status: Status::NotEstimated(reason),
            mean_force_mps2: f64::NAN,
        }
    }
    /// True when estimated (and so applied).
    pub fn is_estimated(&self) -> bool {
        self.status.is_estimated()
    }
}

/// The forward specific force `(t, m/s²)` and its mean while moving, over
/// the accelerometer's samples.
fn forward_force(drive: &Drive) -> Vec<(f64, f64)> {
    drive.imu.accel.iter().map(|a| (a.t_s, a.x)).collect()
}

/// One-second block means of the forward specific force, `(t_mid, f)`, with
/// the front/rear speed ratio minus one, where both axles have readings and
/// the vehicle moves.
fn blocks(drive: &Drive, f: &[(f64, f64)]) -> Vec<(f64, f64, f64)> {
    let rows = crate::plausibility::wheel_rows(drive);
    let mut out = Vec::new();
    let mut i = 0;
    while i < rows.len() {
        let t0 = rows[i].0;
        let (mut front, mut rear, mut n) = (0.0, 0.0, 0usize);
        while i < rows.len() && rows[i].0 < t0 + 1.0 {
            let w = rows[i].1;
            front += 0.5 * (w[0] + w[1]);
            rear += 0.5 * (w[2] + w[3]);
            n += 1;
            i += 1;
        }
        if n < 5 {
            continue;
        }
        let (front, rear) = (front / n as f64, rear / n as f64);
        if !(rear >= MIN_SPEED_MPS && front >= MIN_SPEED_MPS) {
            continue;
        }
        let a = f.partition_point(|s| s.0 < t0);
        let b = f.partition_point(|s| s.0 < t0 + 1.0);
        if b < a + 5 {
            continue;
        }
        let mean_f = f[a..b].iter().map(|s| s.1).sum::<f64>() / (b - a) as f64;
        out.push((t0 + 0.5, mean_f, front / rear - 1.0));
    }
    out
}

/// Estimates the driven axle's slip; `None` without an accelerometer.
pub fn estimate(drive: &Drive) -> Option<TractionSlip> {
    if drive.imu.accel.is_empty() {
        return None;
    }
    if matches!(drive.wheels, Wheels::Ticks(_)) {
        return Some(TractionSlip::not_estimated(
            0,
            "wheel ticks: a count cannot be corrected for slip".into(),
        ));
    }
    if drive.vehicle.wheels_present != [true; 4] {
        return Some(TractionSlip::not_estimated(
            0,
            "the front and rear axles are compared: all four wheels are needed".into(),
        ));
    }
    // The x axis must be the forward one: gravity within the tilt's bound
    // of z (a sensor mounted on its side reads its forward force elsewhere).
    let acc = &drive.imu.accel;
    let mean = [0, 1, 2].map(|k| acc.iter().map(|a| a.xyz()[k]).sum::<f64>() / acc.len() as f64);
    let norm = mean.iter().map(|c| c * c).sum::<f64>().sqrt();
    if !(norm > 0.0 && (mean[2] / norm).acos().to_degrees() <= crate::imu::MAX_TILT_DEG) {
        return Some(TractionSlip::not_estimated(
            0,
            format!(
                "the accelerometer's mean specific force ({:.2}, {:.2}, {:.2}) m/s² is not along z: its axes are not x forward, y left, z up",
                mean[0], mean[1], mean[2]
            ),
        ));
    }
    let f = forward_force(drive);
    let b = blocks(drive, &f);
    let n = b.len();
    if n < MIN_BLOCKS {
        return Some(TractionSlip::not_estimated(
            n,
            format!("{n} one-second blocks of driving faster than {MIN_SPEED_MPS} m/s, need {MIN_BLOCKS}"),
        ));
    }
    let mx = b.iter().map(|r| r.1).sum::<f64>() / n as f64;
    let my = b.iter().map(|r| r.2).sum::<f64>() / n as f64;
    let sxx: f64 = b.iter().map(|r| (r.1 - mx).powi(2)).sum();
    let sxy: f64 = b.iter().map(|r| (r.1 - mx) * (r.2 - my)).sum();
    if sxx.is_nan() || sxx <= 0.0 {
        return Some(TractionSlip::not_estimated(
            n,
            "the forward specific force never changes".into(),
        ));
    }
    let k = sxy / sxx;
    let res: Vec<f64> = b.iter().map(|r| r.2 - my - k * (r.1 - mx)).collect();
    let s2 = res.iter().map(|e| e * e).sum::<f64>() / (n - 2) as f64;
    let rho = crate::series::lag1(&res).clamp(0.0, 0.9);
    let std = (s2 / sxx * (1.0 + rho) / (1.0 - rho)).sqrt();
    let status = if !(std.is_finite() && std <= MAX_STD_PER_MPS2) {
        Status::NotEstimated(format!(
            "too little acceleration or grade: standard error {:.3} % per m/s² above {:.1} %",
            100.0 * std,
            100.0 * MAX_STD_PER_MPS2
        ))
    } else if k.abs() > MAX_SLIP_PER_MPS2 {
        Status::NotEstimated(format!(
            "{:+.2} % per m/s² beyond ±{:.0} %: not tyre slip",
            100.0 * k,
            100.0 * MAX_SLIP_PER_MPS2
        ))
    } else {
        Status::Estimated
    };
    Some(TractionSlip {
        slip_per_mps2: k,
        std,
        axle: if k > 0.0 { Axle::Front } else { Axle::Rear },
        mean_force_mps2: mean_force_mps2(drive).unwrap_or(f64::NAN),
        blocks: n,
        status,
    })
}

/// The drive with the driven axle's wheel speeds divided by
/// `1 + |κ|·(f − f̄)` (the front for `κ > 0`, the rear otherwise), `f` the
/// forward specific force over ±0.5 s and `f̄` its mean while moving.
/// Unchanged without an accelerometer, with wheel ticks or with `κ = 0`;
/// a reading with no accelerometer sample within ±0.5 s is left as read.
pub fn apply(drive: &Drive, slip_per_mps2: f64) -> Drive {
    apply_at(drive, slip_per_mps2, None)
}

/// `f̄` of [`apply`]: the mean over the one-second blocks of driving of
/// their mean forward specific force (over every accelerometer sample when
/// there is no such block), m/s²; `None` without an accelerometer.
pub fn mean_force_mps2(drive: &Drive) -> Option<f64> {
    let f = forward_force(drive);
    if f.is_empty() {
        return None;
    }
    let b = blocks(drive, &f);
    Some(if b.is_empty() {
        f.iter().map(|s| s.1).sum::<f64>() / f.len() as f64
    } else {
        b.iter().map(|r| r.1).sum::<f64>() / b.len() as f64
    })
}

/// [`apply`] with `f̄` given (`Some`: the level of the drive the slip was
/// estimated on, as params.toml stores it) or the drive's own (`None`).
pub fn apply_at(drive: &Drive, slip_per_mps2: f64, mean_mps2: Option<f64>) -> Drive {
    let mut d = drive.clone();
    apply_at_in_place(&mut d, slip_per_mps2, mean_mps2);
    d
}

/// [`apply_at`] in place (no copy): `f` and `f̄` are taken from the drive
/// before its wheel speeds are corrected, as [`apply_at`] takes them from
/// the drive it copies.
pub fn apply_at_in_place(d: &mut Drive, slip_per_mps2: f64, mean_mps2: Option<f64>) {
    let f = forward_force(d);
    if !matches!(d.wheels, Wheels::Speeds(_)) || f.is_empty() || slip_per_mps2 == 0.0 {
        return;
    }
    let Some(mean) = mean_mps2.or_else(|| mean_force_mps2(d)) else {
        return;
    };
    let Wheels::Speeds(ws) = &mut d.wheels else {
        return;
    };
    // Running sums for the ±0.5 s means.
    let mut cum = Vec::with_capacity(f.len() + 1);
    cum.push(0.0);
    for s in &f {
        cum.push(cum[cum.len() - 1] + s.1);
    }
    let local = |t: f64| -> Option<f64> {
        let a = f.partition_point(|s| s.0 < t - 0.5);
        let b = f.partition_point(|s| s.0 < t + 0.5);
        (b > a).then(|| (cum[b] - cum[a]) / (b - a) as f64)
    };
    let k = slip_per_mps2.abs();
    for w in ws.iter_mut() {
        let Some(fw) = local(w.t_s) else {
            continue;
        };
        let scale = 1.0 + k * (fw - mean);
        if slip_per_mps2 > 0.0 {
            w.fl_mps /= scale;
            w.fr_mps /= scale;
        } else {
            w.rl_mps /= scale;
            w.rr_mps /= scale;
        }
    }
}
