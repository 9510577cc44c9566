//! The GNSS receiver's slowly wandering position error as filter states.
//!
//! A standalone or SBAS receiver's position error is not white: it wanders
//! by a metre or so over a minute or two (atmosphere, orbits, the satellites
//! in view). Fused as white noise, such fixes pull the aided filter's heading
//! (they move sideways at about `σ·√(2/τ)` m/s) and its position, and an
//! outage inherits both. [`CarWanderLayout`] carries the wander as two more
//! states after the car's five, `[e_E, e_N]` (m), as the differential-drive
//! filter does ([`crate::kinematics::diff_drive::filter`]):
//!
//! ```text
//! z = p_antenna(x, y, ψ) + e + w,   w white (the fix's std_m)
//! e' = φ·e,   φ = exp(−dt/τ),   Q_e = σ²·(1 − φ²)   (first-order Gauss–Markov)
//! ```
//!
//! so the wander's variance stays `σ²` without fixes, and through an outage
//! its estimate decays as `e·exp(−t/τ)`: the part of the fixes' error still
//! expected at a fix hidden `t` later. `σ` and `τ` are the vehicle's
//! `[noise] gnss_wander_std_m` and `gnss_wander_tau_s`
//! ([`crate::vehicle::Noise`]); `gnss_wander_std_m = 0` (the default) is the
//! paper's white fixes and the five-state filter.
//!
//! A fix the χ² gate rejects (a multipath burst: metres for a few seconds)
//! changes neither the position nor the wander; see
//! [`crate::vehicle::Noise::gnss_recovery_after_s`] for when a run of
//! rejections is taken as the filter being lost instead.

use nalgebra::{SMatrix, SVector};

use crate::bound::Cov2;
use crate::model::{X, Y, YAW};

use crate::filter::Layout;

/// Index of the wander's east component in [`CarWanderLayout`]'s state.
pub const WANDER_E: usize = 5;
/// Index of the wander's north component in [`CarWanderLayout`]'s state.
pub const WANDER_N: usize = 6;
/// Dimension of the car state with the wander.
pub const N_WANDER: usize = 7;

/// The five car states then the receiver's wander `[e_E, e_N]`, m; the
/// parameters are fixed.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CarWanderLayout;

impl Layout<N_WANDER> for CarWanderLayout {
    const NAME: &'static str = "car+wander";
    fn param_index(_j: usize) -> Option<usize> {
        None
    }
    fn wander_index() -> Option<usize> {
        Some(WANDER_E)
    }
}

/// The wander's first-order Gauss–Markov model: standard deviation per axis
/// and time constant (params.toml `[model.gnss_wander]`:
/// [`crate::model_options::ModelOptions::gnss_wander`]).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Wander {
    /// Standard deviation per axis, m.
    pub std_m: f64,
    /// Time constant, s.
    pub tau_s: f64,
}

impl Wander {
    /// The transition factor over `dt_s`: `φ = exp(−dt/τ)`.
    pub fn phi(&self, dt_s: f64) -> f64 {
        (-dt_s / self.tau_s).exp()
    }

    /// The process noise variance per axis over `dt_s`: `σ²·(1 − φ²)`,
    /// which keeps the variance at `σ²`.
    pub fn process_var(&self, dt_s: f64) -> f64 {
        self.std_m * self.std_m * (1.0 - (-2.0 * dt_s / self.tau_s).exp())
    }

    /// Propagates the wander states at `w, w + 1` of `x` and `p` over
    /// `dt_s`, after every other state's propagation: with
    /// `F = diag(F_rest, φ·I₂)`, rows and columns `w, w + 1` of `P` are
    /// scaled by `φ` (the other blocks already stand at `F_rest P F_restᵀ`,
    /// which scaling the wander's rows and columns does not touch), then
    /// `Q_e` added. Exactly `F P Fᵀ + Q` for that `F`.
    pub fn propagate<const N: usize>(
        &self,
        w: usize,
        dt_s: f64,
        x: &mut SVector<f64, N>,
        p: &mut SMatrix<f64, N, N>,
    ) {
        if dt_s <= 0.0 {
            return;
        }
        let phi = self.phi(dt_s);
        let q = self.process_var(dt_s);
        for i in [w, w + 1] {
            x[i] *= phi;
            for j in 0..N {
                p[(i, j)] *= phi;
            }
            for j in 0..N {
                p[(j, i)] *= phi;
            }
            p[(i, i)] += q;
        }
    }
}

/// Adds the wander's columns (the identity at `w, w + 1`) to a GNSS
/// Jacobian and the wander to the predicted fix `h`: a fix measures the
/// antenna plus the wander.
pub fn add_wander<const N: usize>(
    w: usize,
    x: &SVector<f64, N>,
    h: &mut SVector<f64, 2>,
    jac: &mut SMatrix<f64, 2, N>,
) {
    h[0] += x[w];
    h[1] += x[w + 1];
    jac[(0, w)] = 1.0;
    jac[(1, w + 1)] = 1.0;
}

