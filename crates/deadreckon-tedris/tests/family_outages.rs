//! TedriS on drives it was never tuned on: members of the simulator's
//! randomized car family (`deadreckon_sim::family`: geometry, tyres, wheel
//! noise kind, GNSS rate, wandering position error, course convention, random
//! or frozen or dropped courses at low speed, stops). For each car, the model
//! is trained on one drive and predicts through 80 s outages on another drive
//! of the same car, one right after a stop and one elsewhere; the plain
//! least-squares baseline (`deadreckon_tedris::baseline`), fitted on the same
//! training drive, runs through the same outages.
//!
//! The per-pair table: `cargo test --release -p deadreckon-tedris --test
//! family_outages -- --nocapture`.
//!
//! The drives and trained models of cars 1–12 and 201–212 are made once
//! per process and shared by the tests that use them (the family tests, car
//! 8's regression tests, `short_training_drives`' test drives, and the
//! module [`calibration_std`], which was a test binary of its own), and the
//! cars of a family run in parallel (rayon), printed in car order: the same
//! figures as one car after another, in less time. `CI=1 cargo test
//! --workspace --profile ci --test family_outages`, back to back on CI's 2
//! cores with other work running: this file alone 197 → 148 s wall (134 →
//! 130 s of CPU); with `calibration_std` merged, the two old binaries' 256 s
//! wall (220 s of CPU) → 192 s (167 s of CPU), peak memory 70 → 332 MB.

use std::fmt::Write as _;

use deadreckon_sim::family::CarFamily;
use deadreckon_sim::{simulate, SimOutput};
use deadreckon_tedris::baseline::Baseline;
use deadreckon_tedris::machine::CourseConvention;
use deadreckon_tedris::{run_outages, train, Outage, TedrisConfig, TedrisModel};
use rayon::prelude::*;

/// The drives and models the tests share (`family_outages/shared.rs`).
#[path = "family_outages/shared.rs"]
mod shared;
use shared::{
    first_car, shared_test_drive, shared_trained, with_test_drive, with_trained, Trained,
};

/// The joint calibration's standard errors on the same cars' training
/// drives (its own file: `family_outages/calibration_std.rs`).
#[path = "family_outages/calibration_std.rs"]
mod calibration_std;

/// One train→test pair's results.
#[derive(Debug, Clone)]
struct PairResult {
    alarms: u64,
    /// Refits accepted and refused by the guard over the test drive.
    refits: (u64, u64),
    outage: Outage,
    tedris_m: f64,
    tedris_max_m: f64,
    /// `None`: the paper's method could not train on the training drive.
    paper_m: Option<f64>,
    baseline_m: f64,
    after_stop: bool,
}

/// Outages of 80 s on a test drive: one starting 2 s after the end of each of
/// the first stops that leave room, one in the middle.
fn outages(stops: &[(f64, f64)], duration_s: f64) -> Vec<(Outage, bool)> {
    let mut v = Vec::new();
    for &(s, d) in stops {
        let start = s + d + 2.0;
        if start >= 120.0 && start + 85.0 < duration_s && v.len() < 2 {
            v.push((
                Outage {
                    start_s: start,
                    end_s: start + 80.0,
                },
                true,
            ));
        }
    }
    let mid = (0.5 * duration_s).max(120.0);
    if mid + 85.0 < duration_s && v.iter().all(|(o, _)| (o.start_s - mid).abs() > 40.0) {
        v.push((
            Outage {
                start_s: mid,
                end_s: mid + 80.0,
            },
            false,
        ));
    }
    v
}

/// The course convention found on the training drive, against the car's.
#[derive(Debug, Clone, Copy, PartialEq)]
enum ConventionCheck {
    Right,
    Wrong,
    Undecided,
}

/// One car's pairs, its convention check and what it reports (written to
/// `log`, printed by [`family`] in car order).
fn run_car(car_seed: u64, log: &mut String) -> (Vec<PairResult>, ConventionCheck) {
    with_trained(car_seed, |trained| {
        with_test_drive(car_seed, |test_out| {
            run_pairs(car_seed, trained, test_out, log)
        })
    })
}

