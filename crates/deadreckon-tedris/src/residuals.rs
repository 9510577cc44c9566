//! Residual analysis of a regression: the sample autocorrelation, the
//! Box–Pierce and Ljung–Box portmanteau tests, and the AR(p) or MA(q)
//! correction fitted when the tests reject white residuals (the paper's robot
//! needed MA(2), table 2).
//!
//! - Sample autocorrelation at lag k: `r_k = Σ_{t=k}^{n−1} (e_t − ē)(e_{t−k} − ē) / Σ_t (e_t − ē)²`.
//! - Box–Pierce: `Q = n Σ_{k=1}^{L} r_k²`; Ljung–Box: `Q* = n (n + 2) Σ_{k=1}^{L} r_k² / (n − k)`;
//!   both χ² with `L − m` degrees of freedom (m: fitted ARMA coefficients).
//! - AR(p): `e_t = Σ φ_i e_{t−i} + u_t`, fitted by least squares on the residuals.
//! - MA(q): `e_t = u_t + Σ θ_j u_{t−j}`, fitted by the Hannan–Rissanen two-step
//!   method: a long AR(m) gives innovation estimates `û_t`, then `e_t` is
//!   regressed on `û_{t−1} … û_{t−q}`. Only least squares is needed.

use serde::{Deserialize, Serialize};
use statrs::distribution::{ChiSquared, ContinuousCDF};

use crate::stats::{ols, OlsFit};
use crate::Error;

/// Sample autocorrelations `r_0 = 1, r_1, …, r_max_lag` (NaN-free: a constant series gives zeros).
pub fn acf(x: &[f64], max_lag: usize) -> Vec<f64> {
    let n = x.len();
    let m = crate::stats::mean(x);
    let c0: f64 = x.iter().map(|v| (v - m).powi(2)).sum();
    (0..=max_lag)
        .map(|k| {
            if k == 0 {
                1.0
            } else if k >= n || c0 == 0.0 {
                0.0
            } else {
                (k..n).map(|t| (x[t] - m) * (x[t - k] - m)).sum::<f64>() / c0
            }
        })
        .collect()
}

/// The outcome of a portmanteau test.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Portmanteau {
    /// The statistic Q.
    pub statistic: f64,
    /// Number of autocorrelations summed, L.
    pub lags: usize,
    /// Degrees of freedom of the χ² reference, `L − fitted`.
    pub dof: usize,
    /// Upper-tail p value.
    pub p_value: f64,
}

fn chi2_upper(q: f64, dof: usize) -> f64 {
    match ChiSquared::new(dof.max(1) as f64) {
        Ok(d) if q.is_finite() => 1.0 - d.cdf(q),
        _ => 1.0,
    }
}

/// Box–Pierce test of the first `lags` autocorrelations; `fitted` ARMA coefficients reduce the dof.
pub fn box_pierce(x: &[f64], lags: usize, fitted: usize) -> Portmanteau {
    let r = acf(x, lags);
    let q = x.len() as f64 * r[1..].iter().map(|v| v * v).sum::<f64>();
    let dof = lags.saturating_sub(fitted).max(1);
    Portmanteau {
        statistic: q,
        lags,
        dof,
        p_value: chi2_upper(q, dof),
    }
}

/// Ljung–Box test of the first `lags` autocorrelations; `fitted` ARMA coefficients reduce the dof.
pub fn ljung_box(x: &[f64], lags: usize, fitted: usize) -> Portmanteau {
    let n = x.len() as f64;
    let r = acf(x, lags);
    let q = n
        * (n + 2.0)
        * r.iter()
            .enumerate()
            .skip(1)
            .map(|(k, v)| v * v / (n - k as f64))
            .sum::<f64>();
    let dof = lags.saturating_sub(fitted).max(1);
    Portmanteau {
        statistic: q,
        lags,
        dof,
        p_value: chi2_upper(q, dof),
    }
}

/// The correction of the regression error.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Correction {
    /// White residuals: no correction.
    #[default]
    None,
    /// AR(p) errors: `e_t = Σ φ_i e_{t−i} + u_t`.
    Ar {
        /// φ_1 … φ_p.
        phi: Vec<f64>,
    },
    /// MA(q) errors: `e_t = u_t + Σ θ_j u_{t−j}`.
    Ma {
        /// θ_1 … θ_q.
        theta: Vec<f64>,
    },
}

