//! Sample cross-correlation between the wheel series ω and the reference heading
//! increments γ, and the lag at its peak.
//!
//! Convention: `ccf(h) = corr(ω_{t−h}, γ_t)`, so a positive `h` means the
//! reference heading responds `h` samples after the wheels (R's `ccf(omega, gamma)`
//! reports the same peak at lag `−h`, which is how the paper's lags −2 and −3 read).

use serde::{Deserialize, Serialize};

/// Cross-correlation of two equally long series over a lag window.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CrossCorrelation {
    /// The lags `−max_lag ..= max_lag`, in samples.
    pub lags: Vec<i64>,
    /// `corr(ω_{t−h}, γ_t)` at each lag (biased estimator, divided by n).
    pub values: Vec<f64>,
}

impl CrossCorrelation {
    /// The lag of smallest |h| whose correlation is within `rel_tol` (relative) of
    /// the largest: the peak of a smooth reference is flat, and the noise then
    /// decides between neighbouring lags; parsimony picks the shortest.
    pub fn peak_lag_within(&self, rel_tol: f64) -> i64 {
        let peak = self
            .values
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max);
        let floor = peak - rel_tol.max(0.0) * peak.abs();
        self.lags
            .iter()
            .zip(&self.values)
            .filter(|(_, v)| **v >= floor)
            .map(|(h, _)| *h)
            .min_by_key(|h| (h.abs(), *h))
            .unwrap_or(0)
    }

    /// The lag of the largest correlation (the first one on ties).
    pub fn peak_lag(&self) -> i64 {
        let mut best = (0i64, f64::NEG_INFINITY);
        for (&h, &v) in self.lags.iter().zip(&self.values) {
            if v > best.1 || (v == best.1 && h.abs() < best.0.abs()) {
                best = (h, v);
            }
        }
        best.0
    }
}

/// Computes `corr(ω_{t−h}, γ_t)` for `h` in `−max_lag ..= max_lag`.
/// Series of different lengths are truncated to the shorter; a constant series gives zeros.
pub fn cross_correlation(omega: &[f64], gamma: &[f64], max_lag: usize) -> CrossCorrelation {
    let n = omega.len().min(gamma.len());
    let (w, g) = (&omega[..n], &gamma[..n]);
    let mw = crate::stats::mean(w);
    let mg = crate::stats::mean(g);
    let sw = w.iter().map(|v| (v - mw).powi(2)).sum::<f64>().sqrt();
    let sg = g.iter().map(|v| (v - mg).powi(2)).sum::<f64>().sqrt();
    let max_lag = max_lag.min(n.saturating_sub(1)) as i64;
    let mut lags = Vec::new();
    let mut values = Vec::new();
    for h in -max_lag..=max_lag {
        let mut s = 0.0;
        for t in 0..n as i64 {
            let j = t - h;
            if j >= 0 && j < n as i64 {
                s += (w[j as usize] - mw) * (g[t as usize] - mg);
            }
        }
        lags.push(h);
        values.push(if sw > 0.0 && sg > 0.0 {
            s / (sw * sg)
        } else {
            0.0
        });
    }
    CrossCorrelation { lags, values }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_a_known_delay() {
        let omega: Vec<f64> = (0..400)
            .map(|i| ((i * 7919) % 101) as f64 / 101.0 - 0.5)
            .collect();
        let mut gamma = vec![0.0; 400];
        for t in 3..400 {
            gamma[t] = 2.0 * omega[t - 3];
        }
        let c = cross_correlation(&omega, &gamma, 10);
        assert_eq!(c.peak_lag(), 3);
        assert_eq!(c.peak_lag_within(0.0), 3);
        let flat = CrossCorrelation {
            lags: vec![-1, 0, 1, 2],
            values: vec![0.9, 0.899, 0.9005, 0.8],
        };
        assert_eq!(flat.peak_lag(), 1);
        assert_eq!(flat.peak_lag_within(0.005), 0);
        assert!(c.values.iter().all(|v| v.abs() <= 1.0 + 1e-12));
    }
}
