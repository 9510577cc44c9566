//! # deadreckon-report
//!
//! Renders the evaluation report of `deadreckon report`: one self-contained HTML
//! file (inline CSS, inline SVG figures drawn with plotters' SVG backend, a few
//! lines of inline script, no network access) from a [`ReportInput`], a plain,
//! serialisable data model that the command line fills from the estimators'
//! results. This crate depends on no estimator: it only draws.
//!
//! Sections, each rendered only when its data is present: header (drive, duration,
//! distance, sensor streams), trajectories, calibration (table III of the
//! four-wheel paper and the parameters over the iterations), drift (table IV,
//! figures 4–5), filter health (the NEES verdict and table through dead-reckoning
//! windows when the drive has truth, the wheel-health lines, innovations and NIS
//! with chi-square bounds, gated fixes), TedriS (cross-correlation, regression models, headings, repositories,
//! error through each outage), the outage evaluation, and a footer (version,
//! command line).
//!
//! Every method keeps one colour across figures. Long series are decimated for
//! drawing (at most about [`MAX_POINTS`] points per series; time series keep the
//! minimum and maximum of each bucket), so an hour-long drive gives a page of a
//! few megabytes at most. Each figure wraps its data in `<g class="data">`, and an
//! inline self-check writes into `<div id="selfcheck" data-ok=…>` whether every
//! figure drew data and whether any script error occurred: the end-to-end test
//! `tests/report_chromium.sh` reads it from headless Chromium.
//!
//! ```
//! use deadreckon_report::{render_html, EnPath, ReportInput, Trajectories};
//!
//! let mut input = ReportInput::default();
//! input.header.drive_name = "loop".into();
//! input.trajectories = Some(Trajectories {
//!     truth: Some(EnPath { east_m: vec![0.0, 10.0, 20.0], north_m: vec![0.0, 5.0, 0.0], ..Default::default() }),
//!     ..Default::default()
//! });
//! let html = render_html(&input).unwrap();
//! assert!(html.contains("<g class=\"data\">"));
//! ```
#![deny(missing_docs)]

mod charts;
mod model;
mod page;
mod plot;
pub mod sample;
mod sections;
mod stats;

use std::path::Path;

pub use model::*;

/// The most points drawn per line series; longer series are decimated for drawing.
pub const MAX_POINTS: usize = 4000;

/// The most points drawn per scatter series of the filter-health figures (a dot
/// costs ten times the bytes of a line vertex, and there is one series per sensor).
pub const MAX_SCATTER_POINTS: usize = 2000;

/// Errors of the report.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReportError {
    /// Two series that must be paired have different lengths.
    #[error("{section}: {series} has {left} values on one axis and {right} on the other")]
    LengthMismatch {
        /// The section.
        section: &'static str,
        /// The series.
        series: String,
        /// Length of the first vector (time, east, lag, index).
        left: usize,
        /// Length of the second vector.
        right: usize,
    },
    /// plotters failed to draw a figure.
    #[error("figure {figure}: {message}")]
    Plot {
        /// The figure.
        figure: String,
        /// plotters' message.
        message: String,
    },
    /// The HTML template failed.
    #[error("HTML template: {0}")]
    Template(String),
    /// The report file could not be written (names the file).
    #[error(transparent)]
    Write(deadreckon_io::IoError),
}

pub(crate) fn check_len(
    section: &'static str,
    series: &str,
    left: usize,
    right: usize,
) -> Result<(), ReportError> {
    if left == right {
        Ok(())
    } else {
        Err(ReportError::LengthMismatch {
            section,
            series: series.to_string(),
            left,
            right,
        })
    }
}

/// Optional per-sample vectors (standard deviations, gate flags) are empty or as long as the series.
pub(crate) fn check_optional_len(
    section: &'static str,
    series: &str,
    n: usize,
    optional: usize,
) -> Result<(), ReportError> {
    if optional == 0 {
        Ok(())
    } else {
        check_len(section, series, n, optional)
    }
}

/// Renders the whole report as one self-contained HTML page.
pub fn render_html(input: &ReportInput) -> Result<String, ReportError> {
    let sections = sections::render_all(input)?;
    page::render_page(&input.header, &input.footer, &sections)
}

/// Renders the report and writes it to `path` atomically
/// ([`deadreckon_io::atomic_write`]: a temporary file in the same directory,
/// then a rename), so a reader never sees a half-written page; a replaced
/// report keeps its permissions, and an interrupted program can remove the
/// temporary file ([`deadreckon_io::temporaries`]).
pub fn write_report(path: impl AsRef<Path>, input: &ReportInput) -> Result<(), ReportError> {
    let path = path.as_ref();
    let html = render_html(input)?;
    deadreckon_io::atomic_write(path, |w| w.write_all(html.as_bytes())).map_err(ReportError::Write)
}
