//! The Rauch–Tung–Striebel smoother, eq. (20)–(22) of Welte et al., run backward
//! over the epochs recorded by the filter, with the very `F` and predicted
//! covariances the forward pass used.

use nalgebra::Cholesky;

use nalgebra::{SMatrix, SVector};

use crate::ekf::Epoch;
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
    // J_k = P_{k|k} F_{k+1}ᵀ P_{k+1|k}⁻¹   (22)
    // computed as the solution of P_{k+1|k} J_kᵀ = F_{k+1} P_{k|k} (P symmetric).
    let chol = Cholesky::new(k1.p_pred).ok_or_else(|| Error::Numerical {
        t_s: k1.t_s,
        what: "predicted covariance is not positive definite".into(),
    })?;
    let jt = chol.solve(&f_times(&k1.f, &k.p));
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
        out[k] = step(&epochs[k], &epochs[k + 1], &out[k + 1])?;
    }
    Ok(out)
}
