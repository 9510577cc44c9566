//! # deadreckon-eval
//!
//! Evaluation and comparison on top of `deadreckon-core` (the four-wheel EKF
//! and its calibration) and `deadreckon-tedris`, with no I/O and no printing,
//! so that every command that shows a comparison (`compare`, `demo`, `report`)
//! computes it in one place:
//!
//! - [`compare`]: TedriS and the calibrated four-wheel EKF through the same GNSS
//!   outages, neither seeing GNSS inside them, not even for calibration or
//!   training ([`compare::compare`], [`compare::Comparison`]);
//! - [`crossval`]: calibrate with every method on one drive and evaluate on
//!   another (`demo`'s tables III and IV);
//! - [`report`]: estimator results as the HTML report's data model
//!   (`deadreckon_report::ReportInput`): calibrations, filter health, dead
//!   reckoning, drift, outages, the TedriS sections.
//!
//! The one error type is [`Error`]; its `Display` says which step failed and
//! its `source` is the estimator's error.
#![deny(missing_docs)]

pub mod compare;
pub mod crossval;
pub mod report;

/// Where a long evaluation reports its steps (the command line's progress bar).
pub trait Progress {
    /// The evaluation starts the step `what`.
    fn step(&self, what: &str);
}

/// No progress reporting.
impl Progress for () {
    fn step(&self, _what: &str) {}
}

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
    /// A calibration of [`crossval::calibrate_and_evaluate`] failed.
    #[error("{method} calibration")]
    Calibration {
        /// The method.
        method: &'static str,
        /// Why.
        #[source]
        source: deadreckon_core::Error,
    },
    /// The drive holds no samples.
    #[error("empty drive")]
    EmptyDrive,
    /// The four-wheel filter failed.
    #[error(transparent)]
    Core(#[from] deadreckon_core::Error),
    /// TedriS failed.
    #[error(transparent)]
    Tedris(#[from] deadreckon_tedris::Error),
    /// A series the report was given did not hold together (its columns
    /// of different lengths).
    #[error(transparent)]
    Report(#[from] deadreckon_report::ReportError),
}
