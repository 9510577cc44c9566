//! The receiver's error model in the four-wheel car filter (issue 28):
//! the wander carried as states ([`deadreckon_core::gnss_error`]) and the
//! multipath bursts rejected, measured on the dynamic family.
//!
//! Protocol of the ablation (`dynamics_ablation.rs`): per dynamic car a
//! calibration drive (RTS, default options) and a separate evaluation drive
//! with the same effects; 30 s outages every 10 s after 5 s of warm-up on
//! the evaluation drive, against the truth; the mean final error per car,
//! averaged over the cars. Cars 1–6 are the development set, 101–110 held
//! out (the ignored test; nothing was chosen on them).
//!
//! ```text
//! cargo test --profile ci -p deadreckon-sim --test gnss_wander -- --nocapture
//! cargo test --profile ci -p deadreckon-sim --test gnss_wander -- --ignored --nocapture
//! ```

use rayon::prelude::*;

use deadreckon_core::calibrate::{calibrate, CalibrationOptions};
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::filter::{GateCounts, SensorKind};
use deadreckon_core::outage::evaluate;
use deadreckon_core::wander_fit::fit;
use deadreckon_sim::family::{DynamicCar, Effects};
use deadreckon_sim::simulate;

/// The receiver model of the evaluation's aided filter.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Model {
    /// White fixes (today's filter).
    White,
    /// The wander as states with this σ (m) and τ (s).
    Fixed(f64, f64),
    /// The wander the car's receiver was drawn with (an oracle, for reference).
    Drawn,
    /// The model most likely on the evaluation drive's own fixes
    /// ([`deadreckon_core::wander_fit`]).
    Fitted,
}

/// One car's result: mean final error, m, windows, and the GNSS gate counts.
#[derive(Debug, Clone)]
struct CarResult {
    mean_m: f64,
    windows: usize,
    gates: GateCounts,
}

/// One car's result, or why there is none (a calibration refused).
type Measured = Result<CarResult, String>;

/// The aided filter's receiver model and `gnss_recovery_after_s`, s.
type Setup = (Model, f64);

fn measure(car: &DynamicCar, effects: &Effects, setup: Setup, drive_s: f64) -> Measured {
    let (model, recovery_after_s) = setup;
    let seed = car.base.seed;
    let cal = simulate(&car.drive(1000 + seed, drive_s, effects), 1000 + seed).unwrap();
    let mut ev = simulate(&car.drive(2000 + seed, drive_s, effects), 2000 + seed).unwrap();
    let c = calibrate(&cal.drive, &CalibrationOptions::default())
        .map_err(|e| format!("calibration: {e}"))?;
    let wander = match model {
        Model::White => None,
        Model::Fixed(s, tau) => Some((s, tau)),
        Model::Drawn => Some(car.base.gnss_markov).filter(|w| effects.wander && w.0 > 0.0),
        Model::Fitted => fit(&ev.drive, &c.estimate.params, &FilterOptions::default())
            .unwrap()
            .best
            .map(|w| (w.std_m, w.tau_s)),
    };
    if model == Model::Fitted {
        println!(
            "car {seed}: fitted {wander:?}, drawn {:?} (wander {})",
            car.base.gnss_markov, effects.wander
        );
    }
    ev.drive.vehicle.noise.gnss_recovery_after_s = recovery_after_s;
    if let Some((s, tau)) = wander {
        ev.drive.vehicle.noise.gnss_wander_std_m = s;
        ev.drive.vehicle.noise.gnss_wander_tau_s = tau;
    }
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
    Ok(CarResult {
        mean_m: f.mean,
        windows: f.n,
        gates: out.gates,
    })
}

/// Every (car, model) pair, the cars in parallel (rayon); `rows[model][car]`.
fn table(cars: &[u64], effects: &Effects, models: &[Setup], drive_s: f64) -> Vec<Vec<Measured>> {
    let drawn: Vec<DynamicCar> = cars.iter().map(|&s| DynamicCar::draw(s)).collect();
    models
        .iter()
        .map(|&model| {
            drawn
                .par_iter()
                .map(|car| measure(car, effects, model, drive_s))
                .collect()
        })
        .collect()
}

