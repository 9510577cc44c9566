//! Small statistics the report needs: summaries, quantiles, histogram bins, the
//! chi-square quantile for the NIS bounds, and decimation of long series.

/// Summaries and quantiles are `deadreckon_core::metrics`' (one place for
/// the whole workspace); the report takes the finite values only.
pub(crate) use deadreckon_core::metrics::{quantile as quantile_sorted, Summary};

/// The finite values of `v`, sorted.
pub(crate) fn sorted_finite(v: &[f64]) -> Vec<f64> {
    let mut s: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    s.sort_by(f64::total_cmp);
    s
}

/// Summary of the finite values of `v`; `None` when there are none.
pub(crate) fn summary(v: &[f64]) -> Option<Summary> {
    let s = sorted_finite(v);
    (!s.is_empty()).then(|| Summary::of(&s))
}

/// Histogram bin edges shared by several samples: about `target` bins over the
/// common finite range, with a "nice" width (1, 2 or 5 × 10ᵏ).
pub(crate) fn bin_edges(samples: &[&[f64]], target: usize) -> Vec<f64> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for s in samples {
        for &x in s.iter().filter(|x| x.is_finite()) {
            lo = lo.min(x);
            hi = hi.max(x);
        }
    }
    if !lo.is_finite() {
        return Vec::new();
    }
    if hi - lo < 1e-12 * lo.abs().max(1.0) {
        let w = 0.5 * lo.abs().max(1e-3);
        return vec![lo - w, lo + w];
    }
    let width = nice_step((hi - lo) / target.max(1) as f64);
    let start = (lo / width).floor() * width;
    let mut edges = vec![start];
    while *edges.last().unwrap_or(&start) <= hi {
        let next = start + edges.len() as f64 * width;
        edges.push(next);
    }
    edges
}

/// The 1, 2 or 5 × 10ᵏ step nearest above `raw`.
pub(crate) fn nice_step(raw: f64) -> f64 {
    if !(raw.is_finite() && raw > 0.0) {
        return 1.0;
    }
    let k = raw.log10().floor();
    let base = 10f64.powf(k);
    let m = raw / base;
    let f = if m <= 1.0 {
        1.0
    } else if m <= 2.0 {
        2.0
    } else if m <= 5.0 {
        5.0
    } else {
        10.0
    };
    f * base
}

/// Counts of the finite values of `v` in the bins `[e_i, e_{i+1})` (the last bin closed).
pub(crate) fn histogram(v: &[f64], edges: &[f64]) -> Vec<usize> {
    let nb = edges.len().saturating_sub(1);
    let mut c = vec![0usize; nb];
    if nb == 0 {
        return c;
    }
    for &x in v.iter().filter(|x| x.is_finite()) {
        let i = edges.partition_point(|e| *e <= x);
        let i = i.saturating_sub(1).min(nb - 1);
        if x >= edges[0] && x <= edges[nb] {
            c[i] += 1;
        }
    }
    c
}

