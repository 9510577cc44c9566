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
    let n = y.len() as f64;
    let noise_sum: Vec<Vec<f64>> = (0..p)
        .map(|i| {
            (0..p)
                .map(|j| match noise_var.get(i) {
                    Some(v) if i == j && v.is_finite() && *v > 0.0 => n * v,
                    _ => 0.0,
                })
                .collect()
        })
        .collect();
    ols_eiv_sum(x, y, names, &noise_sum)
}

/// Least squares with errors in variables whose measurement noise differs
/// by row and is correlated between columns: `noise_sum` is the sum over the
/// rows of each row's noise covariance (p × p), and `XᵀX` is replaced by
/// `XᵀX − noise_sum`. A column that is a product of a noisy regressor and an
/// exact one (the speed kind's ω·d²) carries that regressor's noise times
/// the exact factor, correlated with the regressor's own column: leaving the
/// covariance out, as a diagonal [`ols_eiv`] must, over-corrects (issue 35,
/// the speed kind on tick-counter car 9). With a zero matrix this is [`ols`].
pub fn ols_eiv_sum(
    x: &[Vec<f64>],
    y: &[f64],
    names: &[&str],
    noise_sum: &[Vec<f64>],
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
    for (i, row) in noise_sum.iter().enumerate().take(p) {
        for (j, v) in row.iter().enumerate().take(p) {
            if v.is_finite() {
                xtx[i][j] -= v;
            }
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

/// A one-sided paired test of two losses over the same rows (see
/// [`paired_batch_test`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairedTest {
    /// The mean loss difference `a − b` over the rows.
    pub mean_difference: f64,
    /// Student's t of the batch means of `a − b`.
    pub t_value: f64,
    /// Degrees of freedom (batches − 1).
    pub dof: usize,
    /// One-sided p value of "`a` has the larger mean loss": the probability
    /// of a t value at least this large if the mean losses were equal.
    pub p_a_larger: f64,
}

/// A paired t test of the mean of `a − b` by batch means: the rows (in
/// time order) are cut into `batches` runs of equal count, and the run
/// means of `a − b` are taken as independent (the batch-means estimate of
/// the variance of a mean of autocorrelated values; Diebold and Mariano's
/// comparison of predictive accuracy with a loss differential, its long-run
/// variance from batches instead of a kernel). `None` with different
/// lengths, fewer than two batches, fewer rows than batches, a non-finite
/// loss, or batch means without spread.
pub fn paired_batch_test(a: &[f64], b: &[f64], batches: usize) -> Option<PairedTest> {
    if a.len() != b.len() || batches < 2 || a.len() < batches {
        return None;
    }
    let d: Vec<f64> = a.iter().zip(b).map(|(x, y)| x - y).collect();
    if !d.iter().all(|v| v.is_finite()) {
        return None;
    }
    let n = d.len();
    let means: Vec<f64> = (0..batches)
        .map(|k| {
            let run = &d[k * n / batches..(k + 1) * n / batches];
            run.iter().sum::<f64>() / run.len() as f64
        })
        .collect();
    let m = means.iter().sum::<f64>() / batches as f64;
    let var = means.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (batches - 1) as f64;
    if var.is_nan() || var <= 0.0 {
        return None;
    }
    let t_value = m / (var / batches as f64).sqrt();
    let dof = batches - 1;
    let dist = StudentsT::new(0.0, 1.0, dof as f64).ok()?;
    Some(PairedTest {
        mean_difference: d.iter().sum::<f64>() / n as f64,
        t_value,
        dof,
        p_a_larger: dist.sf(t_value),
    })
}

/// The correlation time of `values` sampled at `times`: the time from the
/// first sample to the first lag at which the autocorrelation falls below
/// 1/e, s. `None` with fewer than four values, without spread, with
/// lengths that differ, or when it does not fall that far within half the
/// series.
pub fn correlation_time(values: &[f64], times: &[f64]) -> Option<f64> {
    let n = values.len();
    if n < 4 || times.len() != n {
        return None;
    }
    let m = values.iter().sum::<f64>() / n as f64;
    let c0: f64 = values.iter().map(|v| (v - m).powi(2)).sum();
    if !(c0 > 0.0 && c0.is_finite()) {
        return None;
    }
    (1..=n / 2)
        .find(|&lag| {
            let c: f64 = (0..n - lag)
                .map(|i| (values[i] - m) * (values[i + lag] - m))
                .sum();
            c / c0 < (-1.0f64).exp()
        })
        .map(|lag| times[lag] - times[0])
}

/// Standard errors of a least-squares fit of a *cumulative* quantity
/// (see [`increment_block_std`]), with what they rest on.
#[derive(Debug, Clone, PartialEq)]
pub struct IncrementBlockStd {
    /// One standard error per column, in column order.
    pub std_error: Vec<f64>,
    /// Blocks of contiguous rows the scores were summed over.
    pub blocks: usize,
    /// Correlation time of the residual increments ([`correlation_time`]), s.
    pub correlation_time_s: f64,
}

/// Standard errors of `β̂ = (XᵀX)⁻¹Xᵀy` when the errors of `y` are
/// random-walk-like (a cumulative heading against cumulative columns):
/// `x` and `residuals` are the fit's design and residuals, centred per run
/// of equal `segments` (an intercept per run), rows in time order.
///
/// Why not the OLS formula, nor blocks of the rows: the OLS formula takes
/// the errors as independent, and a cumulative error stays of one sign for
/// most of a window, so the scores `x̃ₖeₖ` of rows far apart are correlated
/// and no block of rows is independent of the others. Summation by parts
/// moves the sum onto the error *increments* `uₘ = eₘ − eₘ₋₁`, which
/// decorrelate within seconds (wheel noise, reference noise, a turn's
/// misfit): within a run, as `Σₖ x̃ₖ = 0`,
///
/// `Σₖ x̃ₖ eₖ = Σₘ uₘ Sₘ`, `Sₘ = Σ_{k≥m} x̃ₖ` (the run's tail sums),
///
/// an identity. The scores `zₘ = ûₘ Sₘ` are cut into `blocks` contiguous
/// blocks of equal row count and their block sums taken as independent
/// (batch means of the scores; the delete-a-block jackknife's linearised
/// form): `Ω = g/(g − 1) Σ_b z_b z_bᵀ`, `V = (XᵀX)⁻¹ Ω (XᵀX)⁻¹`. White
/// reference noise adds to `ûₘ` a difference that telescopes within a block,
/// as it should: it does not accumulate.
///
/// Errors (naming why) with lengths that differ, a non-finite value, fewer
/// than two blocks or fewer increments than blocks, a singular `XᵀX`,
/// increments that do not decorrelate within half the window, or blocks
/// shorter than `decorrelations` correlation times of the increments (the
/// block sums would not be independent).
pub fn increment_block_std(
    x: &[Vec<f64>],
    residuals: &[f64],
    segments: &[u32],
    times: &[f64],
    blocks: usize,
    decorrelations: f64,
) -> Result<IncrementBlockStd, Error> {
    let n = residuals.len();
    let p = x.first().map_or(0, Vec::len);
    if x.len() != n || segments.len() != n || times.len() != n || x.iter().any(|r| r.len() != p) {
        return Err(Error::Regression(
            "block standard errors: design, residuals, segments and times differ in length".into(),
        ));
    }
    if p == 0 || blocks < 2 {
        return Err(Error::Regression(format!(
            "block standard errors: {p} columns and {blocks} blocks"
        )));
    }
    if x.iter()
        .flatten()
        .chain(residuals)
        .chain(times)
        .any(|v| !v.is_finite())
    {
        return Err(Error::Regression(
            "block standard errors: non-finite value".into(),
        ));
    }
    let mut xtx = vec![vec![0.0; p]; p];
    for r in x {
        for i in 0..p {
            for j in 0..p {
                xtx[i][j] += r[i] * r[j];
            }
        }
    }
    let a = invert(&xtx)
        .ok_or_else(|| Error::Regression("block standard errors: the design is singular".into()))?;
    // The tail sums S_m of each run, from its end backwards (row-major).
    let mut tail = vec![0.0; n * p];
    for k in (0..n).rev() {
        let continues = k + 1 < n && segments[k + 1] == segments[k];
        for j in 0..p {
            let after = if continues {
                tail[(k + 1) * p + j]
            } else {
                0.0
            };
            tail[k * p + j] = after + x[k][j];
        }
    }
    // Increments within a run (the first row of a run has none).
    let rows: Vec<usize> = (1..n).filter(|&k| segments[k] == segments[k - 1]).collect();
    let m = rows.len();
    if m < blocks {
        return Err(Error::Regression(format!(
            "block standard errors: {m} increments cannot fill {blocks} blocks"
        )));
    }
    let u: Vec<f64> = rows
        .iter()
        .map(|&k| residuals[k] - residuals[k - 1])
        .collect();
    let t: Vec<f64> = rows.iter().map(|&k| times[k]).collect();
    let tc = correlation_time(&u, &t).ok_or_else(|| {
        Error::Regression(
            "block standard errors: the heading increments do not decorrelate within half the window"
                .into(),
        )
    })?;
    let span = t[m - 1] - t[0];
    if span < blocks as f64 * decorrelations * tc {
        return Err(Error::Regression(format!(
            "block standard errors: {blocks} blocks of {:.1} s are shorter than {decorrelations} correlation times of {tc:.2} s",
            span / blocks as f64
        )));
    }
    // Ω = Σ_b z_b z_bᵀ, z_b the block's sum of the scores u_m·S_m.
    let mut omega = vec![vec![0.0; p]; p];
    let mut zb = vec![0.0; p];
    for b in 0..blocks {
        zb.iter_mut().for_each(|v| *v = 0.0);
        for i in b * m / blocks..(b + 1) * m / blocks {
            let k = rows[i];
            for (j, z) in zb.iter_mut().enumerate() {
                *z += u[i] * tail[k * p + j];
            }
        }
        for i in 0..p {
            for j in 0..p {
                omega[i][j] += zb[i] * zb[j];
            }
        }
    }
    let g = blocks as f64;
    let std_error = (0..p)
        .map(|j| {
            // V_jj = Σ_ik A_ji Ω_ik A_kj, with Ω grown by g/(g − 1).
            let v: f64 = (0..p)
                .flat_map(|i| (0..p).map(move |k| (i, k)))
                .map(|(i, k)| a[j][i] * omega[i][k] * a[k][j])
                .sum();
            (g / (g - 1.0) * v).max(0.0).sqrt()
        })
        .collect();
    Ok(IncrementBlockStd {
        std_error,
        blocks,
        correlation_time_s: tc,
    })
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

    /// γ = 2·ω − 0.5·ω·d² with ω observed with noise ±0.5 (variance 0.25),
    /// over the full factorial of ω = ±1, noise ±0.5, d² ∈ {1, 3}: the
    /// product column's noise is ω's times d², correlated with ω's column.
    /// The covariance taken off `XᵀX` whole gives the truth exactly; the
    /// diagonal alone (what the speed kind had, issue 35) does not.
    #[test]
    fn a_product_column_needs_the_noise_covariance() {
        let (mut x, mut y, mut sum) = (Vec::new(), Vec::new(), vec![vec![0.0; 2]; 2]);
        let mut d4 = 0.0;
        for &xt in &[1.0, -1.0] {
            for &u in &[0.5, -0.5] {
                for &d2 in &[1.0, 3.0] {
                    let w: f64 = xt + u;
                    x.push(vec![w, w * d2]);
                    y.push(2.0 * xt - 0.5 * xt * d2);
                    let g = [1.0, d2];
                    for i in 0..2 {
                        for j in 0..2 {
                            sum[i][j] += 0.25 * g[i] * g[j];
                        }
                    }
                    d4 += d2 * d2 / 8.0;
                }
            }
        }
        let names = ["alpha1", "omega_speed"];
        let full = ols_eiv_sum(&x, &y, &names, &sum).unwrap().beta();
        assert!(
            (full[0] - 2.0).abs() < 1e-9 && (full[1] + 0.5).abs() < 1e-9,
            "{full:?}"
        );
        let diag = ols_eiv(&x, &y, &names, &[0.25, 0.25 * d4]).unwrap().beta();
        assert!((diag[1] + 0.5).abs() > 0.1, "{diag:?}");
    }

    #[test]
    fn singular_design_is_an_error() {
        let x = vec![vec![1.0, 2.0], vec![2.0, 4.0], vec![3.0, 6.0]];
        assert!(ols(&x, &[1.0, 2.0, 3.0], &["a", "b"]).is_err());
        assert!(ols(&x[..1], &[1.0], &["a", "b"]).is_err());
    }

    /// Batches of (a − b) = 1, 2, 3, 4 (one row each): mean 2.5, variance
    /// 5/3, t = 2.5 / sqrt(5/12) = 3.872983; one-sided p with 3 dof from the
    /// closed form 1 − F(t), F(t) = 1/2 + (u/(1 + u²) + atan u)/π, u = t/√3:
    /// 0.015219.
    #[test]
    fn paired_batch_test_matches_closed_form() {
        let a = [1.5, 2.0, 3.5, 4.25];
        let b = [0.5, 0.0, 0.5, 0.25];
        let p = paired_batch_test(&a, &b, 4).unwrap();
        assert!((p.mean_difference - 2.5).abs() < 1e-12);
        assert!((p.t_value - 3.872983346207417).abs() < 1e-9);
        assert_eq!(p.dof, 3);
        let u = p.t_value / 3f64.sqrt();
        let cdf = 0.5 + (u / (1.0 + u * u) + u.atan()) / std::f64::consts::PI;
        assert!(
            (p.p_a_larger - (1.0 - cdf)).abs() < 1e-9,
            "{}",
            p.p_a_larger
        );
        // Swapped, the same t with the other sign.
        let q = paired_batch_test(&b, &a, 4).unwrap();
        assert!((q.t_value + p.t_value).abs() < 1e-12);
        assert!((q.p_a_larger - cdf).abs() < 1e-9);
        // Batches of two rows: the means are 1.5 and 3.5.
        let r = paired_batch_test(&a, &b, 2).unwrap();
        assert!((r.t_value - 2.5).abs() < 1e-12);
        assert!(paired_batch_test(&a, &b[..3], 2).is_none());
        assert!(paired_batch_test(&a, &b, 5).is_none());
        assert!(paired_batch_test(&a, &a, 2).is_none());
    }

    /// An AR(1) series x_k = 0.9·x_(k−1) + u_k at 10 Hz: its autocorrelation
    /// 0.9^k falls below 1/e at k = 10 (0.9^9 = 0.387, 0.9^10 = 0.349), 1 s.
    #[test]
    fn correlation_time_of_an_ar1_series() {
        let mut seed = 11u64;
        let mut x = 0.0;
        let v: Vec<f64> = (0..20000)
            .map(|_| {
                seed = seed
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                x = 0.9 * x + ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5);
                x
            })
            .collect();
        let t: Vec<f64> = (0..v.len()).map(|k| 0.1 * k as f64).collect();
        let tc = correlation_time(&v, &t).expect("correlated");
        assert!((tc - 1.0).abs() < 0.15, "{tc}");
        // White values decorrelate at the first lag.
        let w: Vec<f64> = (0..v.len()).map(|k| v[k] - 0.9 * v[k.max(1) - 1]).collect();
        assert!((correlation_time(&w[1..], &t[1..]).expect("white") - 0.1).abs() < 1e-9);
        assert!(correlation_time(&[1.0; 10], &t[..10]).is_none());
    }

    /// A cumulative regression with random-walk errors, as the joint
    /// calibration's: `y = c_s + β·Σd + W + v`, Σd the cumulative distance
    /// at a speed that varies, W a random walk, v white noise, two runs with
    /// their own intercepts. Over 300 seeded replications the block standard
    /// error's root mean square is within 20 % of the spread of β̂ (measured
    /// 1.05× the spread), while the OLS one is 35 times too small (0.028×).
    #[test]
    fn block_std_of_a_cumulative_regression_matches_the_spread() {
        let mut seed = 7u64;
        let mut uniform = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let (n, reps) = (2000, 300);
        let (mut betas, mut block_var, mut ols_var) = (Vec::new(), 0.0, 0.0);
        for _ in 0..reps {
            let (mut d, mut w) = (0.0, 0.0);
            let mut x = Vec::with_capacity(n);
            let mut y = Vec::with_capacity(n);
            let segments: Vec<u32> = (0..n).map(|k| u32::from(k >= n / 3)).collect();
            let times: Vec<f64> = (0..n).map(|k| 0.1 * k as f64).collect();
            for (k, &segment) in segments.iter().enumerate() {
                let speed = 1.0 + (0.01 * k as f64).sin() + 0.5 * uniform();
                d += 0.1 * speed;
                w += 0.01 * uniform();
                y.push(2.0e-3 * d + w + 0.02 * uniform() + f64::from(segment));
                x.push(vec![d]);
            }
            let mut rows: Vec<Vec<f64>> = x.iter().zip(&y).map(|(a, b)| vec![a[0], *b]).collect();
            crate::history::centre_per_segment(&mut rows, &segments);
            let (xc, yc): (Vec<Vec<f64>>, Vec<f64>) =
                rows.into_iter().map(|r| (vec![r[0]], r[1])).unzip();
            let fit = ols(&xc, &yc, &["distance"]).expect("fit");
            let e = fit.residuals(&xc, &yc);
            let b = increment_block_std(&xc, &e, &segments, &times, 10, 2.0).expect("std");
            assert_eq!(b.blocks, 10);
            betas.push(fit.coefficients[0].estimate);
            block_var += b.std_error[0].powi(2) / reps as f64;
            ols_var += fit.coefficients[0].std_error.powi(2) / reps as f64;
        }
        let m = mean(&betas);
        let spread =
            (betas.iter().map(|b| (b - m).powi(2)).sum::<f64>() / (reps - 1) as f64).sqrt();
        let (block, plain) = (block_var.sqrt() / spread, ols_var.sqrt() / spread);
        eprintln!("block {block:.3}, OLS {plain:.3} of the spread {spread:.3e}");
        assert!((block - 1.0).abs() < 0.2, "{block}");
        assert!(plain < 0.5, "{plain}");
        // Bad input is an error naming why.
        let x = vec![vec![1.0], vec![2.0], vec![3.0]];
        let err = increment_block_std(&x, &[0.0; 3], &[0; 3], &[0.0, 1.0], 2, 2.0);
        assert!(err.is_err());
        let err = increment_block_std(&x, &[0.1, -0.1, 0.0], &[0; 3], &[0.0, 1.0, 2.0], 4, 2.0);
        assert!(format!("{:?}", err).contains("cannot fill"), "{err:?}");
    }

    #[test]
    fn median_even_odd() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
        assert!(median(&[]).is_nan());
    }
}
