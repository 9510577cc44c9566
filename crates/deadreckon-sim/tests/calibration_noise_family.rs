//! Issue 36: the RTS calibration's parameters within their error bars on
//! randomized family cars with gyros better than table II's. The smoothing
//! passes run at table I's yaw process noise
//! (`calibrate::SMOOTHING_PROCESS_YAW_RAD`, 1e-5, the default) and the
//! standard errors are the batch means' where larger than the lag-1
//! inflation's (`calibrate.rs`'s `BATCHES`); against them, the passes at
//! the vehicle's (`smoothing_process_yaw_rad: None`: the dead-reckoning
//! filter's `vehicle::PROCESS_YAW_RAD`, 5e-5, the default before). With the
//! larger value the smoother lets the yaw take heading changes that the yaw
//! rate, and through it the gyro bias, should explain; how much depends on
//! the gyro: with table II's (0.003 rad/s per reading) the yaw rate's own
//! freedom dwarfs either value (family cars 41–64, `calibration_family.rs`).
//!
//! The family: each car of [`CarFamily`] with a gyro drawn between 0.0003
//! and 0.003 rad/s (log-uniform; vehicle.toml declares it), a gyro bias
//! within ±0.005 rad/s, and a CAN speed stream (so the speed scale is
//! calibrated too). A 600 s calibration drive; the errors of the six
//! parameters in their standard errors; the pose NEES through 30 s
//! dead-reckoning windows every 60 s of a second 600 s drive with the
//! calibrated parameters (the dead-reckoning filter at the vehicle's
//! noise), as the filter's covariance says and with it inflated by the
//! error bound's factor fitted on the calibration drive
//! (`deadreckon_core::bound::fit_on_drive`, `k²·P`). "Consistent" is the
//! NEES averaged over a drive's windows within the χ² 95 % interval of that
//! average at every point of the windows (`consistency::Verdict`), as
//! `consistency.rs` judges it.
//!
//! Cars 65–88 chose the default (yaw noise and batch count); cars 89–112
//! check it (no choice was made on them; slow, `#[ignore]`d):
//!
//! ```text
//! cargo test --profile ci -p deadreckon-sim --test calibration_noise_family -- --nocapture
//! cargo test --profile ci -p deadreckon-sim --test calibration_noise_family -- --ignored --nocapture
//! ```

use deadreckon_core::bound;
use deadreckon_core::calibrate::{calibrate, CalibrationOptions};
use deadreckon_core::consistency::{averaged_nees_bounds, nees_through_windows, windows, Verdict};
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::Params;
use deadreckon_sim::family::CarFamily;
use deadreckon_sim::scenario::Scenario;
use deadreckon_sim::sensors::ScalarSpec;
use deadreckon_sim::simulate;
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;
use rayon::prelude::*;

/// The family members the default was chosen on.
const CHOICE_CARS: std::ops::RangeInclusive<u64> = 65..=88;

/// The family members it is checked on (no choice was made on them).
const CHECK_CARS: std::ops::RangeInclusive<u64> = 89..=112;

/// The calibration options with the passes at the vehicle's yaw noise (the
/// dead-reckoning filter's), the default before issue 36.
fn at_the_vehicles_yaw_noise() -> CalibrationOptions {
    CalibrationOptions {
        smoothing_process_yaw_rad: None,
        ..CalibrationOptions::default()
    }
}

/// Car `seed` of the family with its gyro (noise, bias) and a CAN speed
/// stream drawn from `seed`: the scenario of drive `drive_seed`, and the
/// gyro's noise.
fn scenario(seed: u64, drive_seed: u64) -> (Scenario, f64) {
    let mut car = CarFamily::draw(seed);
    let r = &mut Pcg64::seed_from_u64(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 36);
    let gyro_rps = 0.0003 * 10f64.powf(r.random::<f64>());
    car.errors.gyro_bias_rps = -0.005 + 0.01 * r.random::<f64>();
    car.vehicle.noise.gyro_rps = gyro_rps;
    let mut s = car.drive(drive_seed, 600.0);
    if let Some(g) = s.sensors.gyro.as_mut() {
        g.noise_std = gyro_rps;
    }
    s.sensors.speed = Some(ScalarSpec {
        rate_hz: 50.0,
        offset_s: 0.0,
        noise_std: 0.1,
        latency_s: 0.0,
        scale_error: 0.0,
        tilt_deg: None,
        bias_drift_std_rps: 0.0,
        bias_drift_tau_s: 300.0,
        clock: None,
    });
    (s, gyro_rps)
}

