//! Numerical acceptance tests of the four-wheel method on simulated drives
//! (issue: "what done looks like"). Run with an optimised profile
//! (`cargo test --profile ci`): each case simulates and smooths kilometres of driving.

mod common;

use deadreckon_core::calibrate::{self, CalibrationOptions, Iteration, Method, PassState};
use deadreckon_core::ekf::{self, FilterOptions, Timing};
use deadreckon_core::metrics::{self, Summary};
use deadreckon_core::{rts, Params};
use deadreckon_sim::{simulate, Scenario};

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

/// Calibrates on a simulated calibration drive and evaluates on an evaluation
/// drive; checks the accuracy targets of the issue.
fn check_seed(seed: u64) {
    let cal = common::sim("calibration", seed);
    let eval = common::sim("evaluation", seed + 1000);
    let truth = cal.truth_params.to_array();

    let rts = calibrate::calibrate(&cal.drive, &CalibrationOptions::default()).unwrap();
    let e = rts.estimate.params.to_array();
    assert!(
        rts.converged,
        "seed {seed}: RTS did not converge in {} passes",
        rts.iterations
    );
    assert!(
        rel(e[0], truth[0]) < 0.05,
        "seed {seed}: gyro bias {} vs {}",
        e[0],
        truth[0]
    );
    assert!(
        rel(e[1], truth[1]) < 0.003,
        "seed {seed}: speed scale {} vs {}",
        e[1],
        truth[1]
    );
    for i in 2..6 {
        assert!(
            rel(e[i], truth[i]) < 0.001,
            "seed {seed}: {} {} vs {}",
            Params::NAMES[i],
            e[i],
            truth[i]
        );
    }
    // The standard errors are meaningful: the truth lies within 5 of them.
    let s = rts.estimate.std.to_array();
    for i in 0..6 {
        assert!(
            s[i] > 0.0 && (e[i] - truth[i]).abs() < 5.0 * s[i] + 1e-9,
            "seed {seed}: {} error {} vs std {}",
            Params::NAMES[i],
            e[i] - truth[i],
            s[i]
        );
    }

    let zupt = calibrate::calibrate(
        &cal.drive,
        &CalibrationOptions {
            method: Method::Zupt,
            ..Default::default()
        },
    )
    .unwrap();
    let tru = calibrate::calibrate(
        &cal.drive,
        &CalibrationOptions {
            method: Method::Truth,
            ..Default::default()
        },
    )
    .unwrap();
    let nominal = Params::nominal(&cal.drive.vehicle);
    let drift = |p: &Params| {
        Summary::of(
            &metrics::drift(&eval.drive, p, 100.0, Timing::WheelEpochs)
                .unwrap()
                .errors_pct(),
        )
        .mean
    };
    let (d_nom, d_zupt, d_rts, d_truth) = (
        drift(&nominal),
        drift(&zupt.estimate.params),
        drift(&rts.estimate.params),
        drift(&tru.estimate.params),
    );
    eprintln!("seed {seed}: drift nominal {d_nom:.3}% zupt {d_zupt:.3}% rts {d_rts:.3}% truth {d_truth:.3}%, {} passes", rts.iterations);
    assert!(
        d_rts < d_zupt && d_zupt < d_nom,
        "seed {seed}: drift order nominal {d_nom} zupt {d_zupt} rts {d_rts}"
    );
    assert!(
        d_rts <= 1.1 * d_truth,
        "seed {seed}: RTS drift {d_rts} vs truth-calibrated {d_truth}"
    );
}

#[test]
fn calibration_and_drift_seed_1() {
    check_seed(1);
}
#[test]
fn calibration_and_drift_seed_2() {
    check_seed(2);
}
#[test]
fn calibration_and_drift_seed_3() {
    check_seed(3);
}
#[test]
fn calibration_and_drift_seed_4() {
    check_seed(4);
}
#[test]
fn calibration_and_drift_seed_5() {
    check_seed(5);
}