fn run_pairs(
    car_seed: u64,
    trained: &Trained,
    test_out: &SimOutput,
    log: &mut String,
) -> (Vec<PairResult>, ConventionCheck) {
    let car = CarFamily::draw(car_seed);
    let (train_drive, model) = (&trained.drive, &trained.model);
    // The paper's method may fail to train (its cross-correlation peak
    // requirement): reported, not hidden.
    let paper = match train(train_drive, TedrisConfig::paper(), None) {
        Ok((m, _)) => Some(m),
        Err(e) => {
            let _ = writeln!(log, "  the paper's method did not train: {e}");
            None
        }
    };
    let base = Baseline::fit(train_drive).expect("baseline");
    let _ = writeln!(
        log,
        "  course convention found: {:?}",
        model
            .course_convention
            .map(|c| (c.convention, (c.rss_ratio * 1000.0).round() / 1000.0))
    );
    let body = car.course_convention == deadreckon_sim::CourseConvention::BodyYaw;
    let check = match model.course_convention {
        None => ConventionCheck::Undecided,
        Some(c) if (c.convention == CourseConvention::BodyYaw) == body => ConventionCheck::Right,
        Some(_) => ConventionCheck::Wrong,
    };
    let mut out = Vec::new();
    for (o, after_stop) in outages(&test_out.stats.stops, test_out.stats.duration_s) {
        let r = run_outages(&test_out.drive, model, &[o]).expect("run");
        let p = paper
            .as_ref()
            .map(|m| run_outages(&test_out.drive, m, &[o]).expect("paper run"));
        let b = base.run_outage(&test_out.drive, &o).expect("baseline run");
        out.push(PairResult {
            alarms: r.machine.model_alarms(),
            refits: (r.machine.accepted_refits(), r.machine.refused_refits()),
            outage: o,
            tedris_m: r.outages[0].mean_error_m(),
            tedris_max_m: r.outages[0].max_error_m(),
            paper_m: p.map(|p| p.outages[0].mean_error_m()),
            baseline_m: b.mean_error_m(),
            after_stop,
        });
    }
    (out, check)
}

/// What one set of twelve cars gave.
struct FamilyFigures {
    pairs: usize,
    /// TedriS's mean, worst outage, the paper's method and TedriS over the
    /// pairs the paper's method trained for, the baseline's mean.
    tedris_m: f64,
    worst_m: f64,
    paper_m: f64,
    tedris_on_paper_pairs_m: f64,
    baseline_m: f64,
    /// Course conventions right, wrong, undecided.
    conventions: (usize, usize, usize),
    alarms: u64,
}

