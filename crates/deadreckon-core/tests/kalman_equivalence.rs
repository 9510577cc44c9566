//! Differential tests: the filter's Kalman steps against a textbook Kalman filter
//! written independently here (batch vector update with an explicit inverse), and
//! the RTS smoother against the batch least-squares solution of the same linear
//! Gaussian problem.

use deadreckon_core::drive::{Drive, Scalar, WheelTicks, Wheels};
use deadreckon_core::ekf::{self, FilterOptions, Init, SensorSet, Timing};
use deadreckon_core::kalman::{self, CovarianceForm};
use deadreckon_core::model::{self, Mat, State, V, YAW_RATE};
use deadreckon_core::rts;
use deadreckon_core::{Params, Vehicle};
use nalgebra::{DMatrix, DVector, SMatrix, SVector};
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use rand_pcg::Pcg64;

type M4 = SMatrix<f64, 4, 4>;
type V4 = SVector<f64, 4>;

fn randn(rng: &mut Pcg64) -> f64 {
    StandardNormal.sample(rng)
}

/// A textbook KF step with a vector measurement and an explicit S⁻¹.
fn textbook_update(
    x: &mut V4,
    p: &mut M4,
    z: &SVector<f64, 3>,
    h: &SMatrix<f64, 3, 4>,
    r: &SMatrix<f64, 3, 3>,
) {
    let s = h * *p * h.transpose() + r;
    let k = *p * h.transpose() * s.try_inverse().unwrap();
    *x += k * (z - h * *x);
    let a = M4::identity() - k * h;
    *p = a * *p * a.transpose() + k * r * k.transpose();
}

#[test]
fn sequential_scalar_updates_equal_the_textbook_filter_on_a_linear_model() {
    let mut rng = Pcg64::seed_from_u64(7);
    let dt = 0.1;
    let f = M4::new(
        1.0, 0.0, dt, 0.0, 0.0, 1.0, 0.0, dt, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
    );
    let q = M4::from_diagonal(&V4::new(1e-4, 1e-4, 1e-2, 1e-2));
    let h = SMatrix::<f64, 3, 4>::new(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.3, -0.2, 1.0, 0.5);
    let rd = [0.25, 0.36, 0.04];
    let r = SMatrix::<f64, 3, 3>::from_diagonal(&SVector::<f64, 3>::from(rd));
    let (mut xa, mut pa) = (V4::zeros(), M4::identity() * 4.0);
    let (mut xb, mut pb) = (xa, pa);
    let mut truth = V4::new(0.0, 0.0, 1.0, -0.5);
    let mut max_diff: f64 = 0.0;
    for step in 0..2000 {
        truth = f * truth + V4::from_fn(|i, _| q[(i, i)].sqrt() * randn(&mut rng));
        let z = h * truth + SVector::<f64, 3>::from_fn(|i, _| rd[i].sqrt() * randn(&mut rng));
        // Implementation under test.
        xa = f * xa;
        pa = kalman::predict_covariance(&pa, &f, &q);
        for i in 0..3 {
            let row: V4 = h.row(i).transpose();
            let y = z[i] - row.dot(&xa);
            kalman::update_scalar(
                &mut xa,
                &mut pa,
                y,
                &row,
                rd[i],
                CovarianceForm::Joseph,
                step as f64,
            )
            .unwrap();
        }
        // Reference.
        xb = f * xb;
        pb = f * pb * f.transpose() + q;
        textbook_update(&mut xb, &mut pb, &z, &h, &r);
        max_diff = max_diff.max((xa - xb).amax()).max((pa - pb).amax());
    }
    assert!(max_diff < 1e-12, "max difference {max_diff:e}");
}

