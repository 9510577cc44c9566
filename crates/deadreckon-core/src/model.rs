//! The car's evolution model, eq. (1)–(3) of Welte et al.
//!
//! The state is `x = [x, y, ψ, v, ψ̇]ᵀ`: the position of the rear-axle centre M
//! (east, north, m), the yaw ψ (rad, counter-clockwise from east, *not* wrapped:
//! it stays continuous so that differences between states are small), the
//! longitudinal speed v (m/s) and the yaw rate ψ̇ (rad/s).
//!
//! Evolution over a step `Te` (eq. 3), with a circular-arc position update:
//!
//! ```text
//! x_{k+1} = x_k + Te·v_k·cos(ψ_k + Te·ψ̇_k/2)
//! y_{k+1} = y_k + Te·v_k·sin(ψ_k + Te·ψ̇_k/2)
//! ψ_{k+1} = ψ_k + Te·ψ̇_k
//! v_{k+1} = v_k,   ψ̇_{k+1} = ψ̇_k
//! ```

use nalgebra::{SMatrix, SVector};

use crate::vehicle::Noise;

/// Dimension of the car state.
pub const N: usize = 5;
/// The car state `[x, y, ψ, v, ψ̇]`.
pub type State = SVector<f64, N>;
/// A 5×5 matrix (covariance, Jacobian).
pub type Mat = SMatrix<f64, N, N>;
/// A measurement Jacobian row, stored as a column vector.
pub type Row = SVector<f64, N>;

/// Index of the east position, m.
pub const X: usize = 0;
/// Index of the north position, m.
pub const Y: usize = 1;
/// Index of the yaw ψ, rad.
pub const YAW: usize = 2;
/// Index of the speed v, m/s.
pub const V: usize = 3;
/// Index of the yaw rate ψ̇, rad/s.
pub const YAW_RATE: usize = 4;

/// Eq. (3): the state after `dt` seconds.
pub fn evolve(x: &State, dt: f64) -> State {
    let heading = x[YAW] + 0.5 * dt * x[YAW_RATE];
    let (s, c) = heading.sin_cos();
    let mut n = *x;
    n[X] += dt * x[V] * c;
    n[Y] += dt * x[V] * s;
    n[YAW] += dt * x[YAW_RATE];
    n
}

/// The Jacobian F = ∂f/∂x of [`evolve`] at `x`, filled entry by entry.
pub fn jacobian(x: &State, dt: f64) -> Mat {
    let heading = x[YAW] + 0.5 * dt * x[YAW_RATE];
    let (s, c) = heading.sin_cos();
    let v = x[V];
    let mut f = Mat::identity();
    f[(X, YAW)] = -dt * v * s;
    f[(X, V)] = dt * c;
    f[(X, YAW_RATE)] = -0.5 * dt * dt * v * s;
    f[(Y, YAW)] = dt * v * c;
    f[(Y, V)] = dt * s;
    f[(Y, YAW_RATE)] = 0.5 * dt * dt * v * c;
    f[(YAW, YAW_RATE)] = dt;
    f
}

/// The process noise Q for a step of `dt` seconds.
///
/// Table I gives standard deviations per 20 ms step; for other steps the
/// variances scale linearly with `dt / noise.process_step_s` (random-walk noise).
pub fn process_noise(noise: &Noise, dt: f64) -> Mat {
    let k = (dt / noise.process_step_s).max(0.0);
    let mut q = Mat::zeros();
    q[(X, X)] = k * noise.process_xy_m.powi(2);
    q[(Y, Y)] = k * noise.process_xy_m.powi(2);
    q[(YAW, YAW)] = k * noise.process_yaw_rad.powi(2);
    q[(V, V)] = k * noise.process_speed_mps.powi(2);
    q[(YAW_RATE, YAW_RATE)] = k * noise.process_yaw_rate_rps.powi(2);
    q
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jacobian_matches_finite_differences() {
        let x = State::from([3.0, -2.0, 0.7, 8.3, 0.21]);
        let dt = 0.02;
        let f = jacobian(&x, dt);
        for j in 0..N {
            let h = 1e-6;
            let mut xp = x;
            let mut xm = x;
            xp[j] += h;
            xm[j] -= h;
            let d = (evolve(&xp, dt) - evolve(&xm, dt)) / (2.0 * h);
            for i in 0..N {
                assert!(
                    (d[i] - f[(i, j)]).abs() < 1e-8,
                    "F[{i},{j}] {} vs {}",
                    f[(i, j)],
                    d[i]
                );
            }
        }
    }

    #[test]
    fn straight_and_circle() {
        let x = State::from([0.0, 0.0, 0.0, 10.0, 0.0]);
        let n = evolve(&x, 1.0);
        assert!((n[X] - 10.0).abs() < 1e-12 && n[Y].abs() < 1e-12);
        // A quarter circle of radius 10 m in 100 steps stays within 1 mm of the arc.
        let r = 10.0;
        let mut s = State::from([0.0, 0.0, 0.0, 1.0, 1.0 / r]);
        let steps = 1000;
        let dt = (std::f64::consts::FRAC_PI_2 * r) / steps as f64;
        for _ in 0..steps {
            s = evolve(&s, dt);
        }
        assert!((s[X] - r).abs() < 1e-3 && (s[Y] - r).abs() < 1e-3, "{s}");
    }
}
