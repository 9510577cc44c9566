//! The car filter with the receiver's wander as states
//! ([`deadreckon_core::gnss_error::CarWanderLayout`]) against a textbook
//! extended Kalman filter written here (dense `F P Fᵀ + Q`, explicit `S⁻¹`),
//! the wander's stationary variance, and the GNSS gate's handling of a
//! multipath burst.

use deadreckon_core::drive::GnssFix;
use deadreckon_core::filter::{Filter, SensorKind};
use deadreckon_core::gnss_error::{CarWanderLayout, N_WANDER, WANDER_E, WANDER_N};
use deadreckon_core::model::{self, Mat, State};
use deadreckon_core::observation::Sensors;
use deadreckon_core::{Params, Vehicle};
use nalgebra::{Matrix2, SMatrix, SVector, Vector2};
use rand::{RngExt, SeedableRng};
use rand_distr::{Distribution, StandardNormal};
use rand_pcg::Pcg64;

type X7 = SVector<f64, N_WANDER>;
type P7 = SMatrix<f64, N_WANDER, N_WANDER>;
type WanderFilter = Filter<CarWanderLayout, N_WANDER>;

fn randn(rng: &mut Pcg64) -> f64 {
    StandardNormal.sample(rng)
}

fn vehicle(std_m: f64, tau_s: f64) -> Vehicle {
    let mut v = Vehicle::paper_car();
    v.noise.gnss_wander_std_m = std_m;
    v.noise.gnss_wander_tau_s = tau_s;
    v
}

fn start(v: &Vehicle) -> (WanderFilter, X7, P7) {
    let x0 = State::from([0.0, 0.0, 0.3, 10.0, 0.05]);
    let p0 = Mat::from_diagonal(&State::from([1.0, 1.0, 0.01, 1.0, 0.01]));
    let f = WanderFilter::new(v, &Params::nominal(v), None, 0.0, x0, p0).unwrap();
    let (x, p) = (*f.state(), *f.covariance());
    (f, x, p)
}

/// Textbook prediction: the car's eq. (3) and the wander's `φ`, dense.
fn textbook_predict(v: &Vehicle, x: &X7, p: &P7, dt: f64) -> (X7, P7) {
    let car: State = x.fixed_rows::<5>(0).into_owned();
    let f5 = model::jacobian(&car, dt);
    let q5 = model::process_noise(&v.noise, dt);
    let (s, tau) = (v.noise.gnss_wander_std_m, v.noise.gnss_wander_tau_s);
    let phi = (-dt / tau).exp();
    let mut f = P7::identity();
    f.fixed_view_mut::<5, 5>(0, 0).copy_from(&f5);
    f[(WANDER_E, WANDER_E)] = phi;
    f[(WANDER_N, WANDER_N)] = phi;
    let mut q = P7::zeros();
    q.fixed_view_mut::<5, 5>(0, 0).copy_from(&q5);
    q[(WANDER_E, WANDER_E)] = s * s * (1.0 - phi * phi);
    q[(WANDER_N, WANDER_N)] = s * s * (1.0 - phi * phi);
    let mut xn = *x;
    xn.fixed_rows_mut::<5>(0)
        .copy_from(&model::evolve(&car, dt));
    xn[WANDER_E] *= phi;
    xn[WANDER_N] *= phi;
    (xn, f * p * f.transpose() + q)
}

/// Textbook update with an explicit `S⁻¹`, Joseph form.
fn textbook_update<const M: usize>(
    x: &mut X7,
    p: &mut P7,
    y: &SVector<f64, M>,
    h: &SMatrix<f64, M, N_WANDER>,
    r: &SMatrix<f64, M, M>,
) {
    let s = h * *p * h.transpose() + r;
    let k = *p * h.transpose() * s.try_inverse().unwrap();
    *x += k * y;
    let a = P7::identity() - k * h;
    *p = a * *p * a.transpose() + k * r * k.transpose();
}

