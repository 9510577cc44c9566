//! Time offsets of the streams against the wheel clock.
//!
//! A stream logged late by `d` seconds carries at `t` what happened at `t − d`;
//! the correction moves its timestamps back by `d` ([`Delays::apply`]).
//!
//! - **Gyro, CAN speed, steering** ([`scalar_delay`]): the stream against a
//!   signal derived from the wheels (yaw rate from the rear wheels' speed
//!   difference, the wheels' mean speed, the curvature yaw rate / speed above
//!   [`MIN_CURVATURE_SPEED_MPS`]). For each lag on a grid the stream is fitted
//!   as `a + b·x(t − d)` by least squares; the lag of the smallest residual is
//!   refined by a parabola through its neighbours. The standard error is the
//!   Gauss–Newton one, `σ²/Σ(b·x′ − mean)²`, inflated by `(1 + ρ)/(1 − ρ)` for
//!   the lag-one autocorrelation `ρ` of the residuals. Steering's delay is
//!   the lag of the car's yaw response behind the steering wheel (tyre and
//!   body dynamics included), as openpilot's `lagd` measures it.
//! - **GNSS** ([`gnss_delay`]): a parameter of the least squares between the
//!   fixes and the smoothed track. The drive is calibrated (RTS) with the fixes
//!   moved back by the current delay, smoothed, and the fixes' residuals
//!   against the antenna's smoothed position at `t − d` are regressed on its
//!   velocity (`r = −δ·V + bias`); `d += δ` until `δ` settles. The smoother
//!   absorbs part of a wrong delay, so one step under-corrects and the steps
//!   are repeated.
//!
//! **Status**: a delay is *not estimated* (and not applied) with too few
//! samples, when the best lag lies on the search bound ([`DelayOptions::max_delay_s`]:
//! rejected, never clamped), or when its standard error exceeds
//! [`DelayOptions::max_std_s`] (too little excitation: no turns for the gyro,
//! no speed changes for the CAN speed).

use crate::calibrate::{self, CalibrationOptions};
use crate::drive::{Drive, Scalar};
use crate::ekf::{self, FilterOptions};
use crate::imu::{interp, wheel_speed};
use crate::model::{V, X, Y, YAW, YAW_RATE};
use crate::reference::Reference;
use crate::{rts, Error, Params};

/// Speed above which the steering is compared with the curvature, m/s.
pub const MIN_CURVATURE_SPEED_MPS: f64 = 2.0;

/// Estimated, or not with the reason.
#[derive(Debug, Clone, PartialEq)]
pub enum Status {
    /// Estimated and applied.
    Estimated,
    /// Not estimated (and not applied): why.
    NotEstimated(String),
}

impl Status {
    /// True when estimated.
    pub fn is_estimated(&self) -> bool {
        matches!(self, Status::Estimated)
    }
    /// The reason it was not estimated, if not.
    pub fn reason(&self) -> Option<&str> {
        match self {
            Status::Estimated => None,
            Status::NotEstimated(r) => Some(r),
        }
    }
}

/// The streams with a delay.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stream {
    /// The gyro's yaw rate.
    Gyro,
    /// The CAN vehicle speed.
    Speed,
    /// The steering wheel angle.
    Steering,
    /// The GNSS fixes.
    Gnss,
}

impl Stream {
    /// Every stream, in report order.
    pub const ALL: [Stream; 4] = [Stream::Gyro, Stream::Speed, Stream::Steering, Stream::Gnss];
    /// `gyro`, `speed`, `steering`, `gnss`.
    pub fn name(self) -> &'static str {
        match self {
            Stream::Gyro => "gyro",
            Stream::Speed => "speed",
            Stream::Steering => "steering",
            Stream::Gnss => "gnss",
        }
    }
}

/// One stream's delay.
#[derive(Debug, Clone, PartialEq)]
pub struct Delay {
    /// How late the stream is, s (positive: logged after the instant it describes).
    pub delay_s: f64,
    /// Standard error, s.
    pub std_s: f64,
    /// Samples used.
    pub samples: usize,
    /// Estimated, or why not.
    pub status: Status,
}

