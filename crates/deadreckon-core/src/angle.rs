//! Angle helpers: wrapping and angle-aware differences.

use std::f64::consts::{PI, TAU};

/// Wraps an angle to (-π, π].
pub fn wrap(a: f64) -> f64 {
    let r = (a + PI).rem_euclid(TAU) - PI;
    if r <= -PI {
        r + TAU
    } else {
        r
    }
}

/// The difference `a - b` wrapped to (-π, π].
pub fn diff(a: f64, b: f64) -> f64 {
    wrap(a - b)
}

/// Removes the ±π (or 0/360°) discontinuities of a sequence of angles in radians,
/// so that consecutive values never differ by more than π.
pub fn unwrap(angles: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(angles.len());
    let mut offset = 0.0;
    let mut prev: Option<f64> = None;
    for &a in angles {
        if let Some(p) = prev {
            let d = a - p;
            if d > PI {
                offset -= TAU * ((d + PI) / TAU).floor();
            } else if d < -PI {
                offset += TAU * ((-d + PI) / TAU).floor();
            }
        }
        out.push(a + offset);
        prev = Some(a);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn wrap_range() {
        assert!((wrap(3.0 * PI) - PI).abs() < 1e-12);
        assert!((wrap(-PI) - PI).abs() < 1e-12);
        assert!((wrap(0.5) - 0.5).abs() < 1e-15);
        assert!((diff(PI - 0.1, -PI + 0.1) + 0.2).abs() < 1e-12);
    }
    #[test]
    fn unwrap_removes_jumps() {
        let a = [3.0, -3.0, -2.9, 3.1];
        let u = unwrap(&a);
        for w in u.windows(2) {
            assert!((w[1] - w[0]).abs() < PI);
        }
        assert!((u[1] - (-3.0 + TAU)).abs() < 1e-12);
    }
}
