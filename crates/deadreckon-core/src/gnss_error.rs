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
}
