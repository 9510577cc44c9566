//! TedriS on wheel-tick counters in a dynamic world (issue 35).
//!
//! Members: [`DynamicCar::draw_tick_counter`] cars (tone rings of 40–100
//! teeth counted at 25, 50 or 100 Hz) with every effect of the dynamic
//! family ([`Effects::all`]: tyre side slip, longitudinal slip and loaded
//! radii, grade and bumps, clocks, tooth errors, gyro drift and scale,
//! multipath, wander, latencies, steering offset). Each car is trained on
//! drive 1000 + seed (900 s) and run through 80 s outages starting at 120,
//! 200, 280 and 360 s of drive 2000 + seed (500 s); the block baseline
//! ([`Baseline::fit_blocks`], 2 s blocks of cumulative increments, the
//! issue's) is fitted on the same training drive and run through the same
//! outages.
//!
//! **Which members saw which choices**: the dev members, cars 1–3, saw every
//! choice of issue 35 — the block means and the attenuation target of the
//! block length (`tuning::MAX_QUANTISATION_ATTENUATION`), the speed kind
//! (found on car 3's [280, 360) outage drifting on a straight), the
//! acceptance thresholds (`tuning::{MIN_TURN_GAIN, MAX_TURN_GAIN,
//! R_SQUARED_TEST_LEVEL, MIN_CCF_SHARE}`). Dev cars 4–9
//! (`TEDRIS_TICK_CARS`) saw the second stop's: the speed kind's
//! errors-in-variables covariance (car 9), the run drive's course
//! convention rebuilding a trained model (car 4: tried and withdrawn, see
//! docs/tedris.md) and
//! `tuning::SPEED_TERM_TEST_LEVEL` (with the smooth-speed family's dev cars
//! 1–12). The held-out members, cars 101–108, were run once at the end of
//! the first stop and once at the end of the second; cars 109–116 were
//! drawn for the second stop and run once at its end, with nothing changed
//! after (`tick_family_held_out_members_80s_outages`,
//! `tick_family_new_held_out_members_80s_outages`, `#[ignore]`d: about a
//! minute each on two cores).
//!
//! `cargo test --profile ci -p deadreckon-tedris --test tick_family -- --nocapture`

use deadreckon_sim::family::{DynamicCar, Effects};
use deadreckon_sim::simulate;
use deadreckon_tedris::acceptance;
use deadreckon_tedris::baseline::Baseline;
use deadreckon_tedris::config::ModelKind;
use deadreckon_tedris::{run_outages, train, Outage, TedrisConfig, TedrisModel};

const OUTAGE_STARTS_S: [f64; 4] = [120.0, 200.0, 280.0, 360.0];

/// One car's outages: TedriS and the block baseline, mean errors, m.
struct CarResult {
    seed: u64,
    tedris_m: Vec<f64>,
    baseline_m: Vec<f64>,
}

/// The chosen kind of `model` passes the physical acceptance (turn gain,
/// R²) on a car of rear track `track_m`; returns its turn gain.
fn accepted_gain(model: &TedrisModel, track_m: f64, what: &str) -> f64 {
    let acc = acceptance::check(model, track_m, None);
    let k = acc.kind(model.chosen).expect("the chosen kind was fitted");
    assert!(
        k.refused.is_none(),
        "{what}: the chosen {:?} would be refused: {:?}",
        model.chosen,
        k.refused
    );
    k.turn_gain.expect("a turn gain")
}