#[test]
fn vector_update_equals_textbook_in_both_covariance_forms() {
    let mut rng = Pcg64::seed_from_u64(11);
    let h = SMatrix::<f64, 3, 4>::from_fn(|_, _| randn(&mut rng));
    let r = SMatrix::<f64, 3, 3>::from_diagonal(&SVector::<f64, 3>::new(0.5, 0.2, 0.9));
    let a = M4::from_fn(|_, _| randn(&mut rng));
    let p0 = a * a.transpose() + M4::identity();
    let x0 = V4::from_fn(|_, _| randn(&mut rng));
    let z = SVector::<f64, 3>::from_fn(|_, _| randn(&mut rng));
    let (mut xr, mut pr) = (x0, p0);
    textbook_update(&mut xr, &mut pr, &z, &h, &r);
    for form in [CovarianceForm::Joseph, CovarianceForm::Simple] {
        let (mut x, mut p) = (x0, p0);
        let y = z - h * x;
        kalman::update_vector(&mut x, &mut p, &y, &h, &r, form, 0.0).unwrap();
        assert!(
            (x - xr).amax() < 1e-12 && (p - pr).amax() < 1e-12,
            "{form:?}"
        );
    }
}

/// The Schmidt ("consider") update the augmented filter makes while its
/// heading is unknown: the held states keep their value, and P is the
/// covariance of the estimator with the held rows of the gain zeroed,
/// `(I − Kₛ H) P (I − Kₛ H)ᵀ + Kₛ R Kₛᵀ`, for the scalar and the vector
/// update; with nothing held it is the ordinary update.
#[test]
fn schmidt_updates_equal_the_textbook_consider_update() {
    let mut rng = Pcg64::seed_from_u64(19);
    let a = M4::from_fn(|_, _| randn(&mut rng));
    let p0 = a * a.transpose() + M4::identity();
    let x0 = V4::from_fn(|_, _| randn(&mut rng));
    let textbook =
        |h: &SMatrix<f64, 3, 4>, r: &SMatrix<f64, 3, 3>, y: &SVector<f64, 3>, hold: &[bool; 4]| {
            let s = h * p0 * h.transpose() + r;
            let mut k = p0 * h.transpose() * s.try_inverse().unwrap();
            for (i, &held) in hold.iter().enumerate() {
                if held {
                    k.row_mut(i).fill(0.0);
                }
            }
            let ikh = M4::identity() - k * h;
            (
                x0 + k * y,
                ikh * p0 * ikh.transpose() + k * r * k.transpose(),
            )
        };
    let h = SMatrix::<f64, 3, 4>::from_fn(|_, _| randn(&mut rng));
    let r = SMatrix::<f64, 3, 3>::from_diagonal(&SVector::<f64, 3>::new(0.5, 0.2, 0.9));
    let y = SVector::<f64, 3>::from_fn(|_, _| randn(&mut rng));
    for hold in [
        [false, false, true, true],
        [true, false, false, false],
        [false; 4],
    ] {
        let (xr, pr) = textbook(&h, &r, &y, &hold);
        let (mut x, mut p) = (x0, p0);
        kalman::update_vector_holding(&mut x, &mut p, &y, &h, &r, &hold, 0.0).unwrap();
        assert!(
            (x - xr).amax() < 1e-12 && (p - pr).amax() < 1e-12,
            "vector {hold:?}"
        );
        for (i, &held) in hold.iter().enumerate() {
            if held {
                assert_eq!(x[i], x0[i], "held state {i} moved");
            }
        }
        // One row of the vector measurement as a scalar update.
        let h1 = SMatrix::<f64, 1, 4>::from_fn(|_, j| h[(0, j)]);
        let r1 = SMatrix::<f64, 1, 1>::new(r[(0, 0)]);
        let s = (h1 * p0 * h1.transpose())[(0, 0)] + r1[(0, 0)];
        let mut k = p0 * h1.transpose() / s;
        for (i, &held) in hold.iter().enumerate() {
            if held {
                k[i] = 0.0;
            }
        }
        let ikh = M4::identity() - k * h1;
        let (xs, ps) = (
            x0 + k * y[0],
            ikh * p0 * ikh.transpose() + k * r1 * k.transpose(),
        );
        let inn =
            kalman::ScalarInnovation::new(&p0, &h1.transpose(), r1[(0, 0)], y[0], 0.0).unwrap();
        let (mut x, mut p) = (x0, p0);
        inn.apply_holding(&mut x, &mut p, &hold);
        assert!(
            (x - xs).amax() < 1e-12 && (p - ps).amax() < 1e-12,
            "scalar {hold:?}"
        );
        if !hold.contains(&true) {
            let (mut xo, mut po) = (x0, p0);
            inn.apply(&mut xo, &mut po, CovarianceForm::Joseph);
            assert!((x - xo).amax() < 1e-12 && (p - po).amax() < 1e-12);
        }
    }
}