/// ln Γ(x) for x > 0 (Lanczos, g = 7, n = 9; relative error ~1e-15).
fn ln_gamma(x: f64) -> f64 {
    const G: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection: Γ(x)Γ(1−x) = π / sin(πx).
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = G[0];
    let t = x + 7.5;
    for (i, g) in G.iter().enumerate().skip(1) {
        a += g / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// The regularised lower incomplete gamma function P(a, x) (Numerical Recipes §6.2:
/// series for x < a + 1, continued fraction otherwise).
fn gamma_p(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    let gln = ln_gamma(a);
    if x < a + 1.0 {
        let (mut sum, mut del, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..500 {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if del.abs() < sum.abs() * 1e-15 {
                break;
            }
        }
        (sum.ln() - x + a * x.ln() - gln).exp()
    } else {
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..500 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-15 {
                break;
            }
        }
        1.0 - (-x + a * x.ln() - gln).exp() * h
    }
}

/// The chi-square cumulative distribution function with `dof` degrees of freedom.
pub(crate) fn chi2_cdf(x: f64, dof: u32) -> f64 {
    gamma_p(0.5 * dof as f64, 0.5 * x)
}

/// The `p`-quantile of the chi-square distribution with `dof` degrees of freedom
/// (bisection on the CDF, to 1e-10 relative).
pub(crate) fn chi2_quantile(p: f64, dof: u32) -> f64 {
    let dof = dof.max(1);
    let p = p.clamp(1e-12, 1.0 - 1e-12);
    let mut lo = 0.0;
    let mut hi = dof as f64 + 10.0 * (2.0 * dof as f64).sqrt() + 50.0;
    while chi2_cdf(hi, dof) < p {
        hi *= 2.0;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if chi2_cdf(mid, dof) < p {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-10 * hi {
            break;
        }
    }
    0.5 * (lo + hi)
}

/// Indices to keep when drawing a path of `n` points with at most `max` points:
/// every k-th point, plus the last.
pub(crate) fn stride_indices(n: usize, max: usize) -> Vec<usize> {
    if n <= max || max < 2 {
        return (0..n).collect();
    }
    let k = n.div_ceil(max - 1);
    let mut idx: Vec<usize> = (0..n).step_by(k).collect();
    if idx.last() != Some(&(n - 1)) {
        idx.push(n - 1);
    }
    idx
}

/// Indices to keep when drawing a time series of `n` points with at most `max`
/// points: in each of `max / 2` buckets, the minimum and the maximum (in time
/// order), so spikes survive decimation. Non-finite values are kept as line breaks.
pub(crate) fn minmax_indices(v: &[f64], max: usize) -> Vec<usize> {
    let n = v.len();
    if n <= max || max < 4 {
        return (0..n).collect();
    }
    let buckets = max / 2;
    let size = n.div_ceil(buckets);
    let mut idx = Vec::with_capacity(max);
    for start in (0..n).step_by(size) {
        let end = (start + size).min(n);
        let (mut imin, mut imax, mut gap) = (None::<usize>, None::<usize>, None);
        for i in start..end {
            let x = v[i];
            if !x.is_finite() {
                gap.get_or_insert(i);
                continue;
            }
            if imin.is_none_or(|j| x < v[j]) {
                imin = Some(i);
            }
            if imax.is_none_or(|j| x > v[j]) {
                imax = Some(i);
            }
        }
        let mut keep: Vec<usize> = [imin, imax, gap].into_iter().flatten().collect();
        keep.sort_unstable();
        keep.dedup();
        idx.extend(keep);
    }
    idx
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chi2_quantiles_match_tables() {
        // Standard chi-square table values.
        let cases = [
            (0.975, 1, 5.023_886),
            (0.025, 1, 0.000_982_07),
            (0.975, 2, 7.377_759),
            (0.025, 2, 0.050_636),
            (0.999, 2, 13.815_511),
            (0.975, 3, 9.348_404),
            (0.025, 3, 0.215_795),
            (0.95, 10, 18.307_038),
        ];
        for (p, k, want) in cases {
            let got = chi2_quantile(p, k);
            assert!(
                (got - want).abs() < 1e-4 * want.max(1.0),
                "p={p} k={k}: {got} vs {want}"
            );
        }
    }

    #[test]
    fn quantiles_and_summary() {
        let s = summary(&[3.0, 1.0, f64::NAN, 2.0, 4.0]).unwrap();
        assert_eq!(s.n, 4);
        assert!((s.mean - 2.5).abs() < 1e-12);
        assert!((s.median - 2.5).abs() < 1e-12);
        assert!((s.std - (5.0f64 / 3.0).sqrt()).abs() < 1e-12);
        assert_eq!((s.min, s.max), (1.0, 4.0));
        assert!(summary(&[f64::NAN]).is_none());
    }

    #[test]
    fn histogram_counts_every_finite_value_once() {
        let a = [0.05, 0.1, 0.15, 0.9, 1.0, f64::NAN];
        let b = [0.3, 0.31];
        let e = bin_edges(&[&a, &b], 10);
        assert!(e[0] <= 0.05 && *e.last().unwrap() >= 1.0);
        assert_eq!(histogram(&a, &e).iter().sum::<usize>(), 5);
        assert_eq!(histogram(&b, &e).iter().sum::<usize>(), 2);
    }

    #[test]
    fn decimation_bounds_and_keeps_extremes() {
        let v: Vec<f64> = (0..100_000)
            .map(|i| {
                if i == 54_321 {
                    1e3
                } else {
                    (i as f64 * 0.01).sin()
                }
            })
            .collect();
        let idx = minmax_indices(&v, 4000);
        assert!(idx.len() <= 4000 + 4000 / 2, "{}", idx.len());
        assert!(idx.contains(&54_321));
        assert!(idx.windows(2).all(|w| w[0] < w[1]));
        let s = stride_indices(100_000, 4000);
        assert!(s.len() <= 4000);
        assert_eq!(*s.last().unwrap(), 99_999);
        assert_eq!(stride_indices(10, 4000).len(), 10);
    }
}
