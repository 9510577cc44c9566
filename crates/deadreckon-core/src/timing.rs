//! Time offsets of the streams against the wheel clock.
//!
//! A stream logged late by `d` seconds carries at `t` what happened at `t − d`;
//! the correction moves its timestamps back by `d` ([`Delays::apply`]).
//!
//! - **Gyro, CAN speed, steering** ([`scalar_delay`]): the stream against a
//!   signal derived from the wheels (yaw rate from the rear wheels' speed
//!   difference, the wheels' mean speed, the curvature yaw rate / speed above
//!   [`MIN_CURVATURE_SPEED_MPS`]), both smoothed by a 0.2 s triangle. For
//!   each lag on a grid the stream is fitted as `a + b·x(t − d)` by least
//!   squares; the lag of the smallest residual is
//!   refined by a parabola through its neighbours. The standard error is the
//!   Gauss–Newton one, `σ²/Σ(b·x′ − mean)²`, inflated by `(1 + ρ)/(1 − ρ)` for
//!   the lag-one autocorrelation `ρ` of the residuals. Steering's delay is
//!   the lag of the car's yaw response behind the steering wheel (tyre and
//!   body dynamics included), as openpilot's `lagd` measures it.
//! - **GNSS** ([`gnss_delay`]): a parameter of the least squares between the
//!   fixes and the dead-reckoned track. The drive is calibrated (RTS) with
//!   the fixes moved back by the current delay, dead-reckoned from the
//!   smoothed start (wheels and gyro only), and the fixes' residuals against
//!   the antenna's dead-reckoned position are regressed on its velocity, with
//!   a bias, a rotation and a stretch per 20 s window for the dead
//!   reckoning's drift (`r = −δ·V + b + θ·J(p − p_c) + λ(p − p_c)`), until
//!   `δ` settles. (Against the
//!   smoothed track, which the fixes pull along, a 0.18 s delay read
//!   0.11 s.) The smoother absorbs
//!   part of a wrong delay, so one step under-corrects (`δ ≈ (1 − α)(d* − d)`):
//!   after a first plain step the delay moves by secant steps on `δ(d) = 0`,
//!   and the standard error of `δ` is divided by the slope `1 − α`.
//!
//! **Status**: a delay is *not estimated* (and not applied) with too few
//! samples, when the best lag lies on the search bound ([`DelayOptions::max_delay_s`]:
//! rejected, never clamped), or when its standard error exceeds
//! [`DelayOptions::max_std_s`] (too little excitation: no turns for the gyro,
//! no speed changes for the CAN speed).

use crate::calibrate::{self, CalibrationOptions};
use crate::drive::{Drive, Scalar};
use crate::ekf::{self, FilterOptions, Init, SensorSet};
use crate::imu::{interp, wheel_speed};
use crate::model::{V, X, Y, YAW, YAW_RATE};
use crate::reference::Reference;
use crate::{Error, Params};

/// Speed above which the steering is compared with the curvature, m/s.
pub const MIN_CURVATURE_SPEED_MPS: f64 = 2.0;

/// How the reason of every correction measured but not applied starts
/// (`--corrections gnss`'s other delays, `auto`'s rejected corrections).
pub const MEASURED: &str = "measured, not applied";