#[test]
fn the_wander_filter_equals_a_textbook_ekf() {
    let v = vehicle(1.2, 45.0);
    let (mut f, mut x, mut p) = start(&v);
    let sensors = Sensors::new(&v, &Params::nominal(&v));
    let mut rng = Pcg64::seed_from_u64(28);
    let mut worst: f64 = 0.0;
    let dt = 0.02;
    for k in 1..=3000 {
        let t = k as f64 * dt;
        f.predict_to(t);
        (x, p) = textbook_predict(&v, &x, &p, dt);
        // A gyro reading every step.
        let z = 0.05 + 0.003 * randn(&mut rng);
        assert!(f.update_gyro(z).unwrap().accepted);
        let car: State = x.fixed_rows::<5>(0).into_owned();
        let (h, row) = sensors.gyro(&car);
        let mut hh = SMatrix::<f64, 1, N_WANDER>::zeros();
        hh.fixed_view_mut::<1, 5>(0, 0).copy_from(&row.transpose());
        let r = SMatrix::<f64, 1, 1>::new(v.noise.gyro_rps.powi(2));
        textbook_update(&mut x, &mut p, &SVector::<f64, 1>::new(z - h), &hh, &r);
        // A fix every 0.2 s: a circle of 200 m radius at 10 m/s, plus a
        // slow offset and white noise.
        if k % 10 == 0 {
            let a = 0.05 * t;
            let fix = GnssFix {
                t_s: t,
                east_m: 200.0 * a.sin() + 0.8 + 0.5 * randn(&mut rng),
                north_m: 200.0 * (1.0 - a.cos()) - 0.4 + 0.5 * randn(&mut rng),
                std_m: 0.5,
                course_deg: None,
                speed_mps: None,
            };
            let u = f.update_gnss(&fix).unwrap();
            assert!(u.accepted, "fix at {t}: NIS {}", u.nis);
            let car: State = x.fixed_rows::<5>(0).into_owned();
            let (h5, j5) = sensors.gnss(&car);
            let mut h = SMatrix::<f64, 2, N_WANDER>::zeros();
            h.fixed_view_mut::<2, 5>(0, 0).copy_from(&j5);
            h[(0, WANDER_E)] = 1.0;
            h[(1, WANDER_N)] = 1.0;
            let pred = h5 + Vector2::new(x[WANDER_E], x[WANDER_N]);
            let y = Vector2::new(fix.east_m, fix.north_m) - pred;
            textbook_update(&mut x, &mut p, &y, &h, &(Matrix2::identity() * 0.25));
        }
        let dx = (f.state() - x).abs().max() / x.abs().max().max(1.0);
        let dp = (f.covariance() - p).abs().max() / p.abs().max();
        worst = worst.max(dx).max(dp);
    }
    // Measured: 1e-13 over 60 s of 50 Hz steps (rounding only).
    assert!(worst < 1e-9, "largest relative difference {worst:e}");
}

#[test]
fn the_wander_variance_stays_at_sigma_squared_without_fixes() {
    for (s, tau) in [(0.3, 20.0), (1.5, 120.0)] {
        let v = vehicle(s, tau);
        let (mut f, mut x, p) = start(&v);
        x[WANDER_E] = 1.0;
        x[WANDER_N] = -2.0;
        f.set_state(x, p);
        // Irregular steps (10–30 ms) over ten time constants.
        let mut rng = Pcg64::seed_from_u64(7);
        let mut t = 0.0;
        while t < 10.0 * tau {
            t += 0.01 + 0.02 * rng.random::<f64>();
            f.predict_to(t);
            for i in [WANDER_E, WANDER_N] {
                let var = f.covariance()[(i, i)];
                assert!((var / (s * s) - 1.0).abs() < 1e-9, "σ {s}: {var} at {t}");
            }
        }
        // The estimate decays as exp(−t/τ).
        let decay = (-t / tau).exp();
        assert!((f.wander_m()[0] - decay).abs() < 1e-9);
        assert!((f.wander_m()[1] + 2.0 * decay).abs() < 1e-9);
        // And decorrelates from the car.
        let c = f.covariance();
        for j in 0..5 {
            assert!(
                c[(WANDER_E, j)].abs() < 1e-3 * s * s,
                "{}",
                c[(WANDER_E, j)]
            );
        }
    }
}

/// Issue 28: a recovery inside a multipath burst (the 10th rejected fix,
/// 1–2.5 s into a burst of 2–9 s at 4–10 Hz) took the burst's fix with the
/// position covariance widened, and the filter followed the burst. With
/// `gnss_recovery_after_s` the rejections must also last that long.
#[test]
fn a_recovery_inside_a_multipath_burst_followed_the_burst() {
    for (after_s, recovered) in [(0.0, true), (10.0, false)] {
        let mut v = vehicle(0.5, 60.0);
        v.noise.gnss_recovery_after_s = after_s;
        let fix = |t: f64, offset: f64| GnssFix {
            t_s: t,
            east_m: 10.0 * t + 1.2 * (0.3f64).cos() + offset,
            north_m: 1.2 * (0.3f64).sin(),
            std_m: 0.3,
            course_deg: None,
            speed_mps: None,
        };
        let x0 = State::from([0.0, 0.0, 0.0, 10.0, 0.0]);
        let p0 = Mat::from_diagonal(&State::from([0.01, 0.01, 1e-4, 0.01, 1e-4]));
        let mut f = WanderFilter::new(&v, &Params::nominal(&v), None, 0.0, x0, p0).unwrap();
        // 8 s of a 12 m burst at 10 Hz; wheels and gyro at 50 Hz.
        let mut before = *f.state();
        for k in 1..=400 {
            let t = 0.02 * k as f64;
            f.predict_to(t);
            if k == 1 {
                before = *f.state();
            }
            for i in 0..4 {
                let z = f.predicted_wheel_speed(i);
                f.update_wheel_speed(i, z).unwrap();
            }
            f.update_gyro(0.0).unwrap();
            if k % 5 == 0 {
                f.update_gnss(&fix(t, 12.0)).unwrap();
            }
        }
        let g = f.gates();
        assert_eq!(
            g.recovered(SensorKind::Gnss) > 0,
            recovered,
            "after {after_s} s"
        );
        if !recovered {
            assert_eq!(g.rejected(SensorKind::Gnss), 80);
            // The wander only decayed: no fix moved it.
            let decay = (-7.98f64 / 60.0).exp();
            assert!((f.wander_m()[0] - before[WANDER_E] * decay).abs() < 1e-12);
        }
    }
}
