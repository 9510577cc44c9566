//! Helpers on time series shared by the corrections' estimators
//! ([`crate::timing`], [`crate::imu`], [`crate::traction`],
//! [`crate::gyro_scale`]): interpolation and the lag-one autocorrelation.
//! A leaf: it imports none of them.

/// Linear interpolation of `(t, v)` samples sorted by time; `None` outside.
pub(crate) fn interp(s: &[(f64, f64)], t: f64) -> Option<f64> {
    let n = s.len();
    if n == 0 || !(t >= s[0].0 && t <= s[n - 1].0) {
        return None;
    }
    let i = s.partition_point(|p| p.0 <= t);
    if i >= n {
        return Some(s[n - 1].1);
    }
    let i = i.max(1);
    let (a, b) = (s[i - 1], s[i]);
    let w = if b.0 > a.0 {
        (t - a.0) / (b.0 - a.0)
    } else {
        0.0
    };
    Some(a.1 * (1.0 - w) + b.1 * w)
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
