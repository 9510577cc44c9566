//! The Rauch–Tung–Striebel smoother, eq. (20)–(22) of Welte et al., run backward
//! over the epochs recorded by the filter, with the very `F` and predicted
//! covariances the forward pass used.

use nalgebra::Cholesky;

use nalgebra::{SMatrix, SVector};

use crate::ekf::Epoch;
use crate::gnss_error::Wander;
use crate::model::Mat;
use crate::Error;

/// One smoothed epoch: x̂_{k|N} and P_{k|N}.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Smoothed<const N: usize = 5> {
    /// Timestamp, s.
    pub t_s: f64,
    /// x̂_{k|N}.
    pub x: SVector<f64, N>,
    /// P_{k|N}.
    pub p: SMatrix<f64, N, N>,
}

/// `F M` for `F = diag(f_car, I)`.
fn f_times<const N: usize>(f_car: &Mat, m: &SMatrix<f64, N, N>) -> SMatrix<f64, N, N> {
    let mut out = *m;
    let top = f_car * m.fixed_view::<5, N>(0, 0);
    out.fixed_view_mut::<5, N>(0, 0).copy_from(&top);
    out
}

/// The receiver's wander in a smoothed state: its index and model
/// ([`crate::gnss_error`]); between epochs `k` and `k + 1` its block of
/// `F` is `φ·I₂`, `φ = exp(−(t_{k+1} − t_k)/τ)`, which the recorded car
/// block does not hold.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WanderStates {
    /// Index of the wander's east component.
    pub index: usize,
    /// The wander's model.
    pub wander: Wander,
}

/// `F M` for `F = diag(f_car, I, φ·I₂)` (the wander's rows scaled by φ).
fn f_times_wander<const N: usize>(
    f_car: &Mat,
    m: &SMatrix<f64, N, N>,
    wander: Option<(usize, f64)>,
) -> SMatrix<f64, N, N> {
    let mut out = f_times(f_car, m);
    if let Some((w, phi)) = wander {
        for i in [w, w + 1] {
            for j in 0..N {
                out[(i, j)] *= phi;
            }
        }
    }
    out
}

/// `Fᵀ u` for `F = diag(f_car, I)`.
pub(crate) fn ft_times<const N: usize>(f_car: &Mat, u: &SVector<f64, N>) -> SVector<f64, N> {
    let mut out = *u;
    let top = f_car.transpose() * u.fixed_rows::<5>(0);
    out.fixed_rows_mut::<5>(0).copy_from(&top);
    out
}

/// One backward step: from the smoothed epoch k+1 and the filter's epochs k and
/// k+1, the smoothed epoch k.
pub fn step<const N: usize>(
    k: &Epoch<N>,
    k1: &Epoch<N>,
    s1: &Smoothed<N>,
) -> Result<Smoothed<N>, Error> {
    step_with(k, k1, s1, None)
}

/// [`step`] with the wander's block of `F`, `(index, φ)`, where the state
/// carries the receiver's wander.
pub(crate) fn step_with<const N: usize>(
    k: &Epoch<N>,
    k1: &Epoch<N>,
    s1: &Smoothed<N>,
    wander: Option<(usize, f64)>,
) -> Result<Smoothed<N>, Error> {
    // J_k = P_{k|k} F_{k+1}ᵀ P_{k+1|k}⁻¹   (22)
    // computed as the solution of P_{k+1|k} J_kᵀ = F_{k+1} P_{k|k} (P symmetric).
    let chol = Cholesky::new(k1.p_pred).ok_or_else(|| Error::Numerical {
        t_s: k1.t_s,
        what: "predicted covariance is not positive definite".into(),
    })?;
    let jt = chol.solve(&f_times_wander(&k1.f, &k.p, wander));
    let j = jt.transpose();
    // x̂_{k|N} = x̂_{k|k} + J_k (x̂_{k+1|N} − x̂_{k+1|k})   (20)
    let x = k.x + j * (s1.x - k1.x_pred);
    // P_{k|N} = P_{k|k} + J_k (P_{k+1|N} − P_{k+1|k}) J_kᵀ   (21)
    let p = k.p + j * (s1.p - k1.p_pred) * jt;
    let p = (p + p.transpose()) * 0.5;
    Ok(Smoothed { t_s: k.t_s, x, p })
}