impl Delay {
    fn not_estimated(reason: impl Into<String>) -> Delay {
        Delay {
            delay_s: f64::NAN,
            std_s: f64::NAN,
            samples: 0,
            status: Status::NotEstimated(reason.into()),
        }
    }
    /// The delay to apply: the estimate, or 0 when not estimated.
    pub fn applied_s(&self) -> f64 {
        if self.status.is_estimated() {
            self.delay_s
        } else {
            0.0
        }
    }
}

/// The delays of a drive's streams.
#[derive(Debug, Clone, PartialEq)]
pub struct Delays {
    /// Gyro vs the rear wheels' yaw rate.
    pub gyro: Delay,
    /// CAN speed vs the wheels' mean speed.
    pub speed: Delay,
    /// Steering vs the wheels' curvature.
    pub steering: Delay,
    /// GNSS position vs the smoothed track.
    pub gnss: Delay,
}

impl Delays {
    /// No delay known for any stream.
    pub fn none() -> Delays {
        let n = || Delay::not_estimated("not estimated");
        Delays {
            gyro: n(),
            speed: n(),
            steering: n(),
            gnss: n(),
        }
    }
    /// The delay of `s`.
    pub fn get(&self, s: Stream) -> &Delay {
        match s {
            Stream::Gyro => &self.gyro,
            Stream::Speed => &self.speed,
            Stream::Steering => &self.steering,
            Stream::Gnss => &self.gnss,
        }
    }
    /// The drive with every estimated delay removed (timestamps moved back).
    pub fn apply(&self, drive: &Drive) -> Drive {
        shift(
            drive,
            [
                self.gyro.applied_s(),
                self.speed.applied_s(),
                self.steering.applied_s(),
                self.gnss.applied_s(),
            ],
        )
    }
}

/// The drive with the gyro (one- and three-axis), speed, steering and GNSS
/// timestamps moved back by the given delays, s, in [`Stream::ALL`] order.
pub fn shift(drive: &Drive, delays_s: [f64; 4]) -> Drive {
    let [g, s, st, gn] = delays_s;
    let mut d = drive.clone();
    d.yaw_rate.iter_mut().for_each(|x| x.t_s -= g);
    d.imu.gyro.iter_mut().for_each(|x| x.t_s -= g);
    d.speed.iter_mut().for_each(|x| x.t_s -= s);
    d.steering.iter_mut().for_each(|x| x.t_s -= st);
    d.gnss.iter_mut().for_each(|x| x.t_s -= gn);
    d
}

/// Options of the delay estimation.
#[derive(Debug, Clone, PartialEq)]
pub struct DelayOptions {
    /// Largest delay searched, either sign, s: a best lag on this bound is rejected.
    pub max_delay_s: f64,
    /// Grid step of the lag search, s.
    pub step_s: f64,
    /// Largest standard error of an accepted delay, s.
    pub max_std_s: f64,
    /// Fewest samples.
    pub min_samples: usize,
    /// Largest number of calibrate-and-regress steps of the GNSS delay.
    pub gnss_iterations: usize,
    /// Window of the GNSS regression's biases, s (each window its own east
    /// and north bias: the receiver's slowly wandering error).
    pub gnss_window_s: f64,
}

impl Default for DelayOptions {
    fn default() -> Self {
        DelayOptions {
            max_delay_s: 0.5,
            step_s: 0.005,
            max_std_s: 0.02,
            min_samples: 50,
            gnss_iterations: 8,
            gnss_window_s: f64::INFINITY,
        }
    }
}

/// Lag-one autocorrelation of `r`.
fn lag1(r: &[f64]) -> f64 {
    if r.len() < 3 {
        return 0.0;
    }
    let m = r.iter().sum::<f64>() / r.len() as f64;
    let c0: f64 = r.iter().map(|x| (x - m).powi(2)).sum();
    let c1: f64 = r.windows(2).map(|p| (p[0] - m) * (p[1] - m)).sum();
    if c0 > 0.0 {
        (c1 / c0).clamp(-0.99, 0.99)
    } else {
        0.0
    }
}