/// Cars `first..first + 12`: train, run, print the per-pair table. The cars
/// run in parallel (rayon); their lines are printed and their pairs
/// gathered in car order, so the table and the figures are those of a run
/// one car after another.
fn family(first: u64) -> FamilyFigures {
    let cars: Vec<(String, (Vec<PairResult>, ConventionCheck))> = (first..first + 12)
        .into_par_iter()
        .map(|car| {
            let mut log = String::new();
            let results = run_car(car, &mut log);
            (log, results)
        })
        .collect();
    let mut all = Vec::new();
    let mut conventions = Vec::new();
    for (car, (log, (results, check))) in (first..first + 12).zip(cars) {
        let c = CarFamily::draw(car);
        eprintln!(
            "car {car}: track {:.2} m, lever {:.2} m, rear radii {:+.2} % apart, wheels {} Hz {}, GNSS {} Hz σ {:.1} m GM {:.1} m/{:.0} s latency {:.2} s, course {:?} below {:.1} m/s, {:?}",
            c.vehicle.track_rear_m,
            c.vehicle.gnss_lever_arm_m,
            100.0 * (c.errors.circumference_rr_m / c.errors.circumference_rl_m - 1.0),
            c.wheel_rate_hz,
            if c.wheel_noise_mps > 0.0 { format!("white {:.3} m/s", c.wheel_noise_mps) } else { format!("jitter {:.1} mm", 1e3 * c.edge_jitter_m) },
            c.gnss_rate_hz,
            c.gnss_std_m,
            c.gnss_markov.0,
            c.gnss_markov.1,
            c.gnss_latency_s,
            c.low_speed_course,
            c.min_course_speed_mps,
            c.course_convention,
        );
        eprint!("{log}");
        conventions.push(check);
        for r in results {
            eprintln!(
                "  [{:.0}, {:.0}) {}: tedris mean {:.2} m (max {:.2}), paper {} m, baseline {:.2} m",
                r.outage.start_s,
                r.outage.end_s,
                if r.after_stop { "after a stop" } else { "mid-drive   " },
                r.tedris_m,
                r.tedris_max_m,
                r.paper_m.map_or("not trained".into(), |p| format!("{p:.2}")),
                r.baseline_m
            );
            all.push(r);
        }
    }
    let mean = |f: fn(&PairResult) -> f64| all.iter().map(f).sum::<f64>() / all.len() as f64;
    let worst = all.iter().map(|r| r.tedris_m).fold(0.0, f64::max);
    // The paper's method over the pairs it trained on, and TedriS over the same.
    let paper_pairs: Vec<&PairResult> = all.iter().filter(|r| r.paper_m.is_some()).collect();
    let over_paper = |f: fn(&PairResult) -> f64| {
        paper_pairs.iter().map(|r| f(r)).sum::<f64>() / paper_pairs.len() as f64
    };
    let count = |c| conventions.iter().filter(|x| **x == c).count();
    let fig = FamilyFigures {
        pairs: all.len(),
        tedris_m: mean(|r| r.tedris_m),
        worst_m: worst,
        paper_m: over_paper(|r| r.paper_m.unwrap_or(f64::NAN)),
        tedris_on_paper_pairs_m: over_paper(|r| r.tedris_m),
        baseline_m: mean(|r| r.baseline_m),
        conventions: (
            count(ConventionCheck::Right),
            count(ConventionCheck::Wrong),
            count(ConventionCheck::Undecided),
        ),
        alarms: all.iter().map(|r| r.alarms).sum(),
    };
    let (accepted, refused) = all
        .iter()
        .fold((0, 0), |(a, r), p| (a + p.refits.0, r + p.refits.1));
    eprintln!(
        "{} pairs: tedris mean {:.2} m (worst {:.2}), paper {:.2} m over the {} pairs it trained for (tedris {:.2} m there), baseline {:.2} m (worst {:.2}); course convention {} right, {} wrong, {} undecided; watchdog alarms {}; refits {accepted} accepted, {refused} refused",
        fig.pairs,
        fig.tedris_m,
        fig.worst_m,
        fig.paper_m,
        paper_pairs.len(),
        fig.tedris_on_paper_pairs_m,
        fig.baseline_m,
        all.iter().map(|r| r.baseline_m).fold(0.0, f64::max),
        fig.conventions.0,
        fig.conventions.1,
        fig.conventions.2,
        fig.alarms,
    );
    fig
}

#[test]
fn family_train_test_80s_outages() {
    // TEDRIS_FAMILY_FIRST_CAR=101 runs cars 101–112 instead of 1–12 (held
    // out once, but choices in deadreckon-tedris were since compared on them:
    // no longer untouched; cars 201–212 are, below).
    let first = first_car();
    let f = family(first);
    assert!(f.pairs >= 20, "{} pairs", f.pairs);
    // Measured (cars 1–12, 26 pairs, reversing at 40 % of the stops):
    // TedriS 2.44 m mean, worst 5.80 m (2.41 m while the speed kind was a
    // candidate without a significant speed term, 2.44 m before it;
    // 2.46 m and 6.07 m before held courses were skipped and the run's
    // blocks numbered after the model's); the paper's method alone 34.9 m
    // over the 23 pairs it trained for (not on car 11: cross-correlation
    // peak 0.265); the baseline 6.00 m (worst 18.1 m). Cars 101–112 (29
    // pairs): 1.37 m, worst 2.94 m (1.43 m and 3.65 m before; 1.44 m while
    // the speed kind was a candidate without a significant speed term, issue 35); paper 20.4 m;
    // baseline 5.23 m. Before reversing was added to the family (24 and 28
    // pairs): 2.70 m (worst 8.61) and 1.92 m (worst 5.68) with the distance
    // scale, 3.17 m and 2.22 m without it. Before the heading segments, the
    // consistency check and the per-metre form: 82.3 m mean, worst 390 m.
    // The targets: mean under 3 m, no outage above 10 m.
    assert!(f.tedris_m < 2.7, "TedriS mean {} m", f.tedris_m);
    assert!(f.worst_m < 7.0, "TedriS worst outage {} m", f.worst_m);
    // The course convention: measured 9 right, 3 undecided (cars 101–112: 9
    // right, 3 undecided), none wrong.
    assert_eq!(f.conventions.1, 0);
    assert!(f.conventions.0 >= 8);
    // The watchdog is a noisy signal: measured 3 alarms on trained models over
    // the 26 test runs of cars 1–12 (0 over the 29 of cars 101–112). An alarm
    // only brings a calibration forward, which the held-back check guards, so
    // the errors above are the same with and without it.
    assert!(
        f.alarms <= 5,
        "{} watchdog alarms on trained models",
        f.alarms
    );
    assert!(
        f.tedris_m < 0.6 * f.baseline_m,
        "{} against {}",
        f.tedris_m,
        f.baseline_m
    );
    assert!(
        f.tedris_on_paper_pairs_m < 0.1 * f.paper_m,
        "TedriS {} m against the paper method's {} m",
        f.tedris_on_paper_pairs_m,
        f.paper_m
    );
}