/// The EKF's (v, ψ̇) block with only the gyro and the CAN speed is a linear
/// Kalman filter on a 2-state random walk: the whole `ekf::run` must match one.
#[test]
fn ekf_run_equals_a_plain_kalman_filter_on_its_linear_substate() {
    let mut rng = Pcg64::seed_from_u64(3);
    let vehicle = Vehicle::paper_car();
    let mut drive = Drive::empty(vehicle.clone());
    let n = 3000;
    drive.wheels = Wheels::Ticks(
        (0..n)
            .map(|k| WheelTicks {
                t_s: k as f64 * 0.02,
                fl: 0,
                fr: 0,
                rl: 0,
                rr: 0,
            })
            .collect(),
    );
    // Gyro and speed synchronous with the wheels (one reading per epoch, just before it).
    drive.yaw_rate = (1..n)
        .map(|k| Scalar {
            t_s: k as f64 * 0.02 - 0.001,
            value: 0.1 + 0.01 * randn(&mut rng),
        })
        .collect();
    drive.speed = (1..n)
        .map(|k| Scalar {
            t_s: k as f64 * 0.02 - 0.001,
            value: 8.0 + 0.1 * randn(&mut rng),
        })
        .collect();
    let mut params = Params::nominal(&vehicle);
    params.gyro_bias_rps = -0.003;
    params.speed_scale = 0.987;
    let p0 = Mat::from_diagonal(&State::from([1.0, 1.0, 0.1, 4.0, 0.25]));
    let x0 = State::from([0.0, 0.0, 0.3, 0.0, 0.0]);
    let opts = FilterOptions {
        timing: Timing::WheelEpochs,
        init: Init::Given {
            t_s: 0.0,
            x: x0,
            p: p0,
        },
        sensors: SensorSet {
            wheels: false,
            gyro: true,
            speed: true,
            steering: false,
            gnss: false,
            gnss_course: false,
        },
        ..Default::default()
    };
    let out = ekf::run(&drive, &params, &opts, &mut ()).unwrap();
    assert_eq!(out.epochs.len(), n - 1);

    let noise = vehicle.noise;
    let mut x = nalgebra::Vector2::new(0.0, 0.0);
    let mut p = nalgebra::Matrix2::new(4.0, 0.0, 0.0, 0.25);
    let q = nalgebra::Matrix2::new(
        noise.process_speed_mps.powi(2),
        0.0,
        0.0,
        noise.process_yaw_rate_rps.powi(2),
    );
    let mut max_diff: f64 = 0.0;
    for k in 1..n {
        p += q; // dt = 0.02 = the reference step
                // gyro: z = ψ̇ + b
        let h = nalgebra::RowVector2::new(0.0, 1.0);
        let s = (h * p * h.transpose())[(0, 0)] + noise.gyro_rps.powi(2);
        let kk = p * h.transpose() / s;
        x += kk * (drive.yaw_rate[k - 1].value - params.gyro_bias_rps - x[1]);
        let a = nalgebra::Matrix2::identity() - kk * h;
        p = a * p * a.transpose() + kk * kk.transpose() * noise.gyro_rps.powi(2);
        // speed: z = a_v v
        let h = nalgebra::RowVector2::new(params.speed_scale, 0.0);
        let s = (h * p * h.transpose())[(0, 0)] + noise.speed_mps.powi(2);
        let kk = p * h.transpose() / s;
        x += kk * (drive.speed[k - 1].value - params.speed_scale * x[0]);
        let a = nalgebra::Matrix2::identity() - kk * h;
        p = a * p * a.transpose() + kk * kk.transpose() * noise.speed_mps.powi(2);
        let e = &out.epochs[k - 1];
        max_diff = max_diff
            .max((e.x[V] - x[0]).abs())
            .max((e.x[YAW_RATE] - x[1]).abs())
            .max((e.p[(V, V)] - p[(0, 0)]).abs())
            .max((e.p[(V, YAW_RATE)] - p[(0, 1)]).abs())
            .max((e.p[(YAW_RATE, YAW_RATE)] - p[(1, 1)]).abs());
    }
    assert!(max_diff < 1e-12, "max difference {max_diff:e}");
}

