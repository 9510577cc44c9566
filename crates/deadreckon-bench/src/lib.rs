//! # deadreckon-bench
//!
//! Benchmarks only (`cargo bench -p deadreckon-bench`): one EKF epoch, one RTS
//! epoch and a whole 1-hour drive calibration, on simulated drives (the
//! kernel, `benches/estimation.rs`); the commands' own library path, reading
//! included ([`command`], `benches/command.rs`, and the `command_cost`
//! example for the whole process's peak memory). Kept in its own crate so
//! that test builds do not compile criterion.
#![deny(missing_docs)]

pub mod command;

use deadreckon_core::Drive;

/// A simulated calibration drive of `duration_s` seconds (seed 1).
pub fn drive(duration_s: f64) -> Drive {
    let sc = deadreckon_sim::Scenario::builtin("calibration")
        .expect("built-in scenario")
        .with_duration_s(duration_s);
    deadreckon_sim::simulate(&sc, 1).expect("simulation").drive
}

/// The calibration loop driven `laps` times (8 laps: about an hour of driving, 32 km).
pub fn laps(laps: u32) -> Drive {
    let sc = deadreckon_sim::Scenario::builtin("calibration")
        .expect("built-in scenario")
        .with_laps(laps);
    deadreckon_sim::simulate(&sc, 1).expect("simulation").drive
}