/// Cars 201–212: drawn for issue 33 and run once when this test was
/// written, after issue 35's changes; no choice was made on them. Bounds
/// near their own figures.
#[test]
fn family_held_out_cars_201_to_212() {
    let f = family(201);
    // Measured: 29 pairs, TedriS 1.38 m mean (worst 5.19 m; 1.59 m while
    // the speed kind was a candidate without a significant speed term,
    // issue 35), the paper's method 25.50 m over the 29 pairs, the
    // baseline 5.05 m; course convention 7 right, 0 wrong, 5 undecided; no
    // watchdog alarm.
    assert!(f.pairs >= 27, "{} pairs", f.pairs);
    assert!(f.tedris_m < 1.7, "TedriS mean {} m", f.tedris_m);
    assert!(f.worst_m < 6.5, "TedriS worst outage {} m", f.worst_m);
    assert_eq!(f.conventions.1, 0);
    assert!(f.conventions.0 >= 6, "{:?}", f.conventions);
    assert!(f.alarms <= 2, "{}", f.alarms);
    assert!(
        f.tedris_m < 0.4 * f.baseline_m,
        "{} against {}",
        f.tedris_m,
        f.baseline_m
    );
}

/// The bug of issue 8: a receiver reporting random courses while the car
/// stands still made the unwrapped reference jump by whole turns at every
/// stop; the heading fits read the jumps as drift and the trained model
/// turned the car at −0.17 rad/s while parked.
#[test]
fn random_course_at_stops_does_not_turn_the_parked_car() {
    let mut car = CarFamily::draw(2);
    car.low_speed_course = deadreckon_sim::LowSpeedCourse::Random;
    car.min_course_speed_mps = 1.2;
    let train_drive = simulate(&car.drive(31, 900.0), 31).expect("train").drive;
    let test = simulate(&car.drive(32, 500.0), 32).expect("test");
    let (model, _) = train(&train_drive, TedrisConfig::default(), None).expect("trained");
    assert!(
        model.per_metre_straight,
        "a course reference uses the per-metre form"
    );
    // An outage over the first stop that leaves room: dead reckoning through it.
    let &(stop_t, stop_d) = test
        .stats
        .stops
        .iter()
        .find(|s| s.0 > 60.0 && s.0 + 70.0 < test.stats.duration_s && s.1 > 8.0)
        .expect("a stop");
    let o = Outage {
        start_s: stop_t - 5.0,
        end_s: stop_t + 75.0,
    };
    let r = run_outages(&test.drive, &model, &[o]).expect("run");
    let yaw_at = |t: f64| {
        r.track
            .points
            .iter()
            .find(|p| p.t_s >= t)
            .map(|p| p.yaw_rad)
            .expect("a point")
    };
    let parked = deadreckon_core::angle::wrap(yaw_at(stop_t + stop_d - 1.0) - yaw_at(stop_t + 1.0));
    assert!(parked.abs() < 1e-3, "the parked car turned by {parked} rad");
    let e = &r.outages[0];
    eprintln!(
        "parked turn {parked:.2e} rad; outage mean {:.2} m, max {:.2} m",
        e.mean_error_m(),
        e.max_error_m()
    );
    assert!(e.predicted_fraction > 0.95);
    // Measured 0.52 m mean (1.3 m before wheels at rest read 0 in the
    // simulator and before the distance scale).
    assert!(e.mean_error_m() < 1.0, "{e:?}");
}

