//! Per-stream delays, IMU tilt and gyro scale on seeded members of the car
//! family (issue 13): each recovered within 3 standard errors, and the drift
//! per 100 m on a second drive of the same car, with the corrections and
//! parameters found on the first, against the drift with the true ones
//! (printed, and bounded above; the 5 % is not reached), and against
//! the drift with the true corrections and the same RTS calibration, which
//! separates what the estimated corrections cost from what the GNSS-based
//! calibration itself leaves. The same cars with white GNSS fixes show what
//! that is: the receiver's slow wander (with white fixes the RTS calibration
//! is within 5 % of the truth).
//!
//! The scalar delays are against the wheel clock: a simulated wheel-speed
//! row is the mean speed over the preceding wheel period, so the wheels
//! themselves are half a period late and a stream with latency `L` is
//! `L − T_wheel/2` late against them. The GNSS delay is the receiver's
//! latency `L` (its reference takes each row over its own interval,
//! `timing::REFERENCE_WHEEL_ROWS`, issue 29).

use deadreckon_core::calibrate::{self, CalibrationOptions};
use deadreckon_core::ekf::Timing;
use deadreckon_core::metrics;
use deadreckon_core::timing::{self, DelayOptions, Which};
use deadreckon_sim::family::CarFamily;
use deadreckon_sim::sensors::tilt_rotation;
use deadreckon_sim::{simulate, ScalarSpec, Scenario, SteeringSpec};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;

/// The true values of one car's installation.
#[derive(Debug, Clone, Copy)]
struct Install {
    /// Latencies, s: gyro, speed, steering, GNSS.
    latency_s: [f64; 4],
    /// Pitch and roll, degrees.
    tilt_deg: [f64; 2],
    scale_error: f64,
}

impl Install {
    fn draw(seed: u64) -> Install {
        let r = &mut Pcg64::seed_from_u64(0x7133_0000 + seed);
        Install {
            latency_s: [0, 1, 2, 3].map(|_| r.random_range(0.0..0.2)),
            tilt_deg: [r.random_range(-3.5..3.5), r.random_range(-3.5..3.5)],
            scale_error: r.random_range(-0.02..0.02),
        }
    }
    fn apply(&self, mut sc: Scenario) -> Scenario {
        let s = &mut sc.sensors;
        let g = s.gyro.as_mut().expect("family gyro");
        g.latency_s = self.latency_s[0];
        g.scale_error = self.scale_error;
        g.tilt_deg = Some(self.tilt_deg);
        s.speed = Some(ScalarSpec {
            rate_hz: 50.0,
            offset_s: 0.003,
            noise_std: 0.1,
            latency_s: self.latency_s[1],
            scale_error: 0.0,
            tilt_deg: None,
            bias_drift_std_rps: 0.0,
            bias_drift_tau_s: 300.0,
            clock: None,
        });
        s.steering = Some(SteeringSpec {
            rate_hz: 50.0,
            offset_s: 0.007,
            noise_std: 0.02,
            latency_s: self.latency_s[2],
            true_ratio: None,
            wheel_offset_rad: 0.0,
            clock: None,
        });
        s.gnss.as_mut().expect("family gnss").latency_s = self.latency_s[3];
        sc
    }
    fn up(&self) -> [f64; 3] {
        let m = tilt_rotation(self.tilt_deg[0].to_radians(), self.tilt_deg[1].to_radians());
        [m[0][2], m[1][2], m[2][2]]
    }
    fn tilt_rad(&self) -> f64 {
        self.up()[2].acos()
    }
}

/// The mean drift per 100 m on a member's test drive, %: with our
/// corrections and RTS parameters, with the true corrections and the RTS
/// parameters calibrated on them, and with the truth.
#[derive(Debug, Clone, Copy)]
struct Drift {
    ours: f64,
    known: f64,
    truth: f64,
}

