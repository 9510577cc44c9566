//! The observation models, eq. (4)–(8) and (10) of Welte et al., with their
//! Jacobians. Each scalar model returns the predicted measurement `h(x, p)` and
//! the Jacobian row `H = ∂h/∂x`.
//!
//! Wheel order everywhere is FL, FR, RL, RR (the order of [`Params::circumferences`]).

use crate::model::{Row, State, V, X, Y, YAW, YAW_RATE};
use crate::vehicle::{Params, Vehicle};

/// Index of the front-left wheel.
pub const FL: usize = 0;
/// Index of the front-right wheel.
pub const FR: usize = 1;
/// Index of the rear-left wheel.
pub const RL: usize = 2;
/// Index of the rear-right wheel.
pub const RR: usize = 3;

/// The model quantities the observation models need, taken from the vehicle and
/// the current parameter estimate.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Sensors {
    /// l_RF, m.
    pub wheelbase_m: f64,
    /// l_F, m.
    pub track_front_m: f64,
    /// l_R, m.
    pub track_rear_m: f64,
    /// l_GNSS, m.
    pub lever_arm_m: f64,
    /// N_wheel.
    pub ticks_per_rev: f64,
    /// Nominal circumference used by the ECU to compute reported wheel speeds, m.
    pub nominal_circumference_m: f64,
    /// r_s.
    pub steering_ratio: f64,
    /// The calibration parameters p.
    pub params: Params,
    /// 1/ρ for FL, FR, RL, RR, 1/m.
    pub inv_circumference: [f64; 4],
}

/// Wheel angle above which the filter takes the steering as the constraint
/// [`Sensors::steering_constraint`] instead of eq. (7)'s pseudo-measurement,
/// rad (45°: where eq. 7's loop gain tan²δ reaches 1; a car's wheels stay
/// well below, so its results are those of the paper's form).
pub const STEERING_CONSTRAINT_ABOVE_RAD: f64 = std::f64::consts::FRAC_PI_4;

impl Sensors {
    /// Builds the models for a vehicle and a parameter set.
    pub fn new(vehicle: &Vehicle, params: &Params) -> Self {
        let c = params.circumferences();
        Sensors {
            wheelbase_m: vehicle.wheelbase_m,
            track_front_m: vehicle.track_front_m,
            track_rear_m: vehicle.track_rear_m,
            lever_arm_m: vehicle.gnss_lever_arm_m,
            ticks_per_rev: vehicle.ticks_per_rev as f64,
            nominal_circumference_m: vehicle.wheel_circumference_m,
            steering_ratio: vehicle.steering_ratio,
            params: *params,
            inv_circumference: [1.0 / c[0], 1.0 / c[1], 1.0 / c[2], 1.0 / c[3]],
        }
    }

    /// Ground speed of wheel `i` (m/s) from the state (eq. 6 without the tick
    /// factor) and its partial derivatives with respect to v and ψ̇.
    ///
    /// Rear wheels: `v ∓ (l_R/2)·ψ̇`; front wheels: `sqrt((l_RF·ψ̇)² + (v ∓ (l_F/2)·ψ̇)²)`,
    /// signed like `v` so reversing gives negative speeds.
    pub fn wheel_ground_speed(&self, i: usize, v: f64, yaw_rate: f64) -> (f64, f64, f64) {
        match i {
            RL => (
                v - 0.5 * self.track_rear_m * yaw_rate,
                1.0,
                -0.5 * self.track_rear_m,
            ),
            RR => (
                v + 0.5 * self.track_rear_m * yaw_rate,
                1.0,
                0.5 * self.track_rear_m,
            ),
            _ => {
                let c = if i == FL {
                    -0.5 * self.track_front_m
                } else {
                    0.5 * self.track_front_m
                };
                let l = self.wheelbase_m;
                let u = v + c * yaw_rate;
                let s = v.signum();
                // A tiny floor keeps the derivative defined at standstill (bias < 1e-6 m/s).
                let a = (l * l * yaw_rate * yaw_rate + u * u + 1e-12).sqrt();
                (s * a, s * u / a, s * (l * l * yaw_rate + c * u) / a)
            }
        }
    }

