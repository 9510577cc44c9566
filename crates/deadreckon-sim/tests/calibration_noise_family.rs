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
//! Why the pose NEES is over-confident (issue 36's second stop, measured by
//! `pose_nees_decomposed_on_the_choice_cars`): not the calibrated
//! parameters (the true ones give the same NEES within ±25 %; the six
//! parameters carried as states with their calibrated variance change the
//! end-of-window NEES by −55 %…+55 %, the yaw σ by 0.1–0.3 mrad), but the pose
//! the GNSS-aided filter hands over at the window's start, 0.7–2.1 m off
//! where the filter says 0.1–0.2 m: the receiver's wander (Gauss–Markov,
//! 0–1.5 m) and its latency (0–0.15 s), which a filter taking the fixes as
//! white and prompt averages away. The NEES is largest at the start and
//! falls through the window as the dead reckoning's own growth dominates;
//! with white prompt fixes and the true parameters it is 1–4 per degree of
//! freedom. The filter carrying the receiver's wander
//! (`deadreckon_core::gnss_error`) with (σ, τ) fitted on the calibration
//! drive's own fixes (`deadreckon_core::wander_fit`) is printed beside it.
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
use deadreckon_core::consistency::{
    errors_through_windows, nees_through_windows, windows, Reported, Verdict,
};
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::Params;
use deadreckon_sim::family::CarFamily;
use deadreckon_sim::scenario::Scenario;
use deadreckon_sim::simulate;
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