/// Each member's corrections recovered within 3σ, and its drifts.
/// `white_fixes` takes the receiver's Gauss–Markov wander out (the family
/// draws 0–1.5 m over 20–120 s).
fn family_drift(white_fixes: bool) -> Vec<Drift> {
    let copts = CalibrationOptions::default();
    let o = DelayOptions::default();
    let mut drifts = Vec::new();
    for seed in 1..=4u64 {
        let mut car = CarFamily::draw(seed);
        if white_fixes {
            car.gnss_markov.0 = 0.0;
        }
        let inst = Install::draw(seed);
        let half_wheel = 0.5 / car.wheel_rate_hz;
        let train = simulate(&inst.apply(car.drive(100 + seed, 600.0)), 100 + seed).unwrap();
        let (corrected, c) =
            timing::prepare_with(&train.drive, &copts, &o, Which::All).expect("corrections");
        eprintln!("car {seed}: {inst:?}, wheels {} Hz", car.wheel_rate_hz);
        for (k, s) in timing::Stream::ALL.iter().enumerate() {
            let d = c.delays.get(*s);
            // The scalar streams against the wheel rows' stamps; the GNSS
            // against true time (its reference takes each wheel row over
            // its own interval, issue 29).
            let truth = if *s == timing::Stream::Gnss {
                inst.latency_s[k]
            } else {
                inst.latency_s[k] - half_wheel
            };
            eprintln!(
                "  {:<9} {:+.4} ± {:.4} s (truth {truth:+.4}) {:?}",
                s.name(),
                d.delay_s,
                d.std_s,
                d.status
            );
            // Estimated, or refused for a standard error above 0.02 s (car
            // 4's GNSS since the jackknife: 0.027 s, its true delay 0.007 s),
            // and then not applied; the value is checked either way.
            assert!(
                d.status.is_estimated()
                    || d.status
                        .reason()
                        .is_some_and(|r| r.contains("too little excitation")),
                "car {seed} {}: {:?}",
                s.name(),
                d
            );
            // The steering too since its standard error sees the noise
            // (car 2: +0.0900 ± 0.0084 s against +0.0753 s; it read
            // ± 0.0027 s before).
            assert!(
                (d.delay_s - truth).abs() <= 3.0 * d.std_s,
                "car {seed} {}: {:+.4} ± {:.4} s, truth {truth:+.4}",
                s.name(),
                d.delay_s,
                d.std_s
            );
        }
        let tilt = c.tilt.clone().expect("three-axis IMU");
        eprintln!(
            "  tilt {:.3}° ± {:.3}° (truth {:.3}°)",
            tilt.tilt_rad.to_degrees(),
            tilt.std_rad.to_degrees(),
            inst.tilt_rad().to_degrees()
        );
        assert!(tilt.is_estimated(), "{tilt:?}");
        assert!((tilt.tilt_rad - inst.tilt_rad()).abs() <= 3.0 * tilt.std_rad);
        let gs = c.gyro_scale.clone().expect("gyro scale attempted");
        eprintln!(
            "  gyro scale error {:+.4}% ± {:.4}% over {} turns (truth {:+.4}%)",
            100.0 * gs.scale_error,
            100.0 * gs.std,
            gs.turns,
            100.0 * inst.scale_error
        );
        assert!(gs.is_estimated(), "{gs:?}");
        assert!((gs.scale_error - inst.scale_error).abs() <= 3.0 * gs.std);

        // Drift on another drive of the same car: ours (corrections and
        // parameters from the training drive) against the truth's.
        let cal = calibrate::calibrate(&corrected, &copts).unwrap();
        let test = simulate(&inst.apply(car.drive(200 + seed, 600.0)), 200 + seed).unwrap();
        let ours = timing::apply_known(
            &test.drive,
            [0, 1, 2, 3].map(|k| c.delays.get(timing::Stream::ALL[k]).applied_s()),
            Some(tilt.up),
            gs.scale_error,
        );
        let truth = timing::apply_known(
            &test.drive,
            inst.latency_s.map(|l| l - half_wheel),
            Some(inst.up()),
            inst.scale_error,
        );
        let mean = |r: metrics::DriftResult| {
            let e = r.errors_pct();
            e.iter().sum::<f64>() / e.len() as f64
        };
        let d_ours =
            mean(metrics::drift(&ours, &cal.estimate.params, 100.0, Timing::WheelEpochs).unwrap());
        // The bias the levelled, rescaled gyro shows: b·up_z/(1 + s).
        let mut tp = test.truth_params;
        tp.gyro_bias_rps *= inst.up()[2] / (1.0 + inst.scale_error);
        let d_truth = mean(metrics::drift(&truth, &tp, 100.0, Timing::WheelEpochs).unwrap());
        // What the corrections alone cost: the same RTS calibration on the
        // training drive corrected with the true installation.
        let train_known = timing::apply_known(
            &train.drive,
            inst.latency_s.map(|l| l - half_wheel),
            Some(inst.up()),
            inst.scale_error,
        );
        let cal_known = calibrate::calibrate(&train_known, &copts).unwrap();
        let d_known = mean(
            metrics::drift(
                &truth,
                &cal_known.estimate.params,
                100.0,
                Timing::WheelEpochs,
            )
            .unwrap(),
        );
        eprintln!(
            "  drift per 100 m: {d_ours:.4}% ours, {d_known:.4}% with the true corrections and RTS parameters, {d_truth:.4}% with the truth"
        );
        drifts.push(Drift {
            ours: d_ours,
            known: d_known,
            truth: d_truth,
        });
    }
    drifts
}

