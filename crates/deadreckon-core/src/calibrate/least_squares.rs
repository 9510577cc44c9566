//! The least squares of the parameters against the smoothed states (eq. 26):
//! streamed over the epochs ([`least_squares`]), tick rows summed over
//! [`TICK_BLOCK_S`], with the standard errors' lag-1 and batch-means
//! inflation.

use crate::drive::{Drive, Wheels};
use crate::model::{V, YAW_RATE};
use crate::observation::Sensors;
use crate::reference::Reference;
use crate::vehicle::{Params, ParamsWithStd};
use crate::Error;

/// A one-dimensional least-squares fit `z ≈ θ·r` with the residuals' lag-1
/// autocorrelation folded into its standard error.
#[derive(Debug, Clone, Copy)]
struct Fit1d {
    theta: f64,
    /// Σ r².
    srr: f64,
    /// Residual variance Σe²/(n−1).
    s2: f64,
    /// The factor on the independent-sample standard error: the larger of
    /// the effective-sample-size inflation sqrt(n / n_eff) =
    /// sqrt((1+ρ)/(1−ρ)), ρ the residuals' lag-1 autocorrelation clamped to
    /// [0, 0.99], and the batch means' (`BATCHES`).
    inflation: f64,
    n: usize,
}

/// Batches of consecutive samples (in sample order) whose sums give the
/// batch-means standard error of a fit ([`fit_streamed`]): 20, each 30 s
/// of a 600 s drive.
///
/// The residuals `gyro − ψ̇` against the smoothed states are correlated
/// over seconds, not one sample: the smoothed yaw rate wanders with the
/// fixes. The lag-1 inflation alone read the gyro bias's standard error
/// about 1.65× too small (issue 36: RMS z 1.65 on family cars 65–88 with
/// the passes at table I's yaw noise, 2.45 on cars 89–112). Batch means
/// (the variance of the sum of the residuals' contributions `e·r` over
/// runs of consecutive samples, which holds whatever the correlation
/// within a run) take the correlation up to a batch's length; over longer
/// lags the smoother's yaw-rate errors anticorrelate (their integral is
/// the heading, which the fixes hold), so the batch means err wide. The
/// standard error is the larger of the two. Measured
/// (`calibration_noise_family.rs`, passes at table I's 1e-5): gyro bias
/// RMS z 0.44 and 24/24 within 3σ on cars 65–88 (the choice: 20, 60 and
/// 200 batches read 0.44, 0.48, 0.57), 0.67 and 24/24 on cars 89–112
/// (not used for the choice; 20/24 with the lag-1 inflation alone). The
/// speed scale and circumferences barely move: their standard errors are
/// the GNSS chords' ([`widen_for_chords`]).
const BATCHES: usize = 20;

