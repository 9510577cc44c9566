//! The held-back choice on simulated differential drives (seeded): a
//! robot of the Husky's class (1 m/s, 10 Hz odometry and gyro, 2.5 Hz fixes)
//! whose fixes wander as a first-order Gauss–Markov process. The wander's
//! values are a receiver's, not the Husky bag's: 1 m per axis with a 120 s
//! time constant (SBAS-class horizontal error, correlated over minutes),
//! plus 0.1 m white noise.

use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};

use super::held_back::{calibrate_held_back_with, windows, FIRST_WINDOW_S, MIN_WINDOWS};
use super::*;

/// A 400 s drive of `truth` (the parameters the recorded odometry and gyro
/// must be corrected by), seeded.
fn simulated(truth: &[f64; N_PARAMS], seed: u64) -> DiffDriveDrive {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let mut gauss = move || -> f64 { StandardNormal.sample(&mut rng) };
    let phase = gauss();
    let n = 4000;
    let samples: Vec<DiffDriveSample> = (0..n)
        .map(|i| {
            let t = i as f64 * 0.1;
            DiffDriveSample {
                t_s: t,
                v_mps: 0.95 + 0.1 * (0.07 * t + phase).sin() + 0.02 * gauss(),
                // Curves of both signs, some straight stretches.
                yaw_rate_rps: 0.25 * (0.031 * t + phase).sin().powi(3)
                    + 0.1 * (0.11 * t).sin()
                    + 0.005 * gauss(),
            }
        })
        .collect();
    let mut d = DiffDriveDrive {
        samples,
        fixes: Vec::new(),
        yaw_source: YawSource::Gyro,
    };
    let track = d.local_track(truth, 0, n - 1, false);
    let (sigma_m, tau_s, white_m, dt_fix): (f64, f64, f64, f64) = (1.0, 120.0, 0.1, 0.4);
    let phi = (-dt_fix / tau_s).exp();
    let mut wander = [sigma_m * gauss(), sigma_m * gauss()];
    let mut t = 0.05;
    while t < track[n - 1].2 {
        for w in wander.iter_mut() {
            *w = phi * *w + sigma_m * (1.0 - phi * phi).sqrt() * gauss();
        }
        let (p, _) = at(&track, t);
        d.fixes.push((
            t,
            p[0] + wander[0] + white_m * gauss(),
            p[1] + wander[1] + white_m * gauss(),
        ));
        t += dt_fix;
    }
    d
}

/// Mean final error of 30 s outages every 10 s from the filter, m.
fn outage_mean(d: &DiffDriveDrive, c: &crate::kinematics::KinematicCalibration) -> f64 {
    let std: Vec<Option<f64>> = c
        .params
        .iter()
        .map(|p| if p.estimated { p.std } else { None })
        .collect();
    let start = OutageStart::Filter(FilterNoise::default().with_param_std(&std));
    evaluate_diff_drive(d, &c.values(), 30.0, 10.0, DEFAULT_WARMUP_S, &start)
        .unwrap()
        .outages
        .final_error()
        .mean
}

fn chosen(c: &crate::kinematics::KinematicCalibration) -> Vec<&str> {
    c.held_back
        .as_ref()
        .unwrap()
        .judged
        .iter()
        .filter(|j| j.applied)
        .map(|j| j.name.as_str())
        .collect()
}

