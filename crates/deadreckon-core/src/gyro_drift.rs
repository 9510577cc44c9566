//! The gyro bias as a walking state through the GNSS-aided run.
//!
//! The paper calibrates the gyro bias as one constant per drive. An
//! automotive MEMS gyro's bias moves by 10–40 °/h over minutes (its in-run
//! instability, mostly temperature): the calibration drive's mean is then
//! off by that much at the start of an outage, and a 30 s outage at 20 m/s
//! with 1e-4 rad/s of bias error ends about 0.9 m off (½·v·b·t²).
//! [`CarBiasLayout`] carries the bias as a sixth state after the car's five,
//! a random walk with the vehicle's `[noise] gyro_bias_walk_rps_per_sqrt_s`
//! (a gyro's rate random walk):
//!
//! ```text
//! z_gyro = ψ̇ + b + w,   b' = b,   Q_b = walk²·dt
//! ```
//!
//! so while the fixes come the bias follows what they show, and through an
//! outage the dead reckoning goes on with the bias they last showed, its
//! variance growing by `walk²·t`. The bias starts at the calibrated value
//! with the standard deviation a walk accumulates over [`START_SPAN_S`]
//! (the length of a calibration drive: how far the bias can be from that
//! drive's mean). [`CarWanderBiasLayout`] adds it to the receiver's wander
//! ([`crate::gnss_error`]). `gyro_bias_walk_rps_per_sqrt_s = 0` (the
//! default) is the paper's constant bias and the five-state filter.

use crate::filter::Layout;
use crate::gnss_error::WANDER_E;
use crate::vehicle::{Noise, Params};

/// Index of the gyro bias in [`CarBiasLayout`]'s state.
pub const BIAS: usize = 5;
/// Dimension of the car state with the gyro bias.
pub const N_BIAS: usize = 6;
/// Index of the gyro bias in [`CarWanderBiasLayout`]'s state.
pub const WANDER_BIAS: usize = 7;
/// Dimension of the car state with the receiver's wander and the gyro bias.
pub const N_WANDER_BIAS: usize = 8;

/// The span over which the bias may have walked from its calibrated value
/// when the filter starts, s: a calibration drive's length (10 min).
pub const START_SPAN_S: f64 = 600.0;

/// The five car states then the gyro bias (rad/s); the other parameters are
/// fixed.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CarBiasLayout;

impl Layout<N_BIAS> for CarBiasLayout {
    const NAME: &'static str = "car+gyro-bias";
    fn param_index(j: usize) -> Option<usize> {
        (j == 0).then_some(BIAS)
    }
    fn bias_walks() -> bool {
        true
    }
}

/// The five car states, the receiver's wander `[e_E, e_N]` (m), then the
/// gyro bias (rad/s).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CarWanderBiasLayout;

impl Layout<N_WANDER_BIAS> for CarWanderBiasLayout {
    const NAME: &'static str = "car+wander+gyro-bias";
    fn param_index(j: usize) -> Option<usize> {
        (j == 0).then_some(WANDER_BIAS)
    }
    fn wander_index() -> Option<usize> {
        Some(WANDER_E)
    }
    fn bias_walks() -> bool {
        true
    }
}

/// The prior standard deviations a walking-bias filter starts with: the
/// bias's `walk·√START_SPAN_S` (the other parameters are not states; their
/// entries are unused).
pub fn prior_std(noise: &Noise) -> Params {
    Params {
        gyro_bias_rps: noise.gyro_bias_walk_rps_per_sqrt_s * START_SPAN_S.sqrt(),
        speed_scale: 0.0,
        circumference_fl_m: 0.0,
        circumference_fr_m: 0.0,
        circumference_rl_m: 0.0,
        circumference_rr_m: 0.0,
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{SMatrix, SVector};

    use super::*;
    use crate::filter::Filter;
    use crate::model::{self, Mat, State};
    use crate::vehicle::Vehicle;

    fn walking(walk: f64) -> Filter<CarBiasLayout, N_BIAS> {
        let mut v = Vehicle::paper_car();
        v.noise.gyro_bias_walk_rps_per_sqrt_s = walk;
        let x0 = State::from([1.0, -2.0, 0.3, 12.0, 0.08]);
        let p0 = Mat::from_diagonal(&State::from([1.0, 1.0, 0.01, 1.0, 0.01]));
        let params = Params {
            gyro_bias_rps: 0.002,
            ..Params::nominal(&v)
        };
        Filter::new(&v, &params, Some(&prior_std(&v.noise)), 0.0, x0, p0).unwrap()
    }

    #[test]
    fn the_bias_starts_at_the_calibrated_value_with_ten_minutes_of_walk() {
        let f = walking(3e-6);
        assert_eq!(f.state()[BIAS], 0.002);
        let want = 3e-6 * 600f64.sqrt();
        assert!((f.covariance()[(BIAS, BIAS)].sqrt() - want).abs() < 1e-15);
        assert_eq!(f.params().gyro_bias_rps, 0.002);
    }

    #[test]
    fn the_prediction_is_f_p_ft_plus_q_with_the_walk() {
        let walk = 2e-5;
        let mut f = walking(walk);
        // A covariance with every cross term.
        let a = SMatrix::<f64, 6, 6>::from_fn(|i, j| ((i * 6 + j) as f64 * 0.61).cos() * 0.1);
        let p = a * a.transpose() + SMatrix::<f64, 6, 6>::identity() * 1e-3;
        let x = *f.state();
        f.set_state(x, p);
        let dt = 0.02;
        let car = f.car_state();
        let mut big_f = SMatrix::<f64, 6, 6>::identity();
        big_f
            .fixed_view_mut::<5, 5>(0, 0)
            .copy_from(&model::jacobian_slipping(&car, dt, 0.0));
        let mut q = SMatrix::<f64, 6, 6>::zeros();
        q.fixed_view_mut::<5, 5>(0, 0)
            .copy_from(&model::process_noise(f.noise(), dt));
        q[(BIAS, BIAS)] = walk * walk * dt;
        let want = big_f * p * big_f.transpose() + q;
        f.predict_to(dt);
        let got = f.covariance();
        assert!(
            (got - want).abs().max() < 1e-12,
            "{}",
            (got - want).abs().max()
        );
        // The bias itself does not move in a prediction.
        let x1: SVector<f64, 6> = *f.state();
        assert_eq!(x1[BIAS], 0.002);
    }

    #[test]
    fn a_walking_bias_filter_without_a_walk_is_refused() {
        // prior_std is 0 with no walk: the filter refuses a zero prior
        // (the commands take the five-state filter then).
        let v = Vehicle::paper_car();
        let x0 = State::from([0.0, 0.0, 0.0, 10.0, 0.0]);
        let r = Filter::<CarBiasLayout, N_BIAS>::new(
            &v,
            &Params::nominal(&v),
            Some(&prior_std(&v.noise)),
            0.0,
            x0,
            Mat::identity(),
        );
        assert!(r.is_err());
    }
}
