//! The one error type of the crate.

use std::path::PathBuf;

/// Everything that can go wrong while importing a log. Each variant says where:
/// the file, and the line and column, byte offset or stream and sample.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ImportError {
    /// A file could not be read.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// A NumPy `.npy` file is malformed or holds an unexpected type or shape.
    #[error("{}: byte {offset}: {message}", path.display())]
    Npy {
        /// The file.
        path: PathBuf,
        /// Byte offset in the file where the problem was found.
        offset: u64,
        /// What is wrong.
        message: String,
    },
    /// A text log line is malformed.
    #[error("{}:{line}:{column}: {message}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// Line number, from 1.
        line: usize,
        /// Column (character) number, from 1.
        column: usize,
        /// What is wrong.
        message: String,
    },
    /// A sample of a stream breaks an invariant (time order, finite value,
    /// plausible counter step, matching array lengths).
    #[error("{}: stream `{stream}`: sample {index} (t={t_s} s): {message}", path.display())]
    Stream {
        /// The file or directory the stream comes from.
        path: PathBuf,
        /// The stream's name.
        stream: String,
        /// Index of the offending sample in its source, from 0.
        index: usize,
        /// Its timestamp, s (NaN when unknown).
        t_s: f64,
        /// What is wrong.
        message: String,
    },
    /// A DBC file cannot be parsed or lacks a message or signal.
    #[error("{}: DBC: {message}", path.display())]
    Dbc {
        /// The DBC file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A signal-to-stream mapping file is malformed.
    #[error("{}: mapping: {message}", path.display())]
    Mapping {
        /// The mapping file.
        path: PathBuf,
        /// What is wrong (TOML errors carry their line and column).
        message: String,
    },
    /// The source is not the kind of file or directory the importer reads
    /// (the message says what it looks like and what to give instead).
    #[error("{}: {message}", path.display())]
    WrongSource {
        /// The source given.
        path: PathBuf,
        /// What it is, and what the importer wants.
        message: String,
    },
    /// The vehicle or the assembled drive does not pass validation.
    #[error("{}: {source}", path.display())]
    Invalid {
        /// The source of the drive.
        path: PathBuf,
        /// The core library's validation error.
        source: deadreckon_core::Error,
    },
}

impl ImportError {
    pub(crate) fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        ImportError::Io {
            path: path.into(),
            source,
        }
    }
}