fn run_car(seed: u64) -> CarResult {
    let car = DynamicCar::draw_tick_counter(seed);
    let track = car.base.vehicle.track_rear_m;
    let effects = Effects::all();
    let train_drive = simulate(&car.drive(1000 + seed, 900.0, &effects), 1000 + seed)
        .expect("train drive")
        .drive;
    let test_drive = simulate(&car.drive(2000 + seed, 500.0, &effects), 2000 + seed)
        .expect("test drive")
        .drive;
    let (model, _) = train(&train_drive, TedrisConfig::default(), None).expect("trained");
    let gain = accepted_gain(&model, track, "trained");
    let blocks = model.blocks.expect("quantised blocks for tick counters");
    let base = Baseline::fit_blocks(&train_drive, 2.0).expect("block baseline");
    let acc = model.acceptance.as_ref().expect("checked at training");
    eprintln!(
        "car {seed}: {} teeth at {} Hz, track {track:.2} m: {:?} kind, turn gain {gain:.3}, cross-correlation peak {:.3} (expected {:?}); {}; block baseline k = {:.3}",
        car.base.vehicle.ticks_per_rev,
        car.wheel_rate_hz,
        model.chosen,
        acc.ccf_peak,
        acc.expected_ccf_peak,
        blocks.describe(model.sample_period_s),
        base.gain_rad_per_m * track,
    );
    let mut r = CarResult {
        seed,
        tedris_m: Vec::new(),
        baseline_m: Vec::new(),
    };
    for start_s in OUTAGE_STARTS_S {
        let o = Outage {
            start_s,
            end_s: start_s + 80.0,
        };
        let run = run_outages(&test_drive, &model, &[o]).expect("run");
        // The model the machine holds after its refits and calibrations on
        // the test drive passes too.
        let held = run.machine.model().expect("a model");
        accepted_gain(held, track, "after the run");
        let b = base.run_outage(&test_drive, &o).expect("baseline run");
        eprintln!(
            "  [{start_s:.0}, {:.0}): tedris {:.2} m (max {:.2}), block baseline {:.2} m",
            o.end_s,
            run.outages[0].mean_error_m(),
            run.outages[0].max_error_m(),
            b.mean_error_m()
        );
        r.tedris_m.push(run.outages[0].mean_error_m());
        r.baseline_m.push(b.mean_error_m());
    }
    r
}