/// Errors in standard errors, in [`Params::to_array`] order.
fn z(est: &Params, std: &Params, truth: &Params) -> [f64; 6] {
    let (p, s, t) = (est.to_array(), std.to_array(), truth.to_array());
    std::array::from_fn(|i| (p[i] - t[i]) / s[i])
}

/// One car's figures.
#[derive(Debug, Clone)]
struct Member {
    seed: u64,
    gyro_rps: f64,
    /// The errors in standard errors with the default calibration.
    z: [f64; 6],
    /// The same with the passes at the vehicle's yaw noise.
    z_vehicle: [f64; 6],
    /// The pose NEES on the evaluation drive, as the filter's covariance says.
    pose: Verdict,
    /// The error bound's factor fitted on the calibration drive.
    k: f64,
    /// The pose NEES with the covariance inflated by `k²`.
    pose_bound: Verdict,
}

/// The verdict on the NEES `values` (per point of the windows, `dof`
/// degrees of freedom) with the covariance scaled by `variance_factor`:
/// as `BlockNees::verdict`, the point farthest from its bounds.
fn scaled_verdict(values: &[Vec<f64>], dof: usize, variance_factor: f64) -> Verdict {
    let mut worst = (1.0, Verdict::Consistent);
    for v in values.iter().filter(|v| !v.is_empty()) {
        let mean = v.iter().sum::<f64>() / v.len() as f64 / variance_factor;
        let (lo, hi) = averaged_nees_bounds(dof, v.len()).unwrap();
        let n = dof as f64;
        let (f, verdict) = if mean > hi {
            (mean / n, Verdict::OverConfident(mean / n))
        } else if mean < lo {
            (n / mean, Verdict::UnderConfident(n / mean))
        } else {
            (1.0, Verdict::Consistent)
        };
        if f > worst.0 {
            worst = (f, verdict);
        }
    }
    worst.1
}

fn member(seed: u64) -> Result<Member, String> {
    let (s, gyro_rps) = scenario(seed, 100 + seed);
    let cal = simulate(&s, 100 + seed).map_err(|e| e.to_string())?;
    let c = calibrate(&cal.drive, &CalibrationOptions::default()).map_err(|e| e.to_string())?;
    let old = calibrate(&cal.drive, &at_the_vehicles_yaw_noise()).map_err(|e| e.to_string())?;
    let params = &c.estimate.params;
    let fit = bound::fit_on_drive(&cal.drive, params, &FilterOptions::default());
    let (s, _) = scenario(seed, 200 + seed);
    let ev = simulate(&s, 200 + seed).map_err(|e| e.to_string())?;
    let w = windows(&ev.drive, 30.0, 60.0, 60.0);
    let n = nees_through_windows(&ev.drive, params, &w, &FilterOptions::default())
        .map_err(|e| e.to_string())?;
    Ok(Member {
        seed,
        gyro_rps,
        z: z(params, &c.estimate.std, &cal.truth_params),
        z_vehicle: z(&old.estimate.params, &old.estimate.std, &cal.truth_params),
        pose: n.pose.verdict(),
        k: fit.k,
        pose_bound: scaled_verdict(&n.pose.values, n.pose.dof, fit.k * fit.k),
    })
}

fn within(z: &[f64; 6]) -> bool {
    z.iter().all(|z| z.abs() <= 3.0)
}

/// The family's figures over `cars`, printed as a table.
struct Table {
    n: usize,
    /// Every parameter within 3σ, default and at the vehicle's yaw noise.
    within: (usize, usize),
    /// The gyro bias within 3σ, the same.
    bias_within: (usize, usize),
    /// RMS z of the gyro bias, the same.
    bias_rms_z: (f64, f64),
    /// Pose NEES consistent: the filter's covariance, inflated by `k²`.
    consistent: (usize, usize),
}

