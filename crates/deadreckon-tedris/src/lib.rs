//! # deadreckon-tedris
//!
//! TedriS, the Time Series Dead Reckoning System (Freitas, Costa, Campista et al.):
//! dead reckoning through GNSS outages from the rear wheels alone, with a
//! regression learnt, while GNSS is good, between the rear wheel difference and
//! the GNSS course increments. A streaming API ([`Tedris`], one sample at a time,
//! as on a vehicle) and batch functions over a [`deadreckon_core::Drive`]
//! ([`train`], [`run_outages`]).
//!
//! ## Reading of the paper's ω and γ (units)
//!
//! The paper's notation is loose (its ω is called a yaw rate but tabulated in
//! metres). Here, on the wheel clock (the faster one: 25 Hz wheels against 4 Hz
//! GNSS on the car; both 10 Hz on the robot):
//!
//! - **ω_t** = right − left rear wheel distance over sample t, **metres per sample**
//!   (eq. 1 times the track width times the sample period; left turns positive);
//! - **d_t** = mean rear wheel distance over sample t, metres per sample;
//! - **θ_t** = reference heading (GNSS course of the antenna converted to the
//!   rear-axle heading with the lever arm, or the integrated gyro), linearly
//!   interpolated onto the wheel clock, unwrapped (no 0/360° jump), radians
//!   counter-clockwise from east;
//! - **γ_t** = θ_t − θ_{t−1}, **radians per sample**.
//!
//! So the slope α1 is in rad/m (≈ 1/track width), α0 and the DCF in rad per
//! sample, and µ, W_L, W_H, ε in metres per sample, as in the paper's text.
//! γ_t is regressed on ω_{t−h}, h the lag of the cross-correlation peak.
//!
//! ## What runs, in the paper's order
//!
//! 1. Synchronisation (figure 3) on the wheel clock; a GNSS course (the antenna's)
//!    becomes the rear-axle heading `θ − atan(l·ψ̇/v)` with ψ̇, v from the wheels
//!    over the last fix interval; the course from successive fixes or the
//!    integrated gyro (bias taken at standstill) are the other references.
//! 2. Cross-correlation of ω and γ, lag h at the peak within ±`max_lag_samples`
//!    (the shortest lag within `lag_tolerance` of the peak: the peak is flat).
//! 3. Blocks of τ samples → tuples (median ω, median d, median γ); straight
//!    blocks (reference heading change < `slt_max_change_deg` over `slt_window_s`)
//!    give µ, W_L, W_H and ε = k·(W_H − W_L); repositories R_n with min/max fill.
//! 4. Regressions of eq. (2)–(3) for every kind (paper, distance, ARX), with the
//!    coefficient table, Box–Pierce and Ljung–Box, the AR/MA correction when
//!    Ljung–Box rejects, the joint refit (table 2), the repository fits, and the
//!    choice by residual statistics (simulation BIC among white-innovation kinds).
//! 5. Update phase: DCF by Brent's bounded minimisation of the heading RMSE over
//!    `update_window_s` (eq. 6), starting from DCF₀.
//! 6. Prediction: eq. (4) per wheel sample, heading by cumulative sum (eq. 5),
//!    position by the rear-wheel distance along the heading; the AR/MA forecast
//!    carries the last block errors into the outage.
//!
//! ## Beyond the paper (each can be switched off in [`TedrisConfig`])
//!
//! - `Distance` and `Arx` kinds (the paper's future work): the rear-radius bias
//!   grows with the distance per sample, which a constant DCF cannot follow.
//! - Errors-in-variables slope correction (`eiv_correction`): block medians of ω
//!   are noisy, which attenuates an OLS slope.
//! - Straight-line dead band (`straight_band`): inside ±3 robust σ of the
//!   straight-line ω the heading advances by the straight-line rate instead of
//!   integrating wheel noise (the paper's R0 band used as a detector).
//! - Turn gain (`turn_gain`, module [`gain`]): the turning part of γ̂ is rescaled
//!   so that heading changes over 10 s segments match the reference.
//!
//! ## Measured on the simulator (see `tests/sim_outages.rs`)
//!
//! `tedris-car`: model trained on seed s, 80 s outages starting at 200, 350 and
//! 500 s of the drive of seed s + 100, seeds 1–6 (18 outages), mean position
//! error against truth (mean over the outages, largest in brackets):
//!
//! | configuration | mean error |
//! |---|---|
//! | defaults, distance kind | 3.40 m (6.7) |
//! | defaults, automatic choice | 3.53 m (7.8) |
//! | defaults, paper kind | 4.31 m (9.7) |
//! | defaults, ARX kind | 4.39 m (11.5) |
//! | distance kind, DCF of eq. (6) unsmoothed | 4.51 m (11.9) |
//! | the paper's method alone (no dead band, turn gain, EIV; raw DCF), paper kind | 24.1 m (53.9) |
//! | the same with the distance kind | 12.4 m (32.4) |
//!
//! The paper reports about 3 m (figure 6b) and 4 m (figure 6c). For scale, a
//! wheel-only dead reckoning with the true radii and the true initial pose has
//! 1.5–13 m on the same windows: the simulated wheel speeds carry independent
//! noise whose integral is a heading random walk; the dead band removes it on
//! straights only.
//!
//! `tedris-robot` (gyro reference, error aligned at the outage start, 90 s
//! outages at 60, 120, 180, 240 s, seeds 1–5): the error stays under 0.159 m for
//! a median of 70 s; 10 of the 20 outages for at least 60 s (seed 1: 9–18 s).
//!
//! ## Modules
//!
//! | module | concept |
//! |---|---|
//! | [`stats`] | OLS, coefficient table (estimate, standard error, t, p), median |
//! | [`residuals`] | autocorrelation, Box–Pierce, Ljung–Box, AR/MA correction |
//! | [`ccf`] | cross-correlation ω/γ, lag at the peak |
//! | [`repository`] | tuples, straight-line band, repositories R_n |
//! | [`model`] | the fitted regressions of every kind, model choice, DCF₀ |
//! | [`predict`] | eq. (4) per sample: FIFO median, repository, DCF, correction |
//! | [`history`] | wheel-clock samples with the synchronised heading, block formation |
//! | [`gain`] | the turn gain from heading changes over whole segments |
//! | [`minimise`] | Brent's bounded minimisation (eq. 6) |
//! | [`machine`] | the state machine of section 3.3 |
//! | [`input`] | drive → events (wheels, reference heading, fixes), outage blanking |
//! | [`outage`] | batch training and outage runs with their errors |
//! | [`config`] | every parameter with unit and default |
#![deny(missing_docs)]