/// Runs the cars two at a time; returns (TedriS mean, baseline mean, worst TedriS).
fn run_family(seeds: &[u64]) -> (f64, f64, f64) {
    let results: Vec<CarResult> = std::thread::scope(|s| {
        let handles: Vec<_> = seeds
            .chunks(seeds.len().div_ceil(2))
            .map(|chunk| s.spawn(move || chunk.iter().map(|&c| run_car(c)).collect::<Vec<_>>()))
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().expect("a car's thread"))
            .collect()
    });
    let all_t: Vec<f64> = results.iter().flat_map(|r| r.tedris_m.clone()).collect();
    let all_b: Vec<f64> = results.iter().flat_map(|r| r.baseline_m.clone()).collect();
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let list = |v: &[f64]| {
        v.iter()
            .map(|e| format!("{e:.2}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    for r in &results {
        eprintln!(
            "car {}: tedris {:.2} m ({}), block baseline {:.2} m ({})",
            r.seed,
            mean(&r.tedris_m),
            list(&r.tedris_m),
            mean(&r.baseline_m),
            list(&r.baseline_m)
        );
    }
    let lower = results
        .iter()
        .filter(|r| mean(&r.tedris_m) < mean(&r.baseline_m))
        .count();
    eprintln!("tedris lower on {lower} of {} cars", results.len());
    let worst = all_t.iter().copied().fold(0.0, f64::max);
    eprintln!(
        "{} outages: tedris mean {:.2} m (worst {:.2}), block baseline {:.2} m (worst {:.2})",
        all_t.len(),
        mean(&all_t),
        worst,
        mean(&all_b),
        all_b.iter().copied().fold(0.0, f64::max)
    );
    (mean(&all_t), mean(&all_b), worst)
}

#[test]
fn tick_family_dev_members_80s_outages() {
    // TEDRIS_TICK_CARS=4,5,6 runs other dev cars (not 101–108) instead.
    let cars: Vec<u64> = std::env::var("TEDRIS_TICK_CARS").map_or(vec![1, 2, 3], |v| {
        v.split(',')
            .map(|c| c.trim().parse().expect("car seeds"))
            .collect()
    });
    assert!(
        cars.iter().all(|c| !(101..=132).contains(c)),
        "held-out cars"
    );
    let (t, b, worst) = run_family(&cars);
    // Measured on cars 1–3 (12 outages): TedriS 3.81 m mean (worst 7.66 m),
    // block baseline 6.81 m (worst 24.2 m); 5.81 m (worst 19.0 m) before
    // the speed kind's errors-in-variables fit took the noise covariance of
    // its ω·d² column. Before issue 35: TedriS 74.0 m mean (α1·track
    // 0.33–0.49: medians of quantised ticks). Over dev cars 1–9 (36
    // outages): TedriS 7.28 m (worst 49.1 m: car 4, [120, 200), where the
    // baseline has 30.1 m; car 9's [200, 280) 44.3 m against 50.6 m)
    // against the block baseline's 7.49 m; before this stop 11.41 m
    // (worst 150.5 m). TedriS is above the baseline on cars 1, 2, 4, 6, 7
    // and below on 3, 5, 8, 9.
    //
    // All of the above with every simulated tone ring started at an edge.
    // Since each ring starts at its own phase, cars 1–3 read TedriS 6.31 m
    // (worst 32.80 m: car 1's [200, 280), where the block baseline has
    // 5.94 m; cars 12.89, 2.98 and 3.05 m) against the block baseline's
    // 7.41 m (worst 24.83 m); the held-out members hardly moved (101–108:
    // 4.04 m against 7.53 m, was 4.14 against 7.56; 109–116: 6.46 m
    // against 7.18 m, was 6.26 against 7.42).
    //
    // The bounds follow the dev cars' figures with each ring at its own
    // phase: before issue 35 they read 74.0 m. Tried and withdrawn (the
    // held-out cars 109–116 went from 6.46 to 10.74 m; docs/tedris.md):
    // keeping the kinds a significant speed term nests out of the
    // calibration's choice, and a rebuilt model keeping the heading per
    // metre, which read 3.53 m (worst 7.98 m) on cars 1–3 and 6.61 m on
    // cars 1–9.
    eprintln!("cars {cars:?}: tedris {t:.2} m, block baseline {b:.2} m, worst {worst:.2} m");
    //
    // Issue 28's third stop (a kind switch on a run needs a 10 % lower
    // held-back mean square, `tuning::KIND_SWITCH_MARGIN`): cars 1–3 3.84 m
    // (worst 7.96 m, car 1's [120, 200); car 1's [200, 280) 32.80 → 3.58 m),
    // cars 1–9 6.64 m (worst 45.68 m) against 7.72 m, lower on 6 of 9
    // (`TEDRIS_TICK_CARS=1,2,3,4,5,6,7,8,9 cargo test --workspace --profile
    // ci --test tick_family dev_members -- --nocapture`).
    if cars == [1, 2, 3] {
        assert!(t < 4.3, "TedriS mean {t} m (measured 3.84 m)");
        assert!(worst < 9.0, "TedriS worst {worst} m (measured 7.96 m)");
        assert!(b > 6.0, "block baseline {b} m (measured 7.41 m)");
    }
}

#[test]
#[ignore = "held-out members, about a minute on two cores; run once at the end"]
fn tick_family_held_out_members_80s_outages() {
    let (t, b, worst) = run_family(&(101..=108).collect::<Vec<_>>());
    eprintln!("held out: tedris {t:.2} m, block baseline {b:.2} m, worst {worst:.2} m");
    // Run at the end of the second stop (32 outages): TedriS 4.14 m mean
    // (worst 28.7 m) against the block baseline's 7.56 m (worst 41.1 m);
    // lower on 7 of 8 cars (higher on 107: 4.91 m against 4.38 m). At the
    // end of the first stop: 6.33 m (worst 43.0 m), lower on 4 of 8. Every
    // model accepted had a physical turn gain (trained 0.890–0.970,
    // checked per car in `run_car`, after the run too). With each tone
    // ring at its own start phase (after those runs, nothing else
    // changed): 4.04 m (worst 25.7 m) against 7.53 m (worst 40.4 m),
    // higher on 107 only (4.82 m against 4.60 m).
    assert!(t <= b, "TedriS {t} m against the block baseline's {b} m");
}

#[test]
#[ignore = "held-out members drawn for the second stop, about a minute on two cores; run once at the end"]
fn tick_family_new_held_out_members_80s_outages() {
    let (t, b, worst) = run_family(&(109..=116).collect::<Vec<_>>());
    eprintln!("new held out: tedris {t:.2} m, block baseline {b:.2} m, worst {worst:.2} m");
    // Run once, at the end of the second stop, nothing changed after (32
    // outages): TedriS 6.26 m mean (worst 34.0 m) against the block
    // baseline's 7.42 m (worst 33.3 m); lower on 6 of 8 cars (higher on
    // 113: 5.35 m against 4.64 m, and 116: 9.99 m against 7.96 m). With
    // each tone ring at its own start phase: 6.46 m (worst 33.9 m) against
    // 7.18 m (worst 33.1 m), higher on 113 (5.45 m against 4.68 m) and 116
    // (10.90 m against 7.83 m).
    assert!(t <= b, "TedriS {t} m against the block baseline's {b} m");
}

#[test]
#[ignore = "held-out members drawn for the third stop (issue 28), about two minutes on two cores; run once at the end"]
fn tick_family_third_held_out_members_80s_outages() {
    // Drawn before any change of the third stop (the losing outages of dev
    // cars 1, 2, 4, 6, 7), run once after its last change (64 outages):
    // TedriS 5.55 m (worst 41.05 m, car 117's [120, 200)) against the block
    // baseline's 8.44 m (worst 68.35 m), lower on 12 of 16 (higher on 117,
    // 120, 126, 131). Main's code before the stop, run once on the same set
    // for the rule written down before: 5.54 m (worst 41.05 m), lower on 11
    // of 16; kept (within 10 % of main's mean, worst within 1.5 times).
    let (t, b, worst) = run_family(&(117..=132).collect::<Vec<_>>());
    eprintln!("third held out: tedris {t:.2} m, block baseline {b:.2} m, worst {worst:.2} m");
    assert!(t <= b, "TedriS {t} m against the block baseline's {b} m");
}

/// A drive of a 48-tooth tick counter at 100 Hz (the issue's) in a
/// kinematic world with tooth errors, where the turn gain's truth is
/// exact: the rear wheels' true mean circumference over the nominal one;
/// and the model TedriS's defaults train on it. Made once per process for
/// the two tests that use it.
fn ticks_48_at_100_hz() -> &'static (DynamicCar, TedrisModel) {
    static CAR: std::sync::OnceLock<(DynamicCar, TedrisModel)> = std::sync::OnceLock::new();
    CAR.get_or_init(|| {
        let (car, drive) = simulate_ticks_48_at_100_hz();
        let (model, _) = train(&drive, TedrisConfig::default(), None).expect("trained");
        (car, model)
    })
}

