use super::*;
use rand::{RngExt, SeedableRng};
use rand_distr::StandardNormal;

fn diag(a: f64, b: f64) -> Cov2 {
    Cov2 {
        ee_m2: a,
        en_m2: 0.0,
        nn_m2: b,
    }
}

#[test]
fn the_circle_and_the_line_have_their_textbook_radii() {
    // A circle: the Rayleigh quantile √(−2 ln 0.05) σ; one axis: 1.95996 σ.
    let rayleigh = (-2.0 * 0.05f64.ln()).sqrt();
    assert!((radius_exact(&diag(4.0, 4.0), LEVEL) - 2.0 * rayleigh).abs() < 1e-10);
    assert!((radius(&diag(4.0, 4.0)) - 2.0 * rayleigh).abs() < 1e-10);
    assert!((radius(&diag(9.0, 0.0)) - 3.0 * 1.959963984540054).abs() < 1e-9);
    assert!((radius_exact(&diag(0.0, 9.0), LEVEL) - 3.0 * 1.959963984540054).abs() < 1e-9);
    assert_eq!(radius(&diag(0.0, 0.0)), 0.0);
    // Not 2.45 √trace: on a circle that is √2 too wide.
    assert!(2.45 * 8f64.sqrt() / radius(&diag(4.0, 4.0)) > 1.41);
}

#[test]
fn the_interpolated_radius_matches_the_direct_one() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(31);
    let mut worst = 0.0f64;
    for _ in 0..400 {
        let l1: f64 = 10f64.powf(rng.random_range(-4.0..4.0));
        let ratio: f64 = 10f64.powf(rng.random_range(-7.0..0.0));
        let rot: f64 = rng.random_range(0.0..std::f64::consts::PI);
        let (c, s) = (rot.cos(), rot.sin());
        let l2 = l1 * ratio;
        let cov = Cov2 {
            ee_m2: l1 * c * c + l2 * s * s,
            en_m2: (l1 - l2) * c * s,
            nn_m2: l1 * s * s + l2 * c * c,
        };
        let (a, b) = (radius(&cov), radius_exact(&cov, LEVEL));
        worst = worst.max((a / b - 1.0).abs());
    }
    // Measured: 5.6e-7 relative at worst over these 400 draws.
    println!("worst relative difference {worst:e}");
    assert!(worst < 1e-6, "{worst}");
}

#[test]
fn the_radius_covers_95_percent_of_gaussian_draws() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
    let cov = Cov2 {
        ee_m2: 2.0,
        en_m2: 1.2,
        nn_m2: 1.0,
    };
    let r = radius(&cov);
    // Cholesky of the covariance.
    let l11 = cov.ee_m2.sqrt();
    let l21 = cov.en_m2 / l11;
    let l22 = (cov.nn_m2 - l21 * l21).sqrt();
    let n = 200_000;
    let inside = (0..n)
        .filter(|_| {
            let (z1, z2): (f64, f64) = (rng.sample(StandardNormal), rng.sample(StandardNormal));
            let (e, nn) = (l11 * z1, l21 * z1 + l22 * z2);
            e.hypot(nn) <= r
        })
        .count();
    let cover = inside as f64 / n as f64;
    // The binomial standard error at n = 200 000 is 0.0005.
    assert!((cover - 0.95).abs() < 0.002, "{cover}");
}

#[test]
fn the_antenna_covariance_carries_the_heading_through_the_lever() {
    // Position known exactly, heading ±0.1 rad, antenna 2 m ahead heading
    // north: the antenna's east varies by (2 · 0.1)², its north not at all.
    let p3 = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.01]];
    let c = Cov2::ahead(&p3, std::f64::consts::FRAC_PI_2, 2.0);
    assert!((c.ee_m2 - 0.04).abs() < 1e-12 && c.nn_m2.abs() < 1e-12 && c.en_m2.abs() < 1e-12);
    // With no lever it is the rear axle's.
    let p3 = [[1.0, 0.3, 0.1], [0.3, 2.0, -0.2], [0.1, -0.2, 0.5]];
    assert_eq!(Cov2::ahead(&p3, 0.7, 0.0), Cov2::rear_axle(&p3));
}

