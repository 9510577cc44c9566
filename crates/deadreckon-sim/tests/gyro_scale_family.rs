//! The gyro scale error's estimate ([`deadreckon_core::gyro_scale`]) on the
//! dynamic family's cars with the gyro scale effect alone (±1 %, uniform):
//! per car, the 300 s calibration drive of `dynamic_family_defaults`
//! (seed 1000 + car), core's RTS calibration for the gyro bias, then the
//! estimate against the car's true scale error.
//!
//! ```text
//! cargo test --profile ci --workspace --test gyro_scale_family -- --ignored --nocapture
//! GYRO_SCALE_CARS=held cargo test --profile ci --workspace --test gyro_scale_family -- --ignored --nocapture
//! ```
//!
//! `GYRO_SCALE_EFFECTS=all_but_wander` draws every effect but the
//! receiver's wander, `none` no effect (the truth is then 0),
//! `GYRO_SCALE_CARS=held` (or a list) the cars.
//!
//! Measured (error of the estimate against the truth; z in its own
//! standard errors; cars whose calibration or estimate failed left out):
//!
//! | estimator | effects | cars | estimated | RMS error | RMS z | beyond 3σ |
//! |---|---|---|---|---|---|---|
//! | each turn's course change on its integrated gyro (before) | scale | dev 1–25 | 22 | 0.534 % | 1.28 | 0 |
//! | the same | all but the wander | dev 1–25 | 21 | 0.640 % | 1.74 | 1 |
//! | runs' `o` fitted on `h` and `t` (now) | scale | dev 1–25 | 23 | 0.123 % | 0.90 | 0 |
//! | the same | all but the wander | dev 1–25 | 23 | 0.364 % | 1.33 | 0 |
//! | the same | scale | held-out 101–125 | 20 | 0.159 % | 0.76 | 0 |
//! | the same | all but the wander | held-out 101–125 | 21 | 0.298 % | 1.09 | 0 |
//! | the same | none (truth 0) | dev / held-out | 23 / 20 | 0.123 / 0.159 % | 0.90 / 0.76 | 0 / 0 |
//!
//! Through `calibrate`'s default corrections (whose bias comes from a
//! calibration of the corrected drive) the first estimator put cars 12 and
//! 22 5.0 and 4.4 standard errors off. The cap on a run's weight
//! ([`deadreckon_core::gyro_scale::MAX_RUN_WEIGHT_FIXES`]) was chosen on
//! the development cars. The held-out cars' first run showed car 113 (two
//! turns, five runs) at +1.070 % ± 0.009 % for +0.918 % (16.5 standard
//! errors): two degrees of freedom left a near-zero scatter. The residual
//! variance now has a floor from the course noise within the runs (car
//! 113: ± 0.122 %, z +1.2); the development cars' figures moved by
//! 0.03 in RMS z, and the held-out table above is after that change, so
//! the held-out cars are not untouched by it. Fewer turns than two, or
//! fewer than [`deadreckon_core::gyro_scale::MIN_RUNS`] runs (cars 5 and 9
//! here), give no estimate.

use deadreckon_core::calibrate::{calibrate, CalibrationOptions};
use deadreckon_core::gyro_scale;
use deadreckon_sim::family::{DynamicCar, Effects};
use deadreckon_sim::simulate;

/// One car's (true scale error, estimate), both as fractions.
fn one(seed: u64) -> Result<(f64, gyro_scale::GyroScale), String> {
    let car = DynamicCar::draw(seed);
    let effects = match std::env::var("GYRO_SCALE_EFFECTS").as_deref() {
        Ok("all_but_wander") => Effects::all_but("wander").expect("a known effect"),
        Ok("none") => Effects::none(),
        _ => Effects::only("gyro_scale").expect("a known effect"),
    };
    let cal_seed = 1000 + seed;
    let cal = simulate(&car.drive(cal_seed, 300.0, &effects), cal_seed).expect("simulated");
    let c = calibrate(&cal.drive, &CalibrationOptions::default()).map_err(|e| e.to_string())?;
    Ok((
        if effects.gyro_scale {
            car.gyro_scale_error
        } else {
            0.0
        },
        gyro_scale::estimate(&cal.drive, c.estimate.params.gyro_bias_rps),
    ))
}

/// Cars 12 and 22 read +0.48 % ± 0.65 % (true −0.88 %) and −0.06 % ± 0.27 %
/// (true −0.50 %) here, and +0.93 % ± 0.36 % and +0.08 % ± 0.13 % (5.0 and
/// 4.4 standard errors off) through `calibrate`'s default corrections: the
/// regression of each turn's course change on its integrated gyro took the
/// calibrated bias, which holds the scale error times the drive's mean yaw
/// rate, for scale. Now −0.88 % ± 0.08 % and −0.50 % ± 0.08 %.
#[test]
fn gyro_scale_read_the_calibrated_bias_as_scale() {
    for (seed, within) in [(12, 0.0005), (22, 0.0005)] {
        let (truth, g) = one(seed).expect("calibrated");
        assert!(
            g.is_estimated() || g.std.is_finite(),
            "car {seed}: {:?}",
            g.status
        );
        let err = g.scale_error - truth;
        assert!(
            err.abs() < within && err.abs() < 3.0 * g.std,
            "car {seed}: {:+.3} % ± {:.3} % for a true {:+.3} %",
            100.0 * g.scale_error,
            100.0 * g.std,
            100.0 * truth
        );
    }
}

#[test]
#[ignore = "measurement: 25 cars' calibrations (about a minute)"]
fn gyro_scale_on_the_family() {
    let cars: Vec<u64> = match std::env::var("GYRO_SCALE_CARS").as_deref() {
        Ok("held") => (101..=125).collect(),
        Ok(list) if !list.is_empty() => list.split(',').filter_map(|c| c.parse().ok()).collect(),
        _ => (1..=25).collect(),
    };
    let mut errs = Vec::new();
    let mut zs = Vec::new();
    for seed in cars {
        let (truth, g) = match one(seed) {
            Ok(x) => x,
            Err(e) => {
                println!("car {seed}: calibration failed: {e}");
                continue;
            }
        };
        if !g.std.is_finite() {
            println!(
                "car {seed}: true {:+.3} %, not estimated: {:?}",
                100.0 * truth,
                g.status
            );
            continue;
        }
        let err = g.scale_error - truth;
        let z = err / g.std;
        println!(
            "car {seed}: true {:+.3} %, estimate {:+.3} % ± {:.3} % ({} turns, {:?}): error {:+.3} %, z {:+.1}",
            100.0 * truth,
            100.0 * g.scale_error,
            100.0 * g.std,
            g.turns,
            g.status,
            100.0 * err,
            z
        );
        errs.push(err);
        zs.push(z);
    }
    let rms = |v: &[f64]| (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt();
    println!(
        "{} estimated: RMS error {:.3} %, RMS z {:.2}, beyond 3σ {}",
        errs.len(),
        100.0 * rms(&errs),
        rms(&zs),
        zs.iter().filter(|z| z.abs() > 3.0).count()
    );
}