/// Least squares `y ≈ a + b·x`: `(a, b, residuals)`, `None` if `x` is constant.
fn line_fit(x: &[f64], y: &[f64]) -> Option<(f64, f64, Vec<f64>)> {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxx: f64 = x.iter().map(|v| (v - mx).powi(2)).sum();
    if !(sxx > 0.0) {
        return None;
    }
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let b = sxy / sxx;
    let a = my - b * mx;
    let r = x.iter().zip(y).map(|(xi, yi)| yi - a - b * xi).collect();
    Some((a, b, r))
}

/// The delay of `signal` (`(t, value)`, stream clock) behind `reference`
/// (`(t, value)`, wheel clock, sorted); `keep(t)` selects the samples used.
pub fn scalar_delay(
    reference: &[(f64, f64)],
    signal: &[(f64, f64)],
    keep: &dyn Fn(f64) -> bool,
    o: &DelayOptions,
) -> Delay {
    if reference.len() < 3 {
        return Delay::not_estimated("too few reference samples");
    }
    let (r0, r1) = (reference[0].0, reference[reference.len() - 1].0);
    // Samples whose reference exists at every lag searched.
    let sig: Vec<(f64, f64)> = signal
        .iter()
        .copied()
        .filter(|&(t, v)| {
            v.is_finite()
                && t - o.max_delay_s - o.step_s >= r0
                && t + o.max_delay_s + o.step_s <= r1
                && keep(t)
        })
        .collect();
    if sig.len() < o.min_samples {
        return Delay::not_estimated(format!(
            "{} usable samples, need {}",
            sig.len(),
            o.min_samples
        ));
    }
    let y: Vec<f64> = sig.iter().map(|s| s.1).collect();
    let sse = |d: f64| -> Option<f64> {
        let x: Vec<f64> = sig
            .iter()
            .map(|s| interp(reference, s.0 - d).unwrap_or(f64::NAN))
            .collect();
        line_fit(&x, &y).map(|(_, _, r)| r.iter().map(|e| e * e).sum())
    };
    let k = (o.max_delay_s / o.step_s).round() as i64;
    let grid: Vec<(f64, f64)> = (-k..=k)
        .filter_map(|i| {
            let d = i as f64 * o.step_s;
            sse(d).map(|e| (d, e))
        })
        .collect();
    if grid.len() < 3 {
        return Delay::not_estimated("the reference does not vary");
    }
    let (ib, _) = grid
        .iter()
        .enumerate()
        .min_by(|a, b| a.1 .1.total_cmp(&b.1 .1))
        .map(|(i, g)| (i, g.1))
        .unwrap_or((0, f64::NAN));
    if ib == 0 || ib + 1 == grid.len() {
        return Delay::not_estimated(format!(
            "best lag {:+.3} s on the search bound ±{} s",
            grid[ib].0, o.max_delay_s
        ));
    }
    // Parabola through the minimum and its neighbours.
    let (e0, e1, e2) = (grid[ib - 1].1, grid[ib].1, grid[ib + 1].1);
    let den = e0 - 2.0 * e1 + e2;
    let d = grid[ib].0
        + if den > 0.0 {
            0.5 * o.step_s * (e0 - e2) / den
        } else {
            0.0
        };
    // Gauss–Newton standard error at the refined lag.
    let x: Vec<f64> = sig
        .iter()
        .map(|s| interp(reference, s.0 - d).unwrap_or(f64::NAN))
        .collect();
    let Some((_, b, r)) = line_fit(&x, &y) else {
        return Delay::not_estimated("the reference does not vary");
    };
    let h = 0.01;
    let j: Vec<f64> = sig
        .iter()
        .map(|s| {
            let (Some(p), Some(m)) = (
                interp(reference, s.0 - d + h),
                interp(reference, s.0 - d - h),
            ) else {
                return 0.0;
            };
            b * (p - m) / (2.0 * h)
        })
        .collect();
    let n = j.len();
    let mj = j.iter().sum::<f64>() / n as f64;
    let sjj: f64 = j.iter().map(|v| (v - mj).powi(2)).sum();
    let s2 = r.iter().map(|e| e * e).sum::<f64>() / (n as f64 - 3.0);
    let rho = lag1(&r);
    let std = if sjj > 0.0 {
        (s2 / sjj * (1.0 + rho) / (1.0 - rho)).sqrt()
    } else {
        f64::INFINITY
    };
    status_of(d, std, n, o)
}

