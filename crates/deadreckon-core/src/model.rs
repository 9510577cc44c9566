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
//!
//! ## Rear-axle side slip (not in the paper; off by default)
//!
//! A tyre carrying a side force rolls at a slip angle to its plane, so the
//! rear-axle centre M does not move along the body axis: its velocity makes
//! the angle β_r with it. With a side-slip gradient `g` (rad per m/s²,
//! [`crate::Vehicle::rear_slip_gradient_rad_per_mps2`], the simulator's
//! convention), `β_r = −g·a_y` with the lateral acceleration `a_y = v·ψ̇`
//! (left positive: in a left turn the rear slides outwards, to the right;
//! reversing, `β_r = −g·|v|·ψ̇`: [`rear_slip_angle`]).
//! `v` stays the longitudinal speed of M (what the rear wheels roll at), so
//! M's velocity is `v·[1, tan β_r]` in the body frame, and the position step
//! ([`evolve_slipping`]) is
//!
//! ```text
//! θ = ψ_k + Te·ψ̇_k/2,  τ = tan(−g·v_k·ψ̇_k)
//! x_{k+1} = x_k + Te·v_k·(cos θ − τ·sin θ)
//! y_{k+1} = y_k + Te·v_k·(sin θ + τ·cos θ)
//! ```
//!
//! With `g = 0` this is eq. (3) exactly (the same floating-point operations:
//! [`evolve`] is [`evolve_slipping`] with 0). β_r enters rows X and Y only,
//! through columns ψ̇ and v, so the Jacobian keeps eq. (3)'s sparsity
//! ([`jacobian_times`], [`propagate_covariance`]).

use nalgebra::{SMatrix, SVector};

use crate::vehicle::{Noise, YawIntegration};

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

/// Eq. (3): the state after `dt` seconds (M moves along the body axis).
pub fn evolve(x: &State, dt: f64) -> State {
    evolve_slipping(x, dt, 0.0)
}

/// The side-slip angle of M's velocity against the body axis, rad:
/// `β_r = −g·|v|·ψ̇` (`−g·a_y` forwards; reversing turns its sign round, as
/// the tyre's side force still points into the turn) for the side-slip
/// gradient `g` (rad per m/s²), with its derivatives `∂β/∂v = −g·sign(v)·ψ̇`
/// and `∂β/∂ψ̇ = −g·|v|`.
#[inline]
pub fn rear_slip_angle(v: f64, yaw_rate: f64, slip_gradient: f64) -> (f64, f64, f64) {
    (
        -slip_gradient * v.abs() * yaw_rate,
        -slip_gradient * v.signum() * yaw_rate,
        -slip_gradient * v.abs(),
    )
}

/// The state after `dt` seconds with the rear-axle side slip of gradient
/// `slip_gradient` (rad per m/s²; see the module doc). With 0 it is eq. (3)
/// to the last bit.
pub fn evolve_slipping(x: &State, dt: f64, slip_gradient: f64) -> State {
    let heading = x[YAW] + 0.5 * dt * x[YAW_RATE];
    let (s, c) = heading.sin_cos();
    let mut n = *x;
    if slip_gradient == 0.0 {
        n[X] += dt * x[V] * c;
        n[Y] += dt * x[V] * s;
    } else {
        let tau = rear_slip_angle(x[V], x[YAW_RATE], slip_gradient).0.tan();
        n[X] += dt * x[V] * (c - tau * s);
        n[Y] += dt * x[V] * (s + tau * c);
    }
    n[YAW] += dt * x[YAW_RATE];
    n
}

/// The Jacobian F = ∂f/∂x of [`evolve`] at `x`, filled entry by entry.
pub fn jacobian(x: &State, dt: f64) -> Mat {
    jacobian_slipping(x, dt, 0.0)
}