fn table(cars: std::ops::RangeInclusive<u64>) -> Table {
    let mut ms: Vec<Member> = cars
        .into_par_iter()
        .map(|seed| member(seed).unwrap_or_else(|e| panic!("car {seed}: {e}")))
        .collect();
    ms.sort_by_key(|m| m.seed);
    println!(
        "car | gyro rad/s | default (passes at table I's 1e-5): z bias, scale, circumferences | \
         passes at the vehicle's 5e-5: the same | pose NEES | bound's k: pose NEES of k²P"
    );
    let f = |z: &[f64; 6]| {
        z.iter()
            .map(|v| format!("{v:+6.2}"))
            .collect::<Vec<_>>()
            .join(" ")
    };
    for m in &ms {
        println!(
            "{:3} | {:.5} | {} | {} | {} | k {:.2}: {}",
            m.seed,
            m.gyro_rps,
            f(&m.z),
            f(&m.z_vehicle),
            m.pose,
            m.k,
            m.pose_bound
        );
    }
    let n = ms.len();
    let count = |p: &dyn Fn(&Member) -> bool| ms.iter().filter(|m| p(m)).count();
    let rms = |k: &dyn Fn(&Member) -> f64| {
        (ms.iter().map(|m| k(m).powi(2)).sum::<f64>() / n as f64).sqrt()
    };
    let t = Table {
        n,
        within: (count(&|m| within(&m.z)), count(&|m| within(&m.z_vehicle))),
        bias_within: (
            count(&|m| m.z[0].abs() <= 3.0),
            count(&|m| m.z_vehicle[0].abs() <= 3.0),
        ),
        bias_rms_z: (rms(&|m| m.z[0]), rms(&|m| m.z_vehicle[0])),
        consistent: (
            count(&|m| m.pose == Verdict::Consistent),
            count(&|m| m.pose_bound == Verdict::Consistent),
        ),
    };
    println!(
        "default: every parameter within 3σ {}/{n}, the gyro bias {}/{n} (RMS z {:.2}); \
         passes at the vehicle's yaw noise: {}/{n}, {}/{n} (RMS z {:.2}); \
         pose NEES consistent {}/{n} ({}/{n} with the bound's k²)",
        t.within.0,
        t.bias_within.0,
        t.bias_rms_z.0,
        t.within.1,
        t.bias_within.1,
        t.bias_rms_z.1,
        t.consistent.0,
        t.consistent.1,
    );
    t
}

#[test]
fn calibrated_parameters_within_their_error_bars_with_better_gyros() {
    let t = table(CHOICE_CARS);
    // Measured (cars 65–88, on which the default was chosen): every
    // parameter within 3σ on 24/24 (the worst car 74's distance scale,
    // −2.94σ), the gyro bias RMS z 0.44 (max 0.96: the batch means err
    // wide); at the vehicle's yaw noise 23/24 (car 74, −3.22σ), RMS z 0.97.
    // With the lag-1 standard errors alone (before): 22/24 and 20/24, RMS
    // z 1.65 and 1.97. The pose NEES: see the check below.
    assert_eq!(t.n, 24);
    assert_eq!(t.within.0, 24, "every parameter within 3σ");
    assert!(t.within.1 <= 23);
    assert!(
        t.bias_rms_z.0 > 0.3 && t.bias_rms_z.0 < 0.6,
        "RMS z of the bias {}",
        t.bias_rms_z.0
    );
}

/// The check on cars no choice was made on.
#[test]
#[ignore = "slow: 24 cars, two calibrations and three filter runs each"]
fn calibrated_parameters_within_their_error_bars_on_cars_no_choice_saw() {
    let t = table(CHECK_CARS);
    // Measured (cars 89–112): every parameter within 3σ on 24/24, the gyro
    // bias RMS z 0.67 (max 1.76, car 89); at the vehicle's yaw noise 19/24
    // (the bias 20/24: cars 90 +4.7σ, 96 +3.0σ, 97 +6.1σ, 104 +3.9σ; car
    // 94's distance scale −3.2σ), RMS z 2.04. With the lag-1 standard
    // errors alone: 20/24 at 1e-5 (RMS z 2.45). The pose NEES is
    // over-confident on 24/24 (×2.2–×556) and stays so with the error
    // bound's k² on 24/24 (×8–×760: k is fitted on the horizontal
    // position's 95 % radius against fixes that wander with the
    // receiver; where it is below 1 it shrinks the covariance): the
    // issue's NEES bar is not met, printed, not asserted.
    assert_eq!(t.n, 24);
    assert!(
        t.within.0 >= 23,
        "every parameter within 3σ on {}",
        t.within.0
    );
    assert!(
        t.bias_rms_z.0 > 0.4 && t.bias_rms_z.0 < 0.9,
        "RMS z of the bias {}",
        t.bias_rms_z.0
    );
    assert!(t.within.1 <= 21 && t.bias_rms_z.1 > 1.5);
    assert_eq!(t.consistent, (0, 0));
}

