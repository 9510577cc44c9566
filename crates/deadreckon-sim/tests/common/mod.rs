//! Helpers shared by the integration tests: cached simulations and truth-side
//! recomputations that do not use the simulator's internals.

#![allow(dead_code)]

use std::sync::OnceLock;

use deadreckon_core::drive::TruthPose;
use deadreckon_core::{angle, Drive};
use deadreckon_sim::{simulate, Scenario, SimOutput};

/// The calibration drive with seed 1, simulated once per test binary.
pub fn calibration() -> &'static SimOutput {
    static OUT: OnceLock<SimOutput> = OnceLock::new();
    OUT.get_or_init(|| simulate(&Scenario::builtin("calibration").unwrap(), 1).unwrap())
}

/// The evaluation drive with seed 1.
pub fn evaluation() -> &'static SimOutput {
    static OUT: OnceLock<SimOutput> = OnceLock::new();
    OUT.get_or_init(|| simulate(&Scenario::builtin("evaluation").unwrap(), 1).unwrap())
}

/// Unwrapped truth yaw.
pub fn yaw(truth: &[TruthPose]) -> Vec<f64> {
    angle::unwrap(&truth.iter().map(|p| p.yaw_rad).collect::<Vec<_>>())
}

/// Distance driven by M: trapezoid on the truth speed.
pub fn distance(truth: &[TruthPose]) -> f64 {
    truth
        .windows(2)
        .map(|w| 0.5 * (w[0].speed_mps.unwrap() + w[1].speed_mps.unwrap()) * (w[1].t_s - w[0].t_s))
        .sum()
}

/// Ground distance of each wheel FL, FR, RL, RR recomputed from the truth
/// (midpoint rule: mean speed and yaw-rate difference quotient per interval).
pub fn wheel_distances(drive: &Drive) -> [f64; 4] {
    let v = &drive.vehicle;
    let yaw = yaw(&drive.truth);
    let mut d = [0.0; 4];
    for (k, w) in drive.truth.windows(2).enumerate() {
        let dt = w[1].t_s - w[0].t_s;
        let speed = 0.5 * (w[0].speed_mps.unwrap() + w[1].speed_mps.unwrap());
        let rate = (yaw[k + 1] - yaw[k]) / dt;
        let lat = v.wheelbase_m * rate;
        let speeds = [
            lat.hypot(speed - 0.5 * v.track_front_m * rate),
            lat.hypot(speed + 0.5 * v.track_front_m * rate),
            speed - 0.5 * v.track_rear_m * rate,
            speed + 0.5 * v.track_rear_m * rate,
        ];
        for i in 0..4 {
            d[i] += speeds[i] * dt;
        }
    }
    d
}

/// Standstill intervals (start, duration) of the truth: speed exactly zero.
pub fn stops(truth: &[TruthPose]) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    let mut start: Option<f64> = None;
    for p in truth {
        let still = p.speed_mps.unwrap() == 0.0;
        match (still, start) {
            (true, None) => start = Some(p.t_s),
            (false, Some(s)) => {
                out.push((s, p.t_s - s));
                start = None;
            }
            _ => {}
        }
    }
    if let (Some(s), Some(last)) = (start, truth.last()) {
        out.push((s, last.t_s - s));
    }
    out
}

/// Linear interpolation of the truth at `t` (position and unwrapped yaw).
pub fn truth_at(truth: &[TruthPose], yaw: &[f64], t: f64) -> (f64, f64, f64) {
    let i = truth
        .partition_point(|p| p.t_s <= t)
        .clamp(1, truth.len() - 1);
    let (a, b) = (&truth[i - 1], &truth[i]);
    let l = (t - a.t_s) / (b.t_s - a.t_s);
    (
        a.east_m + l * (b.east_m - a.east_m),
        a.north_m + l * (b.north_m - a.north_m),
        yaw[i - 1] + l * (yaw[i] - yaw[i - 1]),
    )
}

/// Sample standard deviation.
pub fn std(x: &[f64]) -> f64 {
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    (x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
}

/// The true GNSS latency of the car family's member `seed` in the GNSS
/// delay's tests (`gnss_delay_family.rs`, `gnss_delay_applied.rs`): 0 for
/// even members, 0.05–0.2 s for odd.
pub fn gnss_latency_of(seed: u64) -> f64 {
    use rand::{RngExt, SeedableRng};
    if seed.is_multiple_of(2) {
        0.0
    } else {
        rand_pcg::Pcg64::seed_from_u64(0x6e55_0000 + seed).random_range(0.05..0.2)
    }
}
