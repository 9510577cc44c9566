//! The one error type of the crate: every variant says where (file, line, column).

use std::path::PathBuf;

/// Errors of reading and writing drive directories, parameter files and tracks.
///
/// Line numbers are 1-based and count the header as line 1, so the first data
/// row is line 2. Column names are the header names of the contract.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum IoError {
    /// A line of a JSON-lines event stream is not a valid event.
    #[error("{source_name}: line {line}, column {column}: {msg}")]
    BadEvent {
        /// The stream's name (a file, or `stdin`).
        source_name: String,
        /// Line, 1-based.
        line: u64,
        /// Column, 1-based.
        column: usize,
        /// What is wrong.
        msg: String,
    },
    /// The drive directory itself does not exist (or is not a directory).
    #[error(
        "{}: {what} (a drive is a directory holding vehicle.toml and the CSV files, or a recording: a comma2k19 segment, a .bag, an .mcap, a tricycle .txt)",
        dir.display()
    )]
    NoDirectory {
        /// The path given.
        dir: PathBuf,
        /// `no such directory` or `not a directory`.
        what: &'static str,
    },
    /// A required file does not exist.
    #[error("{}: missing required file ({note})", path.display())]
    MissingFile {
        /// The file looked for.
        path: PathBuf,
        /// Why it is needed.
        note: String,
    },
    /// Both `wheel_ticks.csv` and `wheel_speeds.csv` exist and no option picks one.
    #[error(
        "{}: both wheel_ticks.csv and wheel_speeds.csv exist; pick one (command line: --wheels ticks|speeds; library: ReadOptions::prefer_wheels)",
        dir.display()
    )]
    AmbiguousWheels {
        /// The drive directory.
        dir: PathBuf,
    },
    /// A required column is not in the header (line 1).
    #[error("{}: line 1: missing column `{column}`", file.display())]
    MissingColumn {
        /// The CSV file.
        file: PathBuf,
        /// The column name of the contract.
        column: String,
    },
    /// The header names a column twice.
    #[error("{}: line 1: column `{column}` appears more than once", file.display())]
    DuplicateColumn {
        /// The CSV file.
        file: PathBuf,
        /// The repeated column name.
        column: String,
    },
    /// A row has a different number of fields than the header.
    #[error(
        "{}: line {line}: expected {expected} fields (as in the header), found {found}",
        file.display()
    )]
    WrongFieldCount {
        /// The CSV file.
        file: PathBuf,
        /// 1-based line of the row.
        line: u64,
        /// Number of header fields.
        expected: usize,
        /// Number of fields in the row.
        found: usize,
    },
    /// A field does not parse as the number its column holds.
    #[error(
        "{}: line {line}, column `{column}`: cannot parse {text:?} as {expected}",
        file.display()
    )]
    BadNumber {
        /// The CSV file.
        file: PathBuf,
        /// 1-based line of the row.
        line: u64,
        /// The column name.
        column: String,
        /// The field as read.
        text: String,
        /// What was expected ("a number", "an integer").
        expected: &'static str,
    },
    /// A field is NaN or infinite.
    #[error("{}: line {line}, column `{column}`: non-finite value {text:?}", file.display())]
    NonFinite {
        /// The CSV file.
        file: PathBuf,
        /// 1-based line of the row.
        line: u64,
        /// The column name.
        column: String,
        /// The field as read.
        text: String,
    },
    /// A timestamp is not after the previous row's (duplicate or unsorted).
    #[error(
        "{}: line {line}, column `t_s`: time {t_s} s {} the previous row's {prev_t_s} s (timestamps must strictly increase)",
        file.display(),
        if t_s == prev_t_s { "duplicates" } else { "is before" }
    )]
    TimeNotIncreasing {
        /// The CSV file.
        file: PathBuf,
        /// 1-based line of the row.
        line: u64,
        /// Its timestamp, s.
        t_s: f64,
        /// The previous row's timestamp, s.
        prev_t_s: f64,
    },
    /// A value is outside the plausible range of its unit (often: the wrong unit).
    #[error("{}: line {line}, column `{column}`: value {value} is out of range: {hint}", file.display())]
    OutOfRange {
        /// The CSV file.
        file: PathBuf,
        /// 1-based line of the row.
        line: u64,
        /// The column name.
        column: String,
        /// The value read.
        value: f64,
        /// The accepted range and the likely mistake.
        hint: String,
    },
    /// A stream has too few rows.
    #[error("{}: {found} data rows, at least {min} needed", file.display())]
    TooFewRows {
        /// The CSV file.
        file: PathBuf,
        /// Rows found.
        found: usize,
        /// Rows needed.
        min: usize,
    },
    /// A CSV file could not be tokenised.
    #[error("{}: line {line}: malformed CSV: {message}", file.display())]
    Csv {
        /// The CSV file.
        file: PathBuf,
        /// 1-based line where the reader stopped.
        line: u64,
        /// The CSV reader's message.
        message: String,
    },
    /// Latitude/longitude cannot be converted without a common origin.
    #[error("{}: {message}", file.display())]
    NeedsOrigin {
        /// The file in latitude/longitude, or the GeoJSON being written.
        file: PathBuf,
        /// What is missing.
        message: String,
    },
    /// A params.toml of another vehicle shape (its `shape` key: a tricycle's
    /// or a differential drive's) given where a four-wheel car's is read.
    #[error("{}: a {} parameter file (shape = \"{shape}\"), not a four-wheel car's", path.display(), shape.replace('_', "-"))]
    OtherShape {
        /// The file.
        path: PathBuf,
        /// Its `shape` key, as written (`tricycle`, `diff_drive`).
        shape: String,
    },
    /// A TOML file does not parse or does not match its contract (the message
    /// from `toml` carries line and column).
    #[error("{}: {message}", path.display())]
    Toml {
        /// The TOML file.
        path: PathBuf,
        /// What is wrong, with line and column where known.
        message: String,
    },
    /// The data read or to be written breaks an invariant of `deadreckon-core`.
    #[error("{}: {source}", path.display())]
    Invalid {
        /// The drive directory or file.
        path: PathBuf,
        /// The failed check.
        #[source]
        source: deadreckon_core::Error,
    },
    /// Data to be written cannot be represented (e.g. a non-finite coordinate in GeoJSON).
    #[error("{}: {message}", path.display())]
    Unwritable {
        /// The file being written.
        path: PathBuf,
        /// What cannot be written.
        message: String,
    },
    /// An operating-system I/O error.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file or directory concerned.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
}

impl IoError {
    /// Wraps an `std::io::Error` with the path it concerns.
    pub(crate) fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        IoError::Io {
            path: path.into(),
            source,
        }
    }
}