/// Smooths the states only (eq. 20, 22), skipping the covariance recursion (21):
/// what the calibration's least squares needs, at about half the cost.
pub fn smooth_states<const N: usize>(
    epochs: &[Epoch<N>],
) -> Result<Vec<(f64, SVector<f64, N>)>, Error> {
    let n = epochs.len();
    let mut out = vec![(0.0, SVector::<f64, N>::zeros()); n];
    if n == 0 {
        return Ok(out);
    }
    out[n - 1] = (epochs[n - 1].t_s, epochs[n - 1].x);
    for k in (0..n - 1).rev() {
        let (e, e1) = (&epochs[k], &epochs[k + 1]);
        let chol = Cholesky::new(e1.p_pred).ok_or_else(|| Error::Numerical {
            t_s: e1.t_s,
            what: "predicted covariance is not positive definite".into(),
        })?;
        // Jᵀ = P_{k+1|k}⁻¹ F_{k+1} P_{k|k}; x̂_{k|N} = x̂_{k|k} + J (x̂_{k+1|N} − x̂_{k+1|k}).
        // J d = P F ᵀ P_pred⁻¹ d, so solve P_pred u = d and take P Fᵀ u (one vector solve).
        let u = chol.solve(&(out[k + 1].1 - e1.x_pred));
        out[k] = (e.t_s, e.x + e.p * ft_times(&e1.f, &u));
    }
    Ok(out)
}

/// Smooths a whole filter run. The last epoch is its own smoothed estimate.
pub fn smooth<const N: usize>(epochs: &[Epoch<N>]) -> Result<Vec<Smoothed<N>>, Error> {
    smooth_carrying(epochs, None)
}

/// [`smooth`] of a run whose state carries the receiver's wander
/// (`wander`: its index and model; `None` is [`smooth`]).
pub fn smooth_carrying<const N: usize>(
    epochs: &[Epoch<N>],
    wander: Option<WanderStates>,
) -> Result<Vec<Smoothed<N>>, Error> {
    let n = epochs.len();
    if n == 0 {
        return Ok(Vec::new());
    }
    let mut out = vec![
        Smoothed {
            t_s: 0.0,
            x: SVector::zeros(),
            p: SMatrix::zeros()
        };
        n
    ];
    out[n - 1] = Smoothed {
        t_s: epochs[n - 1].t_s,
        x: epochs[n - 1].x,
        p: epochs[n - 1].p,
    };
    for k in (0..n - 1).rev() {
        let (e, e1) = (&epochs[k], &epochs[k + 1]);
        let phi = wander.map(|w| (w.index, w.wander.phi((e1.t_s - e.t_s).max(0.0))));
        out[k] = step_with(e, e1, &out[k + 1], phi)?;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A symmetric positive definite N×N matrix with every cross term.
    fn spd<const N: usize>(seed: f64) -> SMatrix<f64, N, N> {
        let a = SMatrix::<f64, N, N>::from_fn(|i, j| ((i * N + j) as f64 * seed).sin());
        a * a.transpose() + SMatrix::<f64, N, N>::identity()
    }

    #[test]
    fn the_wander_step_is_the_textbook_step_with_the_whole_f() {
        // Eq. (20)–(22) with F = diag(f_car, φ·I₂) written out in full,
        // against the step that keeps F's car block and scales the
        // wander's rows (crate::gnss_error, N = 7).
        const N: usize = 7;
        let wander = Wander {
            std_m: 0.8,
            tau_s: 45.0,
        };
        let dt = 0.02;
        let f_car = Mat::from_fn(|i, j| {
            if i == j {
                1.0
            } else {
                0.01 * (i + 2 * j) as f64
            }
        });
        let k = Epoch::<N> {
            t_s: 10.0,
            x_pred: SVector::from_fn(|i, _| i as f64),
            p_pred: spd(0.41),
            f: Mat::identity(),
            x: SVector::from_fn(|i, _| 0.5 * i as f64 - 1.0),
            p: spd(0.37),
        };
        let k1 = Epoch::<N> {
            t_s: 10.0 + dt,
            x_pred: SVector::from_fn(|i, _| 0.3 * i as f64),
            p_pred: spd(0.53),
            f: f_car,
            x: SVector::from_fn(|i, _| 0.2 * i as f64 + 0.1),
            p: spd(0.29),
        };
        // The last epoch is its own smoothed estimate.
        let s1 = Smoothed {
            t_s: k1.t_s,
            x: k1.x,
            p: k1.p,
        };
        let phi = wander.phi(dt);
        let mut f = SMatrix::<f64, N, N>::identity();
        f.fixed_view_mut::<5, 5>(0, 0).copy_from(&f_car);
        f[(5, 5)] = phi;
        f[(6, 6)] = phi;
        let j = k.p * f.transpose() * k1.p_pred.try_inverse().unwrap();
        let want_x = k.x + j * (s1.x - k1.x_pred);
        let want_p = k.p + j * (s1.p - k1.p_pred) * j.transpose();
        let got = smooth_carrying(&[k, k1], Some(WanderStates { index: 5, wander })).unwrap();
        assert!((got[0].x - want_x).abs().max() < 1e-10);
        assert!((got[0].p - want_p).abs().max() < 1e-10);
        // Without the wander's block the smoother is another one.
        let plain = smooth(&[k, k1]).unwrap();
        assert!((plain[0].x - want_x).abs().max() > 1e-6);
    }
}
