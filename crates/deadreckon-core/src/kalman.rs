//! Kalman filter steps, generic over the state dimension: prediction (eq. 11–12)
//! and update (eq. 13–17), with the Joseph-form covariance update by default.
//!
//! These are the only places that touch covariances in the filter, so the
//! numerical safeguards live here: symmetrisation after every step and an
//! [`Error::Numerical`] (never a panic) when an innovation covariance is not
//! positive.

use nalgebra::{SMatrix, SVector};

use crate::Error;

/// How the updated covariance is computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub enum CovarianceForm {
    /// `P = (I − K H) P (I − K H)ᵀ + K R Kᵀ`: stays symmetric positive definite
    /// under rounding and for non-optimal gains.
    #[default]
    Joseph,
    /// Eq. (17): `P = (I − K H) P`, cheaper, as printed in the paper.
    Simple,
}

/// The result of one update, for filter-health diagnostics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Innovation {
    /// The innovation ỹ (first component for vector updates).
    pub y: f64,
    /// The innovation variance S (first diagonal element for vector updates).
    pub s: f64,
    /// The normalised innovation squared ỹᵀ S⁻¹ ỹ.
    pub nis: f64,
}

/// Eq. (12): `P⁻ = F P Fᵀ + Q`, symmetrised.
pub fn predict_covariance<const N: usize>(
    p: &SMatrix<f64, N, N>,
    f: &SMatrix<f64, N, N>,
    q: &SMatrix<f64, N, N>,
) -> SMatrix<f64, N, N> {
    let pp = f * p * f.transpose() + q;
    (pp + pp.transpose()) * 0.5
}

/// Eq. (13)–(17) for one scalar measurement with innovation `y = z − h(x)`,
/// Jacobian row `h` and variance `r`. Updates `x` and `p` in place.
pub fn update_scalar<const N: usize>(
    x: &mut SVector<f64, N>,
    p: &mut SMatrix<f64, N, N>,
    y: f64,
    h: &SVector<f64, N>,
    r: f64,
    form: CovarianceForm,
    t_s: f64,
) -> Result<Innovation, Error> {
    let pre = ScalarInnovation::new(p, h, r, y, t_s)?;
    pre.apply(x, p, form);
    Ok(pre.innovation())
}

/// Eq. (14) for one scalar measurement, before the update: `P Hᵀ` and
/// `S = H P Hᵀ + R`, checked usable, so the caller can gate on the NIS and
/// then [`ScalarInnovation::apply`] without computing them again.
#[derive(Debug, Clone, Copy)]
pub struct ScalarInnovation<const N: usize> {
    ph: SVector<f64, N>,
    /// Innovation.
    pub y: f64,
    /// Innovation variance S.
    pub s: f64,
}

impl<const N: usize> ScalarInnovation<N> {
    /// `P Hᵀ` (using only the non-zero entries of H) and `S`, with the innovation `y`.
    pub fn new(
        p: &SMatrix<f64, N, N>,
        h: &SVector<f64, N>,
        r: f64,
        y: f64,
        t_s: f64,
    ) -> Result<Self, Error> {
        let mut nz = [(0usize, 0.0f64); N];
        let mut n = 0;
        for (j, &hj) in h.iter().enumerate() {
            if hj != 0.0 {
                nz[n] = (j, hj);
                n += 1;
            }
        }
        Self::sparse(p, &nz[..n], r, y, t_s)
    }

    /// As [`ScalarInnovation::new`] with H given by its non-zero entries
    /// `(column, value)`, in increasing column order (each once).
    pub fn sparse(
        p: &SMatrix<f64, N, N>,
        h: &[(usize, f64)],
        r: f64,
        y: f64,
        t_s: f64,
    ) -> Result<Self, Error> {
        let mut ph = [0.0f64; N];
        let m = p.as_slice();
        for &(j, hj) in h {
            for (o, &c) in ph.iter_mut().zip(&m[j * N..(j + 1) * N]) {
                *o += hj * c;
            }
        }
        Self::finish(ph, h, r, y, t_s)
    }

    fn finish(ph: [f64; N], h: &[(usize, f64)], r: f64, y: f64, t_s: f64) -> Result<Self, Error> {
        // S = H P Hᵀ + R   (14)
        let s = h.iter().map(|&(j, hj)| hj * ph[j]).sum::<f64>() + r;
        if !(s.is_finite() && s > 0.0 && y.is_finite()) {
            return Err(Error::Numerical {
                t_s,
                what: format!("innovation variance {s} or innovation {y} is not usable"),
            });
        }
        Ok(ScalarInnovation {
            ph: SVector::<f64, N>::from(ph),
            y,
            s,
        })
    }

    /// The normalised innovation squared ỹ² / S.
    pub fn nis(&self) -> f64 {
        self.y * self.y / self.s
    }

    /// The diagnostics of this innovation.
    pub fn innovation(&self) -> Innovation {
        Innovation {
            y: self.y,
            s: self.s,
            nis: self.nis(),
        }
    }

