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
//! The first runs the development cars on short drives (under two minutes
//! on two cores); the second, ignored, the development and held-out cars on
//! longer drives.

use std::sync::Mutex;

use deadreckon_core::calibrate::{calibrate, CalibrationOptions};
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::outage::evaluate;
use deadreckon_sim::family::{DynamicCar, Effects};
use deadreckon_sim::simulate;

/// One car's result: the mean final error of its 30 s outages, m, and how
/// many windows; or why there is none.
type CarResult = Result<(f64, usize), String>;

/// Calibrates on one drive of `car` and evaluates on another, both with
/// `effects`, each at least `drive_s` long.
fn ablate(car: &DynamicCar, effects: &Effects, drive_s: f64) -> CarResult {
    let seed = car.base.seed;
    let cal = simulate(&car.drive(1000 + seed, drive_s, effects), 1000 + seed)
        .map_err(|e| format!("calibration drive: {e}"))?;
    let ev = simulate(&car.drive(2000 + seed, drive_s, effects), 2000 + seed)
        .map_err(|e| format!("evaluation drive: {e}"))?;
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

/// Every (car, effects) pair, on two threads.
fn table(cars: &[u64], configs: &[(String, Effects)], drive_s: f64) -> Vec<Vec<CarResult>> {
    let jobs: Vec<(usize, usize)> = (0..configs.len())
        .flat_map(|c| (0..cars.len()).map(move |k| (c, k)))
        .collect();
    let next = Mutex::new(0usize);
    let out = Mutex::new(vec![vec![Err(String::new()); cars.len()]; configs.len()]);
    let drawn: Vec<DynamicCar> = cars.iter().map(|&s| DynamicCar::draw(s)).collect();
    std::thread::scope(|scope| {
        for _ in 0..2 {
            scope.spawn(|| loop {
                let j = {
                    let mut n = next.lock().unwrap();
                    let j = *n;
                    *n += 1;
                    j
                };
                let Some(&(c, k)) = jobs.get(j) else { break };
                let r = ablate(&drawn[k], &configs[c].1, drive_s);
                out.lock().unwrap()[c][k] = r;
            });
        }
    });
    out.into_inner().unwrap()
}

/// The configurations: every effect off, each alone, every effect on.
fn configs() -> Vec<(String, Effects)> {
    let mut v = vec![("none".to_string(), Effects::none())];
    for name in Effects::NAMES {
        v.push((name.to_string(), Effects::only(name).expect("a name")));
    }
    v.push(("all".to_string(), Effects::all()));
    v
}

/// The mean over the cars that have a result.
fn mean_of(row: &[CarResult]) -> f64 {
    let ok: Vec<f64> = row
        .iter()
        .filter_map(|r| r.as_ref().ok())
        .map(|r| r.0)
        .collect();
    ok.iter().sum::<f64>() / ok.len() as f64
}

fn print_table(title: &str, cars: &[u64], configs: &[(String, Effects)], rows: &[Vec<CarResult>]) {
    println!("\n{title}: mean final error of 30 s outages (step 10 s), m");
    print!("{:<16} {:>7}", "effects", "mean");
    for c in cars {
        print!(" {:>7}", format!("car {c}"));
    }
    println!();
    let base = mean_of(&rows[0]);
    for ((name, _), row) in configs.iter().zip(rows) {
        let m = mean_of(row);
        print!("{name:<16} {m:>7.3}");
        for r in row {
            match r {
                Ok((e, _)) => print!(" {e:>7.3}"),
                Err(_) => print!(" {:>7}", "failed"),
            }
        }
        println!("   ×{:.2}", m / base);
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
    let t0 = std::time::Instant::now();
    let rows = table(&cars, &configs, 300.0);
    println!("took {:.1} s", t0.elapsed().as_secs_f64());
    print_table("development cars 1–6, 300 s drives", &cars, &configs, &rows);
}
