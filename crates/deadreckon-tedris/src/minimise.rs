//! Bounded one-dimensional minimisation by Brent's method (golden section with
//! parabolic interpolation), used by the update phase to choose the dynamic
//! correction factor (eq. 6). Short enough to own rather than depend on argmin.

/// Minimises `f` on `[lo, hi]` to an absolute tolerance `tol`; returns `(x, f(x))`.
/// Non-finite values of `f` count as `+∞`. At most `max_iter` iterations.
pub fn brent<F: FnMut(f64) -> f64>(
    mut f: F,
    lo: f64,
    hi: f64,
    tol: f64,
    max_iter: usize,
) -> (f64, f64) {
    let mut eval = |x: f64| {
        let v = f(x);
        if v.is_finite() {
            v
        } else {
            f64::INFINITY
        }
    };
    const GOLD: f64 = 0.381_966_011_250_105_1; // (3 − √5) / 2
    let (mut a, mut b) = if lo <= hi { (lo, hi) } else { (hi, lo) };
    let mut x = a + GOLD * (b - a);
    let (mut w, mut v) = (x, x);
    let mut fx = eval(x);
    let (mut fw, mut fv) = (fx, fx);
    let (mut d, mut e) = (0.0f64, 0.0f64);
    for _ in 0..max_iter {
        let m = 0.5 * (a + b);
        let tol1 = tol + 1e-10 * x.abs();
        let tol2 = 2.0 * tol1;
        if (x - m).abs() <= tol2 - 0.5 * (b - a) {
            break;
        }
        let mut golden = true;
        if e.abs() > tol1 {
            // Parabola through (x, fx), (w, fw), (v, fv).
            let r = (x - w) * (fx - fv);
            let mut q = (x - v) * (fx - fw);
            let mut p = (x - v) * q - (x - w) * r;
            q = 2.0 * (q - r);
            if q > 0.0 {
                p = -p;
            }
            q = q.abs();
            if p.abs() < (0.5 * q * e).abs() && p > q * (a - x) && p < q * (b - x) {
                e = d;
                d = p / q;
                let u = x + d;
                if u - a < tol2 || b - u < tol2 {
                    d = if x < m { tol1 } else { -tol1 };
                }
                golden = false;
            }
        }
        if golden {
            e = if x < m { b - x } else { a - x };
            d = GOLD * e;
        }
        let u = if d.abs() >= tol1 {
            x + d
        } else {
            x + tol1.copysign(d)
        };
        let fu = eval(u);
        if fu <= fx {
            if u < x {
                b = x;
            } else {
                a = x;
            }
            (v, fv, w, fw, x, fx) = (w, fw, x, fx, u, fu);
        } else {
            if u < x {
                a = u;
            } else {
                b = u;
            }
            if fu <= fw || w == x {
                (v, fv, w, fw) = (w, fw, u, fu);
            } else if fu <= fv || v == x || v == w {
                (v, fv) = (u, fu);
            }
        }
    }
    (x, fx)
}

#[cfg(test)]
mod tests {
    use super::brent;

    #[test]
    fn finds_interior_and_boundary_minima() {
        let (x, _) = brent(|x| (x - 0.3).powi(2) + 1.0, -1.0, 2.0, 1e-9, 100);
        assert!((x - 0.3).abs() < 1e-6);
        let (x, _) = brent(|x| x, 0.0, 1.0, 1e-9, 100);
        assert!(x < 1e-6);
        let (x, _) = brent(|x| ((x - 1e-4) * 1e4).abs(), -1e-3, 1e-3, 1e-10, 200);
        assert!((x - 1e-4).abs() < 1e-8);
    }
}