fn status_of(d: f64, std: f64, n: usize, o: &DelayOptions) -> Delay {
    let status = if !(std.is_finite() && std <= o.max_std_s) {
        Status::NotEstimated(format!(
            "too little excitation: standard error {std:.3} s above {} s",
            o.max_std_s
        ))
    } else if d.abs() >= o.max_delay_s {
        Status::NotEstimated(format!(
            "delay {d:+.3} s on the search bound ±{} s",
            o.max_delay_s
        ))
    } else {
        Status::Estimated
    };
    Delay {
        delay_s: d,
        std_s: std,
        samples: n,
        status,
    }
}

/// The rear wheels' yaw rate, `(t, rad/s)`, or `None` without both rear wheels.
fn wheel_yaw_rate(drive: &Drive) -> Option<Vec<(f64, f64)>> {
    let w = drive.vehicle.wheels_present;
    if !(w[2] && w[3]) {
        return None;
    }
    let track = drive.vehicle.track_rear_m;
    Some(
        crate::plausibility::wheel_rows(drive)
            .into_iter()
            .map(|(t, v)| (t, (v[3] - v[2]) / track))
            .collect(),
    )
}

fn pairs(s: &[Scalar]) -> Vec<(f64, f64)> {
    s.iter().map(|x| (x.t_s, x.value)).collect()
}

/// The gyro's delay behind the rear wheels' yaw rate.
pub fn gyro_delay(drive: &Drive, o: &DelayOptions) -> Delay {
    if drive.yaw_rate.is_empty() {
        return Delay::not_estimated("no gyro");
    }
    let Some(reference) = wheel_yaw_rate(drive) else {
        return Delay::not_estimated("needs both rear wheels");
    };
    scalar_delay(&reference, &pairs(&drive.yaw_rate), &|_| true, o)
}

/// The CAN speed's delay behind the wheels' mean speed.
pub fn speed_delay(drive: &Drive, o: &DelayOptions) -> Delay {
    if drive.speed.is_empty() {
        return Delay::not_estimated("no CAN speed");
    }
    scalar_delay(&wheel_speed(drive), &pairs(&drive.speed), &|_| true, o)
}

/// The steering's delay behind the wheels' curvature. The car's yaw response
/// lags the steering wheel, so a steering logged on time shows a negative
/// delay of that response lag.
pub fn steering_delay(drive: &Drive, o: &DelayOptions) -> Delay {
    if drive.steering.is_empty() {
        return Delay::not_estimated("no steering");
    }
    let Some(w) = wheel_yaw_rate(drive) else {
        return Delay::not_estimated("needs both rear wheels");
    };
    let v = wheel_speed(drive);
    let curvature: Vec<(f64, f64)> = w
        .iter()
        .filter_map(|&(t, wz)| {
            let s = interp(&v, t)?;
            (s > MIN_CURVATURE_SPEED_MPS).then(|| (t, wz / s))
        })
        .collect();
    let keep = |t: f64| interp(&v, t).is_some_and(|s| s > MIN_CURVATURE_SPEED_MPS + 0.5);
    scalar_delay(&curvature, &pairs(&drive.steering), &keep, o)
}