fn simulate_ticks_48_at_100_hz() -> (DynamicCar, deadreckon_core::Drive) {
    let mut car = DynamicCar::draw_tick_counter(1);
    car.base.vehicle.ticks_per_rev = 48;
    car.wheel_rate_hz = 100.0;
    let drive = simulate(
        &car.drive(
            1001,
            900.0,
            &Effects::only("tooth_error").expect("an effect"),
        ),
        1001,
    )
    .expect("drive")
    .drive;
    (car, drive)
}

#[test]
fn quantised_ticks_attenuated_the_turn_gain_48_teeth_100_hz() {
    let (car, model) = ticks_48_at_100_hz();
    let v = &car.base.vehicle;
    let e = &car.base.errors;
    let truth = 0.5 * (e.circumference_rl_m + e.circumference_rr_m) / v.wheel_circumference_m;
    let f = model.chosen_fit();
    let alpha1 = f
        .global
        .coefficients
        .iter()
        .find(|c| c.name == "alpha1")
        .expect("alpha1")
        .estimate;
    let fitted = alpha1 * v.track_rear_m;
    let calibrated = accepted_gain(model, v.track_rear_m, "trained");
    let blocks = model.blocks.expect("quantised blocks");
    eprintln!(
        "truth {truth:.4}, fitted α1·track {fitted:.4} ({:?}), calibrated {calibrated:.4}; {}",
        model.chosen,
        blocks.describe(model.sample_period_s)
    );
    // Measured: truth 1.0040, fitted 1.0103 (the baseline kind chosen),
    // calibrated 1.0044; blocks of 228 samples (2.28 s, 1 % attenuation
    // before the errors-in-variables correction). Before issue 35: α1·track
    // 0.09 on the 48-tooth drives, 0.33–0.49 on the dev members
    // (block medians of whole ticks).
    assert!(
        (fitted / truth - 1.0).abs() < 0.05,
        "fitted {fitted} vs {truth}"
    );
    assert!(
        (calibrated / truth - 1.0).abs() < 0.05,
        "calibrated {calibrated} vs {truth}"
    );
    assert!(blocks.tau_samples > 50 && blocks.attenuation <= 0.0101);
}