/// A robot whose odometry reads 6 % fast and whose gyro is 5 % off scale
/// with a 0.003 rad/s bias: the held-back GNSS takes the bias (paired t
/// −3.7) and the speed scale (−1.3; the yaw scale came to −0.98, just short
/// of the threshold), each within 0.01 of the truth, and on a second drive
/// of the same robot the calibration beats the nominal values (measured
/// 1.031 against 1.390 m, mean of 30 s outages).
#[test]
fn held_back_takes_parameters_the_drive_gets_wrong() {
    let truth = [0.94, 1.05, 0.003, 0.0, 0.0];
    let d = simulated(&truth, 11);
    let c = calibrate_held_back(&d, &DiffDriveOptions::default(), &FilterNoise::default()).unwrap();
    let names = chosen(&c);
    eprintln!("chosen {names:?}: {:?}", c.held_back);
    for k in [SPEED_SCALE, YAW_BIAS] {
        assert!(names.contains(&NAMES[k]), "{} not chosen: {c:?}", NAMES[k]);
        assert!(
            (c.params[k].value - truth[k]).abs() < 0.01,
            "{}: {} against {}",
            NAMES[k],
            c.params[k].value,
            truth[k]
        );
    }
    let other = simulated(&truth, 12);
    let nominal = crate::kinematics::KinematicCalibration {
        params: c
            .params
            .iter()
            .zip(DiffDriveDrive::nominal())
            .map(|(p, v)| crate::kinematics::ParamEstimate {
                value: v,
                std: None,
                estimated: false,
                reason: Some("nominal".into()),
                ..p.clone()
            })
            .collect(),
        ..c.clone()
    };
    let (cal, nom) = (outage_mean(&other, &c), outage_mean(&other, &nominal));
    eprintln!("second drive: calibrated {cal:.3} m, nominal {nom:.3} m");
    assert!(cal < 0.8 * nom, "{cal} vs {nom}");
}

/// A robot whose odometry and gyro are exact (nominal is the truth): what
/// the held-back GNSS takes leaves a second drive's outages within 5 % of
/// the nominal values' (a parameter fitted to the truth can only help a
/// little; one fitted to the wander would show). Measured: nothing taken,
/// 0.932 m; every parameter fitted 0.935 m; nominal 0.932 m.
#[test]
fn held_back_keeps_a_nominal_robot_nominal_out_of_sample() {
    let truth = [1.0, 1.0, 0.0, 0.0, 0.0];
    let d = simulated(&truth, 21);
    let c = calibrate_held_back(&d, &DiffDriveOptions::default(), &FilterNoise::default()).unwrap();
    eprintln!("chosen {:?}: {:?}", chosen(&c), c.held_back);
    let h = c.held_back.as_ref().unwrap();
    assert!(h.not_judged.is_none() && h.windows >= 10, "{h:?}");
    let full = calibrate_diff_drive(&d, &DiffDriveOptions::default()).unwrap();
    let other = simulated(&truth, 22);
    let nominal = crate::kinematics::KinematicCalibration {
        params: full
            .params
            .iter()
            .zip(DiffDriveDrive::nominal())
            .map(|(p, v)| crate::kinematics::ParamEstimate {
                value: v,
                std: None,
                estimated: false,
                reason: Some("nominal".into()),
                ..p.clone()
            })
            .collect(),
        ..full.clone()
    };
    let (sel, all, nom) = (
        outage_mean(&other, &c),
        outage_mean(&other, &full),
        outage_mean(&other, &nominal),
    );
    eprintln!("second drive: held-back {sel:.3} m, every parameter {all:.3} m, nominal {nom:.3} m");
    assert!(sel < 1.05 * nom, "{sel} vs {nom}");
}

/// A drive too short for [`MIN_WINDOWS`] windows is not judged: every
/// determined parameter is fitted, and the result says why.
#[test]
fn a_short_drive_is_not_judged() {
    let mut d = simulated(&[0.94, 1.05, 0.003, 0.0, 0.0], 31);
    d.samples.truncate(1500);
    d.fixes.retain(|f| f.0 < 150.0);
    let c = calibrate_held_back(&d, &DiffDriveOptions::default(), &FilterNoise::default()).unwrap();
    let h = c.held_back.as_ref().unwrap();
    assert!(h.windows < MIN_WINDOWS, "{h:?}");
    assert!(
        h.not_judged.as_deref().unwrap().contains("too short"),
        "{h:?}"
    );
    assert!(c.params[SPEED_SCALE].estimated, "{c:?}");
}

/// The folds: back-to-back windows of [`WINDOW_S`] from [`FIRST_WINDOW_S`]
/// in, the earlier half one fold and the later half the other.
#[test]
fn folds_are_the_earlier_and_later_windows() {
    let d = simulated(&[1.0, 1.0, 0.0, 0.0, 0.0], 41);
    let [a, b] = windows(&d);
    // 400 s: eleven windows from 40 s on, six and five.
    assert_eq!((a.len(), b.len()), (6, 5), "{a:?} {b:?}");
    assert!((a[0].0 - FIRST_WINDOW_S).abs() < 1e-9);
    assert!(a.windows(2).all(|w| (w[1].0 - w[0].1).abs() < 1e-9));
    assert!(a.last().unwrap().1 <= b[0].0 + 1e-9);
}