/// The receiver's wander's part of a filter covariance: its covariance
/// with `(X, Y, YAW)` (rows) and its own 2×2 block, m², m·rad.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct WanderCov {
    cross: [[f64; 2]; 3],
    block: [[f64; 2]; 2],
}

impl WanderCov {
    /// From a covariance whose wander starts at index `w`.
    pub(crate) fn of<const N: usize>(p: &SMatrix<f64, N, N>, w: usize) -> Self {
        let i = [X, Y, YAW];
        WanderCov {
            cross: std::array::from_fn(|r| std::array::from_fn(|c| p[(i[r], w + c)])),
            block: std::array::from_fn(|r| std::array::from_fn(|c| p[(w + r, w + c)])),
        }
    }

    /// The covariance of the fix predicted at the antenna (`lever_m` ahead
    /// of the rear axle at `yaw_rad`) plus the wander: `H P Hᵀ` with
    /// `H = [A | I₂]`, `A = [I₂ | l (−sin ψ, cos ψ)ᵀ]`; `antenna` is
    /// `A P_pose Aᵀ` ([`Cov2::ahead`]); what the outage evaluation's bound
    /// compares a hidden fix with ([`crate::outage`]).
    pub(crate) fn fix_cov(&self, antenna: Cov2, yaw_rad: f64, lever_m: f64) -> Cov2 {
        let j = [-lever_m * yaw_rad.sin(), lever_m * yaw_rad.cos()];
        // M = A · cross (2×2).
        let m = |r: usize, c: usize| self.cross[r][c] + j[r] * self.cross[2][c];
        Cov2 {
            ee_m2: antenna.ee_m2 + 2.0 * m(0, 0) + self.block[0][0],
            en_m2: antenna.en_m2 + m(0, 1) + m(1, 0) + 0.5 * (self.block[0][1] + self.block[1][0]),
            nn_m2: antenna.nn_m2 + 2.0 * m(1, 1) + self.block[1][1],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_propagation_is_f_p_ft_plus_q() {
        let wander = Wander {
            std_m: 1.2,
            tau_s: 40.0,
        };
        let a = SMatrix::<f64, 7, 7>::from_fn(|i, j| ((i * 7 + j) as f64 * 0.37).sin());
        let mut p = a * a.transpose() + SMatrix::<f64, 7, 7>::identity();
        let mut x = SVector::<f64, 7>::from_fn(|i, _| i as f64 - 2.0);
        let dt = 0.3;
        let phi = wander.phi(dt);
        let mut f = SMatrix::<f64, 7, 7>::identity();
        f[(5, 5)] = phi;
        f[(6, 6)] = phi;
        let mut q = SMatrix::<f64, 7, 7>::zeros();
        q[(5, 5)] = wander.process_var(dt);
        q[(6, 6)] = wander.process_var(dt);
        let want_p = f * p * f.transpose() + q;
        let want_x = f * x;
        wander.propagate(WANDER_E, dt, &mut x, &mut p);
        assert!((p - want_p).abs().max() < 1e-12);
        assert!((x - want_x).abs().max() < 1e-12);
        assert_eq!(p, p.transpose());
    }

    #[test]
    fn the_predicted_fix_covariance_is_h_p_ht_with_the_wander() {
        let a = SMatrix::<f64, 7, 7>::from_fn(|i, j| ((i * 7 + j) as f64 * 0.43).cos());
        let p = a * a.transpose() + SMatrix::<f64, 7, 7>::identity();
        let (yaw, lever) = (0.7_f64, 1.3);
        let mut h = SMatrix::<f64, 2, 7>::zeros();
        h[(0, X)] = 1.0;
        h[(1, Y)] = 1.0;
        h[(0, YAW)] = -lever * yaw.sin();
        h[(1, YAW)] = lever * yaw.cos();
        h[(0, WANDER_E)] = 1.0;
        h[(1, WANDER_N)] = 1.0;
        let want = h * p * h.transpose();
        let idx = [X, Y, YAW];
        let p3: [[f64; 3]; 3] =
            std::array::from_fn(|r| std::array::from_fn(|c| p[(idx[r], idx[c])]));
        let got = WanderCov::of(&p, WANDER_E).fix_cov(Cov2::ahead(&p3, yaw, lever), yaw, lever);
        assert!((got.ee_m2 - want[(0, 0)]).abs() < 1e-12);
        assert!((got.en_m2 - want[(0, 1)]).abs() < 1e-12);
        assert!((got.nn_m2 - want[(1, 1)]).abs() < 1e-12);
    }
}