pub mod ccf;
pub mod config;
pub mod gain;
pub mod history;
pub mod input;
pub mod machine;
pub mod minimise;
pub mod model;
pub mod outage;
pub mod predict;
pub mod repository;
pub mod residuals;
pub mod stats;

pub use config::{ModelChoice, ModelKind, RepositoryFit, TedrisConfig};
pub use input::ReferenceSource;
pub use machine::{Estimate, Geometry, HeadingSample, Phase, PositionFix, Tedris, WheelSample};
pub use model::TedrisModel;
pub use outage::{
    run_outages, run_outages_with, train, Outage, OutageError, OutageReport, RunOptions,
};

/// Errors of TedriS.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A configuration value is not usable.
    #[error("invalid configuration: {0}")]
    Config(String),
    /// A regression could not be fitted (too few rows, singular design, non-finite data).
    #[error("regression failed: {0}")]
    Regression(String),
    /// A loaded model is inconsistent.
    #[error("invalid model: {0}")]
    Model(String),
    /// A sample was rejected (non-finite, or time not increasing).
    #[error("invalid input: {0}")]
    Input(String),
    /// JSON (de)serialisation failed.
    #[error("JSON: {0}")]
    Json(String),
    /// The data cannot support the request (no reference heading, too short to train).
    #[error("insufficient data: {0}")]
    Insufficient(String),
    /// The drive breaks an invariant.
    #[error(transparent)]
    Drive(#[from] deadreckon_core::Error),
}
