//! Filter consistency (issue 13): the NEES of pose and motion through
//! dead-reckoning windows of the demo's evaluation drive, against the χ²
//! bounds of the average over the windows.
//!
//! Print the figures: `cargo test --profile ci -p deadreckon-sim --test
//! consistency -- --nocapture`.

use deadreckon_core::consistency::{nees_through_windows, windows, Consistency, Verdict};
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::vehicle::Noise;
use deadreckon_sim::{simulate, Scenario};

/// The demo's evaluation drive (`deadreckon demo` simulates it with seed 2),
/// truth-calibrated, 30 s outages every 60 s.
fn nees(noise: Noise) -> Consistency {
    nees_seeds(noise, &[2])
}

/// Windows of several seeds of the evaluation drive, averaged together.
fn nees_seeds(noise: Noise, seeds: &[u64]) -> Consistency {
    let mut all: Option<Consistency> = None;
    for &seed in seeds {
        let mut sim = simulate(&Scenario::builtin("evaluation").unwrap(), seed).unwrap();
        sim.drive.vehicle.noise = noise;
        let w = windows(&sim.drive, 30.0, 60.0, 60.0);
        let c = nees_through_windows(&sim.drive, &sim.truth_params, &w, &FilterOptions::default())
            .unwrap();
        all = Some(match all {
            None => c,
            Some(a) => a.merged(&c).unwrap(),
        });
    }
    all.unwrap()
}

fn print(label: &str, c: &Consistency) {
    for b in [&c.pose, &c.motion] {
        let pts: Vec<String> = b
            .points
            .iter()
            .map(|p| {
                format!(
                    "{:.2}@{:.2} [{:.2},{:.2}]",
                    p.nees, p.fraction, p.lower, p.upper
                )
            })
            .collect();
        println!(
            "{label:<28} {} (n={}): {} -> {}",
            b.name,
            b.dof,
            pts.join(" "),
            b.verdict()
        );
    }
}

const SEEDS: [u64; 5] = [2, 3, 4, 5, 6];

fn factor(v: Verdict) -> f64 {
    match v {
        Verdict::Consistent => 1.0,
        Verdict::OverConfident(k) => k,
        Verdict::UnderConfident(k) => -k,
    }
}

#[test]
fn with_the_papers_noise_the_pose_is_over_confident_and_the_motion_consistent() {
    let c = nees_seeds(Noise::default(), &SEEDS);
    print("defaults, seeds 2-6", &c);
    print("defaults, seed 2 (the demo's)", &nees(Noise::default()));
    // 45 windows of 30 s. Measured: pose ε̄ 4.28, 4.12, 3.75, 4.13 at a
    // quarter, half, three quarters and the end (bounds 2.36..3.72 for n = 3),
    // over-confident by ×1.4; motion ε̄ 2.09–2.14 (bounds 1.48..2.59).
    assert_eq!(c.pose.points.len(), 4);
    assert!(c.pose.points.iter().all(|p| p.windows >= 40));
    let k = factor(c.pose.verdict());
    assert!((1.25..1.6).contains(&k), "pose {}", c.pose.verdict());
    assert_eq!(c.motion.verdict(), Verdict::Consistent);
}

#[test]
fn three_times_the_papers_position_process_noise_makes_the_pose_consistent() {
    // process_xy_m 0.003 instead of table I's 0.001: pose ε̄ 3.25, 2.89,
    // 2.74, 3.24 (bounds 2.36..3.72); 0.01 is under-confident by ×4.4. Not
    // the default: on the real comma2k19 segment it takes the 20 s outage
    // error from 0.722 to 0.757 m (see the report of issue 13).
    let n = Noise {
        process_xy_m: 3e-3,
        ..Noise::default()
    };
    let c = nees_seeds(n, &SEEDS);
    print("process_xy_m 0.003, seeds 2-6", &c);
    assert_eq!(c.pose.verdict(), Verdict::Consistent);
    assert_eq!(c.motion.verdict(), Verdict::Consistent);
    let n = Noise {
        process_xy_m: 1e-2,
        process_yaw_rad: 1e-4,
        ..Noise::default()
    };
    let c = nees_seeds(n, &SEEDS);
    assert!(factor(c.pose.verdict()) < -3.0, "{}", c.pose.verdict());
}