/// The paper's plain iteration converges slowly when the circumferences are 1%
/// off; the accelerated one reaches 0.1% in a few passes.
#[test]
fn accelerated_iteration_beats_the_plain_one_on_a_one_percent_error() {
    let sc = Scenario::builtin("calibration").unwrap();
    let mut errors = sc.true_params();
    let c = sc.vehicle.wheel_circumference_m * 1.01;
    errors.set_circumferences([c, c * 1.0002, c * 0.9998, c]);
    let sim = simulate(&sc.with_errors(errors), 9).unwrap();
    let truth = sim.truth_params.to_array();
    let worst = |p: &Params| {
        (2..6)
            .map(|i| rel(p.to_array()[i], truth[i]))
            .fold(0.0, f64::max)
    };

    let fast = calibrate::calibrate(&sim.drive, &CalibrationOptions::default()).unwrap();
    assert!(
        worst(&fast.estimate.params) < 0.001,
        "accelerated: {}",
        worst(&fast.estimate.params)
    );
    assert!(
        fast.iterations <= 10,
        "accelerated took {} passes",
        fast.iterations
    );

    let plain = calibrate::calibrate(
        &sim.drive,
        &CalibrationOptions {
            state: PassState::Paper,
            iteration: Iteration::Plain,
            max_iterations: 3,
            ..Default::default()
        },
    )
    .unwrap();
    let after3 = worst(&plain.history[2]);
    eprintln!(
        "1% circumference error: accelerated {} passes -> {:.4}%, plain after 3 passes {:.3}%",
        fast.iterations,
        100.0 * worst(&fast.estimate.params),
        100.0 * after3
    );
    assert!(
        after3 > 0.001,
        "plain iteration after 3 passes already within 0.1%: {after3}"
    );
}

/// Over a 2-hour drive every filtered and smoothed covariance stays symmetric
/// positive definite, and no smoothed covariance exceeds the filtered one.
#[test]
fn covariances_stay_symmetric_positive_definite_over_two_hours() {
    let sc = Scenario::builtin("calibration")
        .unwrap()
        .with_duration_s(7200.0);
    let sim = simulate(&sc, 4).unwrap();
    let span = sim.drive.time_span().unwrap();
    assert!(
        span.1 - span.0 >= 7100.0,
        "drive lasts {} s",
        span.1 - span.0
    );
    for timing in [Timing::WheelEpochs, Timing::EachMeasurement] {
        let out = ekf::run(
            &sim.drive,
            &sim.truth_params,
            &FilterOptions {
                timing,
                ..Default::default()
            },
            &mut (),
        )
        .unwrap();
        let sm = rts::smooth(&out.epochs).unwrap();
        for (e, s) in out.epochs.iter().zip(&sm) {
            for p in [&e.p, &e.p_pred, &s.p] {
                assert_eq!(*p, p.transpose(), "asymmetric covariance at t={}", e.t_s);
                assert!(
                    p.cholesky().is_some(),
                    "covariance not positive definite at t={}",
                    e.t_s
                );
            }
            let min_eig = (e.p - s.p).symmetric_eigen().eigenvalues.min();
            assert!(
                min_eig > -1e-9 * e.p.amax(),
                "smoothed exceeds filtered at t={}: {min_eig:e}",
                e.t_s
            );
        }
    }
}

/// Any sensor may be absent: the filter uses what the drive has, and dead
/// reckoning still works with the calibrated parameters.
#[test]
fn filter_runs_with_any_sensor_absent() {
    let cal = common::sim("evaluation", 31);
    let p = cal.truth_params;
    let full = Summary::of(
        &metrics::drift(&cal.drive, &p, 100.0, Timing::WheelEpochs)
            .unwrap()
            .errors_pct(),
    )
    .mean;
    type Strip = fn(&mut deadreckon_core::Drive);
    let strip: [(&str, Strip); 4] = [
        ("gyro", |d| d.yaw_rate.clear()),
        ("speed", |d| d.speed.clear()),
        ("steering", |d| d.steering.clear()),
        ("gnss", |d| d.gnss.clear()),
    ];
    for (name, f) in strip {
        let mut d = cal.drive.clone();
        f(&mut d);
        let drift = Summary::of(
            &metrics::drift(&d, &p, 100.0, Timing::WheelEpochs)
                .unwrap()
                .errors_pct(),
        )
        .mean;
        eprintln!("without {name}: drift {drift:.3}% (all sensors {full:.3}%)");
        // The wheels alone still dead-reckon; losing the gyro costs the most.
        assert!(
            drift < if name == "gyro" { 5.0 } else { 0.5 },
            "without {name}: {drift}%"
        );
    }
    // GNSS-aided filtering without the CAN speed and steering.
    let mut d = cal.drive.clone();
    d.speed.clear();
    d.steering.clear();
    let out = ekf::run(&d, &p, &FilterOptions::default(), &mut ()).unwrap();
    assert_eq!(out.stats.speed_updates + out.stats.steering_updates, 0);
    assert!(out.stats.gnss_updates > 1000);
}