/// The reason of a delay that was measured but not applied because only the
/// GNSS delay was asked for (`Which::Gnss`); such a [`Delay`] keeps its
/// measured `delay_s` and `std_s`.
pub const MEASURED_NOT_APPLIED: &str = "measured, not applied: only the GNSS delay was asked for";

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
    /// True when it was measured and deliberately not applied (the reason
    /// starts with [`MEASURED`]): its value and standard error are kept.
    pub fn is_measured_not_applied(&self) -> bool {
        matches!(self, Status::NotEstimated(r) if r.starts_with(MEASURED))
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

/// The reason of a delay [`Which::None`] did not ask for.
pub const NOT_ASKED: &str = "not asked for";

impl Delays {
    /// No delay asked for any stream ([`Which::None`]).
    pub fn none() -> Delays {
        let n = || Delay::not_estimated(NOT_ASKED);
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
    /// The delay of `s`, to change.
    pub fn get_mut(&mut self, s: Stream) -> &mut Delay {
        match s {
            Stream::Gyro => &mut self.gyro,
            Stream::Speed => &mut self.speed,
            Stream::Steering => &mut self.steering,
            Stream::Gnss => &mut self.gnss,
        }
    }
    /// The drive with every estimated delay removed (timestamps moved back).
    pub fn apply(&self, drive: &Drive) -> Drive {
        let mut d = drive.clone();
        self.apply_in_place(&mut d);
        d
    }

    /// [`Delays::apply`] to a drive in place (no copy).
    pub fn apply_in_place(&self, drive: &mut Drive) {
        shift_in_place(
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
    let mut d = drive.clone();
    shift_in_place(&mut d, delays_s);
    d
}

/// [`shift`] in place (no copy).
pub fn shift_in_place(d: &mut Drive, delays_s: [f64; 4]) {
    let [g, s, st, gn] = delays_s;
    d.yaw_rate.iter_mut().for_each(|x| x.t_s -= g);
    d.imu.gyro.iter_mut().for_each(|x| x.t_s -= g);
    d.speed.iter_mut().for_each(|x| x.t_s -= s);
    d.steering.iter_mut().for_each(|x| x.t_s -= st);
    d.gnss.iter_mut().for_each(|x| x.t_s -= gn);
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
    /// Fewest samples (GNSS fixes, or windows of the scalar streams).
    pub min_samples: usize,
    /// Half-width of the triangle smoothing both scalar streams, s, and the
    /// spacing of the points compared (several sample periods of the
    /// slowest stream).
    pub window_s: f64,
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
            window_s: 0.2,
            gnss_iterations: 8,
            gnss_window_s: 20.0,
        }
    }
}

/// Lag-one autocorrelation of `r`.
pub(crate) fn lag1(r: &[f64]) -> f64 {
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

/// Blocks of consecutive points of the delay's jackknife.
pub const JACKKNIFE_BLOCKS: usize = 20;

/// The delete-a-group jackknife's standard error from the estimates made
/// without each group in turn: `√((g − 1)/g · Σ (θᵢ − θ̄)²)`.
fn jackknife_std(estimates: &[f64]) -> f64 {
    let g = estimates.len() as f64;
    let m = estimates.iter().sum::<f64>() / g;
    ((g - 1.0) / g * estimates.iter().map(|v| (v - m).powi(2)).sum::<f64>()).sqrt()
}

/// The sums of a straight-line fit y = a + b x.
#[derive(Debug, Clone, Copy, Default)]
struct LineSums {
    n: f64,
    x: f64,
    y: f64,
    xx: f64,
    xy: f64,
    yy: f64,
}

impl LineSums {
    fn add(&mut self, x: f64, y: f64) {
        self.n += 1.0;
        self.x += x;
        self.y += y;
        self.xx += x * x;
        self.xy += x * y;
        self.yy += y * y;
    }
    fn total(parts: &[LineSums]) -> LineSums {
        parts.iter().fold(LineSums::default(), |a, p| LineSums {
            n: a.n + p.n,
            x: a.x + p.x,
            y: a.y + p.y,
            xx: a.xx + p.xx,
            xy: a.xy + p.xy,
            yy: a.yy + p.yy,
        })
    }
    fn without(&self, p: &LineSums) -> LineSums {
        LineSums {
            n: self.n - p.n,
            x: self.x - p.x,
            y: self.y - p.y,
            xx: self.xx - p.xx,
            xy: self.xy - p.xy,
            yy: self.yy - p.yy,
        }
    }
    /// The residual sum of squares of the fit (`None`: x does not vary).
    fn sse(&self) -> Option<f64> {
        if self.n < 3.0 {
            return None;
        }
        let sxx = self.xx - self.x * self.x / self.n;
        let sxy = self.xy - self.x * self.y / self.n;
        let syy = self.yy - self.y * self.y / self.n;
        (sxx > 1e-12 * self.xx.max(1e-300)).then(|| (syy - sxy * sxy / sxx).max(0.0))
    }
}

/// Least squares `y ≈ a + b·x`: `(a, b, residuals)`, `None` if `x` is constant.
fn line_fit(x: &[f64], y: &[f64]) -> Option<(f64, f64, Vec<f64>)> {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxx: f64 = x.iter().map(|v| (v - mx).powi(2)).sum();
    if sxx.is_nan() || sxx <= 0.0 {
        return None;
    }
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let b = sxy / sxx;
    let a = my - b * mx;
    let r = x.iter().zip(y).map(|(xi, yi)| yi - a - b * xi).collect();
    Some((a, b, r))
}

/// Exact first and second integrals of a linearly interpolated series.
struct Integral<'a> {
    s: &'a [(f64, f64)],
    cum: Vec<f64>,
    cum2: Vec<f64>,
}

impl<'a> Integral<'a> {
    fn new(s: &'a [(f64, f64)]) -> Self {
        let mut cum = Vec::with_capacity(s.len());
        let mut cum2 = Vec::with_capacity(s.len());
        let (mut c1, mut c2) = (0.0, 0.0);
        cum.push(0.0);
        cum2.push(0.0);
        for w in s.windows(2) {
            let h = w[1].0 - w[0].0;
            let m = if h > 0.0 { (w[1].1 - w[0].1) / h } else { 0.0 };
            c2 += c1 * h + w[0].1 * h * h / 2.0 + m * h * h * h / 6.0;
            c1 += 0.5 * (w[0].1 + w[1].1) * h;
            cum.push(c1);
            cum2.push(c2);
        }
        Integral { s, cum, cum2 }
    }
    /// First and second integral up to `t`; the segment is searched from
    /// `cursor` (the last call's), which is left at this one's.
    fn at(&self, t: f64, cursor: &mut usize) -> Option<(f64, f64)> {
        let n = self.s.len();
        if n < 2 || !(t >= self.s[0].0 && t <= self.s[n - 1].0) {
            return None;
        }
        *cursor = crate::cursor::partition_from(n, |i| self.s[i].0, t, *cursor);
        let i = (*cursor).clamp(1, n - 1);
        let (a, b) = (self.s[i - 1], self.s[i]);
        let h = b.0 - a.0;
        let tau = t - a.0;
        let m = if h > 0.0 { (b.1 - a.1) / h } else { 0.0 };
        let c1 = self.cum[i - 1] + a.1 * tau + 0.5 * m * tau * tau;
        let c2 = self.cum2[i - 1]
            + self.cum[i - 1] * tau
            + a.1 * tau * tau / 2.0
            + m * tau * tau * tau / 6.0;
        Some((c1, c2))
    }
    /// The triangle-weighted mean over `[t − w, t + w]` and its derivative
    /// in `t`; `cursors` are those of the three ends (`t + w`, `t`, `t − w`)
    /// in the last call, so that a pass at increasing `t` searches little.
    fn smooth(&self, t: f64, w: f64, cursors: &mut [usize; 3]) -> Option<(f64, f64)> {
        let [cp, cc, cm] = cursors;
        let (p1, p2) = self.at(t + w, cp)?;
        let (c1, c2) = self.at(t, cc)?;
        let (m1, m2) = self.at(t - w, cm)?;
        Some((
            (p2 - 2.0 * c2 + m2) / (w * w),
            (p1 - 2.0 * c1 + m1) / (w * w),
        ))
    }
}

/// The delay of `signal` (`(t, value)`, stream clock) behind `reference`
/// (`(t, value)`, wheel clock, sorted); `keep(t)` selects the windows used.
///
/// The standard error is the larger of the Gauss–Newton one (with the
/// residuals' lag-1 correlation) and a delete-a-block jackknife over
/// [`JACKKNIFE_BLOCKS`] blocks of consecutive points.
///
/// Both series are compared smoothed by a triangle of half-width
/// [`DelayOptions::window_s`] (exact double integrals of the linearly
/// interpolated samples), at points that far apart: interpolating a noisy
/// series at shifted times favours lags that put those times midway between
/// its samples (where interpolation averages the noise), a bias of up to a
/// quarter of a sample period when the two rates are commensurate; a smooth
/// kernel over many samples weighs every phase alike.
pub fn scalar_delay(
    reference: &[(f64, f64)],
    signal: &[(f64, f64)],
    keep: &dyn Fn(f64) -> bool,
    o: &DelayOptions,
) -> Delay {
    if reference.len() < 3 || signal.len() < 3 {
        return Delay::not_estimated("too few samples");
    }
    if signal.iter().any(|s| !s.1.is_finite()) || reference.iter().any(|s| !s.1.is_finite()) {
        return Delay::not_estimated("non-finite samples");
    }
    let (r0, r1) = (reference[0].0, reference[reference.len() - 1].0);
    let (s0, s1) = (signal[0].0, signal[signal.len() - 1].0);
    let w = o.window_s;
    let margin = o.max_delay_s + o.step_s;
    let isig = Integral::new(signal);
    let iref = Integral::new(reference);
    // Points spaced w on the reference clock, inside both spans at every lag
    // searched; the signal is read at the point + the lag.
    let (start, end) = (r0.max(s0 + margin) + w, r1.min(s1 - margin) - w);
    // (t, smoothed reference, its derivative)
    let mut pts: Vec<(f64, f64, f64)> = Vec::new();
    let mut t = start;
    let mut cursors = [0; 3];
    while t <= end {
        if keep(t) {
            if let Some((m, dm)) = iref.smooth(t, w, &mut cursors) {
                pts.push((t, m, dm));
            }
        }
        t += w;
    }
    if pts.len() < o.min_samples {
        return Delay::not_estimated(format!(
            "{} usable points {w} s apart, need {}",
            pts.len(),
            o.min_samples
        ));
    }
    let x: Vec<f64> = pts.iter().map(|s| s.1).collect();
    let ys = |d: f64| -> Vec<(f64, f64)> {
        let mut cursors = [0; 3];
        pts.iter()
            .map(|&(t, _, _)| {
                isig.smooth(t + d, w, &mut cursors)
                    .unwrap_or((f64::NAN, 0.0))
            })
            .collect()
    };
    // Per lag of the grid and per block of consecutive points, the sums of a
    // line fit, so that the fit without one block is the totals minus it.
    let k = (o.max_delay_s / o.step_s).round() as i64;
    let lags: Vec<f64> = (-k..=k).map(|i| i as f64 * o.step_s).collect();
    let blocks = JACKKNIFE_BLOCKS.min(pts.len() / 10).max(1);
    let block_of = |i: usize| i * blocks / pts.len();
    let mx = x.iter().sum::<f64>() / x.len() as f64;
    let sums: Vec<Vec<LineSums>> = lags
        .iter()
        .map(|&d| {
            let mut per = vec![LineSums::default(); blocks];
            for (i, (yv, _)) in ys(d).into_iter().enumerate() {
                if yv.is_finite() {
                    per[block_of(i)].add(x[i] - mx, yv);
                }
            }
            per
        })
        .collect();
    let totals: Vec<LineSums> = sums.iter().map(|per| LineSums::total(per)).collect();
    // The refined lag of a set of SSE values over the grid: the minimum, a
    // parabola through it and its neighbours; `Err` on the bound.
    let refine = |sse: &[Option<f64>]| -> Result<f64, f64> {
        let grid: Vec<(f64, f64)> = lags
            .iter()
            .zip(sse)
            .filter_map(|(d, e)| e.map(|e| (*d, e)))
            .collect();
        if grid.len() < 3 {
            return Err(f64::NAN);
        }
        let ib = grid
            .iter()
            .enumerate()
            .min_by(|a, b| a.1 .1.total_cmp(&b.1 .1))
            .map_or(0, |(i, _)| i);
        if ib == 0 || ib + 1 == grid.len() {
            return Err(grid[ib].0);
        }
        let (e0, e1, e2) = (grid[ib - 1].1, grid[ib].1, grid[ib + 1].1);
        let den = e0 - 2.0 * e1 + e2;
        Ok(grid[ib].0
            + if den > 0.0 {
                0.5 * o.step_s * (e0 - e2) / den
            } else {
                0.0
            })
    };
    let full: Vec<Option<f64>> = totals.iter().map(LineSums::sse).collect();
    let d = match refine(&full) {
        Ok(d) => d,
        Err(b) if b.is_nan() => return Delay::not_estimated("the reference does not vary"),
        Err(b) => {
            return Delay::not_estimated(format!(
                "best lag {b:+.3} s on the search bound ±{} s",
                o.max_delay_s
            ))
        }
    };
    // Delete-a-block jackknife: the lag without each block in turn.
    let jack: Vec<f64> = (0..blocks)
        .filter_map(|b| {
            let sse: Vec<Option<f64>> = totals
                .iter()
                .zip(&sums)
                .map(|(t, per)| t.without(&per[b]).sse())
                .collect();
            refine(&sse).ok()
        })
        .collect();
    let jack_std = if jack.len() == blocks && blocks >= 5 {
        jackknife_std(&jack)
    } else {
        f64::INFINITY
    };
    // Gauss–Newton standard error at the refined lag. The sensitivity to the
    // lag is the signal's derivative, estimated two ways: the smoothed
    // signal's own derivative, and the fitted slope times the reference's.
    // Each is the true derivative plus its series' smoothed noise, which
    // only adds to Σ j² (a steering wheel read with 0.3 rad of white noise
    // made the standard error five to ten times too small): the smaller sum
    // is taken.
    let yd = ys(d);
    let y: Vec<f64> = yd.iter().map(|p| p.0).collect();
    let Some((_, slope, r)) = line_fit(&x, &y) else {
        return Delay::not_estimated("the reference does not vary");
    };
    let centred_ss = |j: &[f64]| -> f64 {
        let mj = j.iter().sum::<f64>() / j.len() as f64;
        j.iter().map(|v| (v - mj).powi(2)).sum()
    };
    let j_signal: Vec<f64> = yd.iter().map(|p| p.1).collect();
    let j_reference: Vec<f64> = pts.iter().map(|p| slope * p.2).collect();
    let n = j_signal.len();
    let sjj = centred_ss(&j_signal).min(centred_ss(&j_reference));
    let s2 = r.iter().map(|e| e * e).sum::<f64>() / (n as f64 - 3.0);
    let rho = lag1(&r);
    let gn_std = if sjj > 0.0 {
        (s2 / sjj * (1.0 + rho) / (1.0 - rho)).sqrt()
    } else {
        f64::INFINITY
    };
    // The Gauss–Newton error sees the signal's noise only; the jackknife
    // also sees the reference's and whatever varies along the drive. On a
    // simulated steering wheel (0.3 rad of white noise) over ten noise seeds
    // the lag scattered by 0.0069 and 0.0142 s where the Gauss–Newton error
    // said 0.0044 and 0.0064 s.
    status_of(d, gn_std.max(jack_std), n, o)
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
    let (ratio, wheelbase) = (drive.vehicle.steering_ratio, drive.vehicle.wheelbase_m);
    let curvature: Vec<(f64, f64)> = w
        .iter()
        .filter_map(|&(t, wz)| {
            let s = interp(&v, t)?;
            // The wheel angle of that curvature, in steering-wheel units
            // with the nominal ratio (the fit absorbs a ratio error).
            (s > MIN_CURVATURE_SPEED_MPS).then(|| (t, ratio * (wheelbase * wz / s).atan()))
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
    gnss_delay_of(drive.clone(), copts, o)
}

/// [`gnss_delay`] of a drive it may change: its fixes are moved to each
/// step's delay in place (one copy of the drive, not one per step).
fn gnss_delay_of(
    mut shifted: Drive,
    copts: &CalibrationOptions,
    o: &DelayOptions,
) -> Result<(Delay, Option<Params>), Error> {
    let drive = &shifted;
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
    // The fixes' own times and the vehicle, which each step starts from.
    let fix_times: Vec<f64> = drive.gnss.iter().map(|g| g.t_s).collect();
    let vehicle = drive.vehicle.clone();
    let mut d = 0.0;
    let mut last = None;
    let mut prev: Option<(f64, f64)> = None;
    for _ in 0..o.gnss_iterations.max(1) {
        // As `shift(drive, [0, 0, 0, d])`, in place.
        for (g, &t) in shifted.gnss.iter_mut().zip(&fix_times) {
            g.t_s = t - d;
        }
        shifted.vehicle = vehicle.clone();
        // The parameters only: the wheel health, the manoeuvres, the side
        // slip and the steering are not read here.
        let cal = calibrate::calibrate_parameters(&shifted, copts)?;
        let params = cal.estimate.params;
        // Only the smoothed start is used: smoothed in O(√N) memory
        // (checkpointed re-runs), equal to the first of `rts::smooth` over
        // the recorded run.
        let fopts = FilterOptions {
            record_epochs: true,
            ..copts.filter.clone()
        };
        let s0 = crate::checkpoint::smoothed_start(
            &shifted,
            ekf::car_filter(&shifted, &params, &fopts)?,
            &fopts,
        )?;
        // Dead reckoning (no GNSS) from the smoothed start: a reference the
        // fixes' timing cannot pull along, its drift taken out per window.
        let Some(s0) = s0 else {
            return Ok((Delay::not_estimated("no smoothed track"), None));
        };
        // The reference integrates the yaw with the trapezoid: with eq. 3's
        // Euler step its yaw lags half a step of yaw-rate change in every
        // turn, which the fixes read as time (family car 7, 25 Hz wheels,
        // 0.18 s true: 0.162 ± 0.003 s, −6σ; with the trapezoid 0.179 s).
        // (The calibration and the smoothing above are done with `shifted`;
        // only its fixes are read below.)
        shifted.vehicle.noise.yaw_integration = crate::vehicle::YawIntegration::Trapezoidal;
        let reference = states_at_fixes(
            &shifted,
            &params,
            &FilterOptions {
                record_epochs: true,
                init: Init::Given {
                    t_s: s0.t_s,
                    x: s0.x,
                    p: s0.p,
                },
                sensors: SensorSet::dead_reckoning(),
                ..copts.filter.clone()
            },
        )?;
        let Some((delta, std, n)) = regress_gnss(&shifted.gnss, &reference, lever, o.gnss_window_s)
        else {
            return Ok((
                Delay::not_estimated(
                    "too few fixes inside the smoothed track, or no velocity change",
                ),
                None,
            ));
        };
        // The step under-corrects by the part of the error the smoother
        // absorbed: δ(d) ≈ (1 − α)(d* − d). Secant steps on δ(d) = 0
        // converge in a few passes; the standard error of d* is that of δ
        // divided by the slope (1 − α).
        let slope = match prev {
            Some((dp, fp)) if (d - dp).abs() > 1e-9 => {
                let s = (delta - fp) / (d - dp);
                (s < -0.05 && s > -2.0).then_some(s)
            }
            _ => None,
        };
        prev = Some((d, delta));
        let (next, scale) = match slope {
            Some(s) => (d - delta / s, -1.0 / s),
            None => (d + delta, 1.0),
        };
        last = Some((std * scale, n, params));
        if delta.abs() < 1e-4 {
            break;
        }
        d = next;
        if d.abs() > o.max_delay_s {
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

/// The car filter run over `drive` with `opts`, its states interpolated at
/// the GNSS fixes' times inside its span as [`Reference::state_at`] would
/// interpolate the recorded epochs (linear between the epochs around each
/// fix; the last epoch's state at its own time), as the reference of the
/// fixes' times only: the epochs stream past, none is kept.
pub fn states_at_fixes(
    drive: &Drive,
    params: &Params,
    opts: &FilterOptions,
) -> Result<Reference, Error> {
    let mut f = ekf::car_filter(drive, params, opts)?;
    let (mut feeder, events) = ekf::feed(drive, opts, f.time_s());
    let fixes = &drive.gnss;
    let (mut t_out, mut x_out) = (Vec::new(), Vec::new());
    // The next fix not yet placed, and the previous epoch.
    let mut next = 0;
    let mut prev: Option<(f64, crate::model::State)> = None;
    let mut epoch = |f: &mut crate::filter::Filter<crate::filter::CarLayout, 5>,
                     e: ekf::EpochOut<'_, 5>| {
        if e.prediction.is_none() {
            return;
        }
        let (t1, x1) = (f.time_s(), *f.state());
        match prev {
            // Fixes before the first epoch are outside the span.
            None => {
                while next < fixes.len() && fixes[next].t_s < t1 {
                    next += 1;
                }
            }
            // Fixes in [t0, t1): between the two epochs.
            Some((t0, x0)) => {
                while next < fixes.len() && fixes[next].t_s < t1 {
                    let t = fixes[next].t_s;
                    let a = if t1 > t0 { (t - t0) / (t1 - t0) } else { 0.0 };
                    t_out.push(t);
                    x_out.push(x0 * (1.0 - a) + x1 * a);
                    next += 1;
                }
            }
        }
        prev = Some((t1, x1));
    };
    let end = opts.end_s.unwrap_or(f64::INFINITY);
    for ev in events.take_while(|e| e.t_s <= end) {
        feeder.push(&mut f, ev, &mut epoch)?;
    }
    feeder.finish(&mut f, &mut epoch)?;
    // A fix at the last epoch's time takes its state.
    if let Some((t1, x1)) = prev {
        if next < fixes.len() && fixes[next].t_s == t1 {
            t_out.push(t1);
            x_out.push(x1);
        }
    }
    Ok(Reference::from_states(t_out, x_out))
}

/// One regression step of the GNSS delay: the fixes' residuals against the
/// antenna's position on `reference` at the fixes' times, regressed on the
/// antenna's velocity with an east and north bias and a small rotation about
/// the window's centre per `window_s` window (`r = −δ·V + b + θ·J(p − p_c) + λ(p − p_c)`:
/// the heading and scale drift of a dead-reckoned reference). Returns `(δ, std, fixes)`: `δ` is how much later the
/// fixes still are than `reference`. `None` with fewer than 10 fixes per
/// window on average or a velocity that does not vary.
pub fn regress_gnss(
    fixes: &[crate::drive::GnssFix],
    reference: &Reference,
    lever_m: f64,
    window_s: f64,
) -> Option<(f64, f64, usize)> {
    // (window, residual, antenna velocity, antenna position)
    type Row = (i64, [f64; 2], [f64; 2], [f64; 2]);
    let mut rows: Vec<Row> = Vec::new();
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
        rows.push((w, [g.east_m - ant[0], g.north_m - ant[1]], va, ant));
    }
    let n = rows.len();
    let windows = rows.last().map_or(0, |r| r.0 + 1) as usize;
    if n < 10 * windows.max(1) || n < 10 {
        return None;
    }
    // Partial out each window's east and north bias and small rotation
    // about its centre (the reference's drift) from the residuals and the
    // velocities.
    let mut centred: Vec<([f64; 2], [f64; 2])> = Vec::with_capacity(n);
    // Per window: Σ v·v and Σ v·r, for the jackknife.
    let mut per_window: Vec<(f64, f64)> = Vec::new();
    let mut i = 0;
    while i < n {
        let w = rows[i].0;
        let j = i + rows[i..].iter().take_while(|r| r.0 == w).count();
        let m = (j - i) as f64;
        let pc = [0, 1].map(|k| rows[i..j].iter().map(|r| r.3[k]).sum::<f64>() / m);
        // Nuisance columns besides the biases: a rotation J·(p − p_c) and a
        // stretch (p − p_c) about the window's centre (the reference's
        // heading and scale drift), made orthogonal to each other.
        let mut cols: Vec<Vec<[f64; 2]>> = vec![
            rows[i..j]
                .iter()
                .map(|r| [-(r.3[1] - pc[1]), r.3[0] - pc[0]])
                .collect(),
            rows[i..j]
                .iter()
                .map(|r| [r.3[0] - pc[0], r.3[1] - pc[1]])
                .collect(),
        ];
        let centre = |v: &mut Vec<[f64; 2]>| {
            let m = [0, 1].map(|k| v.iter().map(|a| a[k]).sum::<f64>() / v.len() as f64);
            for a in v.iter_mut() {
                a[0] -= m[0];
                a[1] -= m[1];
            }
        };
        let dot = |a: &[[f64; 2]], b: &[[f64; 2]]| -> f64 {
            a.iter()
                .zip(b)
                .map(|(p, q)| p[0] * q[0] + p[1] * q[1])
                .sum()
        };
        let remove = |v: &mut Vec<[f64; 2]>, q: &[[f64; 2]]| {
            let qq = dot(q, q);
            if qq > 1e-9 {
                let c = dot(v, q) / qq;
                for (a, b) in v.iter_mut().zip(q) {
                    a[0] -= c * b[0];
                    a[1] -= c * b[1];
                }
            }
        };
        for c in cols.iter_mut() {
            centre(c);
        }
        let first = cols[0].clone();
        remove(&mut cols[1], &first);
        let mut rr: Vec<[f64; 2]> = rows[i..j].iter().map(|r| r.1).collect();
        let mut vv: Vec<[f64; 2]> = rows[i..j].iter().map(|r| r.2).collect();
        for v in [&mut rr, &mut vv] {
            centre(v);
            for c in &cols {
                remove(v, c);
            }
        }
        let (mut wvv, mut wvr) = (0.0, 0.0);
        for (r, v) in rr.iter().zip(&vv) {
            wvv += v[0] * v[0] + v[1] * v[1];
            wvr += v[0] * r[0] + v[1] * r[1];
        }
        per_window.push((wvv, wvr));
        centred.extend(rr.into_iter().zip(vv));
        i = j;
    }
    let svv: f64 = centred.iter().map(|(_, v)| v[0] * v[0] + v[1] * v[1]).sum();
    let svr: f64 = centred.iter().map(|(r, v)| v[0] * r[0] + v[1] * r[1]).sum();
    if svv.is_nan() || svv <= 0.0 {
        return None;
    }
    let delta = -svr / svv;
    let res: Vec<[f64; 2]> = centred
        .iter()
        .map(|(r, v)| [0, 1].map(|k| r[k] + delta * v[k]))
        .collect();
    let dof = (2 * n) as f64 - (4 * windows.max(1)) as f64 - 1.0;
    let s2 = res.iter().map(|p| p[0] * p[0] + p[1] * p[1]).sum::<f64>() / dof.max(1.0);
    let rho = 0.5
        * (lag1(&res.iter().map(|p| p[0]).collect::<Vec<_>>())
            + lag1(&res.iter().map(|p| p[1]).collect::<Vec<_>>()));
    let gn_std = (s2 / svv * (1.0 + rho) / (1.0 - rho)).sqrt();
    // Delete-a-window jackknife: the residuals' correlation over a window
    // and from one window to the next (a wandering fix error, the reference's
    // drift) that the Gauss–Newton error does not see. On eight family cars
    // with 0.2 s of latency the errors in Gauss–Newton units had an RMS of
    // 1.8.
    let w = per_window.len();
    let jack_std = if w >= 5 {
        let d: Vec<f64> = per_window
            .iter()
            .filter(|(wvv, _)| svv - wvv > 0.0)
            .map(|(wvv, wvr)| -(svr - wvr) / (svv - wvv))
            .collect();
        jackknife_std(&d)
    } else {
        0.0
    };
    Some((delta, gn_std.max(jack_std), n))
}

/// Every stream's delay: the scalar streams on `drive` as given, then the
/// GNSS on the drive with the scalar delays applied.
pub fn estimate(
    drive: &Drive,
    copts: &CalibrationOptions,
    o: &DelayOptions,
) -> Result<Delays, Error> {
    estimate_with_params(drive, copts, o).map(|(d, _)| d)
}

/// [`estimate`], also returning the calibration at the final GNSS delay
/// (with the scalar delays applied), when the GNSS delay was estimated.
pub fn estimate_with_params(
    drive: &Drive,
    copts: &CalibrationOptions,
    o: &DelayOptions,
) -> Result<(Delays, Option<Params>), Error> {
    let mut delays = Delays {
        gyro: gyro_delay(drive, o),
        speed: speed_delay(drive, o),
        steering: steering_delay(drive, o),
        gnss: Delay::not_estimated("not estimated"),
    };
    let partly = delays.apply(drive);
    let (g, params) = gnss_delay_of(partly, copts, o)?;
    delays.gnss = g;
    Ok((delays, params))
}

/// Which corrections [`crate::held_back::prepare`] estimates and applies.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Which {
    /// Every correction estimated; each applied only when it lowers the
    /// dead-reckoning error through GNSS the calibration did not see
    /// ([`crate::held_back`]): the commands' default.
    #[default]
    Auto,
    /// The driven axle's slip, the IMU tilt, every stream's delay and the
    /// gyro scale.
    All,
    /// The driven axle's slip, the IMU tilt, the GNSS delay and the gyro
    /// scale (the other streams' delays estimated and reported, not
    /// applied).
    Gnss,
    /// Nothing estimated or applied.
    None,
}

impl Which {
    /// The word the command line takes: `auto`, `all`, `gnss`, `none`.
    pub fn name(self) -> &'static str {
        match self {
            Which::Auto => "auto",
            Which::All => "all",
            Which::Gnss => "gnss",
            Which::None => "none",
        }
    }
}

/// What [`prepare`] found and applied.
#[derive(Debug, Clone, PartialEq)]
pub struct Corrections {
    /// The driven axle's slip (`None`: no accelerometer in the drive, or
    /// not attempted).
    pub traction: Option<crate::traction::TractionSlip>,
    /// The IMU's tilt (`None`: no three-axis IMU in the drive).
    pub tilt: Option<crate::imu::Tilt>,
    /// The streams' delays.
    pub delays: Delays,
    /// The gyro's scale error (`None` when not attempted: no GNSS delay, so
    /// no calibration to take the bias from).
    pub gyro_scale: Option<crate::gyro_scale::GyroScale>,
    /// With [`Which::Auto`]: what the held-back GNSS said of each
    /// correction ([`crate::held_back`]).
    pub held_back: Option<crate::held_back::HeldBack>,
    /// With [`Which::Auto`]: the additions to the paper's model the
    /// held-back GNSS chose ([`crate::model_options`]; empty otherwise).
    pub model: crate::model_options::ModelOptions,
}

impl Corrections {
    /// Nothing estimated or applied: what [`prepare_with`] returns with
    /// [`Which::None`] (the drive then unchanged).
    pub fn none() -> Corrections {
        Corrections {
            traction: None,
            tilt: None,
            delays: Delays::none(),
            gyro_scale: None,
            held_back: None,
            model: Default::default(),
        }
    }
}

/// Estimates the driven axle's slip ([`crate::traction`], correcting its
/// wheel speeds when estimated), the IMU tilt (projecting the gyro on the
/// vertical when estimated), every stream's delay and the gyro scale error
/// ([`crate::gyro_scale`], with the bias of a calibration at the final
/// delays), and returns the drive with them applied.
pub fn prepare(
    drive: &Drive,
    copts: &CalibrationOptions,
    o: &DelayOptions,
) -> Result<(Drive, Corrections), Error> {
    prepare_with(drive, copts, o, Which::All)
}

/// [`prepare`] with a choice of what is applied (see [`Which`]); an
/// unapplied delay is marked not estimated with the reason.
/// [`Which::Auto`] is decided by [`crate::held_back::prepare`], which calls
/// this with [`Which::All`]; asked here, it is refused.
pub fn prepare_with(
    drive: &Drive,
    copts: &CalibrationOptions,
    o: &DelayOptions,
    which: Which,
) -> Result<(Drive, Corrections), Error> {
    if which == Which::None {
        return Ok((drive.clone(), Corrections::none()));
    }
    if which == Which::Auto {
        return Err(Error::InvalidParams(
            "the automatic choice of corrections is made by held_back::prepare".into(),
        ));
    }
    // The driven axle's slip first: the wheels are the clock and the scale
    // every other correction is measured against.
    let traction = crate::traction::estimate(drive);
    let slipped;
    let drive = match &traction {
        Some(t) if t.is_estimated() => {
            slipped = crate::traction::apply(drive, t.slip_per_mps2);
            &slipped
        }
        _ => drive,
    };
    let (levelled, tilt) = crate::imu::level(drive);
    let (mut delays, params) = estimate_with_params(&levelled, copts, o)?;
    if which == Which::Gnss {
        for d in [&mut delays.gyro, &mut delays.speed, &mut delays.steering] {
            if d.status.is_estimated() {
                // The measured delay and its std stay in `d` for the reports.
                d.status = Status::NotEstimated(MEASURED_NOT_APPLIED.to_string());
            }
        }
    }
    // The levelled drive becomes the output (moved, not copied).
    let mut out = levelled;
    delays.apply_in_place(&mut out);
    // The bias of the calibration at the final GNSS delay (a time shift of
    // the gyro does not change its bias), else of a calibration here.
    let params = match params {
        Some(p) => Some(p),
        None => calibrate::calibrate_parameters(&out, copts)
            .ok()
            .map(|c| c.estimate.params),
    };
    let gyro_scale = params.map(|p| crate::gyro_scale::estimate(&out, p.gyro_bias_rps));
    if let Some(g) = gyro_scale.as_ref().filter(|g| g.is_estimated()) {
        crate::gyro_scale::apply_in_place(&mut out, g.scale_error);
    }
    Ok((
        out,
        Corrections {
            traction,
            tilt,
            delays,
            gyro_scale,
            held_back: None,
            model: Default::default(),
        },
    ))
}

/// Applies known corrections (e.g. from a params.toml): the yaw rate
/// projected on `up` (sensor axes) when given and the drive has a three-axis
/// gyro, then the delays, s, in [`Stream::ALL`] order, then the gyro scale
/// error.
pub fn apply_known(
    drive: &Drive,
    delays_s: [f64; 4],
    up: Option<[f64; 3]>,
    gyro_scale_error: f64,
) -> Drive {
    let d = match up {
        Some(u) => crate::imu::level_with(drive, u),
        None => drive.clone(),
    };
    let d = shift(&d, delays_s);
    if gyro_scale_error != 0.0 {
        crate::gyro_scale::apply(&d, gyro_scale_error)
    } else {
        d
    }
}

/// Corrections known beforehand and applied as they are: those a
/// params.toml stores (`[delays]`, `[traction]`, `[imu]`, `[gyro_scale]`), or those a
/// TedriS model was trained with.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct KnownCorrections {
    /// Delays, s, in [`Stream::ALL`] order (0: none).
    pub delays_s: [f64; 4],
    /// The IMU's vertical in its own axes (`None`: the gyro as it is).
    pub up: Option<[f64; 3]>,
    /// The gyro's relative scale error (0: none).
    pub gyro_scale_error: f64,
    /// The driven axle's slip per m/s² of forward specific force
    /// ([`crate::traction`]; 0: none; the sign names the axle). Absent from
    /// models and files written before it: 0.
    #[serde(default)]
    pub traction_slip_per_mps2: f64,
    /// The mean forward specific force, m/s², of the drive the slip was
    /// estimated on ([`crate::traction::TractionSlip::mean_force_mps2`]),
    /// the level the wheel speeds are corrected to. `None` (files written
    /// before it): each drive's own mean, which a live stream cannot know
    /// ([`crate::live_corrections`] then leaves the slip out).
    #[serde(default)]
    pub traction_mean_force_mps2: Option<f64>,
    /// Additions to the paper's model set on the vehicle
    /// ([`crate::model_options`]; empty: the vehicle's own). Absent from
    /// models and files written before them: none.
    #[serde(default)]
    pub model: crate::model_options::ModelOptions,
}

impl KnownCorrections {
    /// Applies them to `drive`: the slip first ([`crate::traction::apply`]),
    /// then [`apply_known`], in [`prepare_with`]'s order.
    pub fn apply(&self, drive: &Drive) -> Drive {
        let slipped;
        let drive = if self.traction_slip_per_mps2 != 0.0 {
            slipped = crate::traction::apply_at(
                drive,
                self.traction_slip_per_mps2,
                self.traction_mean_force_mps2,
            );
            &slipped
        } else {
            drive
        };
        let mut out = apply_known(drive, self.delays_s, self.up, self.gyro_scale_error);
        self.model.apply_to(&mut out.vehicle);
        out
    }

    /// Whether there is nothing to apply.
    pub fn is_empty(&self) -> bool {
        *self == KnownCorrections::default()
    }

    /// Checks the values are plausible: delays finite and under 10 s, `up`
    /// a unit vector, the scale error within
    /// [`crate::gyro_scale::MAX_SCALE_ERROR`]. The error names the key.
    pub fn validate(&self) -> Result<(), String> {
        for (s, v) in Stream::ALL.iter().zip(self.delays_s) {
            if !(v.is_finite() && v.abs() < 10.0) {
                return Err(format!(
                    "`delays.{}.delay_s` = {v} is not a plausible delay (|d| < 10 s)",
                    s.name()
                ));
            }
        }
        if let Some(u) = self.up {
            let n = u.iter().map(|x| x * x).sum::<f64>().sqrt();
            if (n - 1.0).abs().is_nan() || (n - 1.0).abs() >= 1e-3 {
                return Err("`imu.up` must be a unit vector of 3 numbers".into());
            }
        }
        let g = self.gyro_scale_error;
        if !(g.is_finite() && g.abs() <= crate::gyro_scale::MAX_SCALE_ERROR) {
            return Err(format!(
                "`gyro_scale.scale_error` = {g} is not a plausible gyro scale error"
            ));
        }
        let k = self.traction_slip_per_mps2;
        if !(k.is_finite() && k.abs() <= crate::traction::MAX_SLIP_PER_MPS2) {
            return Err(format!(
                "`traction.slip_per_mps2` = {k} is not a plausible tyre slip (|κ| ≤ {} per m/s²)",
                crate::traction::MAX_SLIP_PER_MPS2
            ));
        }
        self.model.validate()?;
        if let Some(m) = self.traction_mean_force_mps2 {
            if !(m.is_finite() && m.abs() < 100.0) {
                return Err(format!(
                    "`traction.mean_force_mps2` = {m} is not a plausible mean forward specific force (|f| < 100 m/s²)"
                ));
            }
        }
        Ok(())
    }
}
