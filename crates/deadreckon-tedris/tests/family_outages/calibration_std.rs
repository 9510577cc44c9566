//! The standard errors of the joint calibration's installed values
//! (`TedrisModel::dcf_std_rad`, `dcf_distance_std_rad_per_m`,
//! `turn_gain_std`) against the truth on the simulator's car family: the
//! per-metre term of the extended variant with a GNSS course is the whole
//! straight-line heading rate, set by the rear tyres' radius mismatch.
//!
//! The table: `cargo test --workspace --profile ci --test family_outages
//! calibration_std -- --nocapture` (`TEDRIS_FAMILY_FIRST_CAR=101` for the
//! cars 101–112).
//!
//! A module of `family_outages.rs` (it was the test binary
//! `calibration_std`): the training drives and the models [`train`] makes
//! on them are that file's, made once for both (cars 1–12 and 201–212), and
//! the cars run in parallel (rayon), printed in car order.

use deadreckon_sim::family::CarFamily;
use deadreckon_tedris::input::{drive_input, Event};
use deadreckon_tedris::{Tedris, TedrisConfig};
use rayon::prelude::*;

use super::shared::{first_car, with_trained, Trained};

/// One car's installed distance term against its truth.
struct Row {
    car: u64,
    estimate: f64,
    truth: f64,
    /// The truth without the wheels' distance scale (mismatch over track).
    truth_unscaled: f64,
    robust_std: Option<f64>,
    ols_std: f64,
    blocks: usize,
    correlation_time_s: Option<f64>,
}

/// The heading per metre the rear radius mismatch turns a straight-driving
/// car by, rad per metre of the wheels' own distance: with the right tyre
/// larger, its wheel speed reads low and ω (right − left) reads a right turn;
/// the per-metre term turns it back, `+(c_rr − c_rl)/c̄ / track`. The wheels
/// count rotations × the nominal circumference, so a metre of theirs is
/// `c̄/nominal` true metres and the term grows by that scale (first order).
fn truth_rad_per_m(car: &CarFamily) -> f64 {
    let e = &car.errors;
    let mean = 0.5 * (e.circumference_rl_m + e.circumference_rr_m);
    let mismatch = (e.circumference_rr_m - e.circumference_rl_m) / mean;
    mismatch * (mean / car.vehicle.wheel_circumference_m) / car.vehicle.track_rear_m
}

/// Trains on the car's 900 s training drive (`family_outages.rs`'s) the
/// way [`train`](deadreckon_tedris::train) does, keeping the machine for
/// its last calibration, and checks that `train` installed the same values
/// and standard errors in the model it made on that drive.
fn run_car(seed: u64) -> Option<Row> {
    with_trained(seed, |t| row(seed, t))
}

fn row(seed: u64, t: &Trained) -> Option<Row> {
    let car = CarFamily::draw(seed);
    let drive = &t.drive;
    let input = drive_input(drive, None, &[]).expect("input");
    let mut m = Tedris::new(TedrisConfig::default(), input.geometry).expect("machine");
    if let Some((e, n, y)) = input.initial_pose {
        m.set_pose(e, n, y);
    }
    for e in &input.events {
        // Invalid samples are counted by the machine and skipped (as `train`).
        let _ = match e {
            Event::Wheel(w) => m.push_wheel(*w).map(|_| ()),
            Event::Heading(h) => m.push_heading(*h),
            Event::Fix(f) => m.push_fix(*f),
        };
    }
    let model = m.model().expect("trained").clone();
    let trained = &t.model;
    assert_eq!(
        (
            trained.dcf_distance_rad_per_m,
            trained.dcf_distance_std_rad_per_m,
            trained.dcf_std_rad,
            trained.turn_gain_std
        ),
        (
            model.dcf_distance_rad_per_m,
            model.dcf_distance_std_rad_per_m,
            model.dcf_std_rad,
            model.turn_gain_std
        ),
        "car {seed}: train() installed other values than its machine"
    );
    assert!(
        model.per_metre_straight,
        "car {seed}: not the per-metre form"
    );
    // The per-metre form has no per-sample DCF: never reported with a
    // standard error.
    assert_eq!(model.dcf_std_rad, None, "car {seed}");
    let last = m.last_calibration()?;
    let j = last.names.iter().position(|n| n == "dcf_distance")?;
    // The installed value is the last calibration's.
    assert_eq!(
        last.estimates[j], model.dcf_distance_rad_per_m,
        "car {seed}"
    );
    assert_eq!(
        last.std_error.as_ref().map(|s| s[j]),
        model.dcf_distance_std_rad_per_m,
        "car {seed}"
    );
    if let Some(g) = last.names.iter().position(|n| n == "gain") {
        assert_eq!(
            last.std_error.as_ref().map(|s| s[g]),
            model.turn_gain_std,
            "car {seed}"
        );
    }
    Some(Row {
        car: seed,
        estimate: model.dcf_distance_rad_per_m,
        truth: truth_rad_per_m(&car),
        truth_unscaled: {
            let e = &car.errors;
            2.0 * (e.circumference_rr_m - e.circumference_rl_m)
                / (e.circumference_rl_m + e.circumference_rr_m)
                / car.vehicle.track_rear_m
        },
        robust_std: model.dcf_distance_std_rad_per_m,
        ols_std: last.ols_std_error[j],
        blocks: last.blocks,
        correlation_time_s: last.correlation_time_s,
    })
}