/// The baseline's fit is what its model says: the gain is the inverse of the
/// effective rear track, the per-metre term the rear radius mismatch over the
/// track (right tyre larger: its wheel speed reads low, ω reads a right turn
/// on a straight, and the per-metre term turns it back left).
#[test]
fn baseline_fit_recovers_track_and_radius_mismatch() {
    let car = CarFamily::draw(4);
    let d = simulate(&car.drive(41, 600.0), 41).expect("drive").drive;
    let b = Baseline::fit(&d).expect("fit");
    let track = car.vehicle.track_rear_m;
    let nominal = car.vehicle.wheel_circumference_m;
    let e = &car.errors;
    // Wheel speeds report rotation × nominal circumference: distances scale by
    // true/nominal, so the measured ω and d are off by the tyres' errors.
    let scale = 0.5 * (e.circumference_rl_m + e.circumference_rr_m) / nominal;
    let mismatch = (e.circumference_rr_m - e.circumference_rl_m)
        / (0.5 * (e.circumference_rl_m + e.circumference_rr_m));
    eprintln!(
        "baseline gain {:.5} rad/m (1/(track·scale) {:.5}), per metre {:.2e} (mismatch/track {:.2e}), {} pairs",
        b.gain_rad_per_m,
        1.0 / (track * scale),
        b.per_metre_rad,
        mismatch / track,
        b.pairs
    );
    // Measured: gain 1.4 % low (0.6550 against 0.6642), per metre 2.40e-3
    // against 2.38e-3.
    assert!(
        (b.gain_rad_per_m * track * scale - 1.0).abs() < 0.02,
        "{b:?}"
    );
    assert!((b.per_metre_rad - mismatch / track).abs() < 1e-4, "{b:?}");
}

/// Training drives shorter than the default windows (about 190 s and 430 s of
/// drive against the 600 s calibration window and 1200 s history): TedriS
/// still trains on most cars and beats the baseline through an 80 s outage of
/// another drive; where it cannot train, it says which requirement failed.
#[test]
fn short_training_drives() {
    // Every (length, car) in parallel; the sums below run in car order.
    let runs: Vec<Result<(f64, f64), String>> = [150.0, 300.0]
        .into_iter()
        .flat_map(|len| (1..=12u64).map(move |car| (len, car)))
        .collect::<Vec<_>>()
        .into_par_iter()
        .map(|(len, car)| {
            let c = CarFamily::draw(car);
            let tr = simulate(&c.drive(1000 + car, len), 1000 + car).expect("train drive");
            let o = Outage {
                start_s: 300.0,
                end_s: 380.0,
            };
            let base = Baseline::fit(&tr.drive).expect("baseline");
            let (m, _) =
                train(&tr.drive, TedrisConfig::default(), None).map_err(|e| e.to_string())?;
            with_test_drive(car, |te| {
                Ok((
                    run_outages(&te.drive, &m, &[o]).expect("run").outages[0].mean_error_m(),
                    base.run_outage(&te.drive, &o)
                        .expect("baseline run")
                        .mean_error_m(),
                ))
            })
        })
        .collect();
    for (len, runs) in [150.0, 300.0].into_iter().zip(runs.chunks(12)) {
        let (mut t, mut b, mut n) = (0.0, 0.0, 0);
        let mut failures = Vec::new();
        for (car, run) in (1..=12u64).zip(runs) {
            match run {
                Ok((tedris, baseline)) => {
                    t += tedris;
                    b += baseline;
                    n += 1;
                }
                Err(e) => failures.push((car, e.clone())),
            }
        }
        let (t, b) = (t / n as f64, b / n as f64);
        eprintln!("training drives of {len} s of route: {n} trained, TedriS {t:.2} m, baseline {b:.2} m; not trained: {failures:?}");
        // Measured: 11 and 12 of 12 trained (car 11, 50 Hz white wheel noise,
        // on the shorter drive: cross-correlation peak 0.13 against
        // min_ccf_peak 0.3 and too little turning); TedriS 2.78 m and 2.64 m
        // (2.79 m and 2.78 m before issue 35's speed-term test), the
        // baseline 4.19 m and 5.11 m.
        assert!(n >= 11, "{failures:?}");
        assert!(t < 3.0 && t < 0.7 * b, "TedriS {t} m, baseline {b} m");
        for (_, e) in &failures {
            assert!(e.contains("needs"), "{e}");
        }
    }
}