/// Issue 36's case, a new user's drive: the built-in calibration scenario
/// (600 s, seed 1) with a gyro of 0.0005 rad/s per reading (declared in
/// vehicle.toml) and a true bias of 0.0041 rad/s. With the passes at the
/// dead-reckoning filter's 5e-5 the bias reads 0.0040942 (−5.8e-6 rad/s);
/// with table I's 1e-5 (the default), 0.0041009 (+0.9e-6). The standard
/// error is 0.0000041 with either (the batch means'; 0.0000020 with the
/// lag-1 inflation alone, which made them −2.93σ and +0.46σ): now +0.22σ
/// and −1.42σ.
#[test]
fn a_good_gyros_bias_read_low_with_the_dead_reckoning_yaw_noise_in_the_passes() {
    let mut s = Scenario::builtin("calibration").unwrap();
    s.duration_s = Some(600.0);
    let truth = 0.0041;
    s.errors.as_mut().unwrap().gyro_bias_rps = truth;
    s.vehicle.noise.gyro_rps = 0.0005;
    s.sensors.gyro.as_mut().unwrap().noise_std = 0.0005;
    let d = simulate(&s, 1).unwrap().drive;
    let z = |o: &CalibrationOptions| {
        let c = calibrate(&d, o).unwrap();
        let e = c.estimate;
        println!(
            "{:?}: bias {:.7} ± {:.7}",
            o.smoothing_process_yaw_rad, e.params.gyro_bias_rps, e.std.gyro_bias_rps
        );
        (e.params.gyro_bias_rps - truth) / e.std.gyro_bias_rps
    };
    let (now, before) = (
        z(&CalibrationOptions::default()),
        z(&at_the_vehicles_yaw_noise()),
    );
    println!("z: {now:+.2} with table I's yaw noise, {before:+.2} with the vehicle's");
    assert!(now.abs() < 0.4, "{now}");
    assert!(before < -1.2 && before < -5.0 * now.abs(), "{before}");
}

/// Family car 30 with white fixes (drive 130), whose heading is found late
/// (13–20° off at the first fixes). Issue 36's first stop saw the command
/// refuse it with table I's yaw noise (distance scale −9.8 % against the
/// GNSS chords): that was `tests/edges.rs`'s second half, with the scale
/// hold off, which is meant to be refused; with the hold (the default) the
/// command calibrates it, and so does the core calibration with the wheel
/// monitor as the command runs it, with either yaw noise (table I's: z
/// within 1.37, the bias +0.24; the vehicle's: within 1.46, +0.32).
#[test]
fn car_30s_late_heading_calibrates_in_the_core_with_either_yaw_noise() {
    let mut car = CarFamily::draw(30);
    car.gnss_markov = (0.0, 60.0);
    let sim = simulate(&car.drive(130, 600.0), 130).unwrap();
    for mut opts in [CalibrationOptions::default(), at_the_vehicles_yaw_noise()] {
        // As `calibrate` runs it: with the wheel-health monitor.
        opts.filter.wheel_monitor = Some(Default::default());
        let c = calibrate(&sim.drive, &opts).unwrap();
        let z = z(&c.estimate.params, &c.estimate.std, &sim.truth_params);
        let chords = c.gnss_chords.map(|ch| ch.std);
        println!(
            "{:?}: converged {} after {} passes, z {:?}, chords {chords:?}",
            opts.smoothing_process_yaw_rad, c.converged, c.iterations, z
        );
        assert!(c.converged);
        // No CAN speed on this car: the speed scale is not estimated (σ 0).
        assert!(
            z.iter().filter(|v| v.is_finite()).all(|v| v.abs() <= 3.0),
            "{z:?}"
        );
    }
}