/// The threshold [`MIN_T`](super::held_back::MIN_T), chosen on a family of
/// simulated robots (not on the Husky): each robot's true errors drawn
/// (speed and yaw scales N(1, 0.03), gyro bias N(0, 0.001) rad/s, antenna
/// N(0, 0.3) m per axis), calibrated on one drive and evaluated on another
/// whose gyro bias has moved by N(0, 0.0005) rad/s (a MEMS gyro's turn-on
/// repeatability). Prints the mean over the robots of the second drive's
/// 30 s outages for each threshold, every parameter and nominal.
/// `cargo test --profile ci -p deadreckon-core --lib min_t_family -- --ignored --nocapture`
#[test]
#[ignore]
fn min_t_family() {
    let robots: u64 = std::env::var("HB_ROBOTS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(12);
    let thresholds = [0.5, 1.0, 1.5, 2.0, 3.0];
    let mut sums = vec![0.0; thresholds.len() + 2];
    for r in 0..robots {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(1000 + r);
        let mut g = move || -> f64 { StandardNormal.sample(&mut rng) };
        let truth = [
            1.0 + 0.03 * g(),
            1.0 + 0.03 * g(),
            0.001 * g(),
            0.3 * g(),
            0.3 * g(),
        ];
        let mut later = truth;
        later[YAW_BIAS] += 0.0005 * g();
        let d = simulated(&truth, 2000 + r);
        let other = simulated(&later, 3000 + r);
        let o = DiffDriveOptions::default();
        let noise = FilterNoise::default();
        let mut row = Vec::new();
        for &t in &thresholds {
            let c = calibrate_held_back_with(&d, &o, &noise, t).unwrap();
            row.push(outage_mean(&other, &c));
        }
        let full = calibrate_diff_drive(&d, &o).unwrap();
        row.push(outage_mean(&other, &full));
        let mut nominal = full.clone();
        for (p, v) in nominal.params.iter_mut().zip(DiffDriveDrive::nominal()) {
            p.value = v;
            p.std = None;
            p.estimated = false;
        }
        row.push(outage_mean(&other, &nominal));
        eprintln!("robot {r} truth {truth:.4?}: {row:.3?}");
        for (s, v) in sums.iter_mut().zip(&row) {
            *s += v / robots as f64;
        }
    }
    eprintln!("thresholds {thresholds:?}, every parameter, nominal: mean {sums:.3?}");
}

/// The calibration's window length ([`DiffDriveOptions::window_s`]), chosen
/// on the family of [`min_t_family`] (not on the Husky): the mean over the
/// robots of the second drive's 30 s outages for each window length, with
/// the held-back choice and with every parameter fitted.
/// `cargo test --profile ci -p deadreckon-core --lib window_family -- --ignored --nocapture`
#[test]
#[ignore]
fn window_family() {
    let robots: u64 = std::env::var("HB_ROBOTS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(12);
    let lengths = [30.0, 60.0, 90.0, 120.0, 200.0];
    let mut held = vec![0.0; lengths.len()];
    let mut every = vec![0.0; lengths.len()];
    for r in 0..robots {
        let mut rng = rand_pcg::Pcg64::seed_from_u64(1000 + r);
        let mut g = move || -> f64 { StandardNormal.sample(&mut rng) };
        let truth = [
            1.0 + 0.03 * g(),
            1.0 + 0.03 * g(),
            0.001 * g(),
            0.3 * g(),
            0.3 * g(),
        ];
        let mut later = truth;
        later[YAW_BIAS] += 0.0005 * g();
        let d = simulated(&truth, 2000 + r);
        let other = simulated(&later, 3000 + r);
        for (i, &w) in lengths.iter().enumerate() {
            let o = DiffDriveOptions {
                window_s: w,
                ..Default::default()
            };
            let c = calibrate_held_back(&d, &o, &FilterNoise::default()).unwrap();
            held[i] += outage_mean(&other, &c) / robots as f64;
            let c = calibrate_diff_drive(&d, &o).unwrap();
            every[i] += outage_mean(&other, &c) / robots as f64;
        }
    }
    eprintln!("window lengths {lengths:?}: held-back {held:.3?}, every parameter {every:.3?}");
}