/// Cars `first..first + 12`: how many have a robust standard error, the
/// worst |z| robust and OLS, and on how many the OLS one is beyond 3.
fn family(first: u64) -> (usize, f64, f64, usize) {
    let (mut worst_robust, mut worst_ols, mut estimated, mut ols_off) = (0.0f64, 0.0f64, 0, 0);
    let rows: Vec<Option<Row>> = (first..first + 12).into_par_iter().map(run_car).collect();
    for (car, row) in (first..first + 12).zip(rows) {
        let Some(r) = row else {
            eprintln!("car {car}: no joint calibration installed a distance term");
            continue;
        };
        let err = r.estimate - r.truth;
        let z_ols = err / r.ols_std;
        eprintln!(
            "car {}: distance term {:+.4e} rad/m, truth {:+.4e}, error {:+.2e}; robust std {} (z {}; {} against mismatch/track unscaled), {} blocks, increments' correlation time {}; OLS std {:.2e} (z {:+.1})",
            r.car,
            r.estimate,
            r.truth,
            err,
            r.robust_std.map_or("not estimated".into(), |s| format!("{s:.2e}")),
            r.robust_std.map_or("-".into(), |s| format!("{:+.2}", err / s)),
            r.robust_std.map_or("-".into(), |s| format!(
                "{:+.2}",
                (r.estimate - r.truth_unscaled) / s
            )),
            r.blocks,
            r.correlation_time_s.map_or("-".into(), |t| format!("{t:.2} s")),
            r.ols_std,
            z_ols
        );
        worst_ols = worst_ols.max(z_ols.abs());
        ols_off += usize::from(z_ols.abs() > 3.0);
        if let Some(s) = r.robust_std {
            estimated += 1;
            worst_robust = worst_robust.max((err / s).abs());
        }
    }
    eprintln!(
        "{estimated} cars with a robust standard error: worst |z| {worst_robust:.2} (robust), {worst_ols:.1} (OLS, beyond 3 on {ols_off} cars)"
    );
    (estimated, worst_robust, worst_ols, ols_off)
}

#[test]
fn the_calibrations_standard_errors_ignored_the_autocorrelated_heading() {
    // TEDRIS_FAMILY_FIRST_CAR=101 runs cars 101–112 (seen by choices since);
    // cars 201–212 are the untouched set, below.
    let first = first_car();
    let (estimated, worst_robust, _, ols_off) = family(first);
    assert!(estimated > 0);
    if first == 1 {
        // Measured on cars 1-12: every car estimated; worst robust |z| 2.34
        // (car 9; the bound 3 leaves a margin of 0.66); the OLS standard
        // errors put the truth beyond |z| = 3 on 9 of the 12 cars, up to 95.
        assert_eq!(estimated, 12);
        assert!(worst_robust < 3.0, "{worst_robust}");
        assert!(ols_off >= 8, "{ols_off}");
    }
}

/// Cars 201–212, drawn for issue 33 and run once when this test was
/// written (the test used to assert only `estimated > 0` out of the
/// development cars).
#[test]
fn the_calibrations_standard_errors_on_held_out_cars_201_to_212() {
    let (estimated, worst_robust, worst_ols, ols_off) = family(201);
    // Measured: every car estimated; worst robust |z| 0.90; the OLS
    // standard errors put the truth beyond |z| = 3 on 11 of the 12, up to
    // 52 (the development cars: 2.34, and 9 of 12 up to 95).
    assert_eq!(estimated, 12);
    assert!(worst_robust < 1.5, "{worst_robust}");
    assert!(ols_off >= 9 && worst_ols > 20.0, "{ols_off} {worst_ols}");
}