#[test]
fn the_score_is_the_least_factor_that_covers_and_charges_nothing_to_the_fix() {
    let s = Sample {
        error_m: 3.0,
        cov: diag(1.0, 1.0),
        reference: diag(0.0, 0.0),
    };
    // r(k² I) = k · 2.4477: k = 3 / 2.4477.
    assert!((s.score() - 3.0 / radius(&diag(1.0, 1.0))).abs() < 1e-5);
    // A fix noisy enough to explain the error on its own: k = 0.
    let noisy = Sample {
        reference: diag(4.0, 4.0),
        ..s
    };
    assert_eq!(noisy.score(), 0.0);
    // In between: r(k² I + R) = 3 exactly at the score.
    let some = Sample {
        reference: diag(0.5, 0.5),
        ..s
    };
    let k = some.score();
    assert!(
        (radius(&diag(k * k + 0.5, k * k + 0.5)) - 3.0).abs() < 1e-4,
        "{k}"
    );
}

#[test]
fn the_factor_is_the_conformal_rank_of_the_scores() {
    // Scores 1, 2, …, 40 (error i against a unit radius).
    let unit = 1.0 / radius(&diag(1.0, 1.0));
    let samples: Vec<Sample> = (1..=40)
        .map(|i| Sample {
            error_m: i as f64,
            cov: diag(unit * unit, unit * unit),
            reference: diag(0.0, 0.0),
        })
        .collect();
    let f = fit(&samples, 30.0, 10.0);
    // ⌈0.95 · 41⌉ = 39: the 39th smallest.
    assert_eq!(f.method, Method::Conformal);
    assert_eq!(f.windows, 40);
    assert!((f.k - 39.0).abs() < 1e-3, "{}", f.k);
    // Ten windows: the largest.
    assert!((fit(&samples[..10], 30.0, 10.0).k - 10.0).abs() < 1e-4);
    // Too few: the filter's covariance alone.
    assert_eq!(fit(&samples[..4], 30.0, 10.0), BoundFit::FILTER);
}

#[test]
fn the_predicted_fix_covariance_is_h_p_ht_with_the_wander() {
    use crate::model::{X, Y, YAW};
    let a = nalgebra::SMatrix::<f64, 7, 7>::from_fn(|i, j| ((i * 7 + j) as f64 * 0.43).cos());
    let p = a * a.transpose() + nalgebra::SMatrix::<f64, 7, 7>::identity();
    let (yaw, lever) = (0.7_f64, 1.3);
    let mut h = nalgebra::SMatrix::<f64, 2, 7>::zeros();
    h[(0, X)] = 1.0;
    h[(1, Y)] = 1.0;
    h[(0, YAW)] = -lever * yaw.sin();
    h[(1, YAW)] = lever * yaw.cos();
    h[(0, crate::gnss_error::WANDER_E)] = 1.0;
    h[(1, crate::gnss_error::WANDER_N)] = 1.0;
    let want = h * p * h.transpose();
    let idx = [X, Y, YAW];
    let p3: [[f64; 3]; 3] = std::array::from_fn(|r| std::array::from_fn(|c| p[(idx[r], idx[c])]));
    let got = WanderCov::of(&p, crate::gnss_error::WANDER_E).fix_cov(
        Cov2::ahead(&p3, yaw, lever),
        yaw,
        lever,
    );
    assert!((got.ee_m2 - want[(0, 0)]).abs() < 1e-12);
    assert!((got.en_m2 - want[(0, 1)]).abs() < 1e-12);
    assert!((got.nn_m2 - want[(1, 1)]).abs() < 1e-12);
}
