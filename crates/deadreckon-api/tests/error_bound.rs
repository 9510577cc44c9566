//! Issue 31: the 95 % error bound validated on drives that did not tune
//! it. Each family car ([`CarFamily`]) is calibrated as `calibrate` does it
//! (`calibration::calibrate`: the default corrections, RTS, then the bound's factor
//! fitted on the calibration drive's own hidden fixes), and evaluated as
//! `evaluate --params` does it (the stored corrections applied) on a second
//! drive of the same car: 30 s outages every 10 s against the truth. Per
//! window, is the final error within `bound_95_m`; per set, the coverage and
//! the sharpness (median bound over median final error).
//!
//! Cars: development 301–306 (in CI) and 501–540 (`#[ignore]`d): the
//! method's choices were made on them (docs/bound.md); held-out 401–424
//! (not used for any choice, `#[ignore]`d, run once per construction):
//!
//! ```text
//! cargo test --profile ci -p deadreckon-api --test error_bound -- --nocapture
//! cargo test --profile ci -p deadreckon-api --test error_bound -- --ignored --nocapture
//! ```
//!
//! Measured with the bound `r(k² P + F)` and the fit's score
//! `r(k² P + 2F + R)` (docs/bound.md), the issue's targets coverage
//! 0.90–0.99 and sharpness at most 3:
//!
//! | cars | windows | within | coverage | sharpness |
//! |---|---|---|---|---|
//! | development 301–306 | 177 | 167 | 0.944 | 2.82 |
//! | development 501–540 | 1383 | 1314 | 0.950 | 2.64 |
//! | held-out 401–424 (run once) | 782 | 752 | 0.962 | 2.71 |
//!
//! The first construction, `k · r(P + F)`: 0.938 / 2.64, 0.967 / 3.06 and
//! 0.976 / 3.37.
//!
//! `BOUND_CORRECTIONS=auto` calibrates with `--corrections auto` instead
//! (where the receiver's wander may be chosen and carried: then the bound
//! has no receiver floor and the fit scores the predicted fix with the
//! wander, docs/gnss-wander.md); each car prints what was carried. On the
//! development cars 301–306 (`BOUND_CORRECTIONS=auto cargo test --profile
//! ci -p deadreckon-api --test error_bound
//! the_bound_covers_95_percent_of_outages_on_development_cars -- --exact
//! --nocapture`, which then fails on its `gnss` pins): the wander carried
//! on 5 of 6 (fitted 0.25–1.0 m against drawn 0.22–0.73 m), k 0–1.91,
//! 168 of 177 windows within (0.949), sharpness 3.57 (with `gnss`: 0.938,
//! 2.81). Coverage holds without the floor; the bound is wider than the
//! issue's 3 (`auto` without the wander was not measured).

use rayon::prelude::*;

use deadreckon_api::corrections::stored_corrections;
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::metrics::Summary;
use deadreckon_core::outage::evaluate;
use deadreckon_core::timing::Which;
use deadreckon_sim::family::CarFamily;
use deadreckon_sim::simulate;

/// One car's windows: (final error, bound at the end, within), and its factor.
struct Car {
    seed: u64,
    k: f64,
    fitted_on: usize,
    windows: Vec<(f64, f64, bool)>,
}

fn car(seed: u64, drive_s: f64) -> Result<Car, String> {
    let family = CarFamily::draw(seed);
    let cal = simulate(&family.drive(1000 + seed, drive_s), 1000 + seed)
        .map_err(|e| format!("calibration drive: {e}"))?;
    let ev = simulate(&family.drive(2000 + seed, drive_s), 2000 + seed)
        .map_err(|e| format!("evaluation drive: {e}"))?;
    let which = match std::env::var("BOUND_CORRECTIONS").as_deref() {
        Ok("auto") => Which::Auto,
        _ => Which::Gnss,
    };
    let c = deadreckon_api::calibration::calibrate(
        &cal.drive,
        &deadreckon_api::calibration::CalibrationRequest::with_corrections(which),
        "cal",
    )
    .map_err(|e| format!("calibration: {e}"))?;
    let stored = stored_corrections(&c.params_extra()).map_err(|e| format!("stored: {e}"))?;
    if let Some(w) = stored.model.gnss_wander {
        println!(
            "car {seed}: the receiver's wander carried ({:.2} m, {:.0} s; drawn {:.2} m, {:.0} s)",
            w.std_m, w.tau_s, family.gnss_markov.0, family.gnss_markov.1
        );
    }
    let drive = stored.apply(&ev.drive);
    let out = evaluate(
        &drive,
        &c.calibration.estimate.params,
        30.0,
        10.0,
        5.0,
        &FilterOptions::default(),
    )
    .map_err(|e| format!("evaluation: {e}"))?;
    let fit = c.bound;
    Ok(Car {
        seed,
        k: fit.k,
        fitted_on: fit.windows,
        windows: out
            .windows
            .iter()
            .map(|w| {
                (
                    w.final_m(),
                    w.bound_95_m(&fit).unwrap_or(f64::NAN),
                    w.within_bound(&fit).unwrap_or(false),
                )
            })
            .collect(),
    })
}

