//! # deadreckon-import
//!
//! Log readers that turn recordings into a [`deadreckon_core::Drive`]: SI units,
//! a local east-north frame, one clock, strictly increasing timestamps.
//!
//! - [`comma2k19`]: a comma2k19 segment directory (NumPy `t`/`value` pairs) with
//!   its `global_pose` reference trajectory, and the built-in Toyota RAV4
//!   profile ([`profiles::toyota_rav4`]).
//! - [`can`]: raw CAN frames (candump logs, comma2k19 `raw_can` arrays) decoded
//!   with a DBC file parsed by `can-dbc` and our own signal decoder, routed into
//!   drive streams by a TOML mapping ([`can::mapping`]).
//! - [`tricycle`]: the tricycle-with-tracker log (`dataset.txt`), with its
//!   wrapping 32-bit traction counter.
//!
//! ## Example: one RAV4 wheel-speed frame
//!
//! ```
//! use std::path::Path;
//! use deadreckon_import::can::{parse_candump, Database, TOYOTA_RAV4_DBC};
//!
//! let log = b"(46408.589503) 0 0AA#25B525B525A0258D\n";
//! let frames = parse_candump(log, Path::new("drive.log")).unwrap();
//! let db = Database::parse(TOYOTA_RAV4_DBC, Path::new("toyota_rav4_subset.dbc")).unwrap();
//! let fl = db.message("WHEEL_SPEEDS").unwrap().signal("WHEEL_SPEED_FL").unwrap();
//! let kph = fl.decode(&frames[0].data).unwrap(); // Motorola 16 bits, 0.01 km/h, offset -67.67
//! assert!((kph / 3.6 - 8.0167).abs() < 1e-4);
//!
//! // A malformed line is an error naming the file, line and column.
//! let err = parse_candump(b"(1.0) can0 0AA#0G\n", Path::new("drive.log")).unwrap_err();
//! assert_eq!(err.to_string(), "drive.log:1:16: data is not hexadecimal");
//! ```
//!
//! ## Conventions and policies
//!
//! - Positions are metres east/north of an origin; yaw is radians
//!   counter-clockwise from east; yaw rate is counter-clockwise positive.
//! - The reference (truth) pose is the rear-axle centre: readers move the
//!   recorded sensor pose there and say how in their docs and in the
//!   [`ImportReport`] notes.
//! - A sample whose time is not after the previous one, or that holds a
//!   non-finite value, is never repaired silently: by default it is an
//!   [`ImportError::Stream`]; with [`TimeOrderPolicy::Gate`] it is dropped and
//!   counted in the [`ImportReport`].
//! - Every parser returns errors that name the file and the line and column,
//!   byte offset or stream and sample; no input makes a reader panic (each
//!   parser is property-tested and fuzzed on arbitrary bytes).
#![deny(missing_docs)]

pub mod can;
pub mod comma2k19;
mod error;
pub mod npy;
pub mod profiles;
mod report;
mod stream;
pub mod tricycle;

pub use comma2k19::{
    read_comma2k19, read_comma2k19_with, Comma2k19Options, GyroSource, SpeedSource,
};
pub use error::ImportError;
pub use report::{ImportReport, StreamReport};
pub use stream::TimeOrderPolicy;

/// A drive read from a log, with the report of what was kept, gated and decided.
#[derive(Debug, Clone, PartialEq)]
pub struct Import {
    /// The drive.
    pub drive: deadreckon_core::Drive,
    /// Counts per stream, gated samples and the decisions taken.
    pub report: ImportReport,
}

impl Import {
    /// The importers' common end: the drive checked against its invariants
    /// ([`deadreckon_core::Drive::validate`]), an error naming the log
    /// `path` if it breaks one.
    pub fn checked(
        drive: deadreckon_core::Drive,
        report: ImportReport,
        path: &std::path::Path,
    ) -> Result<Import, ImportError> {
        drive.validate().map_err(|source| ImportError::Invalid {
            path: path.to_path_buf(),
            source,
        })?;
        Ok(Import { drive, report })
    }
}
