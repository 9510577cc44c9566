//! What each effect of the dynamic family costs the four-wheel filter
//! (issue 28), by ablation, and that each effect is in the drives at the
//! magnitude drawn.
//!
//! For each dynamic family car ([`DynamicCar`]): a calibration drive and a
//! separate evaluation drive of the same car with the same effects; the RTS
//! calibration (default options) on the first, the 30 s outages (step 10 s,
//! 5 s warm-up, against the truth) on the second with the calibrated
//! parameters. The mean final error per car, averaged over the cars, with
//! every effect off, each effect alone, and every effect on.
//!
//! Cars 1–6 are the development set; cars 101–110 are held out (printed on
//! their own, nothing tuned on them):
//!
//! ```text
//! cargo test --profile ci -p deadreckon-sim --test dynamics_ablation -- --nocapture
//! cargo test --profile ci -p deadreckon-sim --test dynamics_ablation -- --ignored --nocapture
//! ```
//!
//! The first runs the development cars on short drives (about 75 s of CPU
//! for the ablation); the second, ignored, the development and held-out
//! cars on 600 s drives (10 min 15 s of CPU, 24 min on the shared two
//! cores). Measured with the second (mean final error, m; ×: of "none"):
//!
//! | effects | dev cars 1–6 | × | held-out 101–110 (104 apart) | × |
//! |---|---|---|---|---|
//! | kinematic family | 0.883 | 1.11 | 0.858 | 1.05 |
//! | none | 0.799 | 1.00 | 0.815 | 1.00 |
//! | side_slip | 0.940 | 1.18 | 0.861 | 1.06 |
//! | longitudinal | 0.822 | 1.03 | 0.815 | 1.00 |
//! | terrain | 0.798 | 1.00 | 0.813 | 1.00 |
//! | clocks | 1.578 | 1.98 | 1.682 | 2.06 |
//! | tooth_error | 0.798 | 1.00 | 0.816 | 1.00 |
//! | gyro_drift | 1.288 | 1.61 | 1.366 | 1.68 |
//! | gyro_scale | 1.172 | 1.47 | 1.264 | 1.55 |
//! | multipath | 1.238 | 1.55 | 0.880 | 1.08 |
//! | wander | 2.844 | 3.56 | 1.363 | 1.67 |
//! | latency | 1.171 | 1.47 | 1.055 | 1.30 |
//! | steering_offset | 0.829 | 1.04 | 0.857 | 1.05 |
//! | all | 4.489 | 5.62 | 2.993 | 3.67 |
//!
//! Car 104's calibration drive is rejected by the RTS calibration (the
//! smoothing filter loses the fixes: circumferences of about 4 m for 2 m
//! tyres) in every configuration but "kinematic family" and "clocks"; the
//! held-out means are over the nine other cars in every row (the test
//! prints "kinematic family" 0.897 and "clocks" 1.671 with car 104 in).
//! Car 104 is the only one of the sixteen with wheel speeds at 100 Hz from
//! tone-ring edge jitter (0.8 mm: about 0.1 m/s per reading); the same drive
//! with its wheels at 50 Hz calibrates (rear-left 1.9977 m, truth 1.9974 m),
//! without steering or CAN speed it is still rejected. An estimator
//! finding, left as drawn (held-out members are not tuned on).

use std::collections::HashMap;
use std::sync::{Mutex, OnceLock};

use rayon::prelude::*;

use deadreckon_core::angle;
use deadreckon_core::calibrate::{calibrate, CalibrationOptions};
use deadreckon_core::drive::Wheels;
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::model::{X, Y, YAW};
use deadreckon_core::outage::evaluate;
use deadreckon_core::reference::Reference;
use deadreckon_sim::dynamics::DrivenAxle;
use deadreckon_sim::family::{DynamicCar, Effects};
use deadreckon_sim::{simulate, SimOutput, WheelKind};

/// One car's result: the mean final error of its 30 s outages, m, and how
/// many windows; or why there is none.
type CarResult = Result<(f64, usize), String>;

