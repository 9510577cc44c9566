//! The crate's error type.

use std::path::PathBuf;

/// What went wrong, and where. The `Display` of each variant is the context
/// (which file, doing what); the cause is its `source`.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A drive directory could not be read.
    #[error("reading drive {}", path.display())]
    Drive {
        /// The directory.
        path: PathBuf,
        /// The reader's error (file, line, column).
        #[source]
        source: Box<deadreckon_io::IoError>,
    },
    /// A comma2k19 segment could not be read.
    #[error("reading comma2k19 segment {}", path.display())]
    Comma2k19 {
        /// The segment directory.
        path: PathBuf,
        /// The reader's error.
        #[source]
        source: Box<deadreckon_import::ImportError>,
    },
    /// A tricycle log could not be read.
    #[error("reading tricycle log {}", path.display())]
    Tricycle {
        /// The log file.
        path: PathBuf,
        /// The reader's error.
        #[source]
        source: Box<deadreckon_import::ImportError>,
    },
    /// A topic mapping file could not be read.
    #[error("reading mapping {}", path.display())]
    MappingFile {
        /// The mapping file.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// A topic mapping file is not a valid mapping.
    #[error("mapping {}", path.display())]
    Mapping {
        /// The mapping file.
        path: PathBuf,
        /// The parser's error.
        #[source]
        source: Box<deadreckon_ros::RosError>,
    },
    /// A ROS bag or MCAP file could not be read.
    #[error("reading {}", path.display())]
    Ros {
        /// The recording.
        path: PathBuf,
        /// The reader's error.
        #[source]
        source: Box<deadreckon_ros::RosError>,
    },
    /// The path is none of the sources the tool reads.
    #[error("{}: not a drive directory and not a recording this tool reads (.bag, .mcap, comma2k19 segment, tricycle .txt)", path.display())]
    Unrecognised {
        /// The path.
        path: PathBuf,
    },
    /// The cross-stream plausibility checks found data that cannot be right
    /// (a mistake of units, clocks or signs).
    #[error(
        "{}: the streams disagree (a mistake of units, clocks or signs?):\n{findings}\n(--skip-checks reads the drive anyway)",
        path.display()
    )]
    Implausible {
        /// The drive.
        path: PathBuf,
        /// Each error finding on a line: what disagrees, by how much, and the check's name.
        findings: String,
    },
    /// A log could not be imported.
    #[error("importing {}", path.display())]
    Import {
        /// The log.
        path: PathBuf,
        /// The importer's error (file, stream, line).
        #[source]
        source: Box<deadreckon_import::ImportError>,
    },
    /// A CAN import with its own DBC or mapping has no vehicle description.
    #[error("a vehicle description (--vehicle) is required with your own DBC or CAN mapping")]
    NeedsVehicle,
    /// TedriS failed (its configuration, training).
    #[error("TedriS")]
    Tedris(#[source] deadreckon_tedris::Error),
    /// A TedriS model file could not be read.
    #[error("reading the TedriS model {}", path.display())]
    ModelFile {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// A TedriS model file is not a usable model.
    #[error("the TedriS model {}", path.display())]
    Model {
        /// The file.
        path: PathBuf,
        /// Why (JSON, or the checks of `TedrisModel::validate`).
        #[source]
        source: deadreckon_tedris::Error,
    },
    /// A library error with no more context to add (its own message names
    /// what is wrong: an unknown track name, too few poses).
    #[error(transparent)]
    Core(#[from] deadreckon_core::Error),
    /// One step of a calibration failed ("calibrating DIR", "calibrating the
    /// steering").
    #[error("{step}")]
    Step {
        /// What was being done, and on what.
        step: String,
        /// The library's error.
        #[source]
        source: deadreckon_core::Error,
    },
    /// A calibration (or the estimation before it) failed.
    #[error("{what}")]
    Calibration {
        /// What was being done.
        what: &'static str,
        /// The library's error.
        #[source]
        source: deadreckon_core::Error,
    },
    /// A file error that names its file, line and column itself.
    #[error(transparent)]
    Io(#[from] deadreckon_io::IoError),
    /// A scenario that could not be read (its message names the file).
    #[error(transparent)]
    Sim(#[from] deadreckon_sim::SimError),
    /// An evaluation or comparison failed (its message says which step).
    #[error(transparent)]
    Eval(#[from] deadreckon_eval::Error),
    /// A report could not be built or written.
    #[error(transparent)]
    Report(#[from] deadreckon_report::ReportError),
    /// TedriS through outages failed, or an outage window is malformed (its
    /// message says which and why).
    #[error(transparent)]
    Outages(deadreckon_tedris::Error),
    /// The request does not fit the data or the other options (a range
    /// outside the drive, a method the vehicle's shape does not take).
    #[error("{0}")]
    Invalid(String),
    /// Reading, writing or computing something named failed ("reading
    /// parameters p.toml", "calibrating DIR"); the cause is the source.
    #[error("{what}")]
    While {
        /// What was being done, and on what.
        what: String,
        /// The cause.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// An option word is not one of those allowed.
    #[error("unknown {what} `{value}` ({allowed})")]
    UnknownOption {
        /// The option (`timing`, `pass state`, ...).
        what: &'static str,
        /// The word given.
        value: String,
        /// The words allowed, comma-separated.
        allowed: &'static str,
    },
}

/// Adds what was being done to an error: [`Error::While`].
pub(crate) trait While<T> {
    /// The error, with `what` as its context.
    fn doing(self, what: impl FnOnce() -> String) -> Result<T, Error>;
}

impl<T, E: std::error::Error + Send + Sync + 'static> While<T> for Result<T, E> {
    fn doing(self, what: impl FnOnce() -> String) -> Result<T, Error> {
        self.map_err(|e| Error::While {
            what: what(),
            source: Box::new(e),
        })
    }
}

/// Refuses a request: [`Error::Invalid`].
macro_rules! invalid {
    ($($arg:tt)*) => {
        return Err($crate::Error::Invalid(format!($($arg)*)))
    };
}
pub(crate) use invalid;

/// An error and its sources as one line, `outer: inner: ...`: the form
/// `anyhow` prints with `{:#}` (the command line's `error:` lines).
pub fn chain_text(e: &(dyn std::error::Error + 'static)) -> String {
    let mut text = e.to_string();
    let mut cur = e.source();
    while let Some(s) = cur {
        text.push_str(": ");
        text.push_str(&s.to_string());
        cur = s.source();
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chain_text_joins_the_sources_like_anyhow() {
        let e = Error::MappingFile {
            path: "m.toml".into(),
            source: std::io::Error::new(std::io::ErrorKind::NotFound, "gone"),
        };
        assert_eq!(chain_text(&e), "reading mapping m.toml: gone");
    }

    /// The error stays under clippy's `result_large_err` limit (128 bytes):
    /// the readers' errors (96 bytes each) are boxed where a path stands
    /// beside them; the largest variant left is `Io`, an `IoError` by value.
    /// With those unboxed it was 128 bytes, and the lint fired on functions
    /// returning it outside this crate (`deadreckon-bench`, `deadreckon-ffi`'s
    /// tests).
    #[test]
    fn the_error_is_at_most_104_bytes() {
        let size = std::mem::size_of::<super::Error>();
        assert!(size <= 104, "{size}");
    }
}
