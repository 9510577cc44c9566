//! Blocks that quantised wheel ticks cannot bias (issue 35).
//!
//! A wheel-tick counter reports whole ticks per sample: on a 48-tooth ring
//! one tick is about 4 cm of wheel travel, while a 0.3 rad/s turn moves the
//! right − left difference of a 100 Hz sample by 5 mm. Per sample, ω is then
//! mostly quantisation noise; the median of τ = 6 such samples is a whole
//! number of ticks (usually 0), and the slope of γ on it came out ten times
//! too small (α1·track = 0.09 instead of about 1), which the model then
//! turned with.
//!
//! Over a block, the sum of the counts is the exact tick count between the
//! block's ends: its quantisation error is that of the two ends only (for
//! ω, four uniform phase errors of one tick: variance q²/3), and it does
//! not grow with the block. So when the wheel distances lie on a lattice of
//! step q ([`wheel_resolution`]) and that step is coarse against the
//! turning the reference heading shows ([`turn_signal_m`]), the blocks are
//! **means** (cumulative increments divided by τ) instead of medians, and τ
//! is the shortest one whose quantisation variance stays below
//! [`crate::tuning::MAX_QUANTISATION_ATTENUATION`] of the turning's
//! ([`choose`]); the errors-in-variables correction then takes out the rest
//! with the quantisation variance as the floor of the noise variance.
//! Wheel speeds (not on a lattice, or on one far finer than the turning)
//! keep the configuration's τ and medians, as before.

use serde::{Deserialize, Serialize};

use crate::history::Sample;
use crate::tuning::{
    MAX_BLOCK_S, MAX_QUANTISATION_ATTENUATION, MIN_LATTICE_SHARE, TURN_SIGNAL_WINDOW_S,
};

/// The blocks chosen for quantised wheel distances, and why.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct QuantisedBlocks {
    /// The lattice step of the wheel distances (one tick), m.
    pub resolution_m: f64,
    /// The turning's standard deviation in ω per sample, m (track ×
    /// the reference heading's change per sample over
    /// [`TURN_SIGNAL_WINDOW_S`]).
    pub turn_signal_m: f64,
    /// τ: wheel samples per block (block means).
    pub tau_samples: usize,
    /// Standard deviation of a block mean of ω from the quantisation, m per
    /// sample: `resolution_m / (√3 · τ)`.
    pub quantisation_std_m: f64,
    /// The slope's attenuation the quantisation leaves before the
    /// errors-in-variables correction: `σ_q² / (σ_q² + σ_turn²)`.
    pub attenuation: f64,
    /// τ would have had to exceed [`MAX_BLOCK_S`] to keep the attenuation
    /// below [`MAX_QUANTISATION_ATTENUATION`]; it was capped there.
    pub capped: bool,
}

impl QuantisedBlocks {
    /// Words for the summary: what was chosen and why.
    pub fn describe(&self, period_s: f64) -> String {
        format!(
            "wheel distances in whole ticks of {:.4} m against a turning of {:.2e} m per sample: blocks of tau = {} samples ({:.2} s) as cumulative increments (means), quantisation std {:.2e} m, attenuation before the errors-in-variables correction {:.1} %{}",
            self.resolution_m,
            self.turn_signal_m,
            self.tau_samples,
            self.tau_samples as f64 * period_s,
            self.quantisation_std_m,
            100.0 * self.attenuation,
            if self.capped {
                format!(" (capped at {MAX_BLOCK_S} s: too little turning for less)")
            } else {
                String::new()
            }
        )
    }

    /// The variance of a block mean's ω from the quantisation, m².
    pub fn quantisation_var_m2(&self) -> f64 {
        self.quantisation_std_m * self.quantisation_std_m
    }
}

/// The step of the lattice the moving samples' wheel distances lie on (one
/// tick, m): the smallest nonzero per-sample wheel distance, when at least
/// [`MIN_LATTICE_SHARE`] of the left and right distances are whole
/// multiples of it (within 10⁻⁶ of a step). `None` for wheel speeds.
pub fn wheel_resolution<'a>(samples: impl Iterator<Item = &'a Sample>) -> Option<f64> {
    let mut v = Vec::new();
    for s in samples.filter(|s| s.moving()) {
        v.push((s.dist_m - 0.5 * s.omega_m).abs());
        v.push((s.dist_m + 0.5 * s.omega_m).abs());
    }
    let q = v
        .iter()
        .copied()
        .filter(|x| *x > 1e-9)
        .fold(f64::INFINITY, f64::min);
    if !q.is_finite() || v.len() < 100 {
        return None;
    }
    let on = v
        .iter()
        .filter(|x| {
            let k = *x / q;
            (k - k.round()).abs() <= 1e-6 * k.max(1.0)
        })
        .count();
    (on as f64 >= MIN_LATTICE_SHARE * v.len() as f64).then_some(q)
}