/// The GNSS delay against the smoothed track, calibrating with `copts` at
/// each step (see the module documentation). `params` (the calibration's
/// result at the final delay) is returned with it.
pub fn gnss_delay(
    drive: &Drive,
    copts: &CalibrationOptions,
    o: &DelayOptions,
) -> Result<(Delay, Option<Params>), Error> {
    if drive.gnss.len() < o.min_samples {
        return Ok((
            Delay::not_estimated(format!(
                "{} GNSS fixes, need {}",
                drive.gnss.len(),
                o.min_samples
            )),
            None,
        ));
    }
    let lever = drive.vehicle.gnss_lever_arm_m;
    let mut d = 0.0;
    let mut last = None;
    for _ in 0..o.gnss_iterations.max(1) {
        let shifted = shift(drive, [0.0, 0.0, 0.0, d]);
        let cal = calibrate::calibrate(&shifted, copts)?;
        let params = cal.estimate.params;
        let f = ekf::run(
            &shifted,
            &params,
            &FilterOptions {
                record_epochs: true,
                ..copts.filter.clone()
            },
            &mut (),
        )?;
        let sm = rts::smooth(&f.epochs)?;
        let reference = Reference::from_states(
            sm.iter().map(|s| s.t_s).collect(),
            sm.iter().map(|s| s.x).collect(),
        );
        let Some((delta, std, n)) = regress_gnss(&shifted.gnss, &reference, lever, o.gnss_window_s)
        else {
            return Ok((
                Delay::not_estimated(
                    "too few fixes inside the smoothed track, or no velocity change",
                ),
                None,
            ));
        };
        d += delta;
        last = Some((std, n, params));
        if d.abs() > o.max_delay_s {
            break;
        }
        if delta.abs() < 1e-4 {
            break;
        }
    }
    let Some((std, n, params)) = last else {
        return Ok((Delay::not_estimated("no step"), None));
    };
    let delay = status_of(d, std, n, o);
    let params = delay.status.is_estimated().then_some(params);
    Ok((delay, params))
}

/// One regression step of the GNSS delay: the fixes' residuals against the
/// antenna's position on `reference` at the fixes' times, regressed on the
/// antenna's velocity with one bias per coordinate and `window_s` window
/// (`r = −δ·V + b`). Returns `(δ, std, fixes)`: `δ` is how much later the
/// fixes still are than `reference`. `None` with fewer than 10 fixes per
/// window on average or a velocity that does not vary.
pub fn regress_gnss(
    fixes: &[crate::drive::GnssFix],
    reference: &Reference,
    lever_m: f64,
    window_s: f64,
) -> Option<(f64, f64, usize)> {
    // (window, residual, antenna velocity)
    let mut rows: Vec<(i64, [f64; 2], [f64; 2])> = Vec::new();
    let t0 = fixes.first()?.t_s;
    for g in fixes {
        let Some(x) = reference.state_at(g.t_s) else {
            continue;
        };
        let (c, s) = (x[YAW].cos(), x[YAW].sin());
        let ant = [x[X] + lever_m * c, x[Y] + lever_m * s];
        let va = [
            x[V] * c - lever_m * x[YAW_RATE] * s,
            x[V] * s + lever_m * x[YAW_RATE] * c,
        ];
        let w = ((g.t_s - t0) / window_s).floor() as i64;
        rows.push((w, [g.east_m - ant[0], g.north_m - ant[1]], va));
    }
    let n = rows.len();
    let windows = rows.last().map_or(0, |r| r.0 + 1) as usize;
    if n < 10 * windows.max(1) || n < 10 {
        return None;
    }
    // Remove each window's means.
    let mut centred: Vec<([f64; 2], [f64; 2])> = Vec::with_capacity(n);
    let mut i = 0;
    while i < n {
        let w = rows[i].0;
        let j = i + rows[i..].iter().take_while(|r| r.0 == w).count();
        let m = (j - i) as f64;
        let mr = [0, 1].map(|k| rows[i..j].iter().map(|r| r.1[k]).sum::<f64>() / m);
        let mv = [0, 1].map(|k| rows[i..j].iter().map(|r| r.2[k]).sum::<f64>() / m);
        for r in &rows[i..j] {
            centred.push((
                [0, 1].map(|k| r.1[k] - mr[k]),
                [0, 1].map(|k| r.2[k] - mv[k]),
            ));
        }
        i = j;
    }
    let svv: f64 = centred.iter().map(|(_, v)| v[0] * v[0] + v[1] * v[1]).sum();
    let svr: f64 = centred.iter().map(|(r, v)| v[0] * r[0] + v[1] * r[1]).sum();
    if !(svv > 0.0) {
        return None;
    }
    let delta = -svr / svv;
    let res: Vec<[f64; 2]> = centred
        .iter()
        .map(|(r, v)| [0, 1].map(|k| r[k] + delta * v[k]))
        .collect();
    let dof = (2 * n) as f64 - (2 * windows.max(1)) as f64 - 1.0;
    let s2 = res.iter().map(|p| p[0] * p[0] + p[1] * p[1]).sum::<f64>() / dof.max(1.0);
    let rho = 0.5
        * (lag1(&res.iter().map(|p| p[0]).collect::<Vec<_>>())
            + lag1(&res.iter().map(|p| p[1]).collect::<Vec<_>>()));
    let std = (s2 / svv * (1.0 + rho) / (1.0 - rho)).sqrt();
    Some((delta, std, n))
}