#[test]
fn a_model_turning_a_tenth_of_the_wheels_turn_is_refused() {
    let (car, model) = ticks_48_at_100_hz();
    let track = car.base.vehicle.track_rear_m;
    // The model: α1 ten times too small, in every kind but the baseline.
    let mut m = model.clone();
    m.chosen = ModelKind::Distance;
    let scale = |m: &mut TedrisModel, keep: Option<ModelKind>| {
        for f in m.fits.iter_mut().filter(|f| Some(f.kind) != keep) {
            for c in f.global.coefficients.iter_mut() {
                if c.name == "alpha1" {
                    c.estimate *= 0.09;
                }
            }
        }
    };
    scale(&mut m, Some(ModelKind::Baseline));
    let acc = acceptance::check(&m, track, None);
    let d = acc.kind(ModelKind::Distance).unwrap();
    assert!(d.turn_gain.unwrap() < 0.1, "{d:?}");
    assert!(d.refused.as_deref().unwrap().contains("turn gain"), "{d:?}");
    acceptance::apply(&mut m, acc).expect("the baseline kind passes");
    assert_eq!(m.chosen, ModelKind::Baseline);
    assert_eq!(
        m.acceptance.as_ref().unwrap().fell_back_from,
        Some(ModelKind::Distance)
    );
    assert!(!m.kind_usable(ModelKind::Distance));
    // The baseline kind too: the model is refused, with what to do.
    let mut m = model.clone();
    m.chosen = ModelKind::Distance;
    scale(&mut m, None);
    let acc = acceptance::check(&m, track, None);
    let why = acceptance::apply(&mut m, acc).expect_err("refused");
    assert!(
        why.contains("distance model was refused: turn gain")
            && why.contains("baseline model")
            && why.contains("what to do"),
        "{why}"
    );
    // A cross-correlation peak far below what the turning should give
    // refuses every kind.
    let acc = acceptance::check(model, track, Some(10.0));
    assert!(acc.kinds.iter().all(|k| k
        .refused
        .as_deref()
        .is_some_and(|r| r.contains("cross-correlation peak"))));
}

/// The speed kind's turn gain, `(α1 + α3·d²)·track`, at a distance per
/// sample `d_m`.
fn speed_kind_gain(model: &TedrisModel, track_m: f64, d_m: f64) -> f64 {
    let f = model
        .fits
        .iter()
        .find(|f| f.kind == ModelKind::Speed)
        .expect("a speed kind fit");
    let c = |n: &str| {
        f.global
            .coefficients
            .iter()
            .find(|c| c.name == n)
            .expect("a coefficient")
            .estimate
    };
    (c("alpha1") + c("omega_speed") * d_m * d_m) * track_m
}

/// Tick car 9 (40 teeth at 50 Hz) lost 150 m in its [200, 280) outage, at
/// 9–11 m/s in long turns: the speed kind, chosen by the held-back
/// calibration on the test drive, turned at 0.55 of the wheels' turn there.
/// Its errors-in-variables fit took ω's noise off the ω·d² column's
/// variance but not off its covariance with the ω column (the same noise
/// times d²), and over-corrected the speed term: α1·track 1.085 at rest,
/// 0.553 at 11 m/s. The wheels' turn over the true yaw rate on that drive
/// is 1.00–1.05 at 1–6 m/s and 1.11–1.26 near 10 m/s (a gain of 0.79–0.90).
#[test]
fn the_speed_kind_over_corrected_the_turn_at_speed_tick_car_9() {
    let car = DynamicCar::draw_tick_counter(9);
    let track = car.base.vehicle.track_rear_m;
    let drive = simulate(&car.drive(1009, 900.0, &Effects::all()), 1009)
        .expect("train drive")
        .drive;
    let (model, _) = train(&drive, TedrisConfig::default(), None).expect("trained");
    let per_sample = |v_mps: f64| v_mps / car.wheel_rate_hz;
    let slow = speed_kind_gain(&model, track, per_sample(1.0));
    let fast = speed_kind_gain(&model, track, per_sample(11.11));
    eprintln!("speed kind's gain: {slow:.3} at 1 m/s, {fast:.3} at 11.1 m/s");
    // Measured: 0.973 at 1 m/s, 0.878 at 11.1 m/s (before: 1.085, 0.553).
    assert!((0.93..=1.01).contains(&slow), "{slow}");
    assert!((0.84..=0.92).contains(&fast), "{fast}");
}