    /// Eq. (6): ticks of wheel `i` over an interval of `interval_s`.
    pub fn wheel_ticks(&self, x: &State, i: usize, interval_s: f64) -> (f64, Row) {
        let (g, dv, dw) = self.wheel_ground_speed(i, x[V], x[YAW_RATE]);
        let k = self.ticks_per_rev * self.inv_circumference[i] * interval_s;
        let mut h = Row::zeros();
        h[V] = k * dv;
        h[YAW_RATE] = k * dw;
        (k * g, h)
    }

    /// Reported wheel speed of wheel `i` (m/s): the ECU converts the wheel rotation
    /// with the nominal circumference, so `s = ρ_nom/ρ_i · g_i`.
    pub fn wheel_speed(&self, x: &State, i: usize) -> (f64, Row) {
        let (g, dv, dw) = self.wheel_ground_speed(i, x[V], x[YAW_RATE]);
        let k = self.nominal_circumference_m * self.inv_circumference[i];
        let mut h = Row::zeros();
        h[V] = k * dv;
        h[YAW_RATE] = k * dw;
        (k * g, h)
    }

    /// Eq. (4): gyro reading `ψ̇ + b_gyro`.
    pub fn gyro(&self, x: &State) -> (f64, Row) {
        let mut h = Row::zeros();
        h[YAW_RATE] = 1.0;
        (x[YAW_RATE] + self.params.gyro_bias_rps, h)
    }

    /// Eq. (5): CAN speed `a_v · v`.
    pub fn can_speed(&self, x: &State) -> (f64, Row) {
        let mut h = Row::zeros();
        h[V] = self.params.speed_scale;
        (self.params.speed_scale * x[V], h)
    }

    /// Eq. (7): the steering pseudo-measurement. The measurement is
    /// `z = v_{k-1}·tan(δ/r_s)` (built with [`Sensors::steering_measurement`]) and its
    /// model is `h = l_RF·ψ̇`.
    pub fn steering(&self, x: &State) -> (f64, Row) {
        let mut h = Row::zeros();
        h[YAW_RATE] = self.wheelbase_m;
        (self.wheelbase_m * x[YAW_RATE], h)
    }

    /// The steering pseudo-measurement `z = v·tan(δ/r_s)` and its variance
    /// `(v·β_δ)²` for the prior speed `v` (floored at 0.1 m/s so the variance never
    /// vanishes).
    pub fn steering_measurement(
        &self,
        steering_wheel_rad: f64,
        v_prior: f64,
        beta: f64,
    ) -> (f64, f64) {
        let z = v_prior * (steering_wheel_rad / self.steering_ratio).tan();
        let r = (v_prior.abs().max(0.1) * beta).powi(2);
        (z, r)
    }

    /// The steering as a constraint, for large wheel angles: the rear-axle
    /// velocity and the turn agree with the wheel angle `δ = s / r_s`,
    /// `h = l_RF·ψ̇·cos δ − v·sin δ = 0`, bounded at every angle (at ±90° it
    /// says that the rear axle centre stands still). Eq. (7)'s
    /// pseudo-measurement `v_{k-1}·tan δ` feeds the prior speed back with a
    /// loop gain of about tan²δ through the front wheel's observation, which
    /// makes speed and yaw rate alternate in sign and grow beyond 45° (the
    /// tricycle log steers to 1.1 rad); the filter uses this form there
    /// ([`STEERING_CONSTRAINT_ABOVE_RAD`]). Returns the model, its row and
    /// the variance for a wheel-angle error of `beta` rad, scaled by the
    /// front wheel's rolling speed `l_RF·ψ̇·sin δ + v·cos δ` of the prior
    /// (floored at 0.1 m/s; at small angles this is eq. 7's `(v·β)²`).
    pub fn steering_constraint(
        &self,
        x: &State,
        steering_wheel_rad: f64,
        beta: f64,
    ) -> (f64, Row, f64) {
        let (sd, cd) = (steering_wheel_rad / self.steering_ratio).sin_cos();
        let l = self.wheelbase_m;
        let mut h = Row::zeros();
        h[YAW_RATE] = l * cd;
        h[V] = -sd;
        let rolling = l * x[YAW_RATE] * sd + x[V] * cd;
        let r = (rolling.abs().max(0.1) * beta).powi(2);
        (l * x[YAW_RATE] * cd - x[V] * sd, h, r)
    }