#[test]
fn delays_tilt_and_gyro_scale_are_recovered_on_the_car_family() {
    let drifts = family_drift(false);
    let drift_ratios: Vec<f64> = drifts.iter().map(|d| d.ours / d.truth).collect();
    let known_ratios: Vec<f64> = drifts.iter().map(|d| d.ours / d.known).collect();
    eprintln!("drift ours / truth: {drift_ratios:?}");
    eprintln!("drift ours / true corrections with RTS parameters: {known_ratios:?}");
    // What the estimated corrections cost against the true ones, the RTS
    // calibration being the same: measured 1.047, 0.996, 1.002 and 1.008
    // (seeds 1–4); most of the gap to the truth is the RTS calibration's
    // own, and that is the receiver's wander (see
    // `with_white_fixes_the_rts_calibration_is_within_5_percent_of_the_truth`).
    // Bound: 8 % above the worst.
    assert!(known_ratios.iter().all(|&r| r <= 1.13), "{known_ratios:?}");
    // Not the 5 %: measured 1.131, 1.186, 1.017 and 1.437 (seeds
    // 1–4). This bound (8 % above the worst) only pins that result.
    assert!(drift_ratios.iter().all(|&r| r <= 1.56), "{drift_ratios:?}");
}

/// What limits the drift above: the same cars with a receiver whose fixes
/// are white noise about the antenna (no Gauss–Markov wander). The RTS
/// calibration on truly corrected streams is then within the 5 % of
/// the truth (measured 1.0055, 1.0434, 1.0016, 1.0015 on cars 1–4, against
/// 1.06, 1.33, 1.02, 1.41 with the wander, whose metre-scale drift over a
/// minute or two the white-noise filter reads as a scale error of every
/// wheel: 1–5 mm of circumference, 50–250 times its claimed standard
/// error). With our estimated corrections it is 1.06, 1.58, 1.02, 1.05 ×
/// the truth: car 2's gyro scale error reads +0.85 % ± 0.30 % for +1.33 %,
/// and that alone moves its drift by half.
#[test]
fn with_white_fixes_the_rts_calibration_is_within_5_percent_of_the_truth() {
    let drifts = family_drift(true);
    let known: Vec<f64> = drifts.iter().map(|d| d.known / d.truth).collect();
    let ours: Vec<f64> = drifts.iter().map(|d| d.ours / d.truth).collect();
    eprintln!(
        "white fixes: true corrections, RTS parameters / truth {known:?}; ours / truth {ours:?}"
    );
    assert!(known.iter().all(|&r| r <= 1.05), "{known:?}");
    // Pinned: the worst measured (car 2, 1.58) plus 8 %.
    assert!(ours.iter().all(|&r| r <= 1.7), "{ours:?}");
}