/// The speed kind on a car without loaded tyres (the smooth-speed family's
/// car 1): its ω·d² term is noise (t = 0.08), and the held-back choice
/// picked such kinds by chance (the family's cars 101–112: 1.44 m with the
/// speed kind a candidate, 1.37 m without it). Refused, with why.
#[test]
fn the_speed_kind_without_loaded_tyres_is_refused() {
    let car = deadreckon_sim::family::CarFamily::draw(1);
    let drive = simulate(&car.drive(1001, 900.0), 1001)
        .expect("train drive")
        .drive;
    let (model, _) = train(&drive, TedrisConfig::default(), None).expect("trained");
    let r = model
        .refused_kinds
        .iter()
        .find(|r| r.kind == ModelKind::Speed)
        .expect("the speed kind refused");
    assert!(r.reason.contains("speed term"), "{}", r.reason);
    assert_ne!(model.chosen, ModelKind::Speed);
}

/// The truth's yaw at `t`, the nearest truth pose's.
fn truth_yaw(drive: &deadreckon_core::Drive, t: f64) -> Option<f64> {
    let i = drive.truth.partition_point(|p| p.t_s < t);
    drive.truth.get(i).map(|p| p.yaw_rad)
}

/// The wrapped difference `a − b`, rad.
fn wrap(a: f64) -> f64 {
    (a + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI) - std::f64::consts::PI
}

/// What TedriS did on a dev car's run drive, outage by outage: the trained
/// kind and convention, every change of the held kind (time, kind, turn
/// gain, heading per metre) before the outage, and the heading error at the
/// outage's start and end against the truth. A diagnosis, not a check:
/// `TEDRIS_TICK_CARS=1,2 cargo test --workspace --profile ci --test
/// tick_family diagnose -- --ignored --nocapture`.
#[test]
#[ignore = "a diagnosis of the dev cars' outages, printed"]
fn tick_family_diagnose_dev_outages() {
    use deadreckon_tedris::input::{drive_input, Event};
    use deadreckon_tedris::Tedris;
    let cars: Vec<u64> = std::env::var("TEDRIS_TICK_CARS").map_or(vec![1], |v| {
        v.split(',')
            .map(|c| c.trim().parse().expect("car seeds"))
            .collect()
    });
    assert!(
        cars.iter().all(|c| !(101..=132).contains(c)),
        "held-out cars"
    );
    for seed in cars {
        let car = DynamicCar::draw_tick_counter(seed);
        let effects = Effects::all();
        let train_drive = simulate(&car.drive(1000 + seed, 900.0, &effects), 1000 + seed)
            .expect("train drive")
            .drive;
        let test_drive = simulate(&car.drive(2000 + seed, 500.0, &effects), 2000 + seed)
            .expect("test drive")
            .drive;
        let (model, _) = train(&train_drive, TedrisConfig::default(), None).expect("trained");
        eprintln!(
            "car {seed}: trained {:?} gain {:.3} per metre {:.2e} convention {:?}",
            model.chosen, model.turn_gain, model.dcf_distance_rad_per_m, model.course_convention
        );
        for start_s in OUTAGE_STARTS_S {
            let end_s = start_s + 80.0;
            let input = drive_input(&test_drive, None, &[(start_s, end_s)]).expect("input");
            let mut m = Tedris::with_model(model.clone(), input.geometry).expect("machine");
            let mut last: Option<(ModelKind, Option<bool>)> = None;
            let mut changes = Vec::new();
            let (mut at_start, mut at_end) = (None, None);
            for e in &input.events {
                match e {
                    Event::Wheel(w) => {
                        let Ok(est) = m.push_wheel(*w) else { continue };
                        if let Some(h) = m.model() {
                            let now = (
                                h.chosen,
                                h.course_convention.map(|c| c.convention.is_antenna()),
                            );
                            if last != Some(now) && w.t_s < end_s {
                                changes.push(format!(
                                    "{:.0} s {:?} gain {:.3} /m {:.2e} antenna {:?}",
                                    w.t_s, h.chosen, h.turn_gain, h.dcf_distance_rad_per_m, now.1
                                ));
                                last = Some(now);
                            }
                        }
                        let err = truth_yaw(&test_drive, est.t_s).map(|y| wrap(est.yaw_rad - y));
                        if at_start.is_none() && est.t_s >= start_s {
                            at_start = err.map(|e| (e, m.model().map(|h| (h.chosen, h.turn_gain))));
                        }
                        if at_end.is_none() && est.t_s >= end_s - 0.05 {
                            at_end = err;
                        }
                    }
                    Event::Heading(h) => {
                        let _ = m.push_heading(*h);
                    }
                    Event::Fix(f) => {
                        let _ = m.push_fix(*f);
                    }
                }
            }
            eprintln!(
                "  [{start_s:.0}, {end_s:.0}): heading error at start {:?}, at end {:?}; kinds: {}",
                at_start,
                at_end,
                changes.join("; ")
            );
        }
    }
}

