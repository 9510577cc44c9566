//! # deadreckon-eval
//!
//! Evaluation and comparison on top of `deadreckon-core` (the four-wheel EKF
//! and its calibration) and `deadreckon-tedris`, with no I/O and no printing,
//! so that every command that shows a comparison (`compare`, `demo`, `report`)
//! computes it in one place:
//!
//! - [`compare`]: TedriS and the calibrated four-wheel EKF through the same GNSS
//!   outages, neither seeing GNSS inside them, not even for calibration or
//!   training ([`compare::compare`], [`compare::Comparison`]).
//!
//! The one error type is [`Error`]; its `Display` says which step failed and
//! its `source` is the estimator's error.
#![deny(missing_docs)]

pub mod compare;

/// Errors of the evaluation: which step failed, with the estimator's error as
/// the source.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The RTS calibration of the drive with the outages hidden failed.
    #[error("RTS calibration with the outages hidden")]
    HiddenCalibration(#[source] deadreckon_core::Error),
    /// TedriS could not be trained on the drive with the outages hidden.
    #[error("TedriS training with the outages hidden")]
    HiddenTraining(#[source] deadreckon_tedris::Error),
    /// The four-wheel filter failed.
    #[error(transparent)]
    Core(#[from] deadreckon_core::Error),
    /// TedriS failed.
    #[error(transparent)]
    Tedris(#[from] deadreckon_tedris::Error),
}
