//! The yaw lag of eq. (3): with table I's diagonal Q the filter's yaw
//! integrates the yaw rate at the start of each step, so entering a turn it
//! lags the vehicle's yaw by `dt/2 · Δψ̇` (0.23° at 50 Hz into a 0.4 rad/s
//! turn), which its covariance does not cover. `YawIntegration::Trapezoidal`
//! carries the yaw rate's noise into the yaw over the step.

use deadreckon_core::filter::CarFilter;
use deadreckon_core::model::{Mat, State, YAW};
use deadreckon_core::vehicle::YawIntegration;
use deadreckon_core::{Params, Vehicle};

/// The filter fed an exact gyro (and wheel speeds) through a turn entry:
/// the yaw rate ramps from 0 to 0.4 rad/s over 1 s at 50 Hz and stays there
/// 1 s. Returns the largest |yaw error| (rad) and its standard deviation
/// there.
fn turn_entry(integration: YawIntegration) -> (f64, f64) {
    let mut v = Vehicle::paper_car();
    v.noise.yaw_integration = integration;
    let params = Params::nominal(&v);
    let x0 = State::from([0.0, 0.0, 0.0, 10.0, 0.0]);
    let p0 = Mat::from_diagonal(&State::from([0.01, 0.01, 1e-8, 0.01, 1e-6]));
    let mut f = CarFilter::new(&v, &params, None, 0.0, x0, p0).unwrap();
    let dt = 0.02;
    let rate = |t: f64| 0.4 * (t / 1.0).clamp(0.0, 1.0);
    // The exact yaw: ∫ rate, ramp then constant.
    let yaw = |t: f64| {
        if t <= 1.0 {
            0.2 * t * t
        } else {
            0.2 + 0.4 * (t - 1.0)
        }
    };
    let (mut worst, mut std_there) = (0.0f64, 0.0);
    for k in 1..=100 {
        let t = k as f64 * dt;
        f.predict_to(t);
        f.update_gyro(rate(t)).unwrap();
        let e = (f.car_state()[YAW] - yaw(t)).abs();
        if e > worst {
            worst = e;
            std_there = f.covariance()[(YAW, YAW)].sqrt();
        }
    }
    (worst, std_there)
}

#[test]
fn the_filters_yaw_lagged_half_a_step_of_yaw_rate_behind_the_vehicle() {
    let (euler, euler_std) = turn_entry(YawIntegration::Euler);
    let (trap, trap_std) = turn_entry(YawIntegration::Trapezoidal);
    // Euler: dt/2 · 0.4 rad/s = 0.004 rad once the ramp is over, at 4σ and
    // more of the yaw's own standard deviation.
    assert!((euler - 0.004).abs() < 2e-4, "euler lag {euler}");
    assert!(euler > 4.0 * euler_std, "{euler} vs σ {euler_std}");
    // Trapezoidal: the lag is gone to a tenth and within 3σ.
    assert!(trap < 4e-4, "trapezoidal lag {trap}");
    assert!(trap < 3.0 * trap_std, "{trap} vs σ {trap_std}");
}

#[test]
fn the_trapezoidal_process_noise_is_symmetric_positive_semidefinite() {
    let mut v = Vehicle::paper_car();
    v.noise.yaw_integration = YawIntegration::Trapezoidal;
    for dt in [0.001, 0.01, 0.02, 0.1, 1.0] {
        let q = deadreckon_core::model::process_noise(&v.noise, dt);
        assert_eq!(q, q.transpose());
        let eig = q.symmetric_eigenvalues();
        let largest = eig.max();
        assert!(eig.iter().all(|&l| l >= -1e-12 * largest), "dt {dt}: {eig}");
    }
}