/// For a linear Gaussian model the RTS smoother is the batch least-squares
/// (maximum a posteriori) solution; its covariance never exceeds the filter's.
#[test]
fn rts_equals_batch_least_squares_on_a_linear_model() {
    let mut rng = Pcg64::seed_from_u64(5);
    let n = 60;
    let dt = 0.02;
    // Use the car model with yaw and yaw rate fixed at 0 and only speed/position
    // observed: x_{k+1} = x_k + dt v_k is linear.
    let f = model::jacobian(&State::from([0.0, 0.0, 0.0, 5.0, 0.0]), dt);
    let noise = deadreckon_core::vehicle::Noise {
        process_xy_m: 0.05,
        process_yaw_rad: 0.01,
        process_speed_mps: 0.5,
        process_yaw_rate_rps: 0.1,
        ..Default::default()
    };
    let q = model::process_noise(&noise, dt);
    let h = SMatrix::<f64, 3, 5>::new(
        1.0, 0.0, 0.0, 0.0, 0.0, //
        0.0, 0.0, 0.0, 1.0, 0.0, //
        0.0, 0.0, 0.0, 0.0, 1.0,
    );
    let rd = [0.3f64, 0.1, 0.01];
    let x0 = State::from([0.0, 0.0, 0.0, 5.0, 0.0]);
    let p0 = Mat::from_diagonal(&State::from([1.0, 1.0, 0.1, 1.0, 0.1]));
    let zs: Vec<SVector<f64, 3>> = (0..n)
        .map(|k| {
            SVector::<f64, 3>::new(
                5.0 * dt * k as f64 + rd[0] * randn(&mut rng),
                5.0 + rd[1] * randn(&mut rng),
                rd[2] * randn(&mut rng),
            )
        })
        .collect();

    // Filter, recording epochs as the EKF does (epoch 0 is the prior).
    let mut epochs = Vec::new();
    let (mut x, mut p) = (x0, p0);
    for (k, z) in zs.iter().enumerate() {
        let (xp, pp) = if k == 0 {
            (x, p)
        } else {
            (f * x, kalman::predict_covariance(&p, &f, &q))
        };
        x = xp;
        p = pp;
        for i in 0..3 {
            let row: State = h.row(i).transpose();
            let y = z[i] - row.dot(&x);
            kalman::update_scalar(
                &mut x,
                &mut p,
                y,
                &row,
                rd[i] * rd[i],
                CovarianceForm::Joseph,
                0.0,
            )
            .unwrap();
        }
        epochs.push(ekf::Epoch {
            t_s: k as f64 * dt,
            x_pred: xp,
            p_pred: pp,
            f,
            x,
            p,
        });
    }
    let sm = rts::smooth(&epochs).unwrap();

    // Batch: minimise |x_0 − x̄0|²_{P0⁻¹} + Σ|x_{k+1} − F x_k|²_{Q⁻¹} + Σ|z_k − H x_k|²_{R⁻¹}.
    // The smoother's process noise must be invertible: Q has no zero diagonal here.
    let dim = 5 * n;
    let mut info = DMatrix::<f64>::zeros(dim, dim);
    let mut vec = DVector::<f64>::zeros(dim);
    let p0i = p0.try_inverse().unwrap();
    let qi = q.try_inverse().unwrap();
    let ri =
        SMatrix::<f64, 3, 3>::from_diagonal(&SVector::<f64, 3>::from(rd.map(|r| 1.0 / (r * r))));
    let add = |info: &mut DMatrix<f64>, r0: usize, c0: usize, m: &Mat| {
        for i in 0..5 {
            for j in 0..5 {
                info[(r0 + i, c0 + j)] += m[(i, j)];
            }
        }
    };
    add(&mut info, 0, 0, &p0i);
    let b0 = p0i * x0;
    for i in 0..5 {
        vec[i] += b0[i];
    }
    for k in 0..n {
        let hh = h.transpose() * ri * h;
        add(&mut info, 5 * k, 5 * k, &hh);
        let hz = h.transpose() * ri * zs[k];
        for i in 0..5 {
            vec[5 * k + i] += hz[i];
        }
        if k + 1 < n {
            add(&mut info, 5 * k, 5 * k, &(f.transpose() * qi * f));
            add(&mut info, 5 * (k + 1), 5 * (k + 1), &qi);
            add(&mut info, 5 * k, 5 * (k + 1), &(-(f.transpose() * qi)));
            add(&mut info, 5 * (k + 1), 5 * k, &(-(qi * f)));
        }
    }
    let cov = info.clone().try_inverse().unwrap();
    let sol = &cov * vec;
    let mut max_x: f64 = 0.0;
    let mut max_p: f64 = 0.0;
    for k in 0..n {
        for i in 0..5 {
            max_x = max_x.max((sm[k].x[i] - sol[5 * k + i]).abs());
            for j in 0..5 {
                max_p = max_p.max((sm[k].p[(i, j)] - cov[(5 * k + i, 5 * k + j)]).abs());
            }
        }
        // Smoothed covariance never exceeds the filtered one.
        let d = epochs[k].p - sm[k].p;
        let min_eig = d.symmetric_eigen().eigenvalues.min();
        assert!(
            min_eig > -1e-12,
            "epoch {k}: P_filt − P_smooth has eigenvalue {min_eig:e}"
        );
    }
    assert!(
        max_x < 1e-8 && max_p < 1e-8,
        "state diff {max_x:e}, covariance diff {max_p:e}"
    );
}

