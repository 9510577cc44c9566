//! Issue 36: the RTS calibration's smoothing passes at table I's yaw
//! process noise (`calibrate::SMOOTHING_PROCESS_YAW_RAD`, 1e-5, an option)
//! against the vehicle's (the default: the dead-reckoning filter's
//! `vehicle::PROCESS_YAW_RAD`, 5e-5, five times larger to keep the
//! dead-reckoned pose covariance honest through turns). With the larger
//! value the smoother lets the yaw take heading changes that the yaw rate,
//! and through it the gyro bias, should explain; how much depends on the
//! gyro: with table II's gyro (0.003 rad/s per reading) the yaw rate's own
//! freedom dwarfs either value and the bias hardly moves (family cars
//! 41–64, `calibration_family.rs`), with a better gyro the yaw noise
//! dominates and the bias reads low.
//!
//! The family here: cars 65–88 of [`CarFamily`] (no choice of the project
//! was made on them), each with a gyro drawn between 0.0003 and 0.003 rad/s
//! (log-uniform; vehicle.toml declares it), a gyro bias within ±0.005
//! rad/s, and a CAN speed stream (so the speed scale is calibrated too).
//! A 600 s calibration drive, calibrated with the default options (the
//! vehicle's yaw noise in the passes) and with table I's in the passes;
//! the errors of the six parameters in their standard errors; the pose NEES
//! through 30 s dead-reckoning windows every 60 s of a second 600 s drive
//! with the calibrated parameters (the dead-reckoning filter at the
//! vehicle's noise). "Consistent" is the NEES averaged over a drive's
//! windows within the χ² 95 % interval of that average at every point of
//! the windows (`consistency::Verdict`), as `consistency.rs` judges it.
//!
//! ```text
//! cargo test --profile ci -p deadreckon-sim --test calibration_noise_family -- --nocapture
//! ```

use deadreckon_core::calibrate::{calibrate, CalibrationOptions, SMOOTHING_PROCESS_YAW_RAD};
use deadreckon_core::consistency::{nees_through_windows, windows, Verdict};
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::Params;
use deadreckon_sim::family::CarFamily;
use deadreckon_sim::scenario::Scenario;
use deadreckon_sim::sensors::ScalarSpec;
use deadreckon_sim::simulate;
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;
use rayon::prelude::*;

/// The family members checked.
const CARS: std::ops::RangeInclusive<u64> = 65..=88;

