//! Ordinary least squares with the coefficient table of the paper's table 1
//! (estimate, standard error, t value, two-sided p value), information criteria,
//! and small robust statistics (median).
//!
//! The solver forms the normal equations `XᵀX β = Xᵀy` and inverts `XᵀX` by
//! Gauss–Jordan elimination with partial pivoting: the designs here have at most
//! a handful of columns, so the inverse (needed for the standard errors) is cheap.

use serde::{Deserialize, Serialize};
use statrs::distribution::{ContinuousCDF, StudentsT};

use crate::Error;

/// One row of a regression table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Coefficient {
    /// Name of the regressor (`alpha0`, `alpha1`, `distance`, `ma1`, ...).
    pub name: String,
    /// Estimate.
    pub estimate: f64,
    /// Standard error: `sqrt(σ² [(XᵀX)⁻¹]ⱼⱼ)`.
    pub std_error: f64,
    /// t value: estimate / standard error (0 when the standard error is 0).
    pub t_value: f64,
    /// Two-sided p value of the t value under Student's t with `n − p` degrees of freedom.
    pub p_value: f64,
}

/// An ordinary least-squares fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OlsFit {
    /// The coefficient table, one row per column of the design.
    pub coefficients: Vec<Coefficient>,
    /// Number of observations.
    pub n: usize,
    /// Residual variance σ² = RSS / (n − p).
    pub sigma2: f64,
    /// Residual sum of squares.
    pub rss: f64,
    /// Coefficient of determination (0 for a constant response).
    pub r_squared: f64,
    /// Akaike information criterion, `n ln(RSS/n) + 2p`.
    pub aic: f64,
    /// Bayesian information criterion, `n ln(RSS/n) + p ln n`.
    pub bic: f64,
}

impl OlsFit {
    /// The estimates in column order.
    pub fn beta(&self) -> Vec<f64> {
        self.coefficients.iter().map(|c| c.estimate).collect()
    }

    /// The prediction `x·β` for one design row (missing trailing entries count as 0).
    pub fn predict(&self, x: &[f64]) -> f64 {
        self.coefficients
            .iter()
            .zip(x)
            .map(|(c, v)| c.estimate * v)
            .sum()
    }

    /// The residuals `y − Xβ`.
    pub fn residuals(&self, x: &[Vec<f64>], y: &[f64]) -> Vec<f64> {
        x.iter().zip(y).map(|(r, v)| v - self.predict(r)).collect()
    }
}

/// Fits `y = Xβ + e` by ordinary least squares. `names` labels the columns.
///
/// Errors when the rows are fewer than the columns plus one, a value is not
/// finite, or `XᵀX` is singular.
pub fn ols(x: &[Vec<f64>], y: &[f64], names: &[&str]) -> Result<OlsFit, Error> {
    ols_eiv(x, y, names, &[])
}

/// Least squares with errors in variables (method of moments): column j carries
/// additive white measurement noise of variance `noise_var[j]` (missing entries: 0),
/// so `XᵀX` is replaced by `XᵀX − n·diag(noise_var)` — the correction of the slope
/// attenuation ("regression dilution") that plain OLS suffers when a regressor is
/// noisy. Standard errors are then the usual formula on the corrected matrix
/// (an approximation). With no noise this is [`ols`].
pub fn ols_eiv(
    x: &[Vec<f64>],
    y: &[f64],
    names: &[&str],
    noise_var: &[f64],
) -> Result<OlsFit, Error> {
    let p = names.len();
    let n = y.len();
    if x.len() != n || x.iter().any(|r| r.len() != p) {
        return Err(Error::Regression(
            "design and response sizes disagree".into(),
        ));
    }
    if n <= p {
        return Err(Error::Regression(format!(
            "{n} observations cannot fit {p} coefficients"
        )));
    }
    if y.iter().chain(x.iter().flatten()).any(|v| !v.is_finite()) {
        return Err(Error::Regression(
            "non-finite value in the regression data".into(),
        ));
    }
    let mut xtx = vec![vec![0.0; p]; p];
    let mut xty = vec![0.0; p];
    for (row, &yi) in x.iter().zip(y) {
        for i in 0..p {
            xty[i] += row[i] * yi;
            for j in 0..p {
                xtx[i][j] += row[i] * row[j];
            }
        }
    }
    for (j, v) in noise_var.iter().enumerate().take(p) {
        if v.is_finite() && *v > 0.0 {
            xtx[j][j] -= n as f64 * v;
        }
    }
    let inv = invert(&xtx)
        .ok_or_else(|| Error::Regression("the design is singular (XᵀX not invertible)".into()))?;
    // β = (XᵀX)⁻¹ Xᵀy
    let beta: Vec<f64> = (0..p)
        .map(|i| (0..p).map(|j| inv[i][j] * xty[j]).sum())
        .collect();
    let rss: f64 = x
        .iter()
        .zip(y)
        .map(|(r, v)| {
            let e = v - r.iter().zip(&beta).map(|(a, b)| a * b).sum::<f64>();
            e * e
        })
        .sum();
    let dof = (n - p) as f64;
    let sigma2 = rss / dof;
    let ybar = mean(y);
    let tss: f64 = y.iter().map(|v| (v - ybar).powi(2)).sum();
    let r_squared = if tss > 0.0 { 1.0 - rss / tss } else { 0.0 };
    let t_dist = StudentsT::new(0.0, 1.0, dof)
        .map_err(|e| Error::Regression(format!("Student's t: {e}")))?;
    let coefficients = (0..p)
        .map(|j| {
            let std_error = (sigma2 * inv[j][j]).max(0.0).sqrt();
            let t_value = if std_error > 0.0 {
                beta[j] / std_error
            } else {
                0.0
            };
            let p_value = if std_error > 0.0 && t_value.is_finite() {
                2.0 * (1.0 - t_dist.cdf(t_value.abs()))
            } else {
                1.0
            };
            Coefficient {
                name: names[j].to_string(),
                estimate: beta[j],
                std_error,
                t_value,
                p_value,
            }
        })
        .collect();
    let ll = n as f64 * (rss.max(f64::MIN_POSITIVE) / n as f64).ln();
    Ok(OlsFit {
        coefficients,
        n,
        sigma2,
        rss,
        r_squared,
        aic: ll + 2.0 * p as f64,
        bic: ll + p as f64 * (n as f64).ln(),
    })
}

