//! The interval a wheel-tick count covers, from stamps that may jitter.
//!
//! A tick counter is read by its ECU on the ECU's cycle, and the row is
//! stamped later by whatever logs it (a bus, a driver, an operating system),
//! with some jitter. The count then covers the counter's own interval `T_k`,
//! while the stamps give `Δ_k = T_k + e_k − e_{k−1}` (`e` the white stamp
//! jitter). The filter predicts a count as `N/ρ · g · interval`
//! ([`crate::observation::Sensors::wheel_ticks`]); with `interval = Δ_k` the
//! regressor carries the jitter, and a Kalman update, like a least-squares
//! fit, attenuates towards zero by `2σ_e²/(σ_T² + 2σ_e²)` (errors in
//! variables): every speed read from the ticks comes out that much short.
//! At 2.8 ms of interval jitter on a 20 ms cycle that is 2 %.
//!
//! The remedy is regression calibration: use the interval's conditional
//! expectation given the stamps, whose error is uncorrelated with it (the
//! orthogonality of a linear projection), so no attenuation is left. The
//! intervals' own statistics tell the two parts apart: white stamp jitter
//! makes consecutive intervals anti-correlated, `cov(Δ_k, Δ_{k−1}) = −σ_e²`,
//! while independent counting intervals are not, so
//! `σ_e² = −c₁` and `σ_T² = c₀ − 2σ_e²` (`c₀`, `c₁` the intervals' variance
//! and lag-1 covariance). The projection of `T_k` on `Δ_k` is then
//! `T̂ + λ·(Δ_k − T̂)` with `λ = σ_T²/c₀`: the mean cycle for a regular
//! counter with jittery stamps (λ = 0), the stamps as they are for a counter
//! read at irregular times on an exact clock (λ = 1), between the two
//! otherwise. A stamp gap of `m` cycles (rows lost) counts over `m·T̂`.
//!
//! The statistics are running sums over the single-cycle intervals seen so
//! far (causal, the same in a stream as in a batch run, and saved with the
//! feeder's state); until [`MIN_INTERVALS`] have been seen, the stamps'
//! interval is used as it is.
//!
//! The least-squares calibration needs no such estimate: it sums ticks over
//! blocks of rows, where the stamps telescope
//! ([`crate::calibrate::TICK_BLOCK_S`]).

use serde::{Deserialize, Serialize};

/// The statistics are used once this many single-cycle intervals (and
/// consecutive pairs of them) have been seen: the lag-1 covariance's
/// relative standard error is then about `1/√n` ≈ 6 %. Not tuned.
pub const MIN_INTERVALS: u64 = 256;

/// An interval is a single cycle when within this fraction of the mean
/// cycle; beyond, it is `round(Δ/T̂)` cycles (rows lost). Intervals left
/// out by jitter are as many long as short (the trimming is symmetric about
/// the cycle), so the mean is not biased. Not tuned: half a cycle is where
/// one cycle ends and two begin.
const SINGLE_CYCLE_TOLERANCE: f64 = 0.5;

/// Running statistics of a wheel stream's stamp intervals, and the counting
/// interval they give (see the module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct CountingInterval {
    /// The first interval, the origin of the sums (keeps them small).
    origin_s: Option<f64>,
    /// Single-cycle intervals seen, and Σd, Σd² of `d = Δ − origin`.
    n: u64,
    sum: f64,
    sum2: f64,
    /// Consecutive single-cycle pairs seen, and Σd_k·d_{k−1}, Σd_k, Σd_{k−1}
    /// over them.
    pairs: u64,
    sum_lag: f64,
    sum_cur: f64,
    sum_prev: f64,
    /// The previous interval's `d`, when it was a single cycle.
    prev: Option<f64>,
}

/// What the statistics say so far.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IntervalModel {
    /// The mean single-cycle interval `T̂`, s.
    pub cycle_s: f64,
    /// The stamps' white jitter, as its share of an interval's variance
    /// `2σ_e²` is, s (standard deviation of one stamp).
    pub stamp_jitter_s: f64,
    /// The weight of the stamps' interval in the estimate, λ ∈ [0, 1].
    pub lambda: f64,
}

impl CountingInterval {
    /// The model, once [`MIN_INTERVALS`] single cycles have been seen.
    pub fn model(&self) -> Option<IntervalModel> {
        if self.n < MIN_INTERVALS || self.pairs < MIN_INTERVALS {
            return None;
        }
        let origin = self.origin_s?;
        let n = self.n as f64;
        let mean = self.sum / n;
        let c0 = (self.sum2 / n - mean * mean).max(0.0);
        let p = self.pairs as f64;
        let c1 = self.sum_lag / p - (self.sum_cur / p) * (self.sum_prev / p);
        let (var_e, lambda) = if c0 > 0.0 {
            let var_e = (-c1).clamp(0.0, 0.5 * c0);
            (var_e, ((c0 - 2.0 * var_e) / c0).clamp(0.0, 1.0))
        } else {
            (0.0, 1.0)
        };
        Some(IntervalModel {
            cycle_s: origin + mean,
            stamp_jitter_s: var_e.sqrt(),
            lambda,
        })
    }