/// The calibration options with the passes at table I's yaw noise.
fn at_table_one_yaw_noise() -> CalibrationOptions {
    CalibrationOptions {
        smoothing_process_yaw_rad: Some(SMOOTHING_PROCESS_YAW_RAD),
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
    gyro_rps: f64,
    /// The errors in standard errors with the passes at table I's yaw noise.
    z: [f64; 6],
    /// The same with the default calibration (the vehicle's yaw noise).
    z_vehicle: [f64; 6],
    /// The pose NEES on the evaluation drive.
    pose: Verdict,
    /// The same with white fixes and no receiver latency.
    pose_white: Verdict,
}

fn member(seed: u64) -> Result<Member, String> {
    let (s, gyro_rps) = scenario(seed, 100 + seed);
    let cal = simulate(&s, 100 + seed).map_err(|e| e.to_string())?;
    let c = calibrate(&cal.drive, &at_table_one_yaw_noise()).map_err(|e| e.to_string())?;
    let old = calibrate(&cal.drive, &CalibrationOptions::default()).map_err(|e| e.to_string())?;
    let nees = |white: bool| -> Result<Verdict, String> {
        let (mut s, _) = scenario(seed, 200 + seed);
        if white {
            if let Some(g) = s.sensors.gnss.as_mut() {
                g.markov_std_m = 0.0;
                g.latency_s = 0.0;
            }
        }
        let ev = simulate(&s, 200 + seed).map_err(|e| e.to_string())?;
        let w = windows(&ev.drive, 30.0, 60.0, 60.0);
        let n = nees_through_windows(&ev.drive, &c.estimate.params, &w, &FilterOptions::default())
            .map_err(|e| e.to_string())?;
        Ok(n.pose.verdict())
    };
    Ok(Member {
        gyro_rps,
        z: z(&c.estimate.params, &c.estimate.std, &cal.truth_params),
        z_vehicle: z(&old.estimate.params, &old.estimate.std, &cal.truth_params),
        pose: nees(false)?,
        pose_white: nees(true)?,
    })
}

fn within(z: &[f64; 6]) -> bool {
    z.iter().all(|z| z.abs() <= 3.0)
}

#[test]
fn calibrated_parameters_within_their_error_bars_with_better_gyros() {
    let rows: Vec<(u64, Result<Member, String>)> = CARS
        .into_par_iter()
        .map(|seed| (seed, member(seed)))
        .collect();
    println!(
        "car | gyro rad/s | passes at table I's 1e-5: z bias, scale, circumferences | default (the vehicle's 5e-5): the same | pose NEES (white fixes, no latency)"
    );
    let f = |z: &[f64; 6]| {
        z.iter()
            .map(|v| format!("{v:+6.2}"))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let mut ms = Vec::new();
    for (seed, m) in rows {
        let m = m.unwrap_or_else(|e| panic!("car {seed}: {e}"));
        println!(
            "{seed:3} | {:.5} | {} | {} | {} ({})",
            m.gyro_rps,
            f(&m.z),
            f(&m.z_vehicle),
            m.pose,
            m.pose_white
        );
        ms.push(m);
    }
    let n = ms.len();
    let count = |p: &dyn Fn(&Member) -> bool| ms.iter().filter(|m| p(m)).count();
    let ok = count(&|m| within(&m.z));
    let ok_vehicle = count(&|m| within(&m.z_vehicle));
    let bias_ok = count(&|m| m.z[0].abs() <= 3.0);
    let bias_ok_vehicle = count(&|m| m.z_vehicle[0].abs() <= 3.0);
    let consistent = count(&|m| m.pose == Verdict::Consistent);
    let consistent_white = count(&|m| m.pose_white == Verdict::Consistent);
    let rms = |k: &dyn Fn(&Member) -> f64| {
        (ms.iter().map(|m| k(m).powi(2)).sum::<f64>() / n as f64).sqrt()
    };
    println!(
        "passes at table I's yaw noise: {ok}/{n} every parameter within 3σ ({bias_ok}/{n} the gyro bias, RMS z {:.2}); \
         default (the vehicle's): {ok_vehicle}/{n} ({bias_ok_vehicle}/{n}, RMS z {:.2}); \
         pose NEES consistent {consistent}/{n} ({consistent_white}/{n} with white fixes, no latency)",
        rms(&|m| m.z[0]),
        rms(&|m| m.z_vehicle[0]),
    );
    // Measured (cars 65–88, run once): at table I's yaw noise every
    // parameter within 3σ on 22/24 (car 68: bias +4.80σ; car 74: speed
    // scale −3.07σ, circumferences +2.9σ, the distance scale at either yaw
    // noise; car 80's bias +2.97σ is within), the gyro bias on 23/24, RMS z
    // 1.65; with the default (the vehicle's 5e-5): 20/24, bias 21/24 (car
    // 70 −5.82σ, 71 −3.41σ, 82 −3.52σ; car 68 +0.70σ; car 74's distance
    // scale +3.2σ), RMS z 1.97. The issue's bar (95 %, 23 of 24) is met by
    // the gyro bias at table I's value only, by neither for every
    // parameter. The pose NEES is over-confident on 24/24 (×1.9–×276;
    // 23/24 with white fixes and no latency, ×1.7–×16): printed, not
    // asserted (the family's receivers, see calibration_family.rs; issue
    // 31's bound is the remedy).
    assert_eq!(n, 24);
    assert!(bias_ok >= 23, "gyro bias within 3σ on {bias_ok}/{n}");
    assert!(ok >= 22, "every parameter within 3σ on {ok}/{n}");
    assert!(ok >= ok_vehicle + 2 && bias_ok >= bias_ok_vehicle + 2);
    assert!(rms(&|m| m.z[0]) < 1.8, "RMS z of the bias");
    assert!(
        rms(&|m| m.z_vehicle[0]) > 1.85,
        "RMS z of the bias, default"
    );
}

/// Issue 36's case, a new user's drive: the built-in calibration scenario
/// (600 s, seed 1) with a gyro of 0.0005 rad/s per reading (declared in
/// vehicle.toml) and a true bias of 0.0041 rad/s. With the passes at the
/// dead-reckoning filter's 5e-5 (the default) the bias reads 0.0040942 ±
/// 0.0000020 (−2.93σ); with table I's 1e-5, 0.0041009 (+0.46σ).
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
        z(&at_table_one_yaw_noise()),
        z(&CalibrationOptions::default()),
    );
    println!("z: {now:+.2} with table I's yaw noise, {before:+.2} with the vehicle's");
    assert!(now.abs() < 1.0, "{now}");
    assert!(before < -2.5, "{before}");
}

/// Family car 30 with white fixes (drive 130), whose heading is found late
/// (13–20° off at the first fixes). With table I's yaw noise as every
/// calibration's default, the command refused it (its smoothing filter lost
/// the fixes: distance scale −9.8 % against the GNSS chords,
/// `tests/edges.rs`), one of the reasons it is not the default; the core
/// calibration, with the wheel monitor as the command runs it, calibrates
/// it with either (table I's: z within 1.37, the bias +0.43; the
/// vehicle's: within 1.46). The difference was not found.
#[test]
fn car_30s_late_heading_calibrates_in_the_core_with_either_yaw_noise() {
    let mut car = CarFamily::draw(30);
    car.gnss_markov = (0.0, 60.0);
    let sim = simulate(&car.drive(130, 600.0), 130).unwrap();
    for mut opts in [at_table_one_yaw_noise(), CalibrationOptions::default()] {
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
