//! TedriS on the simulator's `tedris-car` and `tedris-robot` scenarios: train on
//! one seed, predict through outages on another seed's drive (seed + 100), print
//! the errors (`cargo test --release -p deadreckon-tedris --test sim_outages --
//! --nocapture`) and assert the targets:
//!
//! - car (the paper's figure 6b): the mean position error over 80 s outages is
//!   below 3 m averaged over seeds 1–6 (three outages each), and below 4 m for
//!   every seed;
//! - robot (figure 7b): the error stays under 0.159 m for at least 60 s in the
//!   majority of 90 s outages (seeds 1–6, eight outages each) and the median
//!   time is at least 60 s.
//!
//! The default configuration is asserted for the distance, paper and automatic
//! kinds; the paper's method alone ([`TedrisConfig::paper`]) is only printed and
//! loosely bounded (it does not reach the targets).
//!
//! The car drives are simulated once per process (the four car tests train
//! on the same ones) and the seeds run in parallel (rayon), printed in seed
//! order: the same figures (`CI=1 cargo test --workspace --profile ci --test
//! sim_outages`, back to back with other work running: 116 → 112 s wall, 65
//! → 60 s of CPU).

use std::sync::OnceLock;

use deadreckon_core::Drive;
use deadreckon_sim::{simulate, Scenario};
use deadreckon_tedris::{
    run_outages_with, train, ModelChoice, ModelKind, Outage, ReferenceSource, RunOptions,
    TedrisConfig,
};
use rayon::prelude::*;

const CAR_WINDOWS: [f64; 3] = [200.0, 350.0, 500.0];
const SEEDS: std::ops::RangeInclusive<u64> = 1..=6;

/// Seeds no choice was made on (issue 33), run once when their tests were
/// written.
const HELD_OUT: std::ops::RangeInclusive<u64> = 7..=12;

/// The `tedris-car` drives of seeds 1–12 (training `seed`, run `seed +
/// 100`), simulated once per process: the four car tests train on the same
/// drives with different configurations.
fn car_drives(seed: u64) -> &'static (Drive, Drive) {
    static DRIVES: [OnceLock<(Drive, Drive)>; 12] = [const { OnceLock::new() }; 12];
    let slot = usize::try_from(seed - 1).expect("a seed from 1");
    DRIVES[slot].get_or_init(|| {
        let sc = Scenario::builtin("tedris-car").unwrap();
        (
            simulate(&sc, seed).unwrap().drive,
            simulate(&sc, seed + 100).unwrap().drive,
        )
    })
}

/// Per seed, the mean of the mean errors of its 80 s outages.
fn car_seed_means(cfg: &TedrisConfig, name: &str) -> Vec<f64> {
    car_seed_means_over(cfg, name, SEEDS)
}

/// [`car_seed_means`] over `seeds`.
fn car_seed_means_over(
    cfg: &TedrisConfig,
    name: &str,
    seeds: std::ops::RangeInclusive<u64>,
) -> Vec<f64> {
    // The seeds in parallel (rayon), printed in seed order.
    let seed_lines: Vec<(String, f64)> = seeds
        .clone()
        .into_par_iter()
        .map(|seed| car_seed_mean(cfg, name, seed))
        .collect();
    let mut means = Vec::new();
    for (line, m) in seed_lines {
        eprintln!("{line}");
        means.push(m);
    }
    let all = means.iter().sum::<f64>() / means.len() as f64;
    eprintln!(
        "car {name}: mean error over 80 s outages {all:.2} m (seeds {seeds:?}, per seed {:?})",
        means
            .iter()
            .map(|v| (v * 100.0).round() / 100.0)
            .collect::<Vec<_>>()
    );
    means
}

/// Seed `seed`'s line and mean error: trained with `cfg`, run through the
/// 80 s outages of [`CAR_WINDOWS`].
fn car_seed_mean(cfg: &TedrisConfig, name: &str, seed: u64) -> (String, f64) {
    let (train_drive, run_drive) = car_drives(seed);
    let (model, _) = train(train_drive, cfg.clone(), None).unwrap();
    let mut line = format!(
        "car {name} seed {seed} (chosen {:?}, lag {}):",
        model.chosen, model.lag_samples
    );
    let mut sum = 0.0;
    for start in CAR_WINDOWS {
        let o = Outage {
            start_s: start,
            end_s: start + 80.0,
        };
        let r = run_outages_with(run_drive, &model, &[o], &RunOptions::default()).unwrap();
        let e = &r.outages[0];
        assert_eq!(r.reference.name(), "truth");
        assert!(
            e.predicted_fraction > 0.95,
            "the machine must predict through the outage"
        );
        line += &format!(
            " [{start:.0},{:.0}) mean {:.2} max {:.2} m;",
            start + 80.0,
            e.mean_error_m(),
            e.max_error_m()
        );
        sum += e.mean_error_m();
    }
    let m = sum / CAR_WINDOWS.len() as f64;
    (format!("{line} seed mean {m:.2} m"), m)
}