/// Regression: interpolating the noisy wheel-derived signal at the gyro's
/// times put the gyro's lag 5 ms (25σ) off when the two rates were
/// commensurate (100 Hz against 50 Hz), and a 0.1 s smoothing triangle left
/// the steering 3.4 ms (3.2σ) off; with the default 0.2 s triangle each
/// stream without latency is half a wheel period late, within 3σ (measured:
/// gyro −9.6 ± 5.5 ms, speed −10.2 ± 1.2 ms, steering −10.9 ± 2.4 ms).
#[test]
fn commensurate_rates_do_not_bias_the_lag() {
    let car = CarFamily::draw(1);
    let inst = Install {
        latency_s: [0.0; 4],
        tilt_deg: [0.0, 0.0],
        scale_error: 0.0,
    };
    let mut sc = inst.apply(car.drive(101, 600.0));
    sc.sensors.gyro.as_mut().unwrap().tilt_deg = None;
    let d = simulate(&sc, 101).unwrap().drive;
    let o = DelayOptions::default();
    for (name, x) in [
        ("gyro", timing::gyro_delay(&d, &o)),
        ("speed", timing::speed_delay(&d, &o)),
        ("steering", timing::steering_delay(&d, &o)),
    ] {
        let truth = -0.5 / car.wheel_rate_hz;
        eprintln!("{name}: {x:?} (truth {truth})");
        assert!(x.status.is_estimated(), "{name}: {x:?}");
        assert!((x.delay_s - truth).abs() <= 3.0 * x.std_s, "{name}: {x:?}");
    }
}

/// Regression: the steering lag's standard error was taken from the
/// derivative of the smoothed steering itself, whose noise (0.3 rad of
/// white noise on the steering wheel, the paper's 0.02 on tan δ) inflated
/// Σ j², so the error read five to ten times too small and the lag looked
/// biased (car 2: +0.0900 ± 0.0011 s against +0.0753 s). Over ten noise
/// seeds of one drive the lag scatters by 0.0069 s (car 2) and 0.0142 s
/// (car 4) around the truth (means −0.0004 and −0.0034 s); the errors it
/// claims now average 0.0060 and 0.0233 s (0.0011 and 0.0012 s before).
#[test]
fn the_steering_lags_standard_error_ignored_the_noise_of_its_derivative() {
    for seed in [2u64, 4] {
        let car = CarFamily::draw(seed);
        let mut sc = car.drive(100 + seed, 600.0);
        sc.sensors.steering = Some(SteeringSpec {
            rate_hz: 50.0,
            offset_s: 0.007,
            noise_std: 0.02,
            latency_s: 0.085,
            true_ratio: None,
            wheel_offset_rad: 0.0,
            clock: None,
        });
        let truth = 0.085 - 0.5 / car.wheel_rate_hz;
        let (mut errors, mut stds) = (Vec::new(), Vec::new());
        for noise_seed in 1001..=1010u64 {
            let sim = simulate(&sc, noise_seed).unwrap();
            let d = timing::steering_delay(&sim.drive, &DelayOptions::default());
            // (Estimated or not: one of car 4's ten reads 0.036 s, above
            // the 0.02 s a delay is applied with.)
            errors.push(d.delay_s - truth);
            stds.push(d.std_s);
        }
        let n = errors.len() as f64;
        let mean = errors.iter().sum::<f64>() / n;
        let scatter = (errors.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        let claimed = stds.iter().sum::<f64>() / n;
        eprintln!("car {seed}: lag error mean {mean:+.4} s, scatter {scatter:.4} s, claimed {claimed:.4} s");
        assert!(
            mean.abs() < 3.0 * scatter / n.sqrt(),
            "car {seed}: biased by {mean}"
        );
        assert!(
            claimed > 0.5 * scatter,
            "car {seed}: {claimed} against {scatter}"
        );
    }
}