/// The watchdog: a model that turns the car by 0.01 rad per metre on a
/// straight (the fault of issue 8: a straight-line rate run into its clamp)
/// is found off while GNSS is good, and the calibration it triggers replaces
/// the value before the outage.
#[test]
fn watchdog_finds_a_model_that_is_off_and_recalibrates() {
    let car = CarFamily::draw(7);
    let train_drive = simulate(&car.drive(71, 900.0), 71).expect("train").drive;
    let test = simulate(&car.drive(72, 500.0), 72).expect("test");
    let (good, _) = train(&train_drive, TedrisConfig::default(), None).expect("trained");
    let mut off = good.clone();
    off.dcf_distance_rad_per_m += 0.01;
    let o = Outage {
        start_s: 380.0,
        end_s: 460.0,
    };
    let rg = run_outages(&test.drive, &good, &[o]).expect("good run");
    let ro = run_outages(&test.drive, &off, &[o]).expect("off run");
    let per_m = ro.machine.model().expect("model").dcf_distance_rad_per_m;
    eprintln!(
        "watchdog: good model {} alarms, {:.2} m; off model {} alarms (last at {:?} s), per metre {:.2e} -> {:.2e} (trained {:.2e}), {:.2} m",
        rg.machine.model_alarms(),
        rg.outages[0].mean_error_m(),
        ro.machine.model_alarms(),
        ro.machine.last_model_alarm_s(),
        off.dcf_distance_rad_per_m,
        per_m,
        good.dcf_distance_rad_per_m,
        ro.outages[0].mean_error_m()
    );
    assert_eq!(rg.machine.model_alarms(), 0);
    assert!(ro.machine.model_alarms() >= 1);
    assert!(
        (per_m - good.dcf_distance_rad_per_m).abs() < 5e-4,
        "{per_m}"
    );
}

/// Family car `seed` with every tyre's true circumference times `factor`.
fn car_with_tyres_scaled(seed: u64, factor: f64) -> CarFamily {
    let mut car = CarFamily::draw(seed);
    let e = &mut car.errors;
    for c in [
        &mut e.circumference_fl_m,
        &mut e.circumference_fr_m,
        &mut e.circumference_rl_m,
        &mut e.circumference_rr_m,
    ] {
        *c *= factor;
    }
    car
}

/// The bug: TedriS took the rear wheels' reported distance as the distance
/// travelled, so a car whose tyres are larger than nominal fell short of
/// the truth in every outage (1 % is 8 m after 800 m). The distance scale
/// is now estimated from GNSS chords: on a car with every tyre 2 % larger
/// than nominal it is found within 0.3 %, and the outage error stays that of
/// a car with nominal tyres.
#[test]
fn tedris_position_ignored_the_tyres_distance_scale() {
    let car = car_with_tyres_scaled(3, 1.02);
    let nominal = car.vehicle.wheel_circumference_m;
    let e = &car.errors;
    let truth = 0.5 * (e.circumference_rl_m + e.circumference_rr_m) / nominal;
    let train_drive = simulate(&car.drive(51, 900.0), 51).expect("train").drive;
    let test = simulate(&car.drive(52, 500.0), 52).expect("test");
    let (model, _) = train(&train_drive, TedrisConfig::default(), None).expect("trained");
    let (paper, _) = train(&train_drive, TedrisConfig::paper(), None).expect("paper");
    eprintln!(
        "distance scale {:.4} (truth {truth:.4}); the paper variant keeps {:.4}",
        model.distance_scale.value, paper.distance_scale.value
    );
    // Measured: 1.0271 against 1.0268.
    assert!(
        (model.distance_scale.value / truth - 1.0).abs() < 0.003,
        "{:?} against {truth}",
        model.distance_scale
    );
    assert!(model.distance_scale.chords >= 12);
    assert_eq!(
        paper.distance_scale.estimated(),
        None,
        "the paper's method has no scale"
    );
    let o = Outage {
        start_s: 300.0,
        end_s: 380.0,
    };
    let r = run_outages(&test.drive, &model, &[o]).expect("run");
    let mut unscaled = model.clone();
    unscaled.distance_scale = Default::default();
    unscaled.config.max_distance_scale_error = 1e-9;
    let u = run_outages(&test.drive, &unscaled, &[o]).expect("run");
    eprintln!(
        "outage mean {:.2} m with the scale, {:.2} m without",
        r.outages[0].mean_error_m(),
        u.outages[0].mean_error_m()
    );
    // Measured: 0.60 m with, 8.02 m without.
    assert!(r.outages[0].mean_error_m() < 1.0, "{:?}", r.outages[0]);
    assert!(u.outages[0].mean_error_m() > 2.0 * r.outages[0].mean_error_m());
}

