//! Property tests of the filter's invariants on random states, covariances and
//! measurements (seeded by proptest's deterministic runner configuration).

use deadreckon_core::kalman::{self, CovarianceForm};
use deadreckon_core::model::{self, Mat, State};
use deadreckon_core::observation::Sensors;
use deadreckon_core::{Params, Vehicle};
use proptest::prelude::*;

fn state() -> impl Strategy<Value = State> {
    (
        -1e3..1e3f64,
        -1e3..1e3f64,
        -10.0..10.0f64,
        -5.0..40.0f64,
        -1.0..1.0f64,
    )
        .prop_map(|(a, b, c, d, e)| State::from([a, b, c, d, e]))
}

/// A random symmetric positive definite covariance.
fn covariance() -> impl Strategy<Value = Mat> {
    (
        prop::collection::vec(-1.0..1.0f64, 25),
        prop::collection::vec(1e-4..2.0f64, 5),
    )
        .prop_map(|(a, d)| {
            let a = Mat::from_iterator(a);
            a * a.transpose() * 0.5 + Mat::from_diagonal(&State::from_iterator(d))
        })
}

fn spd(p: &Mat) -> bool {
    *p == p.transpose() && p.cholesky().is_some()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, rng_seed: proptest::test_runner::RngSeed::Fixed(std::env::var("PROPTEST_RNG_SEED").ok().and_then(|s| s.parse().ok()).unwrap_or(42)), ..ProptestConfig::default() })]

    #[test]
    fn evolution_jacobian_matches_finite_differences(x in state(), dt in 0.001..0.2f64) {
        let f = model::jacobian(&x, dt);
        for j in 0..5 {
            let h = 1e-6 * (1.0 + x[j].abs());
            let mut xp = x; let mut xm = x;
            xp[j] += h; xm[j] -= h;
            let d = (model::evolve(&xp, dt) - model::evolve(&xm, dt)) / (2.0 * h);
            for i in 0..5 {
                prop_assert!((d[i] - f[(i, j)]).abs() < 1e-6 * (1.0 + f[(i, j)].abs()), "F[{},{}]", i, j);
            }
        }
    }

    #[test]
    fn slipping_evolution_jacobian_matches_finite_differences(
        x in state(), dt in 0.001..0.2f64, g in 0.0..0.02f64,
    ) {
        let f = model::jacobian_slipping(&x, dt, g);
        for j in 0..5 {
            let h = 1e-6 * (1.0 + x[j].abs());
            let mut xp = x; let mut xm = x;
            xp[j] += h; xm[j] -= h;
            let d = (model::evolve_slipping(&xp, dt, g) - model::evolve_slipping(&xm, dt, g)) / (2.0 * h);
            for i in 0..5 {
                prop_assert!((d[i] - f[(i, j)]).abs() < 1e-6 * (1.0 + f[(i, j)].abs()), "F[{},{}]", i, j);
            }
        }
    }

    #[test]
    fn wheel_jacobians_match_finite_differences(x in state(), wheel in 0usize..4, g in 0.0..0.02f64) {
        let v = Vehicle { rear_slip_gradient_rad_per_mps2: g, ..Vehicle::paper_car() };
        let s = Sensors::new(&v, &Params::nominal(&v));
        let (_, h) = s.wheel_ticks(&x, wheel, 0.02);
        for j in 0..5 {
            let e = 1e-6;
            let mut xp = x; let mut xm = x;
            xp[j] += e; xm[j] -= e;
            let d = (s.wheel_ticks(&xp, wheel, 0.02).0 - s.wheel_ticks(&xm, wheel, 0.02).0) / (2.0 * e);
            prop_assert!((d - h[j]).abs() < 1e-5 * (1.0 + d.abs()));
        }
    }

    #[test]
    fn prediction_and_updates_keep_covariances_symmetric_positive_definite(
        x in state(), p in covariance(), dt in 0.001..0.2f64,
        z in prop::collection::vec(-50.0..50.0f64, 4), r in prop::collection::vec(1e-6..4.0f64, 4),
    ) {
        let noise = Vehicle::paper_car().noise;
        let f = model::jacobian(&x, dt);
        let mut pp = kalman::predict_covariance(&p, &f, &model::process_noise(&noise, dt));
        prop_assert!(spd(&pp));
        let before = pp;
        let mut xx = model::evolve(&x, dt);
        let v = Vehicle::paper_car();
        let s = Sensors::new(&v, &Params::nominal(&v));
        let preds = [s.gyro(&xx), s.can_speed(&xx), s.wheel_ticks(&xx, 2, dt), s.steering(&xx)];
        for (i, (h, row)) in preds.into_iter().enumerate() {
            kalman::update_scalar(&mut xx, &mut pp, z[i] - h, &row, r[i], CovarianceForm::Joseph, 0.0).unwrap();
            prop_assert!(spd(&pp), "after update {}", i);
        }
        // Updates never increase the uncertainty.
        let min_eig = (before - pp).symmetric_eigen().eigenvalues.min();
        prop_assert!(min_eig > -1e-9 * before.amax());
    }
}

/// The filter predicts with the vehicle's side slip: state and recorded F
/// (what the RTS smoother uses) are the model's, in both layouts.
#[test]
fn the_filter_predicts_with_the_vehicles_side_slip() {
    use deadreckon_core::filter::{AugmentedFilter, CarFilter};
    let v = Vehicle {
        rear_slip_gradient_rad_per_mps2: 0.005,
        ..Vehicle::paper_car()
    };
    let p = Params::nominal(&v);
    let x0 = State::from([1.0, 2.0, 0.4, 20.0, 0.2]);
    let p0 = Mat::from_diagonal(&State::from([1.0, 1.0, 0.01, 1.0, 0.01]));
    let mut car = CarFilter::new(&v, &p, None, 0.0, x0, p0).unwrap();
    let pred = car.predict_to(0.02);
    assert_eq!(pred.x, model::evolve_slipping(&x0, 0.02, 0.005));
    assert_eq!(pred.f, model::jacobian_slipping(&x0, 0.02, 0.005));
    assert_ne!(pred.x, model::evolve(&x0, 0.02));
    let sd = Params::from_array([0.01, 0.05, 0.05, 0.05, 0.05, 0.05]);
    let mut aug = AugmentedFilter::new(&v, &p, Some(&sd), 0.0, x0, p0).unwrap();
    let pa = aug.predict_to(0.02);
    assert_eq!(pa.x.fixed_rows::<5>(0).into_owned(), pred.x);
    assert_eq!(pa.f, pred.f);
    assert_eq!(pa.p.fixed_view::<5, 5>(0, 0).into_owned(), pred.p);
}
