use super::*;
use crate::kinematics::{calibrate, evaluate, KinematicOptions};

fn params() -> TricycleParams {
    TricycleParams {
        ktraction_m: 0.0106,
        ksteer: 0.56,
        steer_offset_rad: 0.03,
        axle_length_m: 1.3,
        mount: Pose2::new(1.8, 0.05, -0.02),
    }
}

fn geometry() -> TricycleGeometry {
    TricycleGeometry {
        ticks_per_rev: 5000,
        steer_counts_per_rev: 8192,
    }
}

/// A drive with varying steering (up to ±90° of wheel angle) and reversals,
/// references left empty.
fn wiggly(n: usize) -> TricycleDrive {
    let mut ticks = 0i64;
    let samples = (0..n)
        .map(|i| {
            let t = i as f64 * 0.04;
            ticks += (40.0 * (0.3 * t).cos()).round() as i64;
            TricycleSample {
                t_s: t,
                ticks,
                steer_counts: (2700.0 * (0.21 * t).sin()).round() as i64,
                reference: None,
            }
        })
        .collect();
    TricycleDrive {
        geometry: geometry(),
        nominal: params(),
        samples,
    }
}

#[test]
fn prediction_jacobian_matches_finite_differences() {
    let d = wiggly(400);
    let p = params().to_vec();
    let start = Pose2::new(0.3, -1.2, 2.5);
    for (a, b) in [(0, 50), (10, 399), (200, 201)] {
        let (_, j) = d.predict(&p, &start, a, b, true);
        let j = j.unwrap();
        for q in 0..N_PARAMS {
            let h = 1e-6 * p[q].abs().max(1e-2);
            let mut hi = p.clone();
            hi[q] += h;
            let mut lo = p.clone();
            lo[q] -= h;
            let (ph, _) = d.predict(&hi, &start, a, b, false);
            let (pl, _) = d.predict(&lo, &start, a, b, false);
            let fd = [
                (ph.x_m - pl.x_m) / (2.0 * h),
                (ph.y_m - pl.y_m) / (2.0 * h),
                (ph.yaw_rad - pl.yaw_rad) / (2.0 * h),
            ];
            for r in 0..3 {
                let scale = fd[r].abs().max(1.0);
                assert!(
                    (j[(r, q)] - fd[r]).abs() < 1e-5 * scale,
                    "window {a}..{b}, d row {r} / d {}: analytic {} vs finite difference {}",
                    NAMES[q],
                    j[(r, q)],
                    fd[r]
                );
            }
        }
    }
}

#[test]
fn predict_agrees_with_dead_reckon_and_the_mounting() {
    let d = wiggly(300);
    let p = params();
    let base = Pose2::new(2.0, 1.0, -0.4);
    let track = d.dead_reckon(&p, base, 0, 299);
    let (meas, _) = d.predict(&p.to_vec(), &base.compose(&p.mount), 0, 299, false);
    let want = track.last().unwrap().compose(&p.mount);
    assert!((meas.x_m - want.x_m).abs() < 1e-12 && (meas.y_m - want.y_m).abs() < 1e-12);
}

#[test]
fn full_lock_turns_on_the_spot_and_reversing_retraces() {
    // Wheel at +90°: the base turns on the spot around the rear axle; then
    // the same ticks backwards bring it back exactly.
    let counts_90 = (8192.0 * 0.25 / 1.0) as i64; // encoder quarter turn, ksteer 1
    let mut samples = Vec::new();
    let mut ticks = 0;
    for i in 0..200 {
        if i > 0 {
            ticks += if i < 100 { 25 } else { -25 };
        }
        samples.push(TricycleSample {
            t_s: i as f64 * 0.04,
            ticks,
            steer_counts: counts_90,
            reference: None,
        });
    }
    let d = TricycleDrive {
        geometry: geometry(),
        nominal: TricycleParams {
            ksteer: 1.0,
            steer_offset_rad: 0.0,
            mount: Pose2::default(),
            ..params()
        },
        samples,
    };
    let tr = d.dead_reckon(&d.nominal, Pose2::default(), 0, 199);
    let at_lock = tr[99];
    assert!(
        at_lock.x_m.hypot(at_lock.y_m) < 1e-9,
        "moved {at_lock:?} at full lock"
    );
    let wheel_travel = 99.0 * 25.0 * 0.0106 / 5000.0;
    assert!((at_lock.yaw_rad - wheel_travel / 1.3).abs() < 1e-9);
    // 99 steps forward, 100 back: one step of reversal past the start.
    let back = d.dead_reckon(&d.nominal, Pose2::default(), 0, 198)[198];
    assert!(back.x_m.abs() < 1e-9 && back.y_m.abs() < 1e-9 && back.yaw_rad.abs() < 1e-9);
    assert!(tr
        .iter()
        .all(|p| p.x_m.is_finite() && p.yaw_rad.is_finite()));
}

#[test]
fn calibrate_with_zero_windows_estimates_nothing_and_does_not_claim_convergence() {
    // Regression: `calibrate --method truth` on the tricycle wrote the
    // nominal values with `converged: true` when 0 samples were used.
    let mut d = wiggly(600);
    for s in &mut d.samples {
        s.reference = Some(Pose2::default().compose(&params().mount));
    }
    let c = calibrate(
        &d,
        &KinematicOptions {
            min_speed_mps: 2.0,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(c.windows_used, 0);
    assert!(!c.converged);
    for e in &c.params {
        assert!(!e.estimated, "{} estimated from 0 windows", e.name);
        assert!(e.std.is_none());
        assert!(
            e.reason.as_deref().unwrap().contains("0 of"),
            "{:?}",
            e.reason
        );
    }
}

#[test]
fn evaluate_rejects_bad_lengths_and_missing_references() {
    let d = wiggly(100);
    let p = d.nominal.to_vec();
    assert!(evaluate(&d, &p, 0.0, 1.0).is_err());
    assert!(evaluate(&d, &p, 30.0, f64::NAN).is_err());
    assert!(matches!(
        evaluate(&d, &p, 1.0, 1.0),
        Err(Error::Insufficient { .. })
    ));
    assert!(evaluate(&d, &p[..3], 1.0, 1.0).is_err());
}