/// The kinds the machine held on `drive` with GNSS blanked in `outage`,
/// from `model`: (time, kind) at the start and at every change before the
/// outage's end.
fn held_kinds(
    model: &TedrisModel,
    drive: &deadreckon_core::Drive,
    outage: &Outage,
) -> Vec<(f64, ModelKind)> {
    use deadreckon_tedris::input::{drive_input, Event};
    let input = drive_input(drive, None, &[(outage.start_s, outage.end_s)]).expect("input");
    let mut m =
        deadreckon_tedris::Tedris::with_model(model.clone(), input.geometry).expect("machine");
    let mut kinds: Vec<(f64, ModelKind)> = Vec::new();
    for e in &input.events {
        match e {
            Event::Wheel(w) if w.t_s < outage.end_s => {
                let _ = m.push_wheel(*w);
                let k = m.model().expect("a model").chosen;
                if kinds.last().is_none_or(|l| l.1 != k) {
                    kinds.push((w.t_s, k));
                }
            }
            Event::Wheel(_) => break,
            Event::Heading(h) => {
                let _ = m.push_heading(*h);
            }
            Event::Fix(f) => {
                let _ = m.push_fix(*f);
            }
        }
    }
    kinds
}

/// Tick car 1 (dev): its [200, 280) outage, an 80 s straight after a fast
/// right turn, read 32.8 m against the block baseline's 5.9 m. On the run
/// drive the held kind changed five times before 280 s: each refit took the
/// block statistics' kind with the former kind's calibrated values (speed →
/// baseline at 63 s), and each calibration the kind with the smallest
/// held-back residual however small the difference (paper at 193 s, turn
/// gain 1.023, entering the outage 0.055 rad off after over-turning the
/// turn). On a machine started from a trained model a calibration now
/// leaves the incumbent kind only when the challenger's held-back mean
/// square is lower by more than `tuning::KIND_SWITCH_MARGIN`.
#[test]
fn the_run_drives_kind_flips_over_turned_car_1s_fast_turn_tick_car_1() {
    let seed = 1;
    let car = DynamicCar::draw_tick_counter(seed);
    let effects = Effects::all();
    let train_drive = simulate(&car.drive(1000 + seed, 900.0, &effects), 1000 + seed)
        .expect("train drive")
        .drive;
    let test_drive = simulate(&car.drive(2000 + seed, 500.0, &effects), 2000 + seed)
        .expect("test drive")
        .drive;
    let (model, _) = train(&train_drive, TedrisConfig::default(), None).expect("trained");
    let o = Outage {
        start_s: 200.0,
        end_s: 280.0,
    };
    let kinds = held_kinds(&model, &test_drive, &o);
    let run = run_outages(&test_drive, &model, &[o]).expect("run");
    let e = run.outages[0].mean_error_m();
    let base = Baseline::fit_blocks(&train_drive, 2.0)
        .expect("block baseline")
        .run_outage(&test_drive, &o)
        .expect("baseline run")
        .mean_error_m();
    eprintln!(
        "held kinds {kinds:?}; kind switches kept {}; outage {e:.2} m, block baseline {base:.2} m",
        run.machine.kept_kinds()
    );
    // Measured: held speed (trained), baseline at 63 s (a refit's), speed
    // again at 193 s (the calibration kept the trained kind where the paper
    // kind's held-back residual was lower by less than the margin); 6
    // calibrations kept the kind; outage 3.58 m against the block
    // baseline's 5.94 m. Before: speed, baseline at 63 s, paper at 193 s
    // (turn gain 1.023), 32.80 m.
    let at_start = kinds
        .iter()
        .rev()
        .find(|k| k.0 < o.start_s)
        .expect("a kind")
        .1;
    assert_eq!(at_start, model.chosen, "held kinds {kinds:?}");
    assert!(
        !kinds.iter().any(|k| k.1 == ModelKind::Paper),
        "held kinds {kinds:?}"
    );
    assert!(run.machine.kept_kinds() > 0);
    assert!(e < 5.0, "outage mean {e} m (32.8 m with the kind flips)");
}