/// Every stream's delay: the scalar streams on `drive` as given, then the
/// GNSS on the drive with the scalar delays applied.
pub fn estimate(
    drive: &Drive,
    copts: &CalibrationOptions,
    o: &DelayOptions,
) -> Result<Delays, Error> {
    let mut delays = Delays {
        gyro: gyro_delay(drive, o),
        speed: speed_delay(drive, o),
        steering: steering_delay(drive, o),
        gnss: Delay::not_estimated("not estimated"),
    };
    let partly = delays.apply(drive);
    delays.gnss = gnss_delay(&partly, copts, o)?.0;
    Ok(delays)
}

/// Which corrections [`prepare_with`] estimates and applies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Which {
    /// The IMU tilt and every stream's delay.
    All,
    /// The IMU tilt and the GNSS delay only (the other streams' delays
    /// estimated and reported, not applied).
    Gnss,
    /// Nothing estimated or applied.
    None,
}

/// What [`prepare`] found and applied.
#[derive(Debug, Clone, PartialEq)]
pub struct Corrections {
    /// The IMU's tilt (`None`: no three-axis IMU in the drive).
    pub tilt: Option<crate::imu::Tilt>,
    /// The streams' delays.
    pub delays: Delays,
}

/// Estimates the IMU tilt (projecting the gyro on the vertical when
/// estimated) and every stream's delay, and returns the drive with both
/// applied.
pub fn prepare(
    drive: &Drive,
    copts: &CalibrationOptions,
    o: &DelayOptions,
) -> Result<(Drive, Corrections), Error> {
    prepare_with(drive, copts, o, Which::All)
}

/// [`prepare`] with a choice of what is applied (see [`Which`]); an
/// unapplied delay is marked not estimated with the reason.
pub fn prepare_with(
    drive: &Drive,
    copts: &CalibrationOptions,
    o: &DelayOptions,
    which: Which,
) -> Result<(Drive, Corrections), Error> {
    if which == Which::None {
        return Ok((
            drive.clone(),
            Corrections {
                tilt: None,
                delays: Delays::none(),
            },
        ));
    }
    let (levelled, tilt) = crate::imu::level(drive);
    let mut delays = estimate(&levelled, copts, o)?;
    if which == Which::Gnss {
        for d in [&mut delays.gyro, &mut delays.speed, &mut delays.steering] {
            if d.status.is_estimated() {
                d.status = Status::NotEstimated(format!(
                    "not applied (GNSS delay only): {:+.4} ± {:.4} s measured",
                    d.delay_s, d.std_s
                ));
            }
        }
    }
    let out = delays.apply(&levelled);
    Ok((out, Corrections { tilt, delays }))
}

/// Applies known corrections (e.g. from a params.toml): the yaw rate
/// projected on `up` (sensor axes) when given and the drive has a three-axis
/// gyro, then the delays, s, in [`Stream::ALL`] order.
pub fn apply_known(drive: &Drive, delays_s: [f64; 4], up: Option<[f64; 3]>) -> Drive {
    let d = match up {
        Some(u) => crate::imu::level_with(drive, u),
        None => drive.clone(),
    };
    shift(&d, delays_s)
}
