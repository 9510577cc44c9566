//! Tests of the differential drive's GNSS-aided filter on seeded simulated
//! drives whose fixes wander (first-order Gauss–Markov) and jump.

use nalgebra::SVector;
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use rand_pcg::Pcg64;

use super::filter::*;
use super::*;

/// The simulated drive's true parameters (scales, bias, antenna).
const TRUTH: [f64; N_PARAMS] = [0.97, 0.96, 0.0004, -0.6, 0.1];

/// How the simulated fixes err.
struct FixError {
    wander_m: f64,
    tau_s: f64,
    white_m: f64,
    /// A step added to the wander at this time, (s, east m, north m).
    jump: Option<(f64, f64, f64)>,
}

/// 400 s at 10 Hz, about 1 m/s, straight stretches and turns both ways;
/// fixes at 2.5 Hz from the true parameters, rotated and shifted into the
/// world frame, with the wander, the jump and white noise of `err`.
fn simulated(seed: u64, err: &FixError) -> DiffDriveDrive {
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut randn = || -> f64 { StandardNormal.sample(&mut rng) };
    let n = 4001;
    let samples: Vec<DiffDriveSample> = (0..n)
        .map(|i| {
            let t = i as f64 * 0.1;
            let turn = match (t / 40.0) as u32 % 4 {
                1 => 0.08,
                3 => -0.06,
                _ => 0.0,
            };
            DiffDriveSample {
                t_s: t,
                v_mps: 1.0 + 0.1 * (0.07 * t).sin() + 0.01 * randn(),
                yaw_rate_rps: turn + 0.005 * randn(),
            }
        })
        .collect();
    let mut d = DiffDriveDrive {
        samples,
        fixes: Vec::new(),
        yaw_source: YawSource::Gyro,
    };
    let track = d.local_track(&TRUTH, 0, n - 1, false);
    let (th, t0) = (0.8f64, [120.0, -40.0]);
    let (s, c) = th.sin_cos();
    let mut e = [err.wander_m * randn(), err.wander_m * randn()];
    let mut jumped = false;
    let dt = 0.4;
    let phi = (-dt / err.tau_s).exp();
    let q = err.wander_m * (1.0 - phi * phi).sqrt();
    for k in (0..n).step_by(4) {
        let t = track[k].2;
        if let Some((tj, je, jn)) = err.jump {
            if t >= tj && !jumped {
                e[0] += je;
                e[1] += jn;
                jumped = true;
            }
        }
        let [x, y] = track[k].0;
        d.fixes.push((
            t,
            t0[0] + c * x - s * y + e[0] + err.white_m * randn(),
            t0[1] + s * x + c * y + e[1] + err.white_m * randn(),
        ));
        e = [phi * e[0] + q * randn(), phi * e[1] + q * randn()];
    }
    d
}

fn wandering() -> FixError {
    FixError {
        wander_m: 2.0,
        tau_s: 100.0,
        white_m: 0.05,
        jump: None,
    }
}

#[test]
fn propagation_and_fix_jacobians_match_finite_differences() {
    let x = State::from_column_slice(&[3.0, -2.0, 0.7, 0.002, 0.97, 1.04, 0.8, -1.1]);
    let u = StepInput {
        dt_s: 0.1,
        v_mps: 1.1,
        yaw_rate_rps: 0.3,
    };
    let tau = 90.0;
    let (_, f, g) = propagate(&x, &u, tau);
    let h = 1e-6;
    for j in 0..N {
        let (mut hi, mut lo) = (x, x);
        hi[j] += h;
        lo[j] -= h;
        let fd = (propagate(&hi, &u, tau).0 - propagate(&lo, &u, tau).0) / (2.0 * h);
        for i in 0..N {
            assert!(
                (f[(i, j)] - fd[i]).abs() < 1e-8,
                "F[{i},{j}] {} vs {}",
                f[(i, j)],
                fd[i]
            );
        }
    }
    // G: the speed, and the scaled rate a_ω·ω (ω moved by h / a_ω).
    for (col, du) in [(0, [h, 0.0]), (1, [0.0, h / x[filter::YAW_SCALE]])] {
        let shifted = |sign: f64| StepInput {
            v_mps: u.v_mps + sign * du[0],
            yaw_rate_rps: u.yaw_rate_rps + sign * du[1],
            ..u
        };
        let fd = (propagate(&x, &shifted(1.0), tau).0 - propagate(&x, &shifted(-1.0), tau).0)
            / (2.0 * h);
        for i in 0..N {
            assert!(
                (g[(i, col)] - fd[i]).abs() < 1e-8,
                "G[{i},{col}] {} vs {}",
                g[(i, col)],
                fd[i]
            );
        }
    }
    let antenna = [-0.6, 0.15];
    let (_, hm) = predicted_fix(&x, antenna);
    for j in 0..N {
        let (mut hi, mut lo) = (x, x);
        hi[j] += h;
        lo[j] -= h;
        let fd = (predicted_fix(&hi, antenna).0 - predicted_fix(&lo, antenna).0) / (2.0 * h);
        for i in 0..2 {
            assert!(
                (hm[(i, j)] - fd[i]).abs() < 1e-8,
                "H[{i},{j}] {} vs {}",
                hm[(i, j)],
                fd[i]
            );
        }
    }
}