/// Calibrates on one drive of `car` and evaluates on another, both with
/// `effects` (`None`: the kinematic family's drives, `CarFamily::drive`,
/// with white fixes and no latency), each at least `drive_s` long; the
/// evaluation with the gyro bias walking by `walk` rad/s/√s
/// (`deadreckon_core::gyro_drift`; 0: the calibrated constant).
fn ablate(car: &DynamicCar, effects: Option<&Effects>, drive_s: f64, walk: f64) -> CarResult {
    let seed = car.base.seed;
    let scenario = |drive_seed: u64| match effects {
        Some(e) => car.drive(drive_seed, drive_s, e),
        None => {
            let mut sc = car.base.drive(drive_seed, drive_s);
            let g = sc.sensors.gnss.as_mut().expect("family GNSS");
            g.markov_std_m = 0.0;
            g.latency_s = 0.0;
            sc
        }
    };
    let cal = simulate(&scenario(1000 + seed), 1000 + seed)
        .map_err(|e| format!("calibration drive: {e}"))?;
    let mut ev = simulate(&scenario(2000 + seed), 2000 + seed)
        .map_err(|e| format!("evaluation drive: {e}"))?;
    ev.drive.vehicle.noise.gyro_bias_walk_rps_per_sqrt_s = walk;
    // The paper's constant bias (or the walk alone), not the default
    // gyro-bias switch: these figures are what each effect costs the
    // paper's filter (the switch's are in bias_switch.rs).
    ev.drive.vehicle.noise.gyro_bias_drive_std_rps = 0.0;
    ev.drive.vehicle.noise.gyro_bias_switch_llr = 0.0;
    let c = calibrate(&cal.drive, &CalibrationOptions::default())
        .map_err(|e| format!("calibration: {e}"))?;
    let out = evaluate(
        &ev.drive,
        &c.estimate.params,
        30.0,
        10.0,
        5.0,
        &FilterOptions::default(),
    )
    .map_err(|e| format!("evaluation: {e}"))?;
    let f = out.final_error();
    Ok((f.mean, f.n))
}

/// Every (car, effects) pair, the cars in parallel (rayon), with the gyro
/// bias walk `walk`.
fn table(
    cars: &[u64],
    configs: &[(String, Option<Effects>)],
    drive_s: f64,
    walk: f64,
) -> Vec<Vec<CarResult>> {
    let drawn: Vec<DynamicCar> = cars.iter().map(|&s| DynamicCar::draw(s)).collect();
    configs
        .iter()
        .map(|(_, effects)| {
            drawn
                .par_iter()
                .map(|car| ablate(car, effects.as_ref(), drive_s, walk))
                .collect()
        })
        .collect()
}

/// The configurations: the kinematic family (for reference), every effect
/// off, each alone, every effect on.
fn configs() -> Vec<(String, Option<Effects>)> {
    let mut v = vec![
        ("kinematic family".to_string(), None),
        ("none".to_string(), Some(Effects::none())),
    ];
    for name in Effects::NAMES {
        v.push((name.to_string(), Some(Effects::only(name).expect("a name"))));
    }
    v.push(("all".to_string(), Some(Effects::all())));
    v
}

/// Index of the row with every effect off.
const NONE: usize = 1;

/// The mean over the cars that have a result.
fn mean_of(row: &[CarResult]) -> f64 {
    let ok: Vec<f64> = row
        .iter()
        .filter_map(|r| r.as_ref().ok())
        .map(|r| r.0)
        .collect();
    ok.iter().sum::<f64>() / ok.len() as f64
}

fn print_table(
    title: &str,
    cars: &[u64],
    configs: &[(String, Option<Effects>)],
    rows: &[Vec<CarResult>],
) {
    println!("\n{title}: mean final error of 30 s outages (step 10 s), m");
    print!("{:<16} {:>7}", "effects", "mean");
    for c in cars {
        print!(" {:>7}", format!("car {c}"));
    }
    println!();
    let base = mean_of(&rows[NONE]);
    for ((name, _), row) in configs.iter().zip(rows) {
        let m = mean_of(row);
        print!("{name:<16} {m:>7.3}");
        for r in row {
            match r {
                Ok((e, _)) => print!(" {e:>7.3}"),
                Err(_) => print!(" {:>7}", "failed"),
            }
        }
        println!("   ×{:.2} of none", m / base);
        for (c, r) in cars.iter().zip(row) {
            if let Err(e) = r {
                println!("    car {c}: {e}");
            }
        }
    }
}

