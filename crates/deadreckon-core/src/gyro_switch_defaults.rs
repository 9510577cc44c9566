//! The gyro-bias switch's default settings and what they were chosen on
//! ([`crate::aided::switch`]; `[noise] gyro_bias_drive_std_rps` and
//! `gyro_bias_switch_llr` in [`crate::vehicle::Noise`]). A leaf module: the
//! vehicle's defaults read it without importing the filter.

/// The default `[noise] gyro_bias_drive_std_rps`, rad/s: 1e-4 (21 °/h), the
/// bias state's start std for the gyro-bias switch. Chosen with
/// [`DEFAULT_THRESHOLD_LLR`] on the dynamic family's dev cars 1–25 (18 apart; 30 s outages every
/// 10 s on a drive other than the calibration's; mean final error,
/// constant → switch at a threshold of 1): std 5e-5: none 0.389 → 0.387,
/// gyro_drift 0.796 → 0.598, all 2.828 → 2.717 m; 1e-4: 0.385, 0.549,
/// 2.723 m; 2e-4: 0.387, 0.545, 2.750 m (`deadreckon-sim/tests/bias_switch.rs`,
/// `bias_switch_on_the_family`). Checked on held-out cars 101–110 (104
/// apart): none 0.463 → 0.480, gyro_drift 1.229 → 0.709, all 2.781 →
/// 2.689 m.
pub const DEFAULT_DRIVE_STD_RPS: f64 = 1e-4;

/// The default `[noise] gyro_bias_switch_llr`: 1. Chosen on the dev cars
/// with [`DEFAULT_DRIVE_STD_RPS`] (std 1e-4; mean final error
/// none / gyro_drift / all): 0.5: 0.392, 0.545, 2.727 m (fired on 8 of 25
/// effect-free cars, worse on 6); 1: 0.385, 0.549, 2.723 m (fired on 1,
/// better); 2: 0.389, 0.589, 2.719 m (never fired); the bias always a
/// state: 0.411, 0.526, 2.735 m. Checked on the held-out cars (above).
pub const DEFAULT_THRESHOLD_LLR: f64 = 1.0;

/// Whether `v` is the default drive std (not written to a vehicle.toml).
pub(crate) fn is_default_drive_std(v: &f64) -> bool {
    *v == DEFAULT_DRIVE_STD_RPS
}

/// Whether `v` is the default threshold (not written to a vehicle.toml).
pub(crate) fn is_default_switch_llr(v: &f64) -> bool {
    *v == DEFAULT_THRESHOLD_LLR
}