/// Eq. (26) for `M` independent series at once without storing them: `visit`
/// calls its argument with `(series, z, r)` for every sample, in the same order
/// each time, and is called three times (θ; residual mean and variance; their
/// autocorrelation). Every sum runs in sample order, so the result is
/// bit-identical to summing stored vectors. A series with fewer than 3 samples
/// or Σr² ≤ 0 has no fit.
fn fit_streamed<const M: usize>(
    visit: impl Fn(&mut dyn FnMut(usize, f64, f64)),
) -> [Option<Fit1d>; M] {
    let mut n = [0usize; M];
    let (mut srr, mut szr) = ([0.0f64; M], [0.0f64; M]);
    visit(&mut |i, z, r| {
        n[i] += 1;
        srr[i] += r * r;
        szr[i] += z * r;
    });
    let ok: [bool; M] = std::array::from_fn(|i| n[i] >= 3 && srr[i] > 0.0);
    let theta: [f64; M] = std::array::from_fn(|i| szr[i] / srr[i]);
    let (mut se, mut se2) = ([0.0f64; M], [0.0f64; M]);
    visit(&mut |i, z, r| {
        let e = z - theta[i] * r;
        se[i] += e;
        se2[i] += e * e;
    });
    let m: [f64; M] = std::array::from_fn(|i| se[i] / n[i] as f64);
    let (mut num, mut den) = ([0.0f64; M], [0.0f64; M]);
    let mut prev: [Option<f64>; M] = [None; M];
    // Batch means: Σ e·r over BATCHES runs of consecutive samples.
    let per_batch: [usize; M] = std::array::from_fn(|i| n[i].div_ceil(BATCHES).max(1));
    let (mut seen, mut open, mut sb2) = ([0usize; M], [0.0f64; M], [0.0f64; M]);
    visit(&mut |i, z, r| {
        let d = z - theta[i] * r - m[i];
        den[i] += d * d;
        if let Some(p) = prev[i] {
            num[i] += p * d;
        }
        prev[i] = Some(d);
        open[i] += (z - theta[i] * r) * r;
        seen[i] += 1;
        if seen[i] % per_batch[i] == 0 || seen[i] == n[i] {
            sb2[i] += open[i] * open[i];
            open[i] = 0.0;
        }
    });
    std::array::from_fn(|i| {
        if !ok[i] {
            return None;
        }
        let rho = if den[i] <= 0.0 {
            0.0
        } else {
            (num[i] / den[i]).clamp(0.0, 0.99)
        };
        let lag1 = ((1.0 + rho) / (1.0 - rho)).sqrt();
        let s2 = se2[i] / (n[i] - 1) as f64;
        // Var(θ) by batch means, Σ_b (Σ_{k∈b} e_k r_k)² / (Σ r²)², with
        // the batches' small-sample correction b/(b−1); as a factor on the
        // lag-1 standard error √(s²/Σr²).
        let b = n[i].div_ceil(per_batch[i]) as f64;
        let batch_var = sb2[i] / (srr[i] * srr[i]) * b / (b - 1.0).max(1.0);
        let plain = (s2 / srr[i]).sqrt();
        let inflation = if plain > 0.0 {
            (batch_var.sqrt() / plain).max(lag1)
        } else {
            lag1
        };
        Some(Fit1d {
            theta: theta[i],
            srr: srr[i],
            s2,
            inflation,
            n: n[i],
        })
    })
}

impl Fit1d {
    /// θ, its standard error, n (eq. 26).
    fn through_origin(self) -> (f64, f64, usize) {
        (
            self.theta,
            (self.s2 / self.srr).sqrt() * self.inflation,
            self.n,
        )
    }
}

/// Tick rows are fitted over blocks of consecutive rows at least this long,
/// s: a count is over the counter's own interval, the regressor over the
/// stamps' (`t_k − t_{k−1}`), and stamp jitter in a least-squares regressor
/// shrinks the slope by `σ²_Δt/(Δt² + σ²_Δt)` (errors in variables), which
/// made every circumference (σΔt/Δt)² too long: +21 to +32 mm for 2 m tyres
/// at 1–3 ms of jitter on a 20 ms cycle (dynamic family cars 1 and 3,
/// `dynamics_ablation.rs`). Summed over a block, the stamps telescope: only
/// the block's two end stamps are jittered, (σ/1 s)² ≈ 10⁻⁵ of the slope,
/// and the ticks' ±1 quantisation is over the block too. Not tuned: the
/// length only needs to be many cycles of the slowest counter (10 Hz) and
/// short against a change of speed; blocks cut short by a gap or a slow
/// stretch are used when at least half this long.
pub const TICK_BLOCK_S: f64 = 1.0;