/// The Jacobian F = ∂f/∂x of [`evolve_slipping`] at `x`, filled entry by
/// entry: with `τ = tan β_r`, `τ_v = ∂τ/∂v = (1 + τ²)·∂β/∂v` and `τ_ω =
/// ∂τ/∂ψ̇`,
///
/// ```text
/// ∂x'/∂ψ = −Te·v·(sin θ + τ cos θ)      ∂y'/∂ψ = Te·v·(cos θ − τ sin θ)
/// ∂x'/∂v = Te·(cos θ − τ sin θ) − Te·v·τ_v·sin θ
/// ∂y'/∂v = Te·(sin θ + τ cos θ) + Te·v·τ_v·cos θ
/// ∂x'/∂ψ̇ = Te/2·∂x'/∂ψ − Te·v·τ_ω·sin θ
/// ∂y'/∂ψ̇ = Te/2·∂y'/∂ψ + Te·v·τ_ω·cos θ
/// ```
pub fn jacobian_slipping(x: &State, dt: f64, slip_gradient: f64) -> Mat {
    let heading = x[YAW] + 0.5 * dt * x[YAW_RATE];
    let (s, c) = heading.sin_cos();
    let v = x[V];
    let mut f = Mat::identity();
    if slip_gradient == 0.0 {
        f[(X, YAW)] = -dt * v * s;
        f[(X, V)] = dt * c;
        f[(X, YAW_RATE)] = -0.5 * dt * dt * v * s;
        f[(Y, YAW)] = dt * v * c;
        f[(Y, V)] = dt * s;
        f[(Y, YAW_RATE)] = 0.5 * dt * dt * v * c;
    } else {
        let (beta, dbeta_dv, dbeta_dw) = rear_slip_angle(x[V], x[YAW_RATE], slip_gradient);
        let tau = beta.tan();
        let sec2 = 1.0 + tau * tau;
        let (tau_v, tau_w) = (sec2 * dbeta_dv, sec2 * dbeta_dw);
        let (ux, uy) = (c - tau * s, s + tau * c);
        f[(X, YAW)] = -dt * v * uy;
        f[(X, V)] = dt * ux - dt * v * tau_v * s;
        f[(X, YAW_RATE)] = -0.5 * dt * dt * v * uy - dt * v * tau_w * s;
        f[(Y, YAW)] = dt * v * ux;
        f[(Y, V)] = dt * uy + dt * v * tau_v * c;
        f[(Y, YAW_RATE)] = 0.5 * dt * dt * v * ux + dt * v * tau_w * c;
    }
    f[(YAW, YAW_RATE)] = dt;
    f
}

/// `F c` for a column `c` of 5 and `F` shaped as [`jacobian`] returns it: the
/// identity but for rows X and Y (columns ψ, v, ψ̇) and entry (ψ, ψ̇). The
/// sums run in column order, as a dense product would add them, so the result
/// equals `f * c` to the last bit (but for the sign of a zero).
#[inline]
pub fn jacobian_times(f: &Mat, c: &[f64; N]) -> [f64; N] {
    debug_assert!(has_jacobian_shape(f));
    shaped_times(f, c)
}

/// [`jacobian_times`] without its `debug_assert!` of `f`'s shape, for a
/// caller that checked it once for every column it multiplies (the check,
/// 25 comparisons, made for each of the 10–16 columns of a prediction was
/// 5.8 % of the default `calibrate`'s CPU time in the `ci` profile, which
/// keeps debug assertions: `perf record` on the 10-minute drive,
/// docs/performance.md, "Ninth round").
#[inline]
pub(crate) fn shaped_times(f: &Mat, c: &[f64; N]) -> [f64; N] {
    let (a, b, e) = (f[(X, YAW)], f[(X, V)], f[(X, YAW_RATE)]);
    let (g, h, k) = (f[(Y, YAW)], f[(Y, V)], f[(Y, YAW_RATE)]);
    let l = f[(YAW, YAW_RATE)];
    [
        c[X] + a * c[YAW] + b * c[V] + e * c[YAW_RATE],
        c[Y] + g * c[YAW] + h * c[V] + k * c[YAW_RATE],
        c[YAW] + l * c[YAW_RATE],
        c[V],
        c[YAW_RATE],
    ]
}