/// The targets (3 m over the seeds, 4 m per seed), and bounds near
/// what was measured: `mean` over the seeds, `worst` per seed.
fn assert_car_target(means: &[f64], mean: f64, worst: f64) {
    let all = means.iter().sum::<f64>() / means.len() as f64;
    assert!(means.len() >= 4);
    assert!(all < 3.0, "mean over seeds {all} m, target < 3 m");
    assert!(
        means.iter().all(|m| *m < 4.0),
        "a seed's mean error reaches 4 m: {means:?}"
    );
    assert!(
        all < mean,
        "mean over seeds {all} m, measured bound {mean} m"
    );
    assert!(
        means.iter().all(|m| *m < worst),
        "a seed's mean error reaches {worst} m: {means:?}"
    );
}

fn with_kind(kind: ModelKind) -> TedrisConfig {
    TedrisConfig {
        model: ModelChoice::Fixed(kind),
        ..TedrisConfig::default()
    }
}

#[test]
fn car_80s_outages_distance_model() {
    // The paper's target (figure 6b). Measured 0.97 m over the seeds, 0.41–1.61 m per seed.
    assert_car_target(
        &car_seed_means(&with_kind(ModelKind::Distance), "distance"),
        1.25,
        2.0,
    );
}

#[test]
fn car_80s_outages_paper_model() {
    // The paper's regression with the default calibration; measured 0.96 m (0.47–1.66).
    assert_car_target(
        &car_seed_means(&with_kind(ModelKind::Paper), "paper"),
        1.25,
        2.1,
    );
}

#[test]
fn car_80s_outages_automatic_choice() {
    // Measured 0.94 m, 0.52–1.66 m per seed.
    assert_car_target(&car_seed_means(&TedrisConfig::default(), "auto"), 1.25, 2.1);
}

#[test]
fn car_80s_outages_automatic_choice_held_out_seeds() {
    // Seeds 7–12 (HELD_OUT). Measured 0.91 m over the seeds, 0.42–1.73 m
    // per seed (the development seeds: 0.94 m, 0.52–1.66 m).
    let means = car_seed_means_over(&TedrisConfig::default(), "auto, held out", HELD_OUT);
    assert_car_target(&means, 1.15, 2.2);
}

#[test]
fn car_80s_outages_paper_method_alone() {
    // The paper's method without this crate's additions (it does not reach the
    // target). Measured 5.58 m over the seeds, 2.77–10.15 m per seed; bounds:
    // measured + 25% (7 m) and the worst seed + 30% (13 m).
    let means = car_seed_means(&TedrisConfig::paper(), "paper method alone");
    let all = means.iter().sum::<f64>() / means.len() as f64;
    assert!(all.is_finite() && all < 7.0, "{all}");
    assert!(means.iter().all(|m| *m < 13.0), "{means:?}");
}

#[test]
fn robot_time_under_0_159_m() {
    let (over60, n, median) = robot_times(SEEDS);
    // Measured: 42/48 at least 60 s (39/48 before issue 35), median 90 s.
    // The paper's target is a majority; the bound is near the measured.
    assert!(over60 >= 38, "{over60}/{n}");
    assert!(median >= 60.0, "{median}");
}

#[test]
fn robot_time_under_0_159_m_held_out_seeds() {
    let (over60, n, median) = robot_times(HELD_OUT);
    // Seeds 7–12 (HELD_OUT). Measured: 25/48 outages at least 60 s (the
    // development seeds: 42/48), median 71 s, shortest 14 s: the paper's
    // majority, by one outage. The robot holds less well out of sample.
    assert!(2 * over60 > n, "{over60}/{n}");
    assert!(median >= 65.0, "{median}");
}

/// Over `seeds`' robot drives: how many 90 s outages stay under 0.159 m for
/// at least 60 s, of how many, and the median time under it.
fn robot_times(seeds: std::ops::RangeInclusive<u64>) -> (usize, usize, f64) {
    let sc = Scenario::builtin("tedris-robot").unwrap();
    // The seeds in parallel (rayon), printed and gathered in seed order.
    let seed_times: Vec<(String, Vec<f64>)> = seeds
        .into_par_iter()
        .map(|seed| robot_seed_times(&sc, seed))
        .collect();
    let mut times = Vec::new();
    for (line, t) in seed_times {
        eprintln!("{line}");
        times.extend(t);
    }
    let mut sorted = times.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    let over60 = times.iter().filter(|t| **t >= 60.0).count();
    eprintln!(
        "robot: median time under 0.159 m {median:.0} s; {over60}/{} outages at least 60 s; shortest {:.0} s",
        times.len(),
        sorted[0]
    );
    (over60, times.len(), median)
}

/// Robot seed `seed`'s line and times under 0.159 m through its eight 90 s
/// outages.
fn robot_seed_times(sc: &Scenario, seed: u64) -> (String, Vec<f64>) {
    let mut times = Vec::new();
    let train_drive = simulate(sc, seed).unwrap().drive;
    let run_drive = simulate(sc, seed + 100).unwrap().drive;
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
    for start in [30.0, 60.0, 90.0, 120.0, 150.0, 180.0, 210.0, 240.0] {
        let o = Outage {
            start_s: start,
            end_s: start + 90.0,
        };
        let r = run_outages_with(&run_drive, &model, &[o], &opts).unwrap();
        assert_eq!(r.reference.name(), "truth aligned at outage start");
        let e = &r.outages[0];
        let t = e.time_to_threshold_s().unwrap_or(90.0);
        line += &format!(" [{start:.0}: {t:.0} s, mean {:.3} m]", e.mean_error_m());
        times.push(t);
    }
    (line, times)
}
