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
//! default) with `gyro_bias_drive_std_rps = 0` is the paper's constant bias
//! and the five-state filter.
//!
//! `[noise] gyro_bias_drive_std_rps` above 0 carries the bias as the same
//! state for another reason: a gyro's bias on a new drive is not the
//! calibration drive's (turn-on repeatability, temperature). The state then
//! starts with that standard deviation added to the walk's
//! ([`prior_std`]), and with no walk it stays put once the drive's fixes
//! have shown it. Measured on the dynamic family (dev cars 1–25, 30 s
//! outages on a drive other than the calibration's; `deadreckon-sim/tests/walk_evidence.rs`):
//! it takes most of what the walk takes back where the gyro drifts, and the
//! calibration drive's own fixes cannot tell whether it will help
//! ([`walk_evidence`]): the bias that differs is the next drive's. Its own
//! fixes can, one fix ahead: by default (`gyro_bias_drive_std_rps` 1e-4,
//! `gyro_bias_switch_llr` 1) the aided filter runs the constant and the
//! state side by side and takes the state from the fix at which they favour
//! it ([`crate::aided::switch`]).

use crate::drive::Drive;
use crate::ekf::FilterOptions;
use crate::filter::{CarLayout, Layout};
use crate::gnss_error::WANDER_E;
use crate::vehicle::{Noise, Params};
use crate::wander_fit::likelihood;
use crate::Error;

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

/// Whether the aided filter carries the gyro bias as a state (a walk, or a
/// bias that may differ on this drive).
pub fn carries_bias(noise: &Noise) -> bool {
    noise.gyro_bias_walk_rps_per_sqrt_s > 0.0 || noise.gyro_bias_drive_std_rps > 0.0
}

/// The prior standard deviations a walking-bias filter starts with: the
/// bias's `walk·√START_SPAN_S` and `gyro_bias_drive_std_rps` together (the
/// other parameters are not states; their entries are unused).
pub fn prior_std(noise: &Noise) -> Params {
    Params {
        gyro_bias_rps: (noise.gyro_bias_walk_rps_per_sqrt_s * START_SPAN_S.sqrt())
            .hypot(noise.gyro_bias_drive_std_rps),
        speed_scale: 0.0,
        circumference_fl_m: 0.0,
        circumference_fr_m: 0.0,
        circumference_rl_m: 0.0,
        circumference_rr_m: 0.0,
    }
}

/// What a drive's own fixes say about a walking bias: the GNSS-aided
/// filter's mean capped log-likelihood per fix (as
/// [`crate::wander_fit`] scores a receiver model) with the calibration's
/// constant bias and with the bias walking.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WalkEvidence {
    /// With the constant bias (the paper's model).
    pub constant: f64,
    /// With the bias a state ([`carries_bias`]).
    pub walking: f64,
    /// Fixes each averages.
    pub fixes: usize,
}

impl WalkEvidence {
    /// The log-likelihood ratio of the bias as a state over the constant
    /// one, summed over the fixes.
    pub fn log_ratio(&self) -> f64 {
        (self.walking - self.constant) * self.fixes as f64
    }
}

/// Runs the GNSS-aided filter over `drive` with the constant bias of
/// `params` and with the bias a state as `noise` (its walk and drive
/// standard deviation) says; each fix's innovation is predicted from the
/// fixes before it only, so the ratio is out of sample one fix ahead.
pub fn walk_evidence(
    drive: &Drive,
    params: &Params,
    opts: &FilterOptions,
    noise: &Noise,
) -> Result<WalkEvidence, Error> {
    let opts = FilterOptions {
        record_epochs: false,
        record_innovations: false,
        ..opts.clone()
    };
    let mut constant_vehicle = drive.vehicle.clone();
    constant_vehicle.noise.gyro_bias_walk_rps_per_sqrt_s = 0.0;
    constant_vehicle.noise.gyro_bias_drive_std_rps = 0.0;
    let constant = likelihood::<CarLayout, 5>(drive, &constant_vehicle, params, None, &opts, None)?;
    let mut v = drive.vehicle.clone();
    v.noise.gyro_bias_walk_rps_per_sqrt_s = noise.gyro_bias_walk_rps_per_sqrt_s;
    v.noise.gyro_bias_drive_std_rps = noise.gyro_bias_drive_std_rps;
    let prior = prior_std(&v.noise);
    let walking =
        likelihood::<CarBiasLayout, N_BIAS>(drive, &v, params, Some(&prior), &opts, None)?;
    Ok(WalkEvidence {
        constant: constant.log_likelihood,
        walking: walking.log_likelihood,
        fixes: constant.fixes.min(walking.fixes),
    })
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
        // The walk alone (no per-drive std).
        v.noise.gyro_bias_drive_std_rps = 0.0;
        let x0 = State::from([1.0, -2.0, 0.3, 12.0, 0.08]);
        let p0 = Mat::from_diagonal(&State::from([1.0, 1.0, 0.01, 1.0, 0.01]));
        let params = Params {
            gyro_bias_rps: 0.002,
            ..Params::nominal(&v)
        };
        Filter::new(&v, &params, Some(&prior_std(&v.noise)), 0.0, x0, p0).unwrap()
    }

    #[test]
    fn a_bias_that_differs_per_drive_starts_with_its_std_and_stays_put() {
        let mut v = Vehicle::paper_car();
        v.noise.gyro_bias_drive_std_rps = 0.0;
        assert!(!carries_bias(&v.noise));
        v.noise.gyro_bias_drive_std_rps = 5e-5;
        assert!(carries_bias(&v.noise));
        let x0 = State::from([1.0, -2.0, 0.3, 12.0, 0.08]);
        let p0 = Mat::from_diagonal(&State::from([1.0, 1.0, 0.01, 1.0, 0.01]));
        let params = Params::nominal(&v);
        let mut f: Filter<CarBiasLayout, N_BIAS> =
            Filter::new(&v, &params, Some(&prior_std(&v.noise)), 0.0, x0, p0).unwrap();
        assert!((f.covariance()[(BIAS, BIAS)] - 2.5e-9).abs() < 1e-22);
        f.predict_to(1.0);
        assert!((f.covariance()[(BIAS, BIAS)] - 2.5e-9).abs() < 1e-22);
        // With a walk too, the two add in variance.
        v.noise.gyro_bias_walk_rps_per_sqrt_s = 3e-6;
        let want = (9e-12 * START_SPAN_S + 2.5e-9).sqrt();
        assert!((prior_std(&v.noise).gyro_bias_rps - want).abs() < 1e-18);
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
        // prior_std is 0 with no walk and no per-drive std: the filter
        // refuses a zero prior (the commands take the five-state filter
        // then).
        let mut v = Vehicle::paper_car();
        v.noise.gyro_bias_drive_std_rps = 0.0;
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