use deadreckon_sim::family::good_gyro_car as scenario;

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
    /// The receiver's wander fitted on the calibration drive
    /// (`deadreckon_core::wander_fit`), `None` for white fixes.
    wander: Option<deadreckon_core::gnss_error::Wander>,
    /// The pose NEES with the filter carrying that wander.
    pose_wander: Verdict,
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
    let errors = errors_through_windows(&ev.drive, params, &w, &FilterOptions::default())
        .map_err(|e| e.to_string())?;
    let n = errors
        .consistency(&Reported::FILTER)
        .map_err(|e| e.to_string())?;
    // The bound's factor alone on the filter's covariance (its floor left
    // out): with k = 0 no heading variance is left, over-confident by ∞.
    let bound = errors
        .consistency(&Reported {
            k: fit.k,
            floor_m2: 0.0,
        })
        .map_err(|e| e.to_string())?;
    let wander = deadreckon_core::wander_fit::fit(&cal.drive, params, &FilterOptions::default())
        .map_err(|e| e.to_string())?
        .best;
    let mut carried = ev.drive.clone();
    if let Some(wd) = wander {
        carried.vehicle.noise.gnss_wander_std_m = wd.std_m;
        carried.vehicle.noise.gnss_wander_tau_s = wd.tau_s;
    }
    let nw = nees_through_windows(&carried, params, &w, &FilterOptions::default())
        .map_err(|e| e.to_string())?;
    Ok(Member {
        seed,
        gyro_rps,
        z: z(params, &c.estimate.std, &cal.truth_params),
        z_vehicle: z(&old.estimate.params, &old.estimate.std, &cal.truth_params),
        pose: n.pose.verdict(),
        k: fit.k,
        pose_bound: bound.pose.verdict(),
        wander,
        pose_wander: nw.pose.verdict(),
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
    /// Pose NEES consistent with the filter carrying the receiver's wander
    /// fitted on the calibration drive.
    consistent_wander: usize,
    /// The largest factor of those verdicts (over- or under-confident).
    worst_wander: f64,
}

/// A verdict's factor (1 when consistent).
fn factor(v: &Verdict) -> f64 {
    match v {
        Verdict::Consistent => 1.0,
        Verdict::OverConfident(k) | Verdict::UnderConfident(k) => *k,
    }
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
            "{:3} | {:.5} | {} | {} | {} | k {:.2}: {} | wander {}: {}",
            m.seed,
            m.gyro_rps,
            f(&m.z),
            f(&m.z_vehicle),
            m.pose,
            m.k,
            m.pose_bound,
            m.wander.map_or("white".to_string(), |w| format!(
                "{:.2} m {:.0} s",
                w.std_m, w.tau_s
            )),
            m.pose_wander
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
        consistent_wander: count(&|m| m.pose_wander == Verdict::Consistent),
        worst_wander: ms
            .iter()
            .map(|m| factor(&m.pose_wander))
            .fold(1.0, f64::max),
    };
    println!(
        "default: every parameter within 3σ {}/{n}, the gyro bias {}/{n} (RMS z {:.2}); \
         passes at the vehicle's yaw noise: {}/{n}, {}/{n} (RMS z {:.2}); \
         pose NEES consistent {}/{n} ({}/{n} with the bound's k²); with the receiver's \
         wander fitted on the calibration drive {}/{n} (worst ×{:.1})",
        t.within.0,
        t.bias_within.0,
        t.bias_rms_z.0,
        t.within.1,
        t.bias_within.1,
        t.bias_rms_z.1,
        t.consistent.0,
        t.consistent.1,
        t.consistent_wander,
        t.worst_wander,
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
    // The pose NEES (issue 36's second stop, `pose_nees_decomposed_on_the_
    // choice_cars`): over-confident on 24/24 (×1.9–×276) with the
    // five-state filter, whose fixes are white; the excess is the pose
    // handed over at the window's start (the receiver's wander and
    // latency, not the parameters: the true ones read the same). With the
    // filter carrying the receiver's wander fitted on the calibration
    // drive (`wander_fit`): 12/24 consistent, the rest ×1.6–×3.4 (over
    // on 6, under on 6).
    assert_eq!(t.consistent.0, 0);
    assert_eq!(t.consistent_wander, 12, "the wander carried");
    assert!(t.worst_wander < 3.6, "worst ×{}", t.worst_wander);
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
#[ignore = "slow: 24 cars, two calibrations, a wander fit and four filter runs each"]
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
    // With the filter carrying the receiver's wander fitted on the
    // calibration drive (chosen on cars 65–88: 12/24), measured once here:
    // 7/24 consistent, the rest ×1.8–×5.9 over or under, and car 107
    // under-confident by ×12.9 (its wander fitted at 1.0 m; its white
    // five-state verdict ×101 over). The issue's NEES bar is not met.
    assert_eq!(t.consistent_wander, 7, "the wander carried");
    assert!(t.worst_wander < 14.0, "worst ×{}", t.worst_wander);
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

/// Collects `(t, x, P)` of the car block at every epoch of any layout.
struct Epochs(
    Vec<(
        f64,
        deadreckon_core::model::State,
        deadreckon_core::model::Mat,
    )>,
);

impl<const N: usize> deadreckon_core::ekf::EpochHook<N> for Epochs {
    fn after_epoch(
        &mut self,
        t: f64,
        x: &mut nalgebra::SVector<f64, N>,
        p: &mut nalgebra::SMatrix<f64, N, N>,
    ) {
        self.0.push((
            t,
            x.fixed_rows::<5>(0).into_owned(),
            p.fixed_view::<5, 5>(0, 0).into_owned(),
        ));
    }
}

/// The window points of the decomposition: the start (the last epoch before
/// the window) and the consistency's four.
const DECOMPOSED_POINTS: [f64; 5] = [0.0, 0.25, 0.5, 0.75, 1.0];

/// Mean NEES per degree of freedom over the windows at each point of
/// [`DECOMPOSED_POINTS`]: `[position (2), heading (1), pose (3)]`, and the
/// RMS errors (position m, heading rad) with the filter's RMS σ. With
/// `prior_std` the filter carries the six parameters as states starting at
/// `params` with those standard deviations (the augmented filter: their
/// uncertainty enters the pose's covariance).
fn decomposed(
    drive: &deadreckon_core::Drive,
    params: &Params,
    prior_std: Option<&Params>,
    w: &[(f64, f64)],
) -> Vec<([f64; 3], [f64; 4])> {
    use deadreckon_core::model::{X, Y, YAW};
    let truth = deadreckon_core::reference::Reference::from_truth(&drive.truth).unwrap();
    let opts = FilterOptions {
        gnss_outages: w.to_vec(),
        record_epochs: false,
        ..FilterOptions::default()
    };
    let mut hook = Epochs(Vec::new());
    if let Some(sd) = prior_std {
        let f = deadreckon_core::ekf::augmented_filter(drive, params, sd, &opts).unwrap();
        deadreckon_core::ekf::run_filter(drive, f, &opts, &mut hook).unwrap();
    } else if drive.vehicle.noise.gnss_wander_std_m > 0.0 {
        use deadreckon_core::gnss_error::{CarWanderLayout, N_WANDER};
        let mut f =
            deadreckon_core::ekf::fixed_filter::<CarWanderLayout, N_WANDER>(drive, params, &opts)
                .unwrap();
        // As the aided filter runs it: its feeder takes the standstill
        // (deadreckon_core::standstill).
        let (feeder, events) = deadreckon_core::ekf::feed(drive, &opts, f.time_s());
        let mut feeder = feeder.with_standstill();
        let mut each = |f: &mut deadreckon_core::filter::Filter<CarWanderLayout, N_WANDER>,
                        _: deadreckon_core::ekf::EpochOut<'_, N_WANDER>| {
            let (mut x, mut p) = (*f.state(), *f.covariance());
            deadreckon_core::ekf::EpochHook::<N_WANDER>::after_epoch(
                &mut hook,
                f.time_s(),
                &mut x,
                &mut p,
            );
        };
        for ev in events {
            feeder.push(&mut f, ev, &mut each).unwrap();
        }
        feeder.finish(&mut f, &mut each).unwrap();
    } else {
        deadreckon_core::ekf::run(drive, params, &opts, &mut hook).unwrap();
    }
    let s = hook.0;
    DECOMPOSED_POINTS
        .iter()
        .map(|f| {
            let (mut acc, mut err, mut m) = ([0.0; 3], [0.0; 4], 0.0);
            for &(a, b) in w {
                let t = a + f * (b - a);
                let k = if *f == 0.0 {
                    s.partition_point(|e| e.0 < a)
                } else {
                    s.partition_point(|e| e.0 <= t)
                };
                let Some((ts, x, p)) = k.checked_sub(1).map(|k| &s[k]) else {
                    continue;
                };
                let Some(r) = truth.state_at(*ts) else {
                    continue;
                };
                let e = nalgebra::Vector3::new(
                    x[X] - r[X],
                    x[Y] - r[Y],
                    deadreckon_core::angle::diff(x[YAW], r[YAW]),
                );
                let p3: nalgebra::Matrix3<f64> = p.fixed_view::<3, 3>(0, 0).into_owned();
                let p2: nalgebra::Matrix2<f64> = p.fixed_view::<2, 2>(0, 0).into_owned();
                let e2 = nalgebra::Vector2::new(e[0], e[1]);
                acc[0] += (e2.transpose() * p2.try_inverse().unwrap() * e2)[0] / 2.0;
                acc[1] += e[2] * e[2] / p3[(2, 2)];
                acc[2] += (e.transpose() * p3.try_inverse().unwrap() * e)[0] / 3.0;
                err[0] += e2.norm_squared();
                err[1] += p2.trace();
                err[2] += e[2] * e[2];
                err[3] += p3[(2, 2)];
                m += 1.0;
            }
            (acc.map(|v| v / m), err.map(|v| (v / m).sqrt()))
        })
        .collect()
}

/// Issue 36's diagnosis: the pose NEES decomposed (window start against
/// end, position against heading) with the calibrated parameters, the true
/// ones, and the true ones on the same car with white fixes (no receiver
/// wander).
#[test]
#[ignore = "diagnostic: prints the decomposition"]
fn pose_nees_decomposed_on_the_choice_cars() {
    let rows: Vec<String> = CHOICE_CARS
        .into_par_iter()
        .map(|seed| {
            let (s, _) = scenario(seed, 100 + seed);
            let cal = simulate(&s, 100 + seed).unwrap();
            let c = calibrate(&cal.drive, &CalibrationOptions::default()).unwrap();
            let (s, _) = scenario(seed, 200 + seed);
            let ev = simulate(&s, 200 + seed).unwrap();
            let w = windows(&ev.drive, 30.0, 60.0, 60.0);
            let mut white = s.clone();
            if let Some(g) = white.sensors.gnss.as_mut() {
                g.markov_std_m = 0.0;
            }
            let evw = simulate(&white, 200 + seed).unwrap();
            let mut prompt = white.clone();
            if let Some(g) = prompt.sensors.gnss.as_mut() {
                g.latency_s = 0.0;
            }
            let evp = simulate(&prompt, 200 + seed).unwrap();
            let mut wandering = ev.drive.clone();
            let g = s.sensors.gnss.as_ref().unwrap();
            wandering.vehicle.noise.gnss_wander_std_m = g.markov_std_m.max(0.05);
            wandering.vehicle.noise.gnss_wander_tau_s = g.markov_tau_s;
            let mut out = format!(
                "car {seed}: latency {:.3} s, markov {:.2} m, fix std {:.2} m, bias err {:+.2e} ± {:.1e}\n",
                s.sensors.gnss.as_ref().unwrap().latency_s,
                s.sensors.gnss.as_ref().unwrap().markov_std_m,
                s.sensors.gnss.as_ref().unwrap().std_m,
                c.estimate.params.gyro_bias_rps - cal.truth_params.gyro_bias_rps,
                c.estimate.std.gyro_bias_rps
            );
            let sd = Some(&c.estimate.std);
            for (name, d, p, prior) in [
                ("calibrated", &ev.drive, &c.estimate.params, None),
                ("calibrated, as states", &ev.drive, &c.estimate.params, sd),
                ("truth", &ev.drive, &cal.truth_params, None),
                ("truth, white fixes", &evw.drive, &cal.truth_params, None),
                ("truth, white, prompt", &evp.drive, &cal.truth_params, None),
                ("calibrated, wander", &wandering, &c.estimate.params, None),
            ] {
                let r = decomposed(d, p, prior, &w);
                out += &format!("  {name:21}");
                for (f, (n, e)) in DECOMPOSED_POINTS.iter().zip(&r) {
                    out += &format!(
                        " | {f:.2}: pos {:7.1} yaw {:7.1} pose {:7.1} (e {:.2}/{:.2} m, {:.4}/{:.4} rad)",
                        n[0], n[1], n[2], e[0], e[1], e[2], e[3]
                    );
                }
                out += "\n";
            }
            out
        })
        .collect();
    for r in rows {
        print!("{r}");
    }
}

/// Issue 36's second stop: `nees_through_windows` ran the five-state filter
/// whatever the vehicle declared, so a vehicle with the receiver's wander
/// (`noise.gnss_wander_std_m`) was judged on a filter it does not run. Now
/// the pose NEES is the wander filter's: the same as its car block through
/// the same windows, averaged by hand.
#[test]
fn the_nees_ran_the_five_state_filter_whatever_the_vehicle_declared() {
    let (s, _) = scenario(68, 268);
    let sim = simulate(&s, 268).unwrap();
    let (mut drive, truth_params) = (sim.drive, sim.truth_params);
    let w = windows(&drive, 30.0, 60.0, 60.0);
    let white = nees_through_windows(&drive, &truth_params, &w, &FilterOptions::default())
        .unwrap()
        .pose;
    drive.vehicle.noise.gnss_wander_std_m = 1.0;
    drive.vehicle.noise.gnss_wander_tau_s = 120.0;
    let wander = nees_through_windows(&drive, &truth_params, &w, &FilterOptions::default())
        .unwrap()
        .pose;
    let by_hand = decomposed(&drive, &truth_params, None, &w);
    for (j, p) in wander.points.iter().enumerate() {
        // DECOMPOSED_POINTS[j + 1] is WINDOW_POINTS[j]; its pose column is
        // the NEES per degree of freedom.
        let hand = 3.0 * by_hand[j + 1].0[2];
        assert!(
            (p.nees - hand).abs() < 1e-9 * hand.max(1.0),
            "{} against {hand}",
            p.nees
        );
    }
    // Car 68 (wander 1.16 m): the white filter's end NEES is ×100 the
    // wander filter's (measured: 290 and 2.7).
    let end = |b: &deadreckon_core::consistency::BlockNees| b.points.last().unwrap().nees;
    println!(
        "end NEES: white {:.1}, wander {:.1}",
        end(&white),
        end(&wander)
    );
    assert!(end(&white) > 30.0 * end(&wander));
}

/// One car of [`pose_nees_with_the_wander_auto_chose`]: its seed, auto's
/// wander, the pose NEES verdict with white fixes and with auto's choice.
type AutoRow = (
    u64,
    Option<deadreckon_core::gnss_error::Wander>,
    Verdict,
    Verdict,
);

/// The pose NEES with the receiver's wander as `--corrections auto` chose
/// it on the calibration drive (issues 28, 36: fitted after the other
/// options, applied only when the held-back fixes say so), against the
/// wander always carried (the figures above) and white fixes. The
/// evaluation filter runs with the default calibration's parameters and
/// auto's wander decision alone (the other corrections auto chose are not
/// applied to the evaluation drive), so the columns differ only in the
/// receiver model. `NEES_CARS=choice` or `check` (default both).
///
/// Measured with the wander applied at a held-back t of −1 or below (the
/// rule until issue 36's fourth stop; now below 0,
/// `held_back::WANDER_MIN_T`, measured through the user's path in
/// `deadreckon-api/tests/pose_nees_family.rs`; each set run once, 220 s
/// and 133 s at a load of 7): choice
/// cars 65–88, the wander chosen on 12/24, pose NEES consistent 0/24
/// white, 6/24 with auto's choice (where chosen ×1.8–×3.0 or consistent;
/// the wander always carried: 12/24); check cars 89–112, chosen on 13/24,
/// consistent 0/24 and 1/24 (where chosen ×1.8–×6.6; always carried:
/// 7/24). Where auto does not choose it the NEES stays the white filter's
/// (×1.9–×128).
///
/// ```text
/// cargo test --profile ci -p deadreckon-sim --test calibration_noise_family pose_nees_with_the_wander_auto_chose -- --ignored --nocapture
/// ```
#[test]
#[ignore = "slow: 48 cars, a calibration with --corrections auto each"]
fn pose_nees_with_the_wander_auto_chose() {
    use deadreckon_core::held_back;
    use deadreckon_core::timing::{DelayOptions, Which};
    let sets = match std::env::var("NEES_CARS").as_deref() {
        Ok("choice") => vec![("choice cars 65–88", CHOICE_CARS)],
        Ok("check") => vec![("check cars 89–112", CHECK_CARS)],
        _ => vec![
            ("choice cars 65–88", CHOICE_CARS),
            ("check cars 89–112", CHECK_CARS),
        ],
    };
    for (title, cars) in sets {
        let mut rows: Vec<AutoRow> = cars
            .into_par_iter()
            .map(|seed| {
                let (s, _) = scenario(seed, 100 + seed);
                let cal = simulate(&s, 100 + seed).unwrap();
                let copts = CalibrationOptions::default();
                let c = calibrate(&cal.drive, &copts).unwrap();
                let (_, corrections) =
                    held_back::prepare(&cal.drive, &copts, &DelayOptions::default(), Which::Auto)
                        .unwrap();
                let chosen = corrections.model.gnss_wander;
                let (s, _) = scenario(seed, 200 + seed);
                let ev = simulate(&s, 200 + seed).unwrap();
                let w = windows(&ev.drive, 30.0, 60.0, 60.0);
                let params = &c.estimate.params;
                let white =
                    nees_through_windows(&ev.drive, params, &w, &FilterOptions::default()).unwrap();
                let mut carried = ev.drive.clone();
                if let Some(wd) = chosen {
                    carried.vehicle.noise.gnss_wander_std_m = wd.std_m;
                    carried.vehicle.noise.gnss_wander_tau_s = wd.tau_s;
                }
                let auto =
                    nees_through_windows(&carried, params, &w, &FilterOptions::default()).unwrap();
                (seed, chosen, white.pose.verdict(), auto.pose.verdict())
            })
            .collect();
        rows.sort_by_key(|r| r.0);
        for (seed, chosen, white, auto) in &rows {
            println!(
                "{seed:3} | auto's wander {} | pose NEES white {white} | with auto's choice {auto}",
                chosen.map_or("not chosen".to_string(), |w| format!(
                    "{:.2} m {:.0} s",
                    w.std_m, w.tau_s
                )),
            );
        }
        let n = rows.len();
        let chosen = rows.iter().filter(|r| r.1.is_some()).count();
        let ok = |f: &dyn Fn(&AutoRow) -> bool| rows.iter().filter(|r| f(r)).count();
        println!(
            "{title}: the wander chosen on {chosen}/{n}; pose NEES consistent {}/{n} white, \
             {}/{n} with auto's choice (worst ×{:.1})",
            ok(&|r| r.2 == Verdict::Consistent),
            ok(&|r| r.3 == Verdict::Consistent),
            rows.iter().map(|r| factor(&r.3)).fold(1.0, f64::max),
        );
    }
}