/// Tyres 8 % larger than nominal are beyond what `max_distance_scale_error`
/// (5 %) allows: the fit is refused, not clamped to the bound.
#[test]
fn a_distance_scale_beyond_its_bound_is_refused_not_clamped() {
    let car = car_with_tyres_scaled(3, 1.08);
    let d = simulate(&car.drive(53, 900.0), 53).expect("drive").drive;
    let (model, _) = train(&d, TedrisConfig::default(), None).expect("trained");
    let r = run_outages(&d, &model, &[]).expect("run");
    eprintln!(
        "scale {:?}, refused calibrations {}",
        model.distance_scale,
        r.machine.refused_calibrations()
    );
    assert_eq!(model.distance_scale.estimated(), None);
    assert_eq!(model.distance_scale.value, 1.0);
    assert!(r.machine.refused_calibrations() > 0);
}

/// Car 8 (its receiver holds its course below 1.4 m/s; shunts): the model
/// trained on its 900 s training drive, and its 500 s test drive.
/// Shared with the family test (car 8 is one of its cars).
fn car8() -> (&'static TedrisModel, &'static SimOutput) {
    (&shared_trained(8).model, shared_test_drive(8))
}

/// Found while adding reversing to the family: courses taken while the car
/// backed up (a receiver frozen on the last forward course, or the direction
/// of motion, π from the heading) were anchored as the heading; an outage
/// starting after a shunt then ran 80 m off (car 8). Courses while the rear
/// wheels roll backwards are now not used, and counted.
#[test]
fn courses_while_reversing_turned_the_anchored_heading() {
    let (model, test) = car8();
    let o = Outage {
        start_s: 316.0,
        end_s: 396.0,
    };
    // The outage follows a shunt: the car backed up just before it.
    let reversed = test.drive.truth.iter().any(|p| {
        p.t_s > o.start_s - 20.0 && p.t_s < o.start_s && p.speed_mps.unwrap_or(0.0) < -0.5
    });
    assert!(reversed, "the drive no longer backs up before the outage");
    let r = run_outages(&test.drive, model, &[o]).expect("run");
    let e = &r.outages[0];
    eprintln!(
        "courses while reversing: {}; outage mean {:.2} m, max {:.2} m",
        r.machine.reversing_courses(),
        e.mean_error_m(),
        e.max_error_m()
    );
    assert!(r.machine.reversing_courses() > 0);
    // Measured: 2.29 m (80.4 m when the reversing courses were anchored,
    // measured before wheels at rest read exactly 0 in the simulator).
    assert!(
        e.mean_error_m() < 3.0,
        "mean {:.2} m, max {:.2} m",
        e.mean_error_m(),
        e.max_error_m()
    );
}

/// Found by outages started every 20 s of the family's test drives (not only
/// after stops): car 8's receiver holds its last course below 1.4 m/s, and
/// the course it held after reversing pointed backwards while the car pulled
/// away above `min_course_speed_mps`. Each held course repeated the one
/// before, so it agreed with the wheels' small turn and passed the
/// consistency check; it started a heading segment 180° off and the anchored
/// heading jumped by 106° at the outage start (324 m mean error over 80 s).
/// A course identical to the one before is now skipped, and counted.
#[test]
fn a_course_held_since_reversing_turned_the_anchored_heading() {
    let (model, test) = car8();
    let o = Outage {
        start_s: 320.0,
        end_s: 400.0,
    };
    // The receiver held one course from reversing until the car passed 1.4 m/s.
    let held = test
        .drive
        .gnss
        .iter()
        .filter(|g| g.t_s > 307.5 && g.t_s < 319.0)
        .filter_map(|g| g.course_deg)
        .collect::<Vec<_>>();
    assert!(
        held.len() > 20 && held.iter().all(|c| *c == held[held.len() - 1]),
        "the drive no longer holds a course after reversing: {held:?}"
    );
    let r = run_outages(&test.drive, model, &[o]).expect("run");
    let e = &r.outages[0];
    let yaw0 = r
        .track
        .points
        .iter()
        .find(|p| p.t_s >= o.start_s)
        .expect("a point")
        .yaw_rad;
    let truth0 = test
        .drive
        .truth
        .iter()
        .find(|p| p.t_s >= o.start_s)
        .expect("truth")
        .yaw_rad;
    let off = deadreckon_core::angle::wrap(yaw0 - truth0);
    eprintln!(
        "repeated courses {}; heading at the outage start {:+.2}° off; outage mean {:.2} m, max {:.2} m",
        r.machine.checks().repeated_courses,
        off.to_degrees(),
        e.mean_error_m(),
        e.max_error_m()
    );
    // Measured: 135 repeated courses skipped, the heading 0.27° off at the
    // start, 5.35 m mean (the baseline 20.7 m; 324.5 m before).
    assert!(r.machine.checks().repeated_courses > 0);
    assert!(off.abs() < 2f64.to_radians(), "{off} rad");
    assert!(e.mean_error_m() < 7.0, "{e:?}");
}