#[test]
fn state_only_smoothing_equals_the_full_smoother() {
    let vehicle = Vehicle::paper_car();
    let mut rng = Pcg64::seed_from_u64(21);
    let mut drive = Drive::empty(vehicle.clone());
    let n = 500;
    drive.wheels = Wheels::Ticks(
        (0..n)
            .map(|k| WheelTicks {
                t_s: k as f64 * 0.02,
                fl: 4,
                fr: 4,
                rl: 4,
                rr: 5,
            })
            .collect(),
    );
    drive.yaw_rate = (1..n)
        .map(|k| Scalar {
            t_s: k as f64 * 0.02 - 0.003,
            value: 0.02 + 0.003 * randn(&mut rng),
        })
        .collect();
    drive.gnss = (1..n / 25)
        .map(|k| deadreckon_core::drive::GnssFix {
            t_s: k as f64 * 0.5 + 0.001,
            east_m: 4.0 * k as f64 + 0.5 * randn(&mut rng),
            north_m: 0.5 * randn(&mut rng),
            std_m: 0.5,
            course_deg: None,
            speed_mps: None,
        })
        .collect();
    let p0 = Mat::from_diagonal(&State::from([1.0, 1.0, 0.1, 4.0, 0.25]));
    let opts = FilterOptions {
        init: Init::Given {
            t_s: 0.0,
            x: State::from([0.0, 0.0, 0.0, 8.0, 0.0]),
            p: p0,
        },
        ..Default::default()
    };
    let params = Params::nominal(&vehicle);
    let out = ekf::run(&drive, &params, &opts, &mut ()).unwrap();
    let full = rts::smooth(&out.epochs).unwrap();
    let states = rts::smooth_states(&out.epochs).unwrap();
    for (a, b) in full.iter().zip(&states) {
        assert!((a.x - b.1).amax() < 1e-9, "t={}: {} vs {}", a.t_s, a.x, b.1);
    }
    // Same for the augmented state.
    let prior = deadreckon_core::calibrate::CalibrationOptions::default().prior_std;
    let aug = ekf::run_augmented(&drive, &params, &prior, &opts).unwrap();
    let full = rts::smooth(&aug.epochs).unwrap();
    let states = rts::smooth_states(&aug.epochs).unwrap();
    for (a, b) in full.iter().zip(&states) {
        assert!((a.x - b.1).amax() < 1e-9);
    }
}