/// Eq. (23)–(26): the least-squares parameters from reference states (smoothed or
/// true). `mid_interval` evaluates the state at the middle of each wheel
/// counting interval (for the truth) instead of at its end (the filter's model).
///
/// Nothing per sample is stored: each series is visited three times (see
/// `fit_streamed`), so the memory of a calibration is the drive and the
/// reference.
pub fn least_squares(
    drive: &Drive,
    reference: &Reference,
    min_speed: f64,
    mid_interval: bool,
) -> Result<(ParamsWithStd, [usize; 6]), Error> {
    let v = &drive.vehicle;
    let nominal = Params::nominal(v);
    let mut est = nominal;
    let mut std = Params::from_array([0.0; 6]);
    let mut samples = [0usize; 6];

    // Gyro bias, eq. (25): mean of gyro − ψ̇ (a fit with r = 1).
    let [bias] = fit_streamed::<1>(|f| {
        for s in &drive.yaw_rate {
            if let Some(x) = reference.state_at(s.t_s) {
                f(0, s.value - x[YAW_RATE], 1.0);
            }
        }
    });
    if let Some(b) = bias {
        est.gyro_bias_rps = b.theta;
        std.gyro_bias_rps = b.s2.sqrt() / (b.n as f64).sqrt() * b.inflation;
        samples[0] = b.n;
    }

    // Speed scale, eq. (26).
    let [scale] = fit_streamed::<1>(|f| {
        for s in &drive.speed {
            if let Some(x) = reference.state_at(s.t_s).filter(|x| x[V] >= min_speed) {
                f(0, s.value, x[V]);
            }
        }
    });
    if let Some((a, sa, n)) = scale.map(Fit1d::through_origin) {
        est.speed_scale = a;
        std.speed_scale = sa;
        samples[1] = n;
    }

    // Inverse circumferences: z = (1/ρ)·r with r = N·T·g (ticks) or ρ_nom·g (speeds).
    // Ticks are fitted over blocks of consecutive rows (see `TICK_BLOCK_S`).
    let sensors = Sensors::new(v, &nominal);
    let n_wheel = drive.wheels.len();
    let rows_used = std::cell::Cell::new([0usize; 4]);
    let fits = fit_streamed::<4>(|f| {
        let mut rows = [0usize; 4];
        // The open block of tick rows: Σz, Σr per wheel, and its duration.
        let mut block = ([0.0f64; 4], [0.0f64; 4], 0.0f64);
        let flush = |f: &mut dyn FnMut(usize, f64, f64), b: &mut ([f64; 4], [f64; 4], f64)| {
            if b.2 >= 0.5 * TICK_BLOCK_S {
                for i in 0..4 {
                    f(i, b.0[i], b.1[i]);
                }
            }
            *b = ([0.0; 4], [0.0; 4], 0.0);
        };
        for k in 1..n_wheel {
            let (t0, t1) = (drive.wheels.t_s(k - 1), drive.wheels.t_s(k));
            let t_eval = if mid_interval { 0.5 * (t0 + t1) } else { t1 };
            let x = reference.state_at(t_eval).filter(|x| x[V] >= min_speed);
            match &drive.wheels {
                Wheels::Ticks(rows_t) => {
                    let interval = t1 - t0;
                    let Some(x) = x.filter(|_| interval <= 0.5) else {
                        flush(f, &mut block);
                        continue;
                    };
                    let r = rows_t[k];
                    for (i, z) in [r.fl, r.fr, r.rl, r.rr].into_iter().enumerate() {
                        let g = sensors.wheel_ground_speed(i, x[V], x[YAW_RATE]).0;
                        block.0[i] += z as f64;
                        block.1[i] += sensors.ticks_per_rev * interval * g;
                        rows[i] += 1;
                    }
                    block.2 += interval;
                    if block.2 >= TICK_BLOCK_S {
                        flush(f, &mut block);
                    }
                }
                Wheels::Speeds(rows_s) => {
                    let Some(x) = x else {
                        continue;
                    };
                    let r = rows_s[k];
                    for (i, z) in [r.fl_mps, r.fr_mps, r.rl_mps, r.rr_mps]
                        .into_iter()
                        .enumerate()
                    {
                        let g = sensors.wheel_ground_speed(i, x[V], x[YAW_RATE]).0;
                        f(i, z, sensors.nominal_circumference_m * g);
                        rows[i] += 1;
                    }
                }
            }
        }
        flush(f, &mut block);
        rows_used.set(rows);
    });
    let rows_used = rows_used.get();
    let mut circ = nominal.circumferences();
    let mut circ_std = [0.0; 4];
    for i in 0..4 {
        if !v.wheels_present[i] {
            continue;
        }
        if let Some((k, sk, n)) = fits[i].map(Fit1d::through_origin) {
            if k > 0.0 {
                circ[i] = 1.0 / k;
                circ_std[i] = sk / (k * k);
                // Rows, not blocks: what the drive gave.
                samples[2 + i] = if n > 0 { rows_used[i] } else { 0 };
            }
        }
    }
    est.set_circumferences(circ);
    std.set_circumferences(circ_std);
    Ok((ParamsWithStd { params: est, std }, samples))
}