/// Regression (of the fix above, before it shipped): every course equal to
/// the one before was skipped as held, also at speed, where a repeat is a
/// straight road in the course's resolution (NMEA gives 0.1° or 0.01°).
/// With car 8's test courses rounded to whole degrees, the repeats at speed
/// are kept: only those below `tuning::HELD_COURSE_MAX_SPEED_MPS` are
/// skipped, and the outage error stays near the unrounded one.
#[test]
fn a_quantised_course_on_a_fast_straight_was_skipped_as_held() {
    let (model, test) = car8();
    let o = Outage {
        start_s: 320.0,
        end_s: 400.0,
    };
    let mut rounded = test.drive.clone();
    for g in &mut rounded.gnss {
        g.course_deg = g.course_deg.map(f64::round);
    }
    // Repeats at speed that the rounding made.
    let mut fast_repeats = 0;
    for w in rounded.gnss.windows(2) {
        if w[1].speed_mps.is_some_and(|v| v > 5.0)
            && w[1].course_deg.is_some()
            && w[1].course_deg == w[0].course_deg
        {
            fast_repeats += 1;
        }
    }
    let raw = run_outages(&test.drive, model, &[o]).expect("run");
    let round = run_outages(&rounded, model, &[o]).expect("run rounded");
    let (n_raw, n_round) = (
        raw.machine.checks().repeated_courses,
        round.machine.checks().repeated_courses,
    );
    let (e_raw, e_round) = (
        raw.outages[0].mean_error_m(),
        round.outages[0].mean_error_m(),
    );
    eprintln!(
        "{fast_repeats} repeats above 5 m/s after rounding; skipped {n_raw} raw, {n_round} rounded; outage mean {e_raw:.2} m raw, {e_round:.2} m rounded"
    );
    assert!(fast_repeats > 200, "{fast_repeats}");
    assert!(
        n_round < n_raw + fast_repeats / 10,
        "{n_round} of {fast_repeats}"
    );
    assert!((e_round - e_raw).abs() < 1.0, "{e_raw} → {e_round}");
}

/// Regression: a machine started from a trained model numbered the new
/// drive's wheel samples from 0, so its blocks took sequence numbers the
/// training drive's blocks already had; a refit sorted the two drives'
/// blocks into one another, and the ARX kind's fit took blocks of different
/// drives for neighbours. The new drive's blocks now come after the model's.
#[test]
fn a_model_run_on_a_new_drive_numbered_its_blocks_among_the_training_drives() {
    let (model, test) = car8();
    let trained: Vec<u64> = model
        .repositories
        .all_sorted()
        .iter()
        .map(|t| t.seq)
        .collect();
    let last_trained = *trained.last().expect("trained blocks");
    let o = Outage {
        start_s: 320.0,
        end_s: 400.0,
    };
    let r = run_outages(&test.drive, model, &[o]).expect("run");
    let after = r
        .machine
        .model()
        .expect("a model")
        .repositories
        .all_sorted();
    let new: Vec<u64> = after
        .iter()
        .map(|t| t.seq)
        .filter(|s| !trained.contains(s))
        .collect();
    // Measured: 3000 trained blocks (last 25601), 1755 new from 25956
    // (numbered from 0: 1559 new from 346, some on training numbers).
    eprintln!(
        "{} trained blocks (last seq {last_trained}), {} new (first seq {:?})",
        trained.len(),
        new.len(),
        new.first()
    );
    assert!(new.len() > 50, "the run added {} blocks", new.len());
    assert!(
        after.iter().filter(|t| trained.contains(&t.seq)).all(|t| {
            model
                .repositories
                .all_sorted()
                .iter()
                .any(|m| m.seq == t.seq && m.omega_m == t.omega_m)
        }),
        "a new block took the sequence number of a training block"
    );
    assert!(new.iter().all(|&s| s > last_trained), "{new:?}");
}