/// Inverse of a small square matrix by Gauss–Jordan elimination with partial
/// pivoting; `None` when a pivot is negligible relative to the matrix scale.
pub fn invert(a: &[Vec<f64>]) -> Option<Vec<Vec<f64>>> {
    let n = a.len();
    let scale = a.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
    if scale == 0.0 || !scale.is_finite() {
        return None;
    }
    let mut m: Vec<Vec<f64>> = a.to_vec();
    let mut inv: Vec<Vec<f64>> = (0..n)
        .map(|i| (0..n).map(|j| f64::from(u8::from(i == j))).collect())
        .collect();
    for col in 0..n {
        let piv = (col..n).max_by(|&i, &j| m[i][col].abs().total_cmp(&m[j][col].abs()))?;
        if m[piv][col].abs() <= scale * 1e-14 {
            return None;
        }
        m.swap(col, piv);
        inv.swap(col, piv);
        let d = m[col][col];
        for j in 0..n {
            m[col][j] /= d;
            inv[col][j] /= d;
        }
        for i in 0..n {
            if i != col {
                let f = m[i][col];
                if f != 0.0 {
                    for j in 0..n {
                        m[i][j] -= f * m[col][j];
                        inv[i][j] -= f * inv[col][j];
                    }
                }
            }
        }
    }
    Some(inv)
}

/// The summary statistics live in one place, `deadreckon_core::metrics`.
pub use deadreckon_core::metrics::{mean, median};

#[cfg(test)]
mod tests {
    use super::*;

    /// Closed form on a fixed data set: x = 1..5, y = (2.1, 3.9, 6.2, 7.8, 10.1).
    /// x̄ = 3, ȳ = 6.02, Sxx = 10, Sxy = 19.9 → slope 1.99, intercept 0.05.
    /// Residuals (0.06, −0.13, 0.18, −0.21, 0.10): RSS = 0.107, σ² = 0.107/3.
    /// se(slope) = sqrt(σ²/10) = 0.0597216, se(intercept) = sqrt(σ² (1/5 + 9/10)) = 0.1980741.
    /// p values from the closed-form CDF of Student's t with 3 dof,
    /// F(t) = 1/2 + (u/(1 + u²) + atan u)/π with u = t/√3:
    /// slope t = 33.3213, p = 5.94154e-5; intercept t = 0.252431, p = 0.817015.
    #[test]
    fn ols_matches_closed_form() {
        let xs = [1.0, 2.0, 3.0, 4.0, 5.0];
        let y = [2.1, 3.9, 6.2, 7.8, 10.1];
        let x: Vec<Vec<f64>> = xs.iter().map(|&v| vec![1.0, v]).collect();
        let f = ols(&x, &y, &["alpha0", "alpha1"]).unwrap();
        let c = &f.coefficients;
        assert!((c[0].estimate - 0.05).abs() < 1e-12);
        assert!((c[1].estimate - 1.99).abs() < 1e-12);
        assert!((f.rss - 0.107).abs() < 1e-12);
        assert!((c[1].std_error - 0.059_721_576_223_896_455).abs() < 1e-12);
        assert!((c[0].std_error - 0.198_074_060_223_274_62).abs() < 1e-12);
        assert!((c[1].t_value - 33.321_290_659_501_03).abs() < 1e-8);
        assert!((c[0].t_value - 0.252_430_832_909_865_2).abs() < 1e-10);
        assert!(
            (c[1].p_value - 5.941_539_111_775_64e-5).abs() < 1e-9,
            "{}",
            c[1].p_value
        );
        assert!(
            (c[0].p_value - 0.817_015_178_175_125_4).abs() < 1e-8,
            "{}",
            c[0].p_value
        );
    }

    #[test]
    fn eiv_undoes_attenuation() {
        // x_true alternates ±1; the observed x adds ±0.5 (variance 0.25): OLS slope
        // is 2·1/(1 + 0.25) = 1.6; the corrected slope is 2.
        let mut x = Vec::new();
        let mut y = Vec::new();
        for i in 0..400 {
            let xt = if i % 2 == 0 { 1.0 } else { -1.0 };
            let u = if (i / 2) % 2 == 0 { 0.5 } else { -0.5 };
            x.push(vec![1.0, xt + u]);
            y.push(2.0 * xt);
        }
        let plain = ols(&x, &y, &["a", "b"]).unwrap();
        assert!((plain.coefficients[1].estimate - 1.6).abs() < 1e-9);
        let f = ols_eiv(&x, &y, &["a", "b"], &[0.0, 0.25]).unwrap();
        assert!(
            (f.coefficients[1].estimate - 2.0).abs() < 1e-9,
            "{}",
            f.coefficients[1].estimate
        );
    }

    #[test]
    fn singular_design_is_an_error() {
        let x = vec![vec![1.0, 2.0], vec![2.0, 4.0], vec![3.0, 6.0]];
        assert!(ols(&x, &[1.0, 2.0, 3.0], &["a", "b"]).is_err());
        assert!(ols(&x[..1], &[1.0], &["a", "b"]).is_err());
    }

    #[test]
    fn median_even_odd() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
        assert!(median(&[]).is_nan());
    }
}