/// Coverage and sharpness over `cars`, printed per car.
fn measure(cars: &[u64], drive_s: f64) -> (f64, f64, usize) {
    let got: Vec<Result<Car, String>> = cars.par_iter().map(|&s| car(s, drive_s)).collect();
    let (mut errors, mut bounds, mut within) = (Vec::new(), Vec::new(), 0);
    for r in got {
        match r {
            Ok(c) => {
                let e: Vec<f64> = c.windows.iter().map(|w| w.0).collect();
                let b: Vec<f64> = c.windows.iter().map(|w| w.1).collect();
                let n_in = c.windows.iter().filter(|w| w.2).count();
                println!(
                    "car {}: k {:.3} (fitted on {} windows); {} of {} windows within; median \
                     bound {:.3} m, median final error {:.3} m",
                    c.seed,
                    c.k,
                    c.fitted_on,
                    n_in,
                    c.windows.len(),
                    Summary::of(&b).median,
                    Summary::of(&e).median
                );
                within += n_in;
                errors.extend(e);
                bounds.extend(b);
            }
            Err(e) => println!("failed: {e}"),
        }
    }
    let n = errors.len();
    let coverage = within as f64 / n as f64;
    let sharpness = Summary::of(&bounds).median / Summary::of(&errors).median;
    println!("coverage {within}/{n} = {coverage:.3}, sharpness {sharpness:.2}");
    (coverage, sharpness, n)
}

#[test]
fn the_bound_covers_95_percent_of_outages_on_development_cars() {
    let (coverage, sharpness, n) = measure(&(301..=306).collect::<Vec<_>>(), 300.0);
    // Measured: 166 of 177 windows within (0.938), median bound / median
    // final error 2.63, since the gyro-bias switch is on by default
    // (issue 28, deadreckon_core::aided::switch; the same coverage). Before
    // that: 166 of 177, 2.81, since the GNSS delay's steps stop once settled
    // (`timing::gnss::GNSS_SETTLED_FRACTION_OF_STD`, issue 30: the delays
    // of these cars' calibrations moved by fractions of their standard
    // errors, and with them each car's k). Before that: 162 of 177
    // (0.915), 2.98, since the calibration's passes run at table I's
    // yaw noise with batch-means standard errors (issue 36). Before that:
    // 167 of 177 (0.944), 2.82 (k 0–2.25 per car, fitted on 29–53 windows;
    // k = 0 on cars 303, 305, 306: the receiver's floor explains their fit
    // windows); the filter's covariance alone, without the receiver's
    // floor: 150 of 177 (0.847), 2.77.
    assert_eq!(n, 177);
    assert!((0.92..=0.96).contains(&coverage), "{coverage}");
    assert!((2.5..=2.8).contains(&sharpness), "{sharpness}");
}

#[test]
#[ignore]
fn the_bound_covers_95_percent_of_outages_on_development_cars_501_to_540() {
    let (coverage, sharpness, n) = measure(&(501..=540).collect::<Vec<_>>(), 300.0);
    // Measured: 1314 of 1383 windows within (0.950), sharpness 2.64: the
    // second development set, on which the fit's score (2F + R, the
    // offsets a window apart independent) was chosen over F + R (0.980,
    // 2.88) and the first construction (0.967, 3.06).
    assert_eq!(n, 1383);
    assert!((0.93..=0.97).contains(&coverage), "{coverage}");
    assert!((2.5..=2.8).contains(&sharpness), "{sharpness}");
}

#[test]
#[ignore]
fn the_bound_covers_95_percent_of_outages_on_held_out_cars_401_to_424() {
    let (coverage, sharpness, n) = measure(&(401..=424).collect::<Vec<_>>(), 300.0);
    // Measured (run once, after every choice was made on cars 301–306 and
    // 501–540): 752 of 782 windows within (0.962), median bound / median
    // final error 2.71 (k 0–23.4 per car; k = 0 on 6 of 24). The issue's
    // coverage (90–99 %) and sharpness (at most 3) are both met. The
    // first construction, k · r(P + F): 763 of 782 (0.976), 3.37. Again
    // after the calibration's passes moved to table I's yaw noise with
    // batch-means standard errors (issue 36): 753 of 782 (0.963), 2.72.
    assert_eq!(n, 782);
    assert!((0.94..=0.98).contains(&coverage), "{coverage}");
    assert!((2.55..=2.85).contains(&sharpness), "{sharpness}");
}
