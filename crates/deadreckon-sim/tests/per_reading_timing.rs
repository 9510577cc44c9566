//! Learning the parameters with per-reading timing (`--timing each`): the
//! process noise must not let the readings between wheel rows set the speed
//! ([`deadreckon_core::calibrate::check_learning_noise`]).

use deadreckon_core::calibrate::{self, CalibrationOptions};
use deadreckon_core::ekf::Timing;
use deadreckon_core::online::{Online, Start};
use deadreckon_core::Params;
use deadreckon_sim::family::CarFamily;
use deadreckon_sim::simulate;

/// Regression: per reading, table I's process noise (10 m/s and 1 rad/s per
/// 20 ms, there for the wheels to set the speed at every wheel epoch) let
/// the GNSS fixes between wheel rows set the speed, and the RTS calibration
/// read the fixes as speed: family car 3's rear-left circumference came out
/// 2.170 m for 1.987 m after 15 passes (183 mm), reported converged; the
/// GNSS delay, which calibrates at each step, read 0.162 s for 0.090 s on
/// car 2, whose dead-reckoned reference ended kilometres off.
/// Now refused, naming the keys; with values within the bounds the
/// calibration lands where the wheel epochs' does.
#[test]
fn per_reading_timing_read_the_gnss_fixes_as_speed() {
    let car = CarFamily::draw(3);
    let mut sc = car.drive(103, 600.0);
    let g = sc.sensors.gyro.as_mut().expect("family gyro");
    (g.tilt_deg, g.latency_s, g.scale_error) = (None, 0.0, 0.0);
    let sim = simulate(&sc, 103).unwrap();
    let each = CalibrationOptions {
        filter: deadreckon_core::ekf::FilterOptions {
            timing: Timing::EachMeasurement,
            ..CalibrationOptions::default().filter
        },
        ..CalibrationOptions::default()
    };
    let err = calibrate::calibrate(&sim.drive, &each).unwrap_err();
    // Both limits as data, for a front end to word (the CLI names its
    // `--timing` flags: issue 34).
    match &err {
        deadreckon_core::Error::NoiseTooHighForPerReadingTiming { over } => {
            let keys: Vec<&str> = over.iter().map(|l| l.key).collect();
            assert_eq!(
                keys,
                ["noise.process_speed_mps", "noise.process_yaw_rate_rps"]
            );
        }
        e => panic!("not the per-reading timing refusal: {e}"),
    }
    let err = err.to_string();
    for needle in [
        "noise.process_speed_mps = 10 (at most 0.5)",
        "noise.process_yaw_rate_rps = 1 (at most 0.03)",
        "timing at the wheel epochs",
    ] {
        assert!(err.contains(needle), "{needle:?} not in {err}");
    }
    let nominal = Params::nominal(&sim.drive.vehicle);
    let online = Online::learning(
        &sim.drive.vehicle,
        &nominal,
        &each.prior_std,
        &each.filter,
        Start::Gnss,
    );
    assert!(
        online.is_err_and(|e| e.to_string().contains("process_speed_mps")),
        "the online learner took table I's noise per reading"
    );

    let mut d = sim.drive.clone();
    d.vehicle.noise.process_speed_mps = calibrate::EACH_MAX_PROCESS_SPEED_MPS;
    d.vehicle.noise.process_yaw_rate_rps = calibrate::EACH_MAX_PROCESS_YAW_RATE_RPS;
    let per_reading = calibrate::calibrate(&d, &each).unwrap();
    let wheel = calibrate::calibrate(&sim.drive, &CalibrationOptions::default()).unwrap();
    let t = sim.truth_params.circumferences();
    let (e, w) = (
        per_reading.estimate.params.circumferences(),
        wheel.estimate.params.circumferences(),
    );
    eprintln!(
        "circumference errors, mm: per reading {:?}, wheel epochs {:?}; gyro bias {:+.2e} / {:+.2e} for {:+.2e}",
        [0, 1, 2, 3].map(|i| 1e3 * (e[i] - t[i])),
        [0, 1, 2, 3].map(|i| 1e3 * (w[i] - t[i])),
        per_reading.estimate.params.gyro_bias_rps,
        wheel.estimate.params.gyro_bias_rps,
        sim.truth_params.gyro_bias_rps
    );
    // Measured: +0.13, +0.15, +0.13, +0.16 mm (wheel epochs −0.88 to −0.90
    // mm); the gyro bias 1.2e-5 rad/s off (wheel epochs 2.2e-5).
    assert!(per_reading.converged);
    for i in 0..4 {
        assert!(
            (e[i] - t[i]).abs() < 0.5e-3,
            "wheel {i}: {} for {}",
            e[i],
            t[i]
        );
    }
    let b = per_reading.estimate.params.gyro_bias_rps - sim.truth_params.gyro_bias_rps;
    assert!(b.abs() < 4e-5, "gyro bias {b:+e} off");
}

/// `EACH_MAX_PROCESS_*` were chosen on family cars 1, 2, 3, 5, 6 and
/// measured on 7–10; cars 101–110 saw no choice (issue 33), run once when
/// this test was written: the per-reading calibration at the bounds against
/// the wheel epochs', both against the truth.
#[test]
fn per_reading_bounds_on_held_out_cars() {
    use rayon::prelude::*;
    let rows: Vec<(u64, f64, f64)> = (101..=110u64)
        .into_par_iter()
        .map(|seed| {
            let car = CarFamily::draw(seed);
            let mut sc = car.drive(100 + seed, 600.0);
            let g = sc.sensors.gyro.as_mut().expect("family gyro");
            (g.tilt_deg, g.latency_s, g.scale_error) = (None, 0.0, 0.0);
            let sim = simulate(&sc, 100 + seed).unwrap();
            let each = CalibrationOptions {
                filter: deadreckon_core::ekf::FilterOptions {
                    timing: Timing::EachMeasurement,
                    ..CalibrationOptions::default().filter
                },
                ..CalibrationOptions::default()
            };
            let mut d = sim.drive.clone();
            d.vehicle.noise.process_speed_mps = calibrate::EACH_MAX_PROCESS_SPEED_MPS;
            d.vehicle.noise.process_yaw_rate_rps = calibrate::EACH_MAX_PROCESS_YAW_RATE_RPS;
            let t = sim.truth_params.circumferences();
            let worst = |c: &calibrate::Calibration| {
                let e = c.estimate.params.circumferences();
                (0..4).map(|i| (e[i] - t[i]).abs()).fold(0.0, f64::max)
            };
            let per_reading = calibrate::calibrate(&d, &each).unwrap();
            let wheel = calibrate::calibrate(&sim.drive, &CalibrationOptions::default()).unwrap();
            (seed, worst(&per_reading), worst(&wheel))
        })
        .collect();
    for (seed, p, w) in &rows {
        eprintln!(
            "car {seed}: largest circumference error per reading {:.2} mm, wheel epochs {:.2} mm",
            p * 1e3,
            w * 1e3
        );
    }
    let (p, w) = rows
        .iter()
        .fold((0.0f64, 0.0f64), |(a, b), r| (a.max(r.1), b.max(r.2)));
    // Measured: per reading 0.04–1.91 mm (car 105), wheel epochs 0.04–1.75
    // mm (car 104): the bounds hold out of sample, at the wheel epochs'
    // accuracy (table I's values were +4 to +5457 mm off on the dev cars).
    assert!(p < 2.4e-3, "{p}");
    assert!(w < 2.2e-3, "{w}");
}