impl Correction {
    /// Number of fitted coefficients.
    pub fn order(&self) -> usize {
        match self {
            Correction::None => 0,
            Correction::Ar { phi } => phi.len(),
            Correction::Ma { theta } => theta.len(),
        }
    }

    /// A short label: `none`, `AR(2)`, `MA(2)`.
    pub fn label(&self) -> String {
        match self {
            Correction::None => "none".into(),
            Correction::Ar { phi } => format!("AR({})", phi.len()),
            Correction::Ma { theta } => format!("MA({})", theta.len()),
        }
    }

    /// The one-step forecast of the error from the past errors `e` and past
    /// innovations `u` (most recent last; missing history counts as zero).
    pub fn forecast(&self, e: &[f64], u: &[f64]) -> f64 {
        let back = |v: &[f64], i: usize| if i <= v.len() { v[v.len() - i] } else { 0.0 };
        match self {
            Correction::None => 0.0,
            Correction::Ar { phi } => phi
                .iter()
                .enumerate()
                .map(|(i, p)| p * back(e, i + 1))
                .sum(),
            Correction::Ma { theta } => theta
                .iter()
                .enumerate()
                .map(|(j, t)| t * back(u, j + 1))
                .sum(),
        }
    }

    /// Innovations `u_t = e_t − forecast_t` of an error series under this correction.
    pub fn innovations(&self, e: &[f64]) -> Vec<f64> {
        let mut u = Vec::with_capacity(e.len());
        for t in 0..e.len() {
            let f = self.forecast(&e[..t], &u);
            u.push(e[t] - f);
        }
        u
    }
}

/// Lagged copies of a series as design columns: row t holds `v_{t−1} … v_{t−order}`.
/// Rows before `order` are not produced: the result starts at t = `order`.
pub fn lagged(v: &[f64], order: usize) -> Vec<Vec<f64>> {
    (order..v.len())
        .map(|t| (1..=order).map(|i| v[t - i]).collect())
        .collect()
}

/// Innovation estimates of a series by a long AR(m) fit (first step of Hannan–Rissanen).
/// The first `m` values, which the AR cannot explain, are set to zero.
pub fn long_ar_innovations(e: &[f64], m: usize) -> Result<Vec<f64>, Error> {
    let x = lagged(e, m);
    let fit = ols(&x, &e[m..], &vec!["ar"; m])?;
    let mut u = vec![0.0; m];
    u.extend(fit.residuals(&x, &e[m..]));
    Ok(u)
}

/// A fitted correction candidate with its information criterion.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CorrectionFit {
    /// The correction.
    pub correction: Correction,
    /// Least-squares fit of the error on its own lags (AR) or lagged innovations (MA).
    pub fit: OlsFit,
    /// Ljung–Box test of the innovations left after the correction.
    pub ljung_box: Portmanteau,
}

/// Fits AR(p) to an error series (no intercept).
pub fn fit_ar(e: &[f64], p: usize, lb_lags: usize) -> Result<CorrectionFit, Error> {
    let x = lagged(e, p);
    let names: Vec<String> = (1..=p).map(|i| format!("ar{i}")).collect();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    let fit = ols(&x, &e[p..], &names)?;
    let correction = Correction::Ar { phi: fit.beta() };
    let u = correction.innovations(e);
    let ljung_box = ljung_box(&u[p..], lb_lags, p);
    Ok(CorrectionFit {
        correction,
        fit,
        ljung_box,
    })
}

/// Fits MA(q) to an error series by Hannan–Rissanen (long AR of order `m`).
pub fn fit_ma(e: &[f64], q: usize, m: usize, lb_lags: usize) -> Result<CorrectionFit, Error> {
    let uhat = long_ar_innovations(e, m)?;
    let start = m + q;
    if e.len() <= start + q + 1 {
        return Err(Error::Regression("too few residuals for the MA fit".into()));
    }
    let x: Vec<Vec<f64>> = (start..e.len())
        .map(|t| (1..=q).map(|j| uhat[t - j]).collect())
        .collect();
    let names: Vec<String> = (1..=q).map(|j| format!("ma{j}")).collect();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    let fit = ols(&x, &e[start..], &names)?;
    let correction = Correction::Ma { theta: fit.beta() };
    let u = correction.innovations(e);
    let ljung_box = ljung_box(&u[start..], lb_lags, q);
    Ok(CorrectionFit {
        correction,
        fit,
        ljung_box,
    })
}

