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
fn with_table_ones_yaw_noise_the_pose_was_over_confident() {
    // The paper's α_ψ = 1e-5 (the default until vehicle::PROCESS_YAW_RAD):
    // the yaw errors of turns are larger than the yaw covariance.
    let n = Noise {
        process_yaw_rad: 1e-5,
        ..Noise::default()
    };
    let c = nees_seeds(n, &SEEDS);
    print("table I's yaw noise, seeds 2-6", &c);
    // Measured: pose ε̄ 4.28, 4.12, 3.75, 4.13 (bounds 2.36..3.72),
    // over-confident by ×1.4; motion consistent.
    assert_eq!(c.pose.points.len(), 4);
    assert!(c.pose.points.iter().all(|p| p.windows >= 40));
    let k = factor(c.pose.verdict());
    assert!((1.25..1.6).contains(&k), "pose {}", c.pose.verdict());
    assert_eq!(c.motion.verdict(), Verdict::Consistent);
}

#[test]
fn the_default_noise_is_consistent_on_the_evaluation_drives() {
    let c = nees_seeds(Noise::default(), &SEEDS);
    print("defaults, seeds 2-6", &c);
    let demo = nees(Noise::default());
    print("defaults, seed 2 (the demo's)", &demo);
    // Measured: seeds 2-6 pose ε̄ 3.36, 3.42, 2.96, 3.00 (bounds
    // 2.36..3.72), motion 2.09–2.14 (1.48..2.59); seed 2 pose 4.67, 2.96,
    // 3.11, 3.47 (1.68..4.70: its first point is close to the bound). Out of
    // these seeds, 7–11 read over-confident ×1.5 at a quarter of the window
    // (vehicle::PROCESS_YAW_RAD).
    assert_eq!(c.pose.verdict(), Verdict::Consistent);
    assert_eq!(c.motion.verdict(), Verdict::Consistent);
    // The demo's own windows (what its report's filter health reads).
    assert_eq!(demo.pose.verdict(), Verdict::Consistent);
    assert_eq!(demo.motion.verdict(), Verdict::Consistent);
    // Ten times the position process noise: under-confident (the test
    // tells both ways).
    let n = Noise {
        process_xy_m: 1e-2,
        ..Noise::default()
    };
    let c = nees_seeds(n, &SEEDS);
    assert!(factor(c.pose.verdict()) < -2.0, "{}", c.pose.verdict());
}

/// `vehicle::PROCESS_YAW_RAD` was chosen on evaluation seeds 3–6; seeds
/// 20–29 saw no choice (issue 33), run once when this test was written.
#[test]
fn the_default_noise_on_held_out_evaluation_seeds() {
    let seeds: Vec<u64> = (20..=29).collect();
    let c = nees_seeds(Noise::default(), &seeds);
    print("defaults, held-out seeds 20-29", &c);
    let t1 = nees_seeds(
        Noise {
            process_yaw_rad: 1e-5,
            ..Noise::default()
        },
        &seeds,
    );
    print("table I's yaw noise, held-out seeds 20-29", &t1);
    // Measured: pose ε̄ 4.22, 4.15, 3.68, 3.47 (bounds 2.54..3.50),
    // over-confident ×1.4 (at a quarter of the windows; ×1.8 with table I's
    // value: 5.30, 4.73, 4.53, 4.72); motion consistent. So the choice
    // helps out of sample but does not make the pose consistent on these
    // seeds (issue 31's calibrated bound is the remedy).
    let k = factor(c.pose.verdict());
    assert!((1.25..1.6).contains(&k), "pose {}", c.pose.verdict());
    assert!(factor(t1.pose.verdict()) > k + 0.2, "{}", t1.pose.verdict());
    assert_eq!(c.motion.verdict(), Verdict::Consistent);
}