    /// Eq. (10): the GNSS antenna position `[x + l·cos ψ, y + l·sin ψ]` and its Jacobian.
    pub fn gnss(&self, x: &State) -> (nalgebra::Vector2<f64>, nalgebra::SMatrix<f64, 2, 5>) {
        let (s, c) = x[YAW].sin_cos();
        let l = self.lever_arm_m;
        let h = nalgebra::Vector2::new(x[X] + l * c, x[Y] + l * s);
        let mut j = nalgebra::SMatrix::<f64, 2, 5>::zeros();
        j[(0, X)] = 1.0;
        j[(0, YAW)] = -l * s;
        j[(1, Y)] = 1.0;
        j[(1, YAW)] = l * c;
        (h, j)
    }

    /// A direct yaw observation (GNSS course, optional, not in the paper).
    pub fn yaw(&self, x: &State) -> (f64, Row) {
        let mut h = Row::zeros();
        h[YAW] = 1.0;
        (x[YAW], h)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fd_check(f: impl Fn(&State) -> (f64, Row), x: &State) {
        let (_, h) = f(x);
        for j in 0..5 {
            let e = 1e-6;
            let mut xp = *x;
            let mut xm = *x;
            xp[j] += e;
            xm[j] -= e;
            let d = (f(&xp).0 - f(&xm).0) / (2.0 * e);
            assert!(
                (d - h[j]).abs() < 1e-6 * (1.0 + d.abs()),
                "column {j}: analytic {} vs numeric {d}",
                h[j]
            );
        }
    }

    #[test]
    fn analytic_jacobians_match_finite_differences() {
        let v = Vehicle::paper_car();
        let mut p = Params::nominal(&v);
        p.gyro_bias_rps = -0.003;
        p.speed_scale = 0.987;
        p.set_circumferences([1.9134, 1.9129, 1.9166, 1.9164]);
        let s = Sensors::new(&v, &p);
        for x in [
            State::from([1.0, 2.0, 0.3, 8.0, 0.2]),
            State::from([-5.0, 7.0, -2.0, 2.5, -0.6]),
            State::from([0.0, 0.0, 1.0, -1.5, 0.1]),
        ] {
            for i in 0..4 {
                fd_check(|x| s.wheel_ticks(x, i, 0.02), &x);
                fd_check(|x| s.wheel_speed(x, i), &x);
            }
            fd_check(|x| s.gyro(x), &x);
            fd_check(|x| s.can_speed(x), &x);
            fd_check(|x| s.steering(x), &x);
            for sw in [
                0.3,
                8.0,
                -20.0,
                s.steering_ratio * std::f64::consts::FRAC_PI_2,
            ] {
                fd_check(
                    |x| {
                        let (h, row, _) = s.steering_constraint(x, sw, 0.02);
                        (h, row)
                    },
                    &x,
                );
            }
            fd_check(|x| s.yaw(x), &x);
            let (_, j) = s.gnss(&x);
            for c in 0..5 {
                let e = 1e-6;
                let mut xp = x;
                let mut xm = x;
                xp[c] += e;
                xm[c] -= e;
                let d = (s.gnss(&xp).0 - s.gnss(&xm).0) / (2.0 * e);
                assert!((d[0] - j[(0, c)]).abs() < 1e-6 && (d[1] - j[(1, c)]).abs() < 1e-6);
            }
        }
    }

    #[test]
    fn rear_wheels_straight_line_ticks() {
        let v = Vehicle::paper_car();
        let s = Sensors::new(&v, &Params::nominal(&v));
        let x = State::from([0.0, 0.0, 0.0, 9.6, 0.0]);
        // 9.6 m/s for 20 ms is 0.192 m = 0.1 turn of a 1.92 m wheel = 4.8 ticks.
        for i in 0..4 {
            assert!((s.wheel_ticks(&x, i, 0.02).0 - 4.8).abs() < 1e-9);
        }
    }
}