#[test]
fn ablation_on_the_development_cars() {
    let cars: Vec<u64> = (1..=6).collect();
    let configs = configs();
    let rows = table(&cars, &configs, DEV_DRIVE_S, 0.0);
    print_table("development cars 1–6, 300 s drives", &cars, &configs, &rows);
    for ((name, _), row) in configs.iter().zip(&rows) {
        for (c, r) in cars.iter().zip(row) {
            assert!(r.is_ok(), "{name}, car {c}: {r:?}");
        }
    }
    let mean = |name: &str| mean_of(&rows[configs.iter().position(|c| c.0 == name).unwrap()]);
    let none = mean("none");
    // With every effect off the dynamic family is a kinematic world: its
    // error is the kinematic family's (white fixes, no latency; wheel
    // speeds only, no CAN speed or steering). Measured: none 0.405 m,
    // kinematic family 0.436 m (cars 1–6, 300 s drives; 1.225 and 1.204 m
    // before the pull-away windows were reported on their own).
    assert!((none - 0.405).abs() < 0.03, "none {none}");
    assert!((none / mean("kinematic family") - 1.0).abs() < 0.1);
    // Every effect changes the drives, and so the errors of some cars.
    for (k, (name, _)) in configs.iter().enumerate().skip(NONE + 1) {
        let changed = rows[k]
            .iter()
            .zip(&rows[NONE])
            .any(|(a, b)| a.as_ref().unwrap().0 != b.as_ref().unwrap().0);
        assert!(changed, "{name} changed nothing");
    }
    // Together they cost the filter far more than any alone.
    let worst_alone = Effects::NAMES.iter().map(|n| mean(n)).fold(0.0, f64::max);
    assert!(
        mean("all") > worst_alone,
        "all {} vs {worst_alone}",
        mean("all")
    );
}

/// Length of the development run's drives, s.
const DEV_DRIVE_S: f64 = 300.0;

/// The bigger run: the development cars and the held-out ones (printed on
/// their own), on 600 s drives (10 min of CPU).
#[test]
#[ignore]
fn ablation_on_the_development_and_held_out_cars() {
    let configs = configs();
    for (title, cars) in [
        (
            "development cars 1–6, 600 s drives",
            (1..=6).collect::<Vec<u64>>(),
        ),
        ("held-out cars 101–110, 600 s drives", (101..=110).collect()),
    ] {
        let rows = table(&cars, &configs, 600.0, 0.0);
        print_table(title, &cars, &configs, &rows);
    }
}

// ---------------------------------------------------------------------------
// Each effect is in the drives, at the magnitude drawn: a drive with one
// effect against the same drive (same seeds) without it.
// ---------------------------------------------------------------------------

/// Length of the drives the effects are measured on, s.
const MEASURE_S: f64 = 900.0;

/// The drive of `car` (seed 7 + its seed) with `effects`.
fn measured(car: &DynamicCar, effects: &Effects) -> SimOutput {
    let seed = 7 + car.base.seed;
    simulate(&car.drive(seed, MEASURE_S, effects), seed).unwrap()
}

/// The drive of `car` without effects (simulated once per car and wheel
/// kind) and with only `name`.
fn pair(car: &DynamicCar, name: &str) -> (&'static SimOutput, SimOutput) {
    type Cache = Mutex<HashMap<(u64, bool), &'static SimOutput>>;
    static NONE: OnceLock<Cache> = OnceLock::new();
    let key = (car.base.seed, car.wheel_kind == WheelKind::Ticks);
    let cached = NONE
        .get_or_init(Default::default)
        .lock()
        .unwrap()
        .get(&key)
        .copied();
    let none = cached.unwrap_or_else(|| {
        let out: &'static SimOutput = Box::leak(Box::new(measured(car, &Effects::none())));
        NONE.get_or_init(Default::default)
            .lock()
            .unwrap()
            .insert(key, out);
        out
    });
    (none, measured(car, &Effects::only(name).unwrap()))
}

/// Least squares y = a + b·x: (a, b, residual std).
fn line(xy: &[(f64, f64)]) -> (f64, f64, f64) {
    let n = xy.len() as f64;
    let mx = xy.iter().map(|p| p.0).sum::<f64>() / n;
    let my = xy.iter().map(|p| p.1).sum::<f64>() / n;
    let sxy: f64 = xy.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = xy.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let b = sxy / sxx;
    let a = my - b * mx;
    let r = (xy.iter().map(|p| (p.1 - a - b * p.0).powi(2)).sum::<f64>() / (n - 2.0)).sqrt();
    (a, b, r)
}