/// Chooses the correction for a residual series: none when Ljung–Box does not
/// reject whiteness at level `alpha`, otherwise the AR(p) or MA(q) (p, q ≤ `max_order`)
/// with the smallest BIC.
pub fn select_correction(
    e: &[f64],
    lb_lags: usize,
    alpha: f64,
    max_order: usize,
) -> Option<CorrectionFit> {
    if ljung_box(e, lb_lags, 0).p_value >= alpha {
        return None;
    }
    let m = (max_order * 3).max(6);
    let mut best: Option<CorrectionFit> = None;
    for k in 1..=max_order {
        for cand in [fit_ar(e, k, lb_lags), fit_ma(e, k, m, lb_lags)]
            .into_iter()
            .flatten()
        {
            if best.as_ref().is_none_or(|b| cand.fit.bic < b.fit.bic) {
                best = Some(cand);
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    /// e = (1, −1, 2, 0, −2, 1): ē = 1/6. Hand computation with deviations
    /// d = (5, −7, 11, −1, −13, 5)/6: Σd² = 390/36; lag-1 cross sum = (−35 −77 −11 +13 −65)/36 = −175/36;
    /// lag-2 = (55 + 7 −143 −5)/36 = −86/36. r1 = −175/390, r2 = −86/390.
    /// Box–Pierce with L = 2: Q = 6 (r1² + r2²) = 6 (30625 + 7396)/152100 = 1.4998817...
    #[test]
    fn box_pierce_matches_hand_computation() {
        let e = [1.0, -1.0, 2.0, 0.0, -2.0, 1.0];
        let r = acf(&e, 2);
        assert!((r[1] + 175.0 / 390.0).abs() < 1e-12);
        assert!((r[2] + 86.0 / 390.0).abs() < 1e-12);
        let bp = box_pierce(&e, 2, 0);
        let q = 6.0 * (30625.0 + 7396.0) / 152100.0;
        assert!((bp.statistic - q).abs() < 1e-12, "{}", bp.statistic);
        // χ²₂ upper tail: exp(−Q/2).
        assert!((bp.p_value - (-q / 2.0).exp()).abs() < 1e-9);
        // Ljung–Box: n(n+2)(r1²/5 + r2²/4) = 48 (0.2013478/5 + 0.0486259/4).
        let lb = ljung_box(&e, 2, 0);
        let r1 = 175.0f64 / 390.0;
        let r2 = 86.0f64 / 390.0;
        assert!((lb.statistic - 48.0 * (r1 * r1 / 5.0 + r2 * r2 / 4.0)).abs() < 1e-12);
    }

    fn lcg(seed: &mut u64) -> f64 {
        // A fixed uniform generator, so the test needs no random crate: mean 0, var 1/12·12 = 1.
        let mut s = 0.0;
        for _ in 0..12 {
            *seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            s += (*seed >> 11) as f64 / (1u64 << 53) as f64;
        }
        s - 6.0
    }

    #[test]
    fn ma2_is_detected_and_recovered() {
        let mut seed = 7u64;
        let u: Vec<f64> = (0..4000).map(|_| lcg(&mut seed)).collect();
        let e: Vec<f64> = (2..u.len())
            .map(|t| u[t] + 0.6 * u[t - 1] + 0.3 * u[t - 2])
            .collect();
        let c = select_correction(&e, 10, 0.05, 3).expect("MA residuals must be detected");
        match &c.correction {
            Correction::Ma { theta } => {
                assert!(
                    (theta[0] - 0.6).abs() < 0.06 && (theta[1] - 0.3).abs() < 0.06,
                    "{theta:?}"
                );
            }
            other => panic!("expected MA, got {other:?}"),
        }
        assert!(c.ljung_box.p_value > 0.01);
        // White noise is left alone.
        assert!(select_correction(&u, 10, 0.01, 3).is_none());
    }
}
