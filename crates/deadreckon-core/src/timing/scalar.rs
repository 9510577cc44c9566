//! The scalar streams' delays (gyro, CAN speed, steering) against signals
//! derived from the wheels: [`scalar_delay`] and its callers.

use super::{
    jackknife_std, lag1, Delay, DelayOptions, Status, JACKKNIFE_BLOCKS, MIN_CURVATURE_SPEED_MPS,
};
use crate::drive::{Drive, Scalar};
use crate::imu::wheel_speed;
use crate::series::interp;

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

/// A sample of a series: its time, s, and its value. A pair `(t, value)`,
/// or a drive's [`Scalar`] read in place (the gyro's, CAN speed's and
/// steering's delays read their stream without a copy: 16 B a sample, 5.8
/// MB of the steering's on the bench's hour, at the default `calibrate`'s
/// peak until the ninth round of docs/performance.md).
pub trait TimedSample: Copy {
    /// The time, s.
    fn t(&self) -> f64;
    /// The value.
    fn value(&self) -> f64;
}

impl TimedSample for (f64, f64) {
    fn t(&self) -> f64 {
        self.0
    }
    fn value(&self) -> f64 {
        self.1
    }
}

impl TimedSample for Scalar {
    fn t(&self) -> f64 {
        self.t_s
    }
    fn value(&self) -> f64 {
        self.value
    }
}

/// Exact first and second integrals of a linearly interpolated series.
struct Integral<'a, S> {
    s: &'a [S],
    cum: Vec<f64>,
    cum2: Vec<f64>,
}

impl<'a, S: TimedSample> Integral<'a, S> {
    fn new(s: &'a [S]) -> Self {
        let mut cum = Vec::with_capacity(s.len());
        let mut cum2 = Vec::with_capacity(s.len());
        let (mut c1, mut c2) = (0.0, 0.0);
        cum.push(0.0);
        cum2.push(0.0);
        for w in s.windows(2) {
            let ((t0, v0), (t1, v1)) = ((w[0].t(), w[0].value()), (w[1].t(), w[1].value()));
            let h = t1 - t0;
            let m = if h > 0.0 { (v1 - v0) / h } else { 0.0 };
            c2 += c1 * h + v0 * h * h / 2.0 + m * h * h * h / 6.0;
            c1 += 0.5 * (v0 + v1) * h;
            cum.push(c1);
            cum2.push(c2);
        }
        Integral { s, cum, cum2 }
    }
    /// First and second integral up to `t`; the segment is searched from
    /// `cursor` (the last call's), which is left at this one's.
    fn at(&self, t: f64, cursor: &mut usize) -> Option<(f64, f64)> {
        let n = self.s.len();
        if n < 2 || !(t >= self.s[0].t() && t <= self.s[n - 1].t()) {
            return None;
        }
        *cursor = crate::cursor::partition_from(n, |i| self.s[i].t(), t, *cursor);
        let i = (*cursor).clamp(1, n - 1);
        let (a, b) = (
            (self.s[i - 1].t(), self.s[i - 1].value()),
            (self.s[i].t(), self.s[i].value()),
        );
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
pub fn scalar_delay<R: TimedSample, S: TimedSample>(
    reference: &[R],
    signal: &[S],
    keep: &dyn Fn(f64) -> bool,
    o: &DelayOptions,
) -> Delay {
    if reference.len() < 3 || signal.len() < 3 {
        return Delay::not_estimated("too few samples");
    }
    if signal.iter().any(|s| !s.value().is_finite())
        || reference.iter().any(|s| !s.value().is_finite())
    {
        return Delay::not_estimated("non-finite samples");
    }
    let (r0, r1) = (reference[0].t(), reference[reference.len() - 1].t());
    let (s0, s1) = (signal[0].t(), signal[signal.len() - 1].t());
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

pub(super) fn status_of(d: f64, std: f64, n: usize, o: &DelayOptions) -> Delay {
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
        step_offset_s: 0.0,
    }
}

/// The rear wheels' yaw rate, `(t, rad/s)`, or `None` without both rear wheels.
fn wheel_yaw_rate(drive: &Drive) -> Option<Vec<(f64, f64)>> {
    let w = drive.vehicle.wheels_present;
    if !(w[2] && w[3]) {
        return None;
    }
    let track = drive.vehicle.track_rear_m;
    // From the rows borrowed, not consumed: a collect in place would keep
    // the rows' allocation (40 B a row) under the 16 B ones (issue 30).
    Some(
        crate::plausibility::wheel_rows(drive)
            .iter()
            .map(|&(t, v)| (t, (v[3] - v[2]) / track))
            .collect(),
    )
}

/// The gyro's delay behind the rear wheels' yaw rate.
pub fn gyro_delay(drive: &Drive, o: &DelayOptions) -> Delay {
    if drive.yaw_rate.is_empty() {
        return Delay::not_estimated("no gyro");
    }
    let Some(reference) = wheel_yaw_rate(drive) else {
        return Delay::not_estimated("needs both rear wheels");
    };
    scalar_delay(&reference, &drive.yaw_rate, &|_| true, o)
}

/// The CAN speed's delay behind the wheels' mean speed.
pub fn speed_delay(drive: &Drive, o: &DelayOptions) -> Delay {
    if drive.speed.is_empty() {
        return Delay::not_estimated("no CAN speed");
    }
    scalar_delay(&wheel_speed(drive), &drive.speed, &|_| true, o)
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
    // At most a row each, reserved once (a collect of the filter doubled
    // its way up, to 4.2 MB for 2.9 MB on the bench's hour).
    let mut curvature: Vec<(f64, f64)> = Vec::with_capacity(w.len());
    curvature.extend(w.iter().filter_map(|&(t, wz)| {
        let s = interp(&v, t)?;
        // The wheel angle of that curvature, in steering-wheel units
        // with the nominal ratio (the fit absorbs a ratio error).
        (s > MIN_CURVATURE_SPEED_MPS).then(|| (t, ratio * (wheelbase * wz / s).atan()))
    }));
    drop(w);
    let keep = |t: f64| interp(&v, t).is_some_and(|s| s > MIN_CURVATURE_SPEED_MPS + 0.5);
    scalar_delay(&curvature, &drive.steering, &keep, o)
}