/// The turning in ω per sample, m: the track times the standard deviation of
/// the reference heading's change over [`TURN_SIGNAL_WINDOW_S`] (within one
/// heading segment, moving), divided by the samples in that window. Over a
/// second the reference's own noise is averaged out; `None` with fewer than
/// 30 windows.
pub fn turn_signal_m<'a>(
    samples: impl Iterator<Item = &'a Sample>,
    track_m: f64,
    period_s: f64,
) -> Option<f64> {
    let n = (TURN_SIGNAL_WINDOW_S / period_s).round().max(1.0) as usize;
    let pts: Vec<(f64, u32, bool)> = samples
        .step_by(n)
        .map(|s| (s.theta_rad.unwrap_or(f64::NAN), s.segment, s.moving()))
        .collect();
    let d: Vec<f64> = pts
        .windows(2)
        .filter(|w| w[0].1 == w[1].1 && w[0].2 && w[1].2)
        .map(|w| w[1].0 - w[0].0)
        .filter(|x| x.is_finite())
        .collect();
    if d.len() < 30 {
        return None;
    }
    let m = d.iter().sum::<f64>() / d.len() as f64;
    let var = d.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / (d.len() - 1) as f64;
    Some(track_m * var.sqrt() / n as f64)
}

/// The blocks for wheel distances on a lattice of `resolution_m` against a
/// turning of `turn_signal_m` per sample: `None` when the configuration's
/// `tau_samples` (medians) already keeps the quantisation's attenuation
/// below [`MAX_QUANTISATION_ATTENUATION`] (wheel speeds, fine tone rings),
/// else the shortest τ that does, as block means, at most [`MAX_BLOCK_S`].
pub fn choose(
    resolution_m: f64,
    turn_signal_m: f64,
    period_s: f64,
    config_tau: usize,
) -> Option<QuantisedBlocks> {
    if !(resolution_m > 0.0 && turn_signal_m > 0.0 && period_s > 0.0) {
        return None;
    }
    // σ_q(τ)² ≤ a/(1 − a)·σ_turn², σ_q(τ) = q/(√3·τ).
    let a = MAX_QUANTISATION_ATTENUATION;
    let ratio = (a / (1.0 - a)).sqrt();
    let need = resolution_m / (3f64.sqrt() * ratio * turn_signal_m);
    if need <= config_tau as f64 {
        return None;
    }
    let max_tau = (MAX_BLOCK_S / period_s).floor().max(1.0);
    let capped = need.ceil() > max_tau;
    let tau = need.ceil().min(max_tau).max(config_tau as f64) as usize;
    let q_std = resolution_m / (3f64.sqrt() * tau as f64);
    let q_var = q_std * q_std;
    Some(QuantisedBlocks {
        resolution_m,
        turn_signal_m,
        tau_samples: tau,
        quantisation_std_m: q_std,
        attenuation: q_var / (q_var + turn_signal_m * turn_signal_m),
        capped,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(idx: u64, left: f64, right: f64) -> Sample {
        Sample {
            idx,
            t_s: idx as f64 * 0.01,
            dt_s: 0.01,
            omega_m: right - left,
            dist_m: 0.5 * (left + right),
            theta_rad: Some(0.0),
            theta_dr_rad: 0.0,
            segment: 0,
            lever_rad: 0.0,
        }
    }

    #[test]
    fn ticks_are_found_on_their_lattice_and_speeds_are_not() {
        let q = 2.0 / 48.0;
        let ticks: Vec<Sample> = (0..500)
            .map(|i| sample(i, q * (1 + i % 3) as f64, q * (2 + i % 2) as f64))
            .collect();
        let r = wheel_resolution(ticks.iter()).unwrap();
        assert!((r - q).abs() < 1e-12, "{r}");
        let speeds: Vec<Sample> = (0..500)
            .map(|i| {
                sample(
                    i,
                    0.1 + 1e-4 * (i as f64).sin(),
                    0.1 + 1e-4 * (i as f64).cos(),
                )
            })
            .collect();
        assert_eq!(wheel_resolution(speeds.iter()), None);
    }

    #[test]
    fn coarse_ticks_get_long_mean_blocks_and_fine_ones_keep_the_configuration() {
        // 48 teeth on a 2 m tyre at 100 Hz, track 1.6 m, turning 0.1 rad/s.
        let signal = 1.6 * 0.1 * 0.01;
        let b = choose(2.0 / 48.0, signal, 0.01, 6).unwrap();
        // q/(√3·τ) ≤ √(0.01/0.99)·signal: τ ≥ 0.0417/(1.732·0.1005·0.0016) = 150.
        assert_eq!(b.tau_samples, 150);
        assert!(b.attenuation <= MAX_QUANTISATION_ATTENUATION + 1e-12);
        assert!(!b.capped);
        // A 0.4 mm lattice (0.01 m/s speed resolution at 25 Hz) is fine.
        assert_eq!(choose(0.0004, 1.6 * 0.1 * 0.04, 0.04, 6), None);
        // Too little turning: capped at MAX_BLOCK_S.
        let c = choose(2.0 / 48.0, signal / 10.0, 0.01, 6).unwrap();
        assert!(c.capped);
        assert_eq!(c.tau_samples, (MAX_BLOCK_S / 0.01) as usize);
    }
}
