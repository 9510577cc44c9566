//! A fleet of drives on one machine: calibrate many drives in parallel and
//! follow each vehicle's parameters across its drives.
//!
//! [`inputs::expand`] turns command-line arguments (drive directories,
//! directories of drives, glob patterns) into a list of drives;
//! [`batch::run`] calibrates them (and optionally evaluates them through
//! sliding GNSS outages) on a [`rayon`] thread pool, one [`batch::DriveResult`]
//! per drive, a failure being a result with its error message, never the end of
//! the batch; [`history::histories`] groups the results by the `vehicle_id` of
//! `vehicle.toml`, orders each vehicle's drives by `recorded_at`, tests whether
//! each parameter is consistent across the drives given their standard errors
//! (a χ² test) and finds the drives where a parameter moved (a change-point
//! test); [`output`] writes both as CSV (atomically) and prints the history
//! table. The column contracts are in `docs/fleet.md`.
//!
//! Reading drives is the caller's: [`batch::run`] takes a loader, so the
//! command-line tool passes the one that also reads recordings (comma2k19,
//! ROS bags) and a library user can pass [`deadreckon_io::read_drive`].
#![deny(missing_docs)]

pub mod batch;
pub mod history;
pub mod inputs;
pub mod output;

use std::path::PathBuf;

/// The errors of this crate: the batch's own (inputs, outputs, threads);
/// a drive that fails is a row of the results, not an error.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FleetError {
    /// A glob pattern that does not parse.
    #[error("bad pattern `{pattern}`: {message}")]
    Pattern {
        /// The pattern as given.
        pattern: String,
        /// What is wrong with it.
        message: String,
    },
    /// An input that is neither a drive nor a directory holding drives, or a
    /// pattern that matches nothing.
    #[error("{}: {note}", path.display())]
    NoDrives {
        /// The argument.
        path: PathBuf,
        /// Why nothing was found.
        note: String,
    },
    /// An output file that is one of the inputs (or the other output).
    #[error("{}: {what} would overwrite {}", out.display(), input.display())]
    OutputIsInput {
        /// The output file.
        out: PathBuf,
        /// The input it coincides with.
        input: PathBuf,
        /// Which output (`--out`, `--history`).
        what: String,
    },
    /// Invalid options (threads, significance level, tolerances, outages).
    #[error("{0}")]
    Options(String),
    /// The thread pool could not be built.
    #[error("thread pool: {0}")]
    ThreadPool(String),
    /// Writing an output file.
    #[error(transparent)]
    Io(#[from] deadreckon_io::IoError),
}