    /// Eq. (15)–(17): updates `x` and `p` in place.
    ///
    /// For a scalar measurement with the optimal gain K = P Hᵀ / S, the Joseph
    /// form (I − K H) P (I − K H)ᵀ + K R Kᵀ and eq. (17) (I − K H) P are the
    /// same matrix, P − (P H)(P H)ᵀ / S; both [`CovarianceForm`]s compute it
    /// that way (one product per entry, computed identically for (i, j) and
    /// (j, i), so P stays exactly symmetric). The forms differ for vector
    /// measurements ([`update_vector`]).
    pub fn apply(
        &self,
        x: &mut SVector<f64, N>,
        p: &mut SMatrix<f64, N, N>,
        _form: CovarianceForm,
    ) {
        let (ph, s, y) = (&self.ph, self.s, self.y);
        // K = P Hᵀ S⁻¹   (15);  x̂ = x̂⁻ + K ỹ   (16)
        x.axpy(y / s, ph, 1.0);
        // P − (P H)(P H)ᵀ / S = P − k kᵀ with k = P H / √S: one product per
        // entry, every column at full length (vectorised). kᵢ kⱼ is the same
        // product for (i, j) and (j, i), so P stays exactly symmetric.
        let scale = s.sqrt().recip();
        let k: [f64; N] = std::array::from_fn(|i| ph[i] * scale);
        for (col, &kj) in p.data.0.iter_mut().zip(&k) {
            for (c, &ki) in col.iter_mut().zip(&k) {
                *c -= ki * kj;
            }
        }
    }

    /// The Schmidt ("consider") update: as [`ScalarInnovation::apply`] but the
    /// states where `hold` is true are not corrected; their covariance with
    /// the others follows, so P stays the covariance of the held states' error
    /// (`P − Kₛ h P − P hᵀ Kₛᵀ + Kₛ S Kₛᵀ`, Kₛ the gain with the held rows 0).
    pub fn apply_holding(
        &self,
        x: &mut SVector<f64, N>,
        p: &mut SMatrix<f64, N, N>,
        hold: &[bool; N],
    ) {
        let (ph, s, y) = (&self.ph, self.s, self.y);
        let ks: SVector<f64, N> = SVector::from_fn(|i, _| if hold[i] { 0.0 } else { ph[i] / s });
        x.axpy(y, &ks, 1.0);
        let d = ks * ph.transpose();
        let out = *p - d - d.transpose() + ks * ks.transpose() * s;
        *p = (out + out.transpose()) * 0.5;
    }
}

/// [`update_vector`] holding the states where `hold` is true (the Schmidt
/// update of [`ScalarInnovation::apply_holding`]). The covariance is always
/// the Joseph form's, `P − K H P − P Hᵀ Kᵀ + K S Kᵀ`, which holds for any
/// gain: [`CovarianceForm::Simple`], `(I − K H) P`, is right only for the
/// optimal one.
pub fn update_vector_holding<const N: usize, const M: usize>(
    x: &mut SVector<f64, N>,
    p: &mut SMatrix<f64, N, N>,
    y: &SVector<f64, M>,
    h: &SMatrix<f64, M, N>,
    r: &SMatrix<f64, M, M>,
    hold: &[bool; N],
    t_s: f64,
) -> Result<(), Error> {
    let (s, s_inv, _) = innovation_stats(p, y, h, r, t_s)?;
    let hp = h * *p;
    let mut k = hp.transpose() * s_inv;
    for (i, &held) in hold.iter().enumerate() {
        if held {
            k.row_mut(i).fill(0.0);
        }
    }
    *x += k * y;
    let d = k * hp;
    let out = *p - d - d.transpose() + k * s * k.transpose();
    *p = (out + out.transpose()) * 0.5;
    Ok(())
}

/// Innovation statistics of an `M`-dimensional measurement without updating:
/// returns `(S, S⁻¹, NIS)` so the caller can gate before [`update_vector`].
pub fn innovation_stats<const N: usize, const M: usize>(
    p: &SMatrix<f64, N, N>,
    y: &SVector<f64, M>,
    h: &SMatrix<f64, M, N>,
    r: &SMatrix<f64, M, M>,
    t_s: f64,
) -> Result<(SMatrix<f64, M, M>, SMatrix<f64, M, M>, f64), Error> {
    let s = h * p * h.transpose() + r;
    let s_inv = s.try_inverse().ok_or_else(|| Error::Numerical {
        t_s,
        what: "innovation covariance is singular".into(),
    })?;
    let nis = (y.transpose() * s_inv * y)[(0, 0)];
    if !nis.is_finite() || nis < 0.0 {
        return Err(Error::Numerical {
            t_s,
            what: format!("normalised innovation squared {nis} is not usable"),
        });
    }
    Ok((s, s_inv, nis))
}

/// Eq. (13)–(17) for an `M`-dimensional measurement with innovation `y`.
pub fn update_vector<const N: usize, const M: usize>(
    x: &mut SVector<f64, N>,
    p: &mut SMatrix<f64, N, N>,
    y: &SVector<f64, M>,
    h: &SMatrix<f64, M, N>,
    r: &SMatrix<f64, M, M>,
    form: CovarianceForm,
    t_s: f64,
) -> Result<Innovation, Error> {
    let (s, s_inv, nis) = innovation_stats(p, y, h, r, t_s)?;
    // H P, then K = P Hᵀ S⁻¹ = (H P)ᵀ S⁻¹ (P symmetric).
    let hp = h * *p;
    let k = hp.transpose() * s_inv;
    *x += k * y;
    // (I − K H) P = P − K (H P): M·N² products instead of N³.
    let b = *p - k * hp;
    *p = match form {
        // (I − K H) P (I − K H)ᵀ + K R Kᵀ, the right factor applied as
        // B − (B Hᵀ) Kᵀ: the same products in another order.
        CovarianceForm::Joseph => b - (b * h.transpose()) * k.transpose() + k * r * k.transpose(),
        CovarianceForm::Simple => b,
    };
    *p = (*p + p.transpose()) * 0.5;
    Ok(Innovation {
        y: y[0],
        s: s[(0, 0)],
        nis,
    })
}