/// The mean over the cars with a result.
fn mean(row: &[Measured]) -> f64 {
    let ok: Vec<f64> = row.iter().flatten().map(|r| r.mean_m).collect();
    ok.iter().sum::<f64>() / ok.len() as f64
}

fn name(setup: &Setup) -> String {
    let m = match setup.0 {
        Model::White => "white fixes".into(),
        Model::Fixed(s, t) => format!("wander {s} m, {t} s"),
        Model::Drawn => "wander as drawn".into(),
        Model::Fitted => "wander fitted".into(),
    };
    format!("{m}, recovery after {} s", setup.1)
}

fn print(title: &str, cars: &[u64], models: &[Setup], rows: &[Vec<Measured>]) {
    println!("\n{title}: mean final error of 30 s outages (step 10 s), m");
    for (m, row) in models.iter().zip(rows) {
        print!("{:<40} {:>7.3}", name(m), mean(row));
        for (c, r) in cars.iter().zip(row) {
            let Ok(r) = r else {
                print!("  car {c}: {r:?}");
                continue;
            };
            let g = &r.gates;
            print!(
                "  car {c}: {:.3} ({} w, gnss {}/{}/{})",
                r.mean_m,
                r.windows,
                g.accepted(SensorKind::Gnss),
                g.rejected(SensorKind::Gnss),
                g.recovered(SensorKind::Gnss)
            );
        }
        println!();
    }
}

/// The explorations' `gnss_recovery_after_s`: `RECOVERY_AFTER_S` in the
/// environment, 0 without.
fn recovery_after_s() -> f64 {
    std::env::var("RECOVERY_AFTER_S")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0.0)
}

const DEV: [u64; 6] = [1, 2, 3, 4, 5, 6];
const DRIVE_S: f64 = 300.0;

/// The GNSS recoveries counted over the cars' evaluations.
fn recoveries(row: &[Measured]) -> u64 {
    row.iter()
        .flatten()
        .map(|r| r.gates.recovered(SensorKind::Gnss))
        .sum()
}

/// Issue 28: on the family's multipath bursts (2–9 s, offsets of 1–4 m per
/// axis) the GNSS recovery — after 10 consecutive rejections, 1–2.5 s at
/// 4–10 Hz — fired inside bursts: the burst's fix was taken with the
/// position covariance widened and the filter followed the burst (car 1:
/// 0.368 m without multipath, 0.807 m with). Waiting for the rejections to
/// last 10 s (`gnss_recovery_after_s`, longer than any burst) removes the
/// cost.
#[test]
fn multipath_bursts_pulled_the_filter_through_gnss_recoveries() {
    let effects = Effects::only("multipath").unwrap();
    let setups = [(Model::White, 0.0), (Model::White, 10.0)];
    let rows = table(&DEV, &effects, &setups, DRIVE_S);
    print("multipath only, cars 1–6", &DEV, &setups, &rows);
    // Measured (cars 1–6, 300 s): 8 recoveries, mean 0.496 m; with 10 s
    // none and 0.400 m (every effect off: 0.405 m). With the gyro-bias
    // switch and the standstill's ψ̇ = 0 (issue 28): 0.478 and 0.380 m
    // (main with the switch alone: 0.479 and 0.380 m).
    assert!(recoveries(&rows[0]) >= 4, "{}", recoveries(&rows[0]));
    assert_eq!(recoveries(&rows[1]), 0);
    let (before, after) = (mean(&rows[0]), mean(&rows[1]));
    assert!((before - 0.478).abs() < 0.02, "{before}");
    assert!((after - 0.380).abs() < 0.02, "{after}");
}