#[test]
fn the_covariance_stays_symmetric_positive_definite_through_fixes_and_outages() {
    let d = simulated(11, &wandering());
    let noise = FilterNoise::default();
    let mut f = DiffDriveFilter::start(&d, &TRUTH, &noise).unwrap().unwrap();
    let check = |p: &Cov, t: f64| {
        assert!((p - p.transpose()).abs().max() < 1e-12, "asymmetric at {t}");
        assert!(p.cholesky().is_some(), "not positive definite at {t}: {p}");
    };
    for &(t, e, n) in d.fixes.iter().filter(|x| x.0 > 20.0) {
        f.predict_to(t);
        check(&f.p, t);
        f.update_fix(e, n).unwrap();
        check(&f.p, t);
        if (t % 50.0) < 0.2 {
            let mut blind = f.clone();
            blind.predict_to(t + 30.0);
            check(&blind.p, t + 30.0);
        }
    }
}

#[test]
fn the_filter_start_beats_the_alignment_when_the_fixes_wander() {
    // Eight seeds, the true parameters: what differs is the start. Measured
    // means 2.122 m (filter) against 2.366 m (alignment); the wander alone
    // moves the scored fix by σ·√(1 − e^(−2·30/τ)) = 1.34 m per axis over an
    // outage, 1.68 m on average in the plane — no start does better.
    let (mut filter, mut aligned) = (0.0, 0.0);
    for seed in 1..=8 {
        let d = simulated(seed, &wandering());
        let start = OutageStart::Filter(FilterNoise::default());
        let f = evaluate_diff_drive(&d, &TRUTH, 30.0, 10.0, 60.0, &start).unwrap();
        let a = evaluate_diff_drive(&d, &TRUTH, 30.0, 10.0, 60.0, &OutageStart::Align).unwrap();
        assert_eq!(f.outages.windows.len(), a.outages.windows.len());
        assert_eq!(f.predicted_std_m.len(), f.outages.windows.len());
        assert!(a.predicted_std_m.is_empty() && a.fixes_used == 0);
        filter += f.outages.final_error().mean / 8.0;
        aligned += a.outages.final_error().mean / 8.0;
    }
    let err = wandering();
    let floor = err.wander_m
        * (1.0 - (-2.0 * 30.0 / err.tau_s).exp()).sqrt()
        * (std::f64::consts::PI / 2.0).sqrt();
    assert!(
        filter < 0.95 * aligned && filter < 1.4 * floor,
        "filter {filter:.3} m, alignment {aligned:.3} m, floor {floor:.3} m"
    );
}

#[test]
fn the_gate_locked_the_filter_out_after_a_jump_of_the_fixes() {
    // A 5 m step of the fixes' error at 150 s: the gate rejected every fix
    // after it while the predicted covariance grew (15 s on the Husky bag).
    let err = FixError {
        jump: Some((150.0, 0.0, -5.0)),
        ..wandering()
    };
    let d = simulated(7, &err);
    let mut f = DiffDriveFilter::start(&d, &TRUTH, &FilterNoise::default())
        .unwrap()
        .unwrap();
    let mut late = Vec::new();
    for &(t, e, n) in d.fixes.iter().filter(|x| x.0 > 20.0) {
        f.predict_to(t);
        let (z, _) = f.predicted_fix();
        if (160.0..170.0).contains(&t) {
            late.push((e - z[0]).hypot(n - z[1]));
        }
        f.update_fix(e, n).unwrap();
    }
    assert_eq!(f.fix_jumps, 1, "{} rejected", f.fixes_rejected);
    // The rejections of the jump's first 2 s (5 fixes) and a few elsewhere:
    // 9 measured, 38 without the jump rule.
    assert!(f.fixes_rejected <= 12, "{} rejected", f.fixes_rejected);
    let worst = late.iter().cloned().fold(0.0, f64::max);
    assert!(
        worst < 1.0,
        "innovations 10–20 s after the jump up to {worst:.2} m"
    );
}

#[test]
fn the_likelihood_is_highest_near_the_simulated_fix_error() {
    let d = simulated(5, &wandering());
    let ll = |wander_m: f64, tau_s: f64| {
        let noise = FilterNoise {
            fix_wander_m: wander_m,
            fix_wander_tau_s: tau_s,
            ..FilterNoise::default()
        };
        fix_log_likelihood(&d, &TRUTH, &noise).unwrap().unwrap().0
    };
    let truth = ll(2.0, 100.0);
    for (w, tau) in [(0.5, 100.0), (8.0, 100.0), (2.0, 10.0), (0.5, 10.0)] {
        let other = ll(w, tau);
        assert!(
            other < truth,
            "wander {w} m, τ {tau} s: {other:.4} against {truth:.4} at the truth"
        );
    }
}

#[test]
fn noise_values_are_checked_and_stated_standard_errors_replace_the_priors() {
    let bad = FilterNoise {
        fix_wander_tau_s: 0.0,
        ..FilterNoise::default()
    };
    let d = simulated(1, &wandering());
    let err = DiffDriveFilter::start(&d, &TRUTH, &bad).unwrap_err();
    assert!(err.to_string().contains("fix_wander_tau_s"), "{err}");
    let n = FilterNoise::default().with_param_std(&[Some(0.002), None, Some(1e-4), Some(0.1)]);
    assert_eq!(n.speed_scale_prior, 0.002);
    assert_eq!(n.yaw_scale_prior, FilterNoise::default().yaw_scale_prior);
    assert_eq!(n.yaw_bias_prior_rps, 1e-4);
    // Fewer than three fixes over the initial path: no start, no panic.
    let short = DiffDriveDrive {
        fixes: d.fixes[..2].to_vec(),
        ..d.clone()
    };
    assert!(
        DiffDriveFilter::start(&short, &TRUTH, &FilterNoise::default())
            .unwrap()
            .is_none()
    );
    let x = SVector::<f64, N>::zeros();
    assert_eq!(predicted_fix(&x, [0.0, 0.0]).0, SVector::<f64, 2>::zeros());
}
