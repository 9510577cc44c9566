//! The one error type of this crate: every variant says where (file, topic, byte offset).

use std::fmt;

/// Where in an input a problem was found: the file, and where known the topic and
/// the byte offset of the record (from the start of the file, or of the
/// decompressed chunk when `in_chunk_at` is set).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Location {
    /// The file (or `<memory>` for byte-slice inputs).
    pub file: String,
    /// The topic, where the problem belongs to one.
    pub topic: Option<String>,
    /// Byte offset of the record.
    pub offset: Option<u64>,
    /// Byte offset of the compressed chunk that holds the record, where it is in one
    /// (then `offset` counts from the start of the decompressed chunk data).
    pub in_chunk_at: Option<u64>,
}

impl Location {
    /// A location in `file` with neither topic nor offset.
    pub fn file(file: &str) -> Self {
        Location {
            file: file.to_owned(),
            topic: None,
            offset: None,
            in_chunk_at: None,
        }
    }
    /// The same location at byte `offset`.
    pub fn at(&self, offset: u64) -> Self {
        Location {
            offset: Some(offset),
            ..self.clone()
        }
    }
    /// The same location on `topic`.
    pub fn on(&self, topic: &str) -> Self {
        Location {
            topic: Some(topic.to_owned()),
            ..self.clone()
        }
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file)?;
        if let Some(t) = &self.topic {
            write!(f, ", topic {t}")?;
        }
        match (self.offset, self.in_chunk_at) {
            (Some(o), Some(c)) => write!(f, ", byte {o} of the chunk at byte {c}")?,
            (Some(o), None) => write!(f, ", byte {o}")?,
            (None, Some(c)) => write!(f, ", chunk at byte {c}")?,
            (None, None) => {}
        }
        Ok(())
    }
}

/// Errors of the ROS readers and the MCAP writer.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RosError {
    /// The file could not be read or written.
    #[error("{file}: {source}")]
    Io {
        /// The file.
        file: String,
        /// The operating-system error.
        #[source]
        source: std::io::Error,
    },
    /// The container (bag records, MCAP records) is malformed or truncated.
    #[error("{at}: malformed file: {what}")]
    Format {
        /// Where.
        at: Box<Location>,
        /// What is wrong.
        what: String,
    },
    /// A compressed chunk could not be decompressed, or uses a compression this
    /// build does not support.
    #[error("{at}: cannot decompress {compression} chunk: {what}")]
    Compression {
        /// Where.
        at: Box<Location>,
        /// The compression named by the chunk.
        compression: String,
        /// What failed.
        what: String,
    },
    /// A message could not be decoded as the type its connection or channel names.
    #[error("{at}: cannot decode {msg_type}: {what}")]
    Message {
        /// Where (with the topic).
        at: Box<Location>,
        /// The message type.
        msg_type: String,
        /// What failed.
        what: String,
    },
    /// A topic of the mapping is not in the file.
    #[error("{at}: topic not in the file (topics: {available})")]
    MissingTopic {
        /// Where (with the topic).
        at: Box<Location>,
        /// The topics the file has, comma-separated.
        available: String,
    },
    /// A topic carries a message type the mapped stream kind cannot read.
    #[error("{at}: stream kind {kind} expects {expected}, the topic carries {found}")]
    TypeMismatch {
        /// Where (with the topic).
        at: Box<Location>,
        /// The mapped stream kind.
        kind: String,
        /// The message types the kind accepts.
        expected: String,
        /// The type the file declares.
        found: String,
    },
    /// The mapping (TOML) is not valid.
    #[error("invalid mapping: {0}")]
    Mapping(String),
    /// The tracks cannot be written (e.g. a fix topic without a geodetic origin).
    #[error("{file}: cannot write: {what}")]
    Write {
        /// The output file.
        file: String,
        /// What is wrong.
        what: String,
    },
}

impl RosError {
    pub(crate) fn format(at: Location, what: impl Into<String>) -> Self {
        RosError::Format {
            at: Box::new(at),
            what: what.into(),
        }
    }
}
