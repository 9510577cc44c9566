//! Issue 36: is what the RTS calibration reports within its error bars over
//! a randomized family, with the yaw process noise the filter runs with
//! (`vehicle::PROCESS_YAW_RAD`, 5e-5, five times table I's, chosen for a
//! consistent pose NEES), and is the pose NEES then consistent on each
//! car's evaluation drive?
//!
//! Family cars 41–64 ([`CarFamily`]; no choice of the project was made on
//! them): a 600 s calibration drive, RTS calibration with the default
//! options; the errors of the gyro bias and the four circumferences in
//! their standard errors against the car's truth; then the pose NEES
//! through 30 s dead-reckoning windows every 60 s of a second 600 s drive
//! with the calibrated parameters. The same with the calibration's passes
//! at table I's 1e-5 (`calibrate::SMOOTHING_PROCESS_YAW_RAD`, an option)
//! printed beside it.
//!
//! Measured (24 cars): every parameter within 3σ on 24 of 24 at 5e-5 and
//! on 24 of 24 at 1e-5 (largest |z| 2.57 and 2.50, car 56's gyro bias;
//! the same with the 1e-5 set in the drive's vehicle.toml, as this test
//! first did): with these cars' gyro
//! (table II's 0.003 rad/s) the yaw noise changes no z by more than 0.4;
//! the family with better gyros where it does is
//! `calibration_noise_family.rs`. The pose NEES, in contrast, reads
//! over-confident on 24 of 24 evaluation drives, by ×1.8 to ×254, and still
//! on 22 of 24 (×1.6 to ×13.5) with white fixes and no receiver latency:
//! the family's receivers (latency 0–0.15 s, Gauss–Markov wander) and
//! more are not in the filter's covariance. That is the error-bound
//! issue's to fix (issue 31), not the calibration's; it is printed here
//! and not asserted.
//!
//! ```text
//! cargo test --profile ci -p deadreckon-sim --test calibration_family -- --nocapture
//! ```

use deadreckon_core::calibrate::{calibrate, CalibrationOptions, SMOOTHING_PROCESS_YAW_RAD};
use deadreckon_core::consistency::{nees_through_windows, windows, Verdict};
use deadreckon_core::ekf::FilterOptions;
use deadreckon_sim::family::CarFamily;
use deadreckon_sim::simulate;
use rayon::prelude::*;

/// The family members checked.
const CARS: std::ops::RangeInclusive<u64> = 41..=64;

/// One car's figures with one calibration noise.
#[derive(Debug, Clone)]
struct Member {
    /// Errors in standard errors: gyro bias, then the four circumferences.
    z: [f64; 5],
    /// The pose NEES verdict on the evaluation drive.
    pose: Verdict,
    /// The same on the evaluation drive with white fixes (the receiver's
    /// slow wander off).
    pose_white: Verdict,
}

/// A member's figures, or why it has none.
type Outcome = Result<Member, String>;

/// A member calibrated with the default options (`at_table_one`: with the
/// passes at table I's yaw noise, 1e-5).
fn member(seed: u64, at_table_one: bool) -> Result<Member, String> {
    let car = CarFamily::draw(seed);
    let cal = simulate(&car.drive(100 + seed, 600.0), 100 + seed).map_err(|e| e.to_string())?;
    let opts = CalibrationOptions {
        smoothing_process_yaw_rad: at_table_one.then_some(SMOOTHING_PROCESS_YAW_RAD),
        ..CalibrationOptions::default()
    };
    let c = calibrate(&cal.drive, &opts).map_err(|e| e.to_string())?;
    let (p, s, t) = (
        c.estimate.params.to_array(),
        c.estimate.std.to_array(),
        cal.truth_params.to_array(),
    );
    let idx = [0usize, 2, 3, 4, 5];
    let z = idx.map(|i| (p[i] - t[i]) / s[i]);
    let pose = |car: &CarFamily| -> Result<Verdict, String> {
        let ev = simulate(&car.drive(200 + seed, 600.0), 200 + seed).map_err(|e| e.to_string())?;
        let w = windows(&ev.drive, 30.0, 60.0, 60.0);
        let nees =
            nees_through_windows(&ev.drive, &c.estimate.params, &w, &FilterOptions::default())
                .map_err(|e| e.to_string())?;
        Ok(nees.pose.verdict())
    };
    let mut white = car.clone();
    white.gnss_markov = (0.0, 60.0);
    white.gnss_latency_s = 0.0;
    Ok(Member {
        z,
        pose: pose(&car)?,
        pose_white: pose(&white)?,
    })
}

fn verdict_text(v: Verdict) -> String {
    match v {
        Verdict::Consistent => "consistent".into(),
        Verdict::OverConfident(k) => format!("over-confident x{k:.2}"),
        Verdict::UnderConfident(k) => format!("under-confident x{k:.2}"),
    }
}

#[test]
fn calibrated_parameters_within_their_error_bars_over_the_family() {
    let rows: Vec<(u64, Outcome, Outcome)> = CARS
        .into_par_iter()
        .map(|seed| (seed, member(seed, false), member(seed, true)))
        .collect();
    let (mut within, mut n, mut consistent, mut within_t1) = (0usize, 0usize, 0usize, 0usize);
    println!("car | default (passes at the vehicle's 5e-5): z bias, z circumferences, pose NEES | passes at table I's 1e-5: the same");
    for (seed, a, b) in &rows {
        let line = |m: &Result<Member, String>| match m {
            Ok(m) => format!(
                "{:+5.2} [{:+5.2} {:+5.2} {:+5.2} {:+5.2}] {} (white fixes, no latency: {})",
                m.z[0],
                m.z[1],
                m.z[2],
                m.z[3],
                m.z[4],
                verdict_text(m.pose),
                verdict_text(m.pose_white)
            ),
            Err(e) => format!("not calibrated: {e}"),
        };
        println!("{seed:3} | {} | {}", line(a), line(b));
        let a = a.as_ref().unwrap_or_else(|e| panic!("car {seed}: {e}"));
        n += 1;
        within += usize::from(a.z.iter().all(|z| z.abs() <= 3.0));
        consistent += usize::from(a.pose == Verdict::Consistent);
        if let Ok(b) = b {
            within_t1 += usize::from(b.z.iter().all(|z| z.abs() <= 3.0));
        }
    }
    println!(
        "default: {within}/{n} with every parameter within 3σ, {consistent}/{n} pose NEES consistent; \
         passes at table I's 1e-5: {within_t1}/{n} within 3σ"
    );
    // Measured 24/24 (see the module docs); the issue's bar is 95 %.
    assert!(within * 100 >= 95 * n, "{within}/{n}");
    assert_eq!(n, 24);
}
