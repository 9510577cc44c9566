//! # deadreckon-api
//!
//! The operations the `deadreckon` command line and the Python bindings
//! (`python/`) share, so both read the same sources and print the same
//! numbers under the same keys; and each command's steps, so the command
//! line only parses, calls one function here and prints:
//!
//! - [`load`]: drives through a [`load::Loader`] (mapping, wheel file,
//!   plausibility checks), parameters (`nominal` or a params.toml with its
//!   stored corrections), the one `--from`/`--until` rule, scenarios and
//!   simulated drives written to disk.
//! - [`binding`]: parameters bound to their vehicle (params.toml's
//!   `[vehicle]` record; another vehicle's file or an implausible
//!   circumference refused).
//! - [`kinematic`]: the tricycle and differential-drive shapes calibrated
//!   and evaluated over sliding outages (a differential drive's started from
//!   its GNSS-aided filter, or aligned), with their tables and JSON.
//! - [`shape`]: the vehicle's shape (car, tricycle, differential drive)
//!   found from the data with its reason, the one rule every command
//!   applies (`--shape` overrides).
//! - [`tracks`]: `run`'s tracks chosen and written for other tools.
//! - [`demo`], [`report`], [`stream`]: those commands whole
//!   ([`report_kinematic`]: the report of a tricycle or a differential
//!   drive).
//!
//! - [`source`]: a drive from any source the tool reads: a drive directory
//!   (`deadreckon-io`), a comma2k19 segment, a ROS1 bag or ROS2 MCAP (with a
//!   topic mapping) or a tricycle log, chosen by what the path holds; errors
//!   name the file and, through their sources, the line and column.
//! - [`calibration`]: the one home of a car calibration: the request
//!   (method, options, corrections; its `Default` holds every default
//!   once), the one function `calibrate`, `batch`, Python and `evaluate`
//!   call, and the status rule of a parameter.
//! - [`calibrate`]: its result, [`calibrate::CarCalibration`] (corrections,
//!   the six parameters, the steering, the bound, the vehicle), with its
//!   `--json` object, params.toml keys and text.
//! - [`checks`]: the cross-stream plausibility checks applied to a drive
//!   read (errors refuse it, warnings go to `"checks"` in `--json`).
//! - [`evaluate`]: the parameters `evaluate` measures when none are given
//!   (one rule for every metric), and the metric measured
//!   ([`evaluate::measure`]).
//! - [`import`]: a log (comma2k19, CAN with a DBC, tricycle, ROS) read into
//!   a drive with the importer's report, as `deadreckon import` writes it.
//! - [`json`]: the objects `calibrate --json`, `evaluate --json` and
//!   `tedris train --json` print, built from the library results.
//! - [`tedris`]: a TedriS model read from its file and checked.
//! - [`text`]: the commands' text tables and summary lines.
//! - [`params_file`]: a car's params.toml read once and checked once
//!   (parameters, `[std]`, `[vehicle]`, stored corrections, `[bound]`),
//!   for every `--params`, and written by the same type.
//! - [`params_tables`]: every params.toml table beside the parameters, one
//!   serde struct each (what is written is what is read).
//! - [`options`]: the option words of the commands (`--timing wheel|each`,
//!   `--state`, `--iteration`) parsed into the library's enums.
//!
//! The one error type is [`Error`]; its `Display` is the context the command
//! line adds ("reading drive DIR") and its `source` chain carries the reader's
//! file/line message, so `{:#}` of an `anyhow` error and the Python
//! exception's text read the same.
#![deny(missing_docs)]

pub mod binding;
pub mod bound;
pub mod calibrate;
pub mod calibration;
pub mod checks;
pub mod corrections;
pub mod demo;
pub mod evaluate;
pub mod import;
pub mod json;
pub mod kinematic;
pub mod load;
pub mod model_keys;
pub mod options;
pub mod params_file;
pub mod params_tables;
pub mod process;
pub mod report;
pub mod report_kinematic;
pub mod report_labels;
pub mod shape;
pub mod source;
pub mod stream;
pub mod tedris;
pub mod text;
pub mod tracks;

mod error;
pub use error::{chain_text, Error};
pub use source::{detect, read_drive, read_drive_with, read_ros, SourceKind};