fn std_of(x: &[f64]) -> f64 {
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    (x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
}

/// The development cars' measurements, one line per car and effect.
const CARS: [u64; 6] = [1, 2, 3, 4, 5, 6];

#[test]
fn side_slip_turns_the_body_by_the_drawn_gradient() {
    for seed in CARS {
        let car = DynamicCar::draw(seed);
        let (none, with) = pair(&car, "side_slip");
        let g = car
            .dynamics
            .rear_slip_gradient_rad_per_mps2(&car.base.vehicle);
        // The same route: the kinematic yaw is the course; β = course − yaw.
        let (a, b) = (&none.drive.truth, &with.drive.truth);
        assert_eq!(a.len(), b.len());
        let yaw_n = angle::unwrap(&a.iter().map(|p| p.yaw_rad).collect::<Vec<_>>());
        let yaw_w = angle::unwrap(&b.iter().map(|p| p.yaw_rad).collect::<Vec<_>>());
        let mut xy = Vec::new();
        for k in 1..a.len() - 1 {
            assert!((a[k].east_m - b[k].east_m).abs() < 1e-9, "the path moved");
            let v = a[k].speed_mps.unwrap();
            let rate = (yaw_n[k + 1] - yaw_n[k - 1]) / (a[k + 1].t_s - a[k - 1].t_s);
            xy.push((v * rate, yaw_n[k] - yaw_w[k]));
        }
        let (_, fit, _) = line(&xy);
        let largest = xy.iter().map(|p| p.1.abs()).fold(0.0, f64::max);
        println!(
            "car {seed}: β on a_y {fit:+.5} rad per m/s² (drawn gradient {g:.5}), largest β {:.2}°",
            largest.to_degrees()
        );
        // Measured on cars 1–6: within 0.6 % of −g (load transfer adds to it).
        assert!((fit + g).abs() < 0.03 * g, "car {seed}: {fit} vs {g}");
    }
}

#[test]
fn terrain_and_longitudinal_slip_change_what_the_wheels_count() {
    for seed in CARS {
        let car = DynamicCar::draw(seed);
        let d = &car.dynamics;
        let (none, with) = pair(&car, "terrain");
        // The wheels roll the length of the road: on average
        // 1 + (2πA/λ)²/4 for each sinusoid (grade and bumps).
        let wave = |a: f64, l: f64| (std::f64::consts::TAU * a / l).powi(2) / 4.0;
        let expected = wave(d.grade_amplitude_m, d.grade_wavelength_m)
            + wave(d.bump_amplitude_m, d.bump_wavelength_m);
        let extra = with.stats.wheel_distance_m[2] / none.stats.wheel_distance_m[2] - 1.0;
        println!("car {seed}: terrain adds {extra:.6} to the rear-left distance (expected {expected:.6})");
        // Measured on cars 1–6: within 1.5 % (the rest: the drive's end is
        // not at a whole wavelength).
        assert!((extra / expected - 1.0).abs() < 0.05, "car {seed}: {extra}");
        // Longitudinal slip and radii: the driven axle counts more than the
        // other (traction beats the braking share on these drives).
        let (none, with) = pair(&car, "longitudinal");
        let axle = |s: &SimOutput, k: usize| {
            s.stats.wheel_distance_m[2 * k] + s.stats.wheel_distance_m[2 * k + 1]
        };
        let driven = usize::from(d.driven_axle == DrivenAxle::Rear);
        let gain = |s: &SimOutput| axle(s, driven) / axle(s, 1 - driven);
        println!(
            "car {seed}: driven over free axle distance {:.5} (without {:.5})",
            gain(&with),
            gain(none)
        );
        assert!(gain(&with) > gain(none), "car {seed}");
    }
}

#[test]
fn clocks_stamp_each_stream_with_the_drawn_offset_drift_and_jitter() {
    for seed in CARS {
        let car = DynamicCar::draw(seed);
        let (none, with) = pair(&car, "clocks");
        let (a, b) = (&none.drive, &with.drive);
        let gyro: Vec<(f64, f64)> = a
            .yaw_rate
            .iter()
            .zip(&b.yaw_rate)
            .map(|(p, q)| {
                assert_eq!(p.value, q.value, "the reading describes the true time");
                (p.t_s, q.t_s - p.t_s)
            })
            .collect();
        let (off, drift, jitter) = line(&gyro);
        let c = car.clocks.gyro;
        println!(
            "car {seed}: gyro clock {:.3} ms, {:+.1} ppm, jitter {:.3} ms (drawn {:.3}, {:+.1}, {:.3})",
            off * 1e3,
            drift * 1e6,
            jitter * 1e3,
            c.offset_s * 1e3,
            c.drift_ppm,
            c.jitter_std_s * 1e3
        );
        // 90000 readings: measured offsets within 8 µs, drifts within 0.1
        // ppm, jitter within 0.3 %.
        assert!((off - c.offset_s).abs() < 2e-5, "car {seed}");
        assert!((drift * 1e6 - c.drift_ppm).abs() < 1.0, "car {seed}");
        assert!((jitter / c.jitter_std_s - 1.0).abs() < 0.02, "car {seed}");
        // The wheels: the same counts (or speeds) over the true intervals,
        // stamped by their own clock.
        let (ta, tb) = (wheel_times(a), wheel_times(b));
        let w: Vec<(f64, f64)> = ta.iter().zip(&tb).map(|(p, q)| (*p, q - p)).collect();
        let (off, drift, jitter) = line(&w);
        let c = car.clocks.wheels;
        assert!((off - c.offset_s).abs() < 2e-5, "car {seed}");
        assert!((drift * 1e6 - c.drift_ppm).abs() < 1.5, "car {seed}");
        assert!(
            (jitter / c.jitter_std_s - 1.0).abs() < 0.03,
            "car {seed}: {jitter}"
        );
        assert_eq!(
            wheel_values(a),
            wheel_values(b),
            "car {seed}: counts changed"
        );
    }
}

fn wheel_times(d: &deadreckon_core::Drive) -> Vec<f64> {
    match &d.wheels {
        Wheels::Ticks(v) => v.iter().map(|w| w.t_s).collect(),
        Wheels::Speeds(v) => v.iter().map(|w| w.t_s).collect(),
    }
}

fn wheel_values(d: &deadreckon_core::Drive) -> Vec<[f64; 4]> {
    match &d.wheels {
        Wheels::Ticks(v) => v
            .iter()
            .map(|w| [w.fl, w.fr, w.rl, w.rr].map(|x| x as f64))
            .collect(),
        Wheels::Speeds(v) => v
            .iter()
            .map(|w| [w.fl_mps, w.fr_mps, w.rl_mps, w.rr_mps])
            .collect(),
    }
}

#[test]
fn tooth_errors_move_the_edges_by_the_drawn_amount() {
    for seed in CARS {
        let mut car = DynamicCar::draw(seed);
        car.wheel_kind = WheelKind::Ticks;
        let (none, with) = pair(&car, "tooth_error");
        let errors = with.stats.tooth_errors.clone().expect("tooth errors");
        let all: Vec<f64> = errors.iter().flatten().copied().collect();
        let mean_abs = all.iter().map(|e| e.abs()).sum::<f64>() / all.len() as f64;
        // White per tooth: E|e| = σ·√(2/π) (less the mean removed per ring).
        let expected = car.tooth_error_std * (2.0 / std::f64::consts::PI).sqrt();
        // The cumulative count differs from the even ring's where the wheel
        // stands between a tooth's place and where it is: on a share E|e| of
        // the moving epochs. Both rings start at the same phase past edge
        // 0's place; where the misplaced edge 0 still lies ahead of the
        // wheel, the rough ring counts one edge more all drive long, and
        // where edge 1 already lies behind it, one fewer. So the difference
        // is counted from each wheel's most frequent one (car 3's RR: −1;
        // counted from 0, 0.252 of the epochs differed).
        let (a, b) = (wheel_values(&none.drive), wheel_values(&with.drive));
        let (mut cum_a, mut cum_b) = ([0.0; 4], [0.0; 4]);
        let mut diffs: [Vec<i64>; 4] = Default::default();
        for (p, q) in a.iter().zip(&b) {
            for i in 0..4 {
                cum_a[i] += p[i];
                cum_b[i] += q[i];
                if p[i] != 0.0 {
                    diffs[i].push((cum_b[i] - cum_a[i]) as i64);
                }
            }
        }
        let usual = diffs.clone().map(|mut d| {
            d.sort_unstable();
            let runs = d.chunk_by(|x, y| x == y);
            runs.max_by_key(|r| r.len()).map_or(0, |r| r[0])
        });
        let moving: usize = diffs.iter().map(Vec::len).sum();
        let differ: usize = (0..4)
            .map(|i| diffs[i].iter().filter(|&&d| d != usual[i]).count())
            .sum();
        let share = differ as f64 / moving as f64;
        println!(
            "car {seed}: tooth error σ {:.4} pitch drawn; mean |e| {mean_abs:.5} (expected \
             {expected:.5}); counts off on {share:.5} of moving epochs, usually by \
             {usual:?} (FL, FR, RL, RR)",
            car.tooth_error_std
        );
        assert!((mean_abs / expected - 1.0).abs() < 0.15, "car {seed}");
        // Measured on cars 1–6: within 7 % of the mean |e| (a few hundred
        // events); the mean |e| within 7 % of σ·√(2/π).
        assert!((share / mean_abs - 1.0).abs() < 0.2, "car {seed}: {share}");
        for i in 0..4 {
            assert!(usual[i].abs() <= 1, "car {seed}: {usual:?}");
            assert!(
                diffs[i].iter().all(|&d| (d - usual[i]).abs() <= 1),
                "car {seed}: the ring lost a tooth"
            );
        }
    }
}

#[test]
fn the_gyro_drifts_and_scales_as_drawn() {
    for seed in CARS {
        let car = DynamicCar::draw(seed);
        let (none, with) = pair(&car, "gyro_drift");
        let (std, tau) = car.gyro_drift;
        // The difference is the drifting bias; sampled each second it is an
        // AR(1) whose innovations have std σ·√(1 − e^(−2/τ)).
        let d: Vec<f64> = none
            .drive
            .yaw_rate
            .iter()
            .zip(&with.drive.yaw_rate)
            .step_by(100)
            .map(|(p, q)| q.value - p.value)
            .collect();
        let a = (-1.0 / tau).exp();
        let innov: Vec<f64> = d.windows(2).map(|w| w[1] - a * w[0]).collect();
        let q = std_of(&innov);
        let q_drawn = std * (1.0 - a * a).sqrt();
        println!(
            "car {seed}: drift std {:.6} rad/s over the drive (drawn {std:.6}, τ {tau:.0} s), \
             innovations {q:.3e} (expected {q_drawn:.3e})",
            std_of(&d)
        );
        // Measured on cars 1–6: within 4 % (900 innovations).
        assert!((q / q_drawn - 1.0).abs() < 0.1, "car {seed}");
        assert!(d.iter().all(|x| x.abs() < 5.0 * std), "car {seed}");
        // Scale: the difference is the scale error times the rate (noise-free
        // gyros, so that the rate is the reading less the bias).
        let quiet = |effects: &Effects| {
            let s = 7 + car.base.seed;
            let mut sc = car.drive(s, 300.0, effects);
            sc.sensors.gyro.as_mut().unwrap().noise_std = 0.0;
            simulate(&sc, s).unwrap()
        };
        let (none, with) = (
            quiet(&Effects::none()),
            quiet(&Effects::only("gyro_scale").unwrap()),
        );
        let bias = none.truth_params.gyro_bias_rps;
        let xy: Vec<(f64, f64)> = none
            .drive
            .yaw_rate
            .iter()
            .zip(&with.drive.yaw_rate)
            .map(|(p, q)| (p.value - bias, q.value - p.value))
            .collect();
        let (_, k, _) = line(&xy);
        println!(
            "car {seed}: gyro scale {k:+.6} (drawn {:+.6})",
            car.gyro_scale_error
        );
        assert!((k - car.gyro_scale_error).abs() < 1e-9, "car {seed}: {k}");
    }
}

#[test]
fn multipath_wander_latency_and_steering_offset_are_as_drawn() {
    for seed in CARS {
        let car = DynamicCar::draw(seed);
        // Multipath: the fixes move by a burst's offset within it, and only there.
        let (none, with) = pair(&car, "multipath");
        let bursts = &with.stats.multipath_bursts;
        for (p, q) in none.drive.gnss.iter().zip(&with.drive.gnss) {
            let t = p.t_s;
            let (e, n) = bursts
                .iter()
                .find(|b| t >= b.0 && t < b.1)
                .map_or((0.0, 0.0), |b| (b.2, b.3));
            assert!((q.east_m - p.east_m - e).abs() < 1e-9, "car {seed} at {t}");
            assert!(
                (q.north_m - p.north_m - n).abs() < 1e-9,
                "car {seed} at {t}"
            );
        }
        let m = &car.multipath;
        let expected = with.stats.duration_s / (60.0 / m.bursts_per_min + m.mean_duration_s);
        let offsets: Vec<f64> = bursts.iter().flat_map(|b| [b.2, b.3]).collect();
        println!(
            "car {seed}: {} multipath bursts (about {expected:.1} expected), offset rms {:.2} m \
             (drawn {:.2})",
            bursts.len(),
            (offsets.iter().map(|x| x * x).sum::<f64>() / offsets.len().max(1) as f64).sqrt(),
            m.offset_std_m
        );
        // Poisson: within 3 standard deviations (measured on cars 1–6: 4–21
        // bursts, 0.6–2.6 expected standard deviations off). The offsets'
        // rms: 0.86–1.23 of the drawn std.
        let rms = (offsets.iter().map(|x| x * x).sum::<f64>() / offsets.len().max(1) as f64).sqrt();
        if bursts.len() >= 3 {
            assert!(
                (rms / m.offset_std_m - 1.0).abs() < 0.5,
                "car {seed}: {rms}"
            );
        }
        let k = bursts.len() as f64;
        assert!(
            (k - expected).abs() < 3.0 * expected.sqrt() + 1.0,
            "car {seed}: {k}"
        );
        // Latency: every stamp moves by the drawn latency.
        let (none, with) = pair(&car, "latency");
        for (p, q) in none.drive.gnss.iter().zip(&with.drive.gnss) {
            assert!((q.t_s - p.t_s - car.base.gnss_latency_s).abs() < 1e-9);
        }
        for (p, q) in none.drive.speed.iter().zip(&with.drive.speed) {
            assert!((q.t_s - p.t_s - car.can_latency_s.0).abs() < 1e-9);
            assert_eq!(p.value, q.value);
        }
        for (p, q) in none.drive.steering.iter().zip(&with.drive.steering) {
            assert!((q.t_s - p.t_s - car.can_latency_s.1).abs() < 1e-9);
        }
        // Steering offset: every reading moves by it.
        let (none, with) = pair(&car, "steering_offset");
        for (p, q) in none.drive.steering.iter().zip(&with.drive.steering) {
            assert!((q.value - p.value - car.steering_offset_rad).abs() < 1e-9);
        }
        // Wander: the fixes' error less the white noise has the drawn variance.
        let (none, with) = pair(&car, "wander");
        let (white, wander) = (fix_errors(&none.drive), fix_errors(&with.drive));
        let (s, tau) = car.base.gnss_markov;
        let extra = (std_of(&wander).powi(2) - std_of(&white).powi(2))
            .max(0.0)
            .sqrt();
        println!(
            "car {seed}: wander {extra:.3} m over the white noise (drawn {s:.3} m, τ {tau:.0} s)"
        );
        // 900 s hold 8–27 correlation times: measured on cars 1–6 within
        // 17 % of the drawn std.
        assert!(
            (extra - s).abs() < 0.3 * s + 0.1,
            "car {seed}: {extra} vs {s}"
        );
    }
}

/// Each fix's east and north errors against the truth's antenna, m.
fn fix_errors(d: &deadreckon_core::Drive) -> Vec<f64> {
    let truth = Reference::from_truth(&d.truth).expect("truth");
    let l = d.vehicle.gnss_lever_arm_m;
    let mut out = Vec::new();
    for f in &d.gnss {
        if let Some(x) = truth.state_at(f.t_s) {
            out.push(f.east_m - (x[X] + l * x[YAW].cos()));
            out.push(f.north_m - (x[Y] + l * x[YAW].sin()));
        }
    }
    out
}

// ---------------------------------------------------------------------------
// The gyro bias as a walking state (deadreckon_core::gyro_drift).
// ---------------------------------------------------------------------------

/// The walk the family checks use, rad/s/√s: chosen on the development cars
/// 1–6 (300 s drives) among 3e-6, 1e-5 and 3e-5 (gyro_drift alone: 0.629,
/// 0.541, 0.553 m against 1.107 m constant; none: 0.404, 0.441, 0.516
/// against 0.405 m): the largest walk that costs nothing without drift. A
/// gyro drawn with the family's drift (0.00005–0.0002 rad/s over 100–600 s)
/// walks by σ·√(2/τ) = 3e-6–3e-5.
const WALK: f64 = 3e-6;

/// The configurations with every effect off, the gyro drift alone, and
/// every effect on.
fn walk_configs() -> Vec<(String, Option<Effects>)> {
    vec![
        ("none".to_string(), Some(Effects::none())),
        (
            "gyro_drift".to_string(),
            Some(Effects::only("gyro_drift").expect("a name")),
        ),
        ("all".to_string(), Some(Effects::all())),
    ]
}

#[test]
fn a_walking_gyro_bias_takes_back_most_of_what_the_gyro_drift_costs() {
    let cars: Vec<u64> = (1..=6).collect();
    let configs = walk_configs()[..2].to_vec();
    let constant = table(&cars, &configs, DEV_DRIVE_S, 0.0);
    let walking = table(&cars, &configs, DEV_DRIVE_S, WALK);
    print_walk_tables(
        "development cars 1–6, 300 s drives",
        &cars,
        &configs,
        &constant,
        &walking,
    );
    let (none_c, drift_c) = (mean_of(&constant[0]), mean_of(&constant[1]));
    let (none_w, drift_w) = (mean_of(&walking[0]), mean_of(&walking[1]));
    // Measured: none 0.405 → 0.404 m, gyro_drift 1.107 → 0.629 m.
    assert!(
        (none_w / none_c - 1.0).abs() < 0.03,
        "none {none_c} → {none_w}"
    );
    assert!(drift_w < 0.62 * drift_c, "gyro_drift {drift_c} → {drift_w}");
    assert!(
        drift_w < 1.7 * none_w,
        "gyro_drift {drift_w} against none {none_w}"
    );
}

/// The same on the held-out cars (nothing chosen on them; car 104's
/// calibration is rejected, see the header), and every effect on:
///
/// ```text
/// cargo test --profile ci -p deadreckon-sim --test dynamics_ablation \
///     a_walking_gyro_bias_on_the_held_out_cars -- --ignored --nocapture
/// ```
#[test]
#[ignore]
fn a_walking_gyro_bias_on_the_held_out_cars() {
    let cars: Vec<u64> = (101..=110).filter(|&c| c != 104).collect();
    let configs = walk_configs();
    let constant = table(&cars, &configs, DEV_DRIVE_S, 0.0);
    let walking = table(&cars, &configs, DEV_DRIVE_S, WALK);
    print_walk_tables(
        "held-out cars 101–110 (104 apart), 300 s drives",
        &cars,
        &configs,
        &constant,
        &walking,
    );
}

fn print_walk_tables(
    title: &str,
    cars: &[u64],
    configs: &[(String, Option<Effects>)],
    constant: &[Vec<CarResult>],
    walking: &[Vec<CarResult>],
) {
    println!(
        "\n{title}: mean final error of 30 s outages, constant bias → walking ({WALK} rad/s/√s), m"
    );
    for ((name, _), (c, w)) in configs.iter().zip(constant.iter().zip(walking)) {
        print!("{name:<12} {:>7.3} → {:>7.3}  |", mean_of(c), mean_of(w));
        for (k, (a, b)) in cars.iter().zip(c.iter().zip(w)) {
            match (a, b) {
                (Ok(a), Ok(b)) => print!(" {k}: {:.2}→{:.2}", a.0, b.0),
                _ => print!(" {k}: failed"),
            }
        }
        println!();
    }
}

/// The bug: stamp jitter made every tick-counter circumference long, as
/// (σΔt/Δt)², +31.5 to +32.5 mm (car 1: 2.8 ms of interval jitter on a 20
/// ms cycle) and +21.4 to +21.8 mm (car 3: 2.1 ms) on all four wheels,
/// because a count is over the counter's cycle and both the least-squares
/// regressor and the filter's predicted count took the stamps' interval
/// (errors in variables). Now the least squares sums ticks over 1 s blocks
/// (`calibrate::TICK_BLOCK_S`) and the filter predicts a count over the
/// interval's conditional expectation (`deadreckon_core::tick_interval`):
/// measured −0.07 to −0.15 mm on the tick cars, −0.08 to +0.11 mm on the
/// speed cars (unchanged), against the issue's 0.3 mm. The same drive of
/// each development car with and without the clocks (300 s, core
/// calibration).
///
/// ```text
/// cargo test --profile ci -p deadreckon-sim --test dynamics_ablation \
///     stamp_jitter_made_tick_circumferences_long -- --nocapture
/// ```
#[test]
fn stamp_jitter_made_tick_circumferences_long() {
    let largest = clock_shifts(&[1, 2, 3, 4, 5, 6]);
    assert!(largest < 0.3, "largest {largest:.2} mm");
}

/// [`stamp_jitter_made_tick_circumferences_long`] on the held-out cars
/// 101–110 (104 apart: its calibration drive is rejected without the
/// clocks, see the module docs), run once the fix was made and never used
/// for a choice. Measured: the six tick cars −0.44 to +0.70 mm (before the
/// fix −2.5 to +22.7 mm: car 109 +21.5 to +22.7, car 101 +6.7 to +6.9),
/// the three speed cars +0.01 to +0.11 mm. Cars 103 (−0.32 to −0.44) and
/// 107 (+0.61 to +0.70) miss the issue's 0.3 mm; the bound is near what
/// was measured.
#[test]
fn stamp_jitter_on_the_held_out_tick_cars() {
    let largest = clock_shifts(&[101, 102, 103, 105, 106, 107, 108, 109, 110]);
    assert!(largest < 0.9, "largest {largest:.2} mm");
}

/// The largest move of a circumference, mm, when the clocks are switched
/// on, over `seeds`' calibration drives (printed per car); checks that the
/// set has a tick-counter car.
fn clock_shifts(seeds: &[u64]) -> f64 {
    let rows: Vec<(u64, WheelKind, Vec<f64>)> = seeds
        .par_iter()
        .map(|&seed| {
            let car = DynamicCar::draw(seed);
            let circ = |e: &Effects| {
                let sc = car.drive(1000 + seed, DEV_DRIVE_S, e);
                let cal = simulate(&sc, 1000 + seed).unwrap();
                let c = calibrate(&cal.drive, &CalibrationOptions::default()).unwrap();
                c.estimate.params.circumferences()
            };
            let (a, b) = (
                circ(&Effects::none()),
                circ(&Effects::only("clocks").unwrap()),
            );
            let d = (0..4).map(|i| (b[i] - a[i]) * 1000.0).collect();
            (seed, car.wheel_kind, d)
        })
        .collect();
    let mut largest: f64 = 0.0;
    for (seed, kind, d) in &rows {
        println!(
            "car {seed} ({kind:?}): clocks move the circumferences by {:+.2} {:+.2} {:+.2} {:+.2} mm",
            d[0], d[1], d[2], d[3]
        );
        largest = d.iter().fold(largest, |m, x| m.max(x.abs()));
    }
    println!("largest {largest:.2} mm");
    assert!(rows.iter().any(|r| r.1 == WheelKind::Ticks), "no tick car");
    largest
}
