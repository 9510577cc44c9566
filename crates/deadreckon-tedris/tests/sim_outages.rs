//! TedriS on the simulator's `tedris-car` and `tedris-robot` scenarios: train on
//! one seed, predict through outages on another seed's drive, print the errors
//! (`cargo test -p deadreckon-tedris --test sim_outages -- --nocapture`) and bound them.
//!
//! The bounds are what this implementation reaches, not the paper's targets (car:
//! mean below 3 m; robot: under 0.159 m for at least 60 s): see the crate
//! documentation, section "Measured", for the numbers and the gap.

use deadreckon_sim::{simulate, Scenario};
use deadreckon_tedris::{
    run_outages_with, train, ModelChoice, ModelKind, Outage, ReferenceSource, RunOptions,
    TedrisConfig,
};

const CAR_WINDOWS: [f64; 3] = [200.0, 350.0, 500.0];

fn car_errors(kind: ModelChoice, seeds: std::ops::RangeInclusive<u64>) -> Vec<f64> {
    let sc = Scenario::builtin("tedris-car").unwrap();
    let mut all = Vec::new();
    for seed in seeds {
        let train_drive = simulate(&sc, seed).unwrap().drive;
        let run_drive = simulate(&sc, seed + 100).unwrap().drive;
        let cfg = TedrisConfig {
            model: kind,
            ..TedrisConfig::default()
        };
        let (model, _) = train(&train_drive, cfg, None).unwrap();
        let mut line = format!(
            "car {kind:?} seed {seed} (chosen {:?}, lag {}):",
            model.chosen, model.lag_samples
        );
        for start in CAR_WINDOWS {
            let o = Outage {
                start_s: start,
                end_s: start + 80.0,
            };
            let r = run_outages_with(&run_drive, &model, &[o], &RunOptions::default()).unwrap();
            let e = &r.outages[0];
            assert_eq!(r.reference, "truth");
            assert!(
                e.predicted_fraction > 0.95,
                "the machine must predict through the outage"
            );
            line += &format!(
                " [{start:.0},{:.0}) mean {:.2} max {:.2} m;",
                start + 80.0,
                e.mean_error_m,
                e.max_error_m
            );
            all.push(e.mean_error_m);
        }
        eprintln!("{line}");
    }
    all
}

fn summary(name: &str, e: &[f64]) -> (f64, f64) {
    let mean = e.iter().sum::<f64>() / e.len() as f64;
    let max = e.iter().copied().fold(0.0, f64::max);
    eprintln!(
        "car {name}: mean error over {} outages of 80 s = {mean:.2} m (largest {max:.2} m)",
        e.len()
    );
    (mean, max)
}

#[test]
fn car_80s_outages_distance_model() {
    let e = car_errors(ModelChoice::Fixed(ModelKind::Distance), 1..=6);
    let (mean, max) = summary("distance", &e);
    // Measured 3.40 m, largest 6.7 m (the paper: about 3 m in figure 6b, 4 m in 6c).
    assert!(mean < 4.0, "{mean}");
    assert!(max < 9.0, "{e:?}");
}

#[test]
fn car_80s_outages_paper_model() {
    let e = car_errors(ModelChoice::Fixed(ModelKind::Paper), 1..=6);
    let (mean, _) = summary("paper", &e);
    // Measured 4.31 m.
    assert!(mean < 5.5, "{mean}");
}

#[test]
fn car_80s_outages_automatic_choice() {
    let e = car_errors(ModelChoice::Auto, 1..=6);
    let (mean, _) = summary("auto", &e);
    // Measured 3.53 m.
    assert!(mean < 4.5, "{mean}");
}

#[test]
fn robot_time_under_0_159_m() {
    let sc = Scenario::builtin("tedris-robot").unwrap();
    let mut times = Vec::new();
    for seed in 1..=5u64 {
        let train_drive = simulate(&sc, seed).unwrap().drive;
        let run_drive = simulate(&sc, seed + 100).unwrap().drive;
        let (model, _) = train(
            &train_drive,
            TedrisConfig::robot(),
            Some(ReferenceSource::Gyro),
        )
        .unwrap();
        let opts = RunOptions {
            source: Some(ReferenceSource::Gyro),
            threshold_m: Some(0.159),
        };
        let mut line = format!("robot seed {seed} (chosen {:?}):", model.chosen);
        for start in [60.0, 120.0, 180.0, 240.0] {
            let o = Outage {
                start_s: start,
                end_s: start + 90.0,
            };
            let r = run_outages_with(&run_drive, &model, &[o], &opts).unwrap();
            assert_eq!(r.reference, "truth aligned at outage start");
            let e = &r.outages[0];
            let t = e.time_to_threshold_s.unwrap_or(90.0);
            line += &format!(
                " [{start:.0}: under 0.159 m for {t:.0} s, mean {:.3} m]",
                e.mean_error_m
            );
            times.push(t);
        }
        eprintln!("{line}");
    }
    let mut sorted = times.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    let over60 = times.iter().filter(|t| **t >= 60.0).count();
    eprintln!(
        "robot: median time under 0.159 m {median:.0} s; {over60}/{} outages at least 60 s",
        times.len()
    );
    assert!(median >= 30.0, "{times:?}");
    assert!(over60 >= times.len() / 3, "{times:?}");
}
