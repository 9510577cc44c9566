//! The observation models, eq. (4)–(8) and (10) of Welte et al., with their
//! Jacobians. Each scalar model returns the predicted measurement `h(x, p)` and
//! the Jacobian row `H = ∂h/∂x`.
//!
//! Wheel order everywhere is FL, FR, RL, RR (the order of [`Params::circumferences`]).
//!
//! Not in the paper, each off (0) by default and then the paper's models to
//! the last bit:
//!
//! - the rear-axle side slip `β_r = −g·v·ψ̇` ([`crate::model`]): M's lateral
//!   velocity `v·tan β_r` reaches the front wheels, whose ground speed is
//!   that of the front-axle point `[v ∓ (l_F/2)ψ̇, l_RF·ψ̇ + v·tan β_r]`
//!   (the rear wheels roll at the longitudinal speed, unchanged), and the
//!   course of M is `ψ + β_r` ([`Sensors::yaw`]). The GNSS antenna's
//!   position is rigid geometry (eq. 10), unchanged;
//! - the steering's offset `s₀` and understeer gradient `K_us`: the wheel
//!   angle of eq. (7) is `δ = (s − s₀)/r_s − K_us·|v|·ψ̇` at the prior state
//!   ([`Sensors::wheel_angle`]), so that `l_RF·ψ̇ = v·tan δ` stays the
//!   kinematic relation `atan(l_RF·κ)` of the convention
//!   `s = r_s·(atan(l_RF·κ) + K_us·a_y) + s₀` (`|v|·ψ̇ = a_y` forwards;
//!   reversing, the front tyre's slip angle turns round with the velocity).

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
    /// s₀: the steering-wheel reading when driving straight, rad.
    #[serde(default)]
    pub steering_offset_rad: f64,
    /// K_us: understeer gradient, rad of wheel angle per m/s².
    #[serde(default)]
    pub understeer_gradient_rad_per_mps2: f64,
    /// g: rear-axle side-slip gradient, rad per m/s² ([`crate::model`]).
    #[serde(default)]
    pub rear_slip_gradient_rad_per_mps2: f64,
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
            steering_offset_rad: vehicle.steering_offset_rad,
            understeer_gradient_rad_per_mps2: vehicle.understeer_gradient_rad_per_mps2,
            rear_slip_gradient_rad_per_mps2: vehicle.rear_slip_gradient_rad_per_mps2,
            params: *params,
            inv_circumference: [1.0 / c[0], 1.0 / c[1], 1.0 / c[2], 1.0 / c[3]],
        }
    }

    /// Ground speed of wheel `i` (m/s) from the state (eq. 6 without the tick
    /// factor) and its partial derivatives with respect to v and ψ̇.
    ///
    /// Rear wheels: `v ∓ (l_R/2)·ψ̇`; front wheels: `sqrt((l_RF·ψ̇)² + (v ∓ (l_F/2)·ψ̇)²)`,
    /// signed like `v` so reversing gives negative speeds. With a rear side-slip
    /// gradient g the front wheels' lateral component is `l_RF·ψ̇ + v·tan β_r`,
    /// `β_r = −g·|v|·ψ̇` (see the module doc).
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
                let g = self.rear_slip_gradient_rad_per_mps2;
                if g != 0.0 {
                    // Lateral w = l·ψ̇ + v·tan β, β = −g·|v|·ψ̇.
                    let (beta, db_dv, db_dr) = crate::model::rear_slip_angle(v, yaw_rate, g);
                    let tau = beta.tan();
                    let sec2 = 1.0 + tau * tau;
                    let w = l * yaw_rate + v * tau;
                    let dw_dv = tau + v * sec2 * db_dv;
                    let dw_dr = l + v * sec2 * db_dr;
                    let a = (w * w + u * u + 1e-12).sqrt();
                    return (s * a, s * (u + w * dw_dv) / a, s * (w * dw_dr + c * u) / a);
                }
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

    /// The virtual front-wheel angle of a steering-wheel reading `s` at the
    /// prior state `x_prior`, rad: `δ = (s − s₀)/r_s − K_us·|v|·ψ̇` (`s/r_s`
    /// with the paper's model, offset and understeer 0). The lateral
    /// acceleration is the prior's, as eq. (7) takes the prior speed.
    pub fn wheel_angle(&self, steering_wheel_rad: f64, x_prior: &State) -> f64 {
        let d = (steering_wheel_rad - self.steering_offset_rad) / self.steering_ratio;
        if self.understeer_gradient_rad_per_mps2 == 0.0 {
            d
        } else {
            d - self.understeer_gradient_rad_per_mps2 * x_prior[V].abs() * x_prior[YAW_RATE]
        }
    }

    /// Eq. (7): the steering pseudo-measurement. The measurement is
    /// `z = v_{k-1}·tan δ` (built with [`Sensors::steering_measurement`]) and its
    /// model is `h = l_RF·ψ̇`.
    pub fn steering(&self, x: &State) -> (f64, Row) {
        let mut h = Row::zeros();
        h[YAW_RATE] = self.wheelbase_m;
        (self.wheelbase_m * x[YAW_RATE], h)
    }

    /// The steering pseudo-measurement `z = v·tan δ` for the wheel angle δ
    /// ([`Sensors::wheel_angle`]) and its variance `(v·β_δ)²` for the prior
    /// speed `v` (floored at 0.1 m/s so the variance never vanishes).
    pub fn steering_measurement(
        &self,
        wheel_angle_rad: f64,
        v_prior: f64,
        beta: f64,
    ) -> (f64, f64) {
        let z = v_prior * wheel_angle_rad.tan();
        let r = (v_prior.abs().max(0.1) * beta).powi(2);
        (z, r)
    }

    /// The steering as a constraint, for large wheel angles: the rear-axle
    /// velocity and the turn agree with the wheel angle δ
    /// ([`Sensors::wheel_angle`]),
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
        wheel_angle_rad: f64,
        beta: f64,
    ) -> (f64, Row, f64) {
        let (sd, cd) = wheel_angle_rad.sin_cos();
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

    /// A direct yaw observation (GNSS course, optional, not in the paper):
    /// the course of M, `ψ + β_r` (ψ without side slip).
    pub fn yaw(&self, x: &State) -> (f64, Row) {
        let mut h = Row::zeros();
        h[YAW] = 1.0;
        let g = self.rear_slip_gradient_rad_per_mps2;
        if g == 0.0 {
            return (x[YAW], h);
        }
        let (beta, db_dv, db_dr) = crate::model::rear_slip_angle(x[V], x[YAW_RATE], g);
        h[V] = db_dv;
        h[YAW_RATE] = db_dr;
        (x[YAW] + beta, h)
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
        let plain = Sensors::new(&v, &p);
        let slipping = Sensors::new(
            &Vehicle {
                rear_slip_gradient_rad_per_mps2: 0.006,
                understeer_gradient_rad_per_mps2: 0.003,
                steering_offset_rad: 0.02,
                ..v.clone()
            },
            &p,
        );
        for (s, x) in [plain, slipping].into_iter().flat_map(|s| {
            [
                State::from([1.0, 2.0, 0.3, 8.0, 0.2]),
                State::from([-5.0, 7.0, -2.0, 2.5, -0.6]),
                State::from([0.0, 0.0, 1.0, -1.5, 0.1]),
                State::from([0.0, 0.0, 1.0, 25.0, 0.3]),
            ]
            .map(|x| (s, x))
        }) {
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
                        let (h, row, _) = s.steering_constraint(x, sw / s.steering_ratio, 0.02);
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