/// The wander as states, fitted on the evaluation drive's own fixes, against
/// white fixes on the family's wandering receivers (0–1.5 m, 20–120 s).
#[test]
fn the_wander_states_cut_the_outage_error_of_a_wandering_receiver() {
    let effects = Effects::only("wander").unwrap();
    let setups = [(Model::White, 0.0), (Model::Fitted, 0.0)];
    let rows = table(&DEV, &effects, &setups, DRIVE_S);
    print("wander only, cars 1–6", &DEV, &setups, &rows);
    // Measured (cars 1–6, 300 s): white 2.143 m, fitted 1.655 m (every car
    // better; the drawn σ and τ gave 1.574 m). With the gyro-bias switch
    // on by default (this stop, `deadreckon_core::aided::switch`): before
    // it, white 1.995 m and fitted 1.669 m. On a wandering receiver taken
    // as white fixes the switch reads part of the wander as a bias that
    // differs and costs 7 %; with the wander carried it does not.
    let (white, fitted) = (mean(&rows[0]), mean(&rows[1]));
    assert!((white - 2.143).abs() < 0.05, "{white}");
    assert!((fitted - 1.655).abs() < 0.05, "{fitted}");
    for (w, f) in rows[0].iter().zip(&rows[1]) {
        let (w, f) = (w.as_ref().unwrap(), f.as_ref().unwrap());
        assert!(f.mean_m < w.mean_m, "{} vs {}", f.mean_m, w.mean_m);
    }
}

/// The fit on a white receiver chooses white fixes, and on a wandering one a
/// σ near the drawn one (truth parameters, the evaluation drives).
#[test]
fn the_fit_tells_a_white_receiver_from_a_wandering_one() {
    for seed in DEV {
        let car = DynamicCar::draw(seed);
        for wander in [false, true] {
            let effects = if wander {
                Effects::only("wander").unwrap()
            } else {
                Effects::none()
            };
            let ev = simulate(&car.drive(2000 + seed, DRIVE_S, &effects), 2000 + seed).unwrap();
            let best = fit(&ev.drive, &ev.truth_params, &FilterOptions::default())
                .unwrap()
                .best;
            let drawn = car.base.gnss_markov;
            println!("car {seed}, wander {wander}: fitted {best:?}, drawn {drawn:?}");
            if !wander {
                assert!(best.is_none(), "car {seed}: {best:?}");
            } else {
                let s = best.map_or(0.0, |w| w.std_m);
                assert!(
                    (s / drawn.0 - 1.0).abs() < 0.5,
                    "car {seed}: {s} vs {drawn:?}"
                );
            }
        }
    }
}

#[test]
#[ignore]
fn explore_models_on_the_development_cars() {
    let r = recovery_after_s();
    let models = vec![
        (Model::White, r),
        (Model::Fixed(1.0, 60.0), r),
        (Model::Drawn, r),
        (Model::Fitted, r),
    ];
    for (title, effects) in [
        ("wander only, cars 1–6", Effects::only("wander").unwrap()),
        (
            "multipath only, cars 1–6",
            Effects::only("multipath").unwrap(),
        ),
        ("all effects, cars 1–6", Effects::all()),
    ] {
        let rows = table(&DEV, &effects, &models, DRIVE_S);
        print(title, &DEV, &models, &rows);
    }
}

#[test]
#[ignore]
fn explore_models_on_the_held_out_cars() {
    let cars: Vec<u64> = (101..=110).collect();
    let r = recovery_after_s();
    let models = vec![(Model::White, r), (Model::Fitted, r)];
    for (title, effects) in [
        (
            "wander only, cars 101–110",
            Effects::only("wander").unwrap(),
        ),
        (
            "multipath only, cars 101–110",
            Effects::only("multipath").unwrap(),
        ),
        ("all effects, cars 101–110", Effects::all()),
    ] {
        let rows = table(&cars, &effects, &models, DRIVE_S);
        print(title, &cars, &models, &rows);
    }
}