/// Eq. (12) for the car block, `P⁻ = F P Fᵀ + Q` symmetrised, with `F` shaped
/// as [`jacobian`] returns it: equal to the dense
/// [`crate::kalman::predict_covariance`] to the last bit (but for the sign of
/// a zero) in about a fifth of the operations.
pub fn propagate_covariance(p: &Mat, f: &Mat, q: &Mat) -> Mat {
    // The shape checked once for the ten products below.
    debug_assert!(has_jacobian_shape(f));
    // A = F P, column by column.
    let mut a = Mat::zeros();
    for j in 0..N {
        let col: [f64; N] = std::array::from_fn(|i| p[(i, j)]);
        a.column_mut(j).copy_from_slice(&shaped_times(f, &col));
    }
    // (A Fᵀ)ᵀ = F Aᵀ: row i of A Fᵀ is F times row i of A.
    let mut pp = Mat::zeros();
    for i in 0..N {
        let row: [f64; N] = std::array::from_fn(|k| a[(i, k)]);
        let r = shaped_times(f, &row);
        for j in 0..N {
            pp[(i, j)] = r[j] + q[(i, j)];
        }
    }
    (pp + pp.transpose()) * 0.5
}

/// Whether `f` has the sparsity of [`jacobian`] (ones on the diagonal, zeros
/// off the entries it fills).
fn has_jacobian_shape(f: &Mat) -> bool {
    let filled = [
        (X, YAW),
        (X, V),
        (X, YAW_RATE),
        (Y, YAW),
        (Y, V),
        (Y, YAW_RATE),
        (YAW, YAW_RATE),
    ];
    (0..N).all(|i| {
        (0..N).all(|j| {
            i == j && f[(i, j)] == 1.0 || i != j && (filled.contains(&(i, j)) || f[(i, j)] == 0.0)
        })
    })
}