    /// Takes the stamps' interval `delta_s` (not a gap) and returns the
    /// interval the count covers, by the statistics before this interval.
    pub fn push(&mut self, delta_s: f64) -> f64 {
        let model = self.model();
        let origin = *self.origin_s.get_or_insert(delta_s);
        // Whether a single cycle: against the model's cycle once there is one,
        // the mean so far before (the first interval opens the count).
        let cycle = match model {
            Some(m) => m.cycle_s,
            None if self.n > 0 => origin + self.sum / self.n as f64,
            None => delta_s,
        };
        let single = cycle > 0.0 && (delta_s / cycle - 1.0).abs() < SINGLE_CYCLE_TOLERANCE;
        if single {
            let d = delta_s - origin;
            self.n += 1;
            self.sum += d;
            self.sum2 += d * d;
            if let Some(p) = self.prev {
                self.pairs += 1;
                self.sum_lag += d * p;
                self.sum_cur += d;
                self.sum_prev += p;
            }
            self.prev = Some(d);
        } else {
            self.prev = None;
        }
        let Some(m) = model else {
            return delta_s;
        };
        let cycles = (delta_s / m.cycle_s).round().max(1.0);
        let expected = cycles * m.cycle_s;
        expected + m.lambda * (delta_s - expected)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};
    use rand_pcg::Pcg64 as Rng64;

    fn gauss(r: &mut Rng64) -> f64 {
        StandardNormal.sample(r)
    }

    /// A regular 20 ms counter stamped with 2 ms of white jitter: the model
    /// finds the cycle and the jitter, and gives the cycle (λ ≈ 0).
    #[test]
    fn a_regular_counter_with_jittered_stamps_counts_over_its_cycle() {
        let mut r = Rng64::seed_from_u64(7);
        let mut c = CountingInterval::default();
        let mut prev = 0.0;
        let mut last = 0.0;
        for k in 1..5000 {
            let s = k as f64 * 0.02 + 0.002 * gauss(&mut r);
            last = c.push(s - prev);
            prev = s;
        }
        let m = c.model().unwrap();
        // The single-cycle intervals' mean no longer telescopes where an interval
        // was left out (two here, of 11 ms): measured 2.5 µs off, 1.2e-4 of
        // the cycle; the trimming is symmetric, so not biased.
        assert!((m.cycle_s - 0.02).abs() < 4e-6, "{m:?}");
        assert!((m.stamp_jitter_s - 0.002).abs() < 1e-4, "{m:?}");
        assert!(m.lambda < 0.05, "{m:?}");
        assert!((last - 0.02).abs() < 3e-4, "{last}");
    }

    /// A counter read at irregular times on an exact clock: the stamps are
    /// the intervals (λ ≈ 1).
    #[test]
    fn irregular_reads_on_an_exact_clock_keep_their_stamps() {
        let mut r = Rng64::seed_from_u64(8);
        let mut c = CountingInterval::default();
        let (mut moved, mut n) = (0.0, 0.0);
        for k in 0..5000 {
            let delta = 0.1 + 0.02 * gauss(&mut r).clamp(-2.0, 2.0);
            let used = c.push(delta);
            if k > 1000 {
                moved += (used - delta).abs();
                n += 1.0;
            }
        }
        let m = c.model().unwrap();
        // Measured: λ 0.97..1, a mean move of 0.5 ms of the 16 ms spread.
        assert!(m.lambda > 0.95, "{m:?}");
        assert!(m.stamp_jitter_s < 0.004, "{m:?}");
        assert!(moved / n < 0.001, "{}", moved / n);
    }

    /// A lost row: the interval is two cycles.
    #[test]
    fn a_lost_row_counts_over_two_cycles() {
        let mut c = CountingInterval::default();
        let mut r = Rng64::seed_from_u64(9);
        let mut prev = 0.0;
        for k in 1..1000 {
            let s = k as f64 * 0.01 + 0.0005 * gauss(&mut r);
            c.push(s - prev);
            prev = s;
        }
        let two = c.push(10.0103 - prev);
        assert!((two - 0.02).abs() < 1e-4, "{two}");
    }

    /// Before the statistics are ready, the stamps' interval as it is.
    #[test]
    fn the_first_intervals_are_the_stamps() {
        let mut c = CountingInterval::default();
        assert_eq!(c.push(0.021), 0.021);
        assert_eq!(c.push(0.019), 0.019);
        assert!(c.model().is_none());
    }
}