/// The process noise Q for a step of `dt` seconds.
///
/// Table I gives standard deviations per 20 ms step; for other steps the
/// variances scale linearly with `dt / noise.process_step_s` (random-walk noise).
/// With [`YawIntegration::Trapezoidal`] the yaw rate's noise `q_ψ̇` also
/// reaches the yaw over the step: `Q_ψψ̇ = dt/2 · q_ψ̇`, `Q_ψψ += dt²/4 · q_ψ̇`.
pub fn process_noise(noise: &Noise, dt: f64) -> Mat {
    let k = (dt / noise.process_step_s).max(0.0);
    let mut q = Mat::zeros();
    q[(X, X)] = k * noise.process_xy_m.powi(2);
    q[(Y, Y)] = k * noise.process_xy_m.powi(2);
    q[(YAW, YAW)] = k * noise.process_yaw_rad.powi(2);
    q[(V, V)] = k * noise.process_speed_mps.powi(2);
    q[(YAW_RATE, YAW_RATE)] = k * noise.process_yaw_rate_rps.powi(2);
    if noise.yaw_integration == YawIntegration::Trapezoidal {
        // ψ_{k+1} = ψ_k + dt ψ̇_k + dt/2 · w, ψ̇_{k+1} = ψ̇_k + w, w ~ N(0, q_ψ̇).
        let w = q[(YAW_RATE, YAW_RATE)];
        q[(YAW, YAW)] += 0.25 * dt * dt * w;
        q[(YAW, YAW_RATE)] = 0.5 * dt * w;
        q[(YAW_RATE, YAW)] = 0.5 * dt * w;
    }
    q
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jacobian_matches_finite_differences() {
        // g = 0 (eq. 3), a car's gradient and an exaggerated one, at a long
        // step too so that the slip terms are not hidden under dt².
        for g in [0.0, 0.005, 0.04] {
            for dt in [0.02, 0.5] {
                for x in [
                    State::from([3.0, -2.0, 0.7, 8.3, 0.21]),
                    State::from([-1.0, 4.0, -2.4, 22.0, -0.3]),
                    State::from([0.0, 0.0, 3.0, -3.0, 0.5]),
                ] {
                    let f = jacobian_slipping(&x, dt, g);
                    assert!(has_jacobian_shape(&f), "g {g}: sparsity changed");
                    for j in 0..N {
                        let h = 1e-6;
                        let mut xp = x;
                        let mut xm = x;
                        xp[j] += h;
                        xm[j] -= h;
                        let d =
                            (evolve_slipping(&xp, dt, g) - evolve_slipping(&xm, dt, g)) / (2.0 * h);
                        for i in 0..N {
                            assert!(
                                (d[i] - f[(i, j)]).abs() < 1e-7 * (1.0 + d[i].abs()),
                                "g {g} dt {dt} F[{i},{j}] {} vs {}",
                                f[(i, j)],
                                d[i]
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn zero_slip_is_eq_3_to_the_last_bit() {
        let x = State::from([3.0, -2.0, 0.7, 8.3, 0.21]);
        assert_eq!(evolve_slipping(&x, 0.02, 0.0), evolve(&x, 0.02));
        assert_eq!(jacobian_slipping(&x, 0.02, 0.0), jacobian(&x, 0.02));
        let heading = 0.7 + 0.5 * 0.02 * 0.21;
        let n = evolve(&x, 0.02);
        assert_eq!(n[X], 3.0 + 0.02 * 8.3 * f64::cos(heading));
    }

    #[test]
    fn a_left_turn_slides_the_rear_axle_outwards() {
        // 20 m/s at 0.2 rad/s: a_y = 4 m/s², g = 0.005 ⇒ β = −0.02 rad.
        let g = 0.005;
        let x = State::from([0.0, 0.0, 0.0, 20.0, 0.2]);
        let (beta, _, _) = rear_slip_angle(x[V], x[YAW_RATE], g);
        assert!((beta + 0.02).abs() < 1e-15);
        let dt = 1e-3;
        let n = evolve_slipping(&x, dt, g);
        // The course of M is ψ + β: to the right of the body axis (ψ + dt·ψ̇/2).
        let course = n[Y].atan2(n[X]);
        assert!((course - (0.5 * dt * 0.2 - 0.02)).abs() < 1e-12, "{course}");
        // Its longitudinal component is v: the speed is v / cos β.
        let speed = n[X].hypot(n[Y]) / dt;
        assert!((speed - 20.0 / 0.02f64.cos()).abs() < 1e-9, "{speed}");
    }

    #[test]
    fn the_structured_covariance_step_equals_the_dense_one_with_slip() {
        let x = State::from([3.0, -2.0, 0.7, 8.3, 0.21]);
        let f = jacobian_slipping(&x, 0.02, 0.006);
        let l =
            Mat::from_fn(|i, j| ((i * 7 + j * 3) % 5) as f64 * 0.3 - 0.4 + (i == j) as u8 as f64);
        let p = l * l.transpose();
        let q = process_noise(&crate::vehicle::Vehicle::paper_car().noise, 0.02);
        let dense = crate::kalman::predict_covariance(&p, &f, &q);
        assert_eq!(propagate_covariance(&p, &f, &q), dense);
    }

    #[test]
    fn the_structured_covariance_step_equals_the_dense_one() {
        let x = State::from([3.0, -2.0, 0.7, 8.3, 0.21]);
        let f = jacobian(&x, 0.02);
        let l =
            Mat::from_fn(|i, j| ((i * 7 + j * 3) % 5) as f64 * 0.3 - 0.4 + (i == j) as u8 as f64);
        let p = l * l.transpose();
        let q = process_noise(&crate::vehicle::Vehicle::paper_car().noise, 0.02);
        let dense = crate::kalman::predict_covariance(&p, &f, &q);
        assert_eq!(propagate_covariance(&p, &f, &q), dense);
        let c = [0.3, -1.2, 0.05, 2.0, -0.4];
        let v = f * State::from(c);
        assert_eq!(jacobian_times(&f, &c), [v[0], v[1], v[2], v[3], v[4]]);
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
