//! Errors of the CARMEN reader and writer: each names the file, the 1-based line, the message
//! type and the field, and says what was expected.

use thiserror::Error;

/// Why a CARMEN log could not be read or written. Display gives `file:line: TYPE: …`.
#[derive(Debug, Error)]
pub enum CarmenError {
    /// The file could not be opened or read. The cause is part of the message (not a source
    /// too, which would print it twice in an error chain).
    #[error("{file}: cannot read: {error}")]
    Io { file: String, error: std::io::Error },
    /// The file could not be created or written.
    #[error("{file}: cannot write: {error}")]
    Write { file: String, error: std::io::Error },
    /// The file is not a plain-text log (e.g. gzip-compressed).
    #[error("{file}: {message}")]
    NotText { file: String, message: String },
    /// A line of a known type is malformed.
    #[error("{file}:{line}: {message}: {kind}")]
    Line {
        file: String,
        /// 1-based line number.
        line: usize,
        /// The message type (`ODOM`, `FLASER`, …).
        message: &'static str,
        kind: Box<LineError>,
    },
    /// A reader option is out of range.
    #[error("CARMEN read option `{name}`: expected {expected}, found {value}")]
    BadOption {
        name: String,
        expected: String,
        value: f64,
    },
}

impl CarmenError {
    /// The 1-based line the error is on, if it is about a line.
    pub fn line(&self) -> Option<usize> {
        match self {
            CarmenError::Line { line, .. } => Some(*line),
            _ => None,
        }
    }
}

/// What is wrong with a line of a known type.
#[derive(Debug, Error, PartialEq)]
pub enum LineError {
    /// The line ends before this field.
    #[error("missing field `{field}` (expected `{format}`)")]
    MissingField { field: String, format: &'static str },
    /// A field is present but is not what the format needs (non-numeric, NaN, negative count…).
    #[error("field `{field}`: expected {expected}, found `{found}`")]
    BadField {
        field: String,
        expected: String,
        found: String,
    },
    /// A counted array (`num_readings`, `num_remissions`) does not match the fields present.
    #[error("expected {expected} {what}, found {found} ({hint})")]
    CountMismatch {
        what: &'static str,
        expected: usize,
        found: usize,
        hint: String,
    },
    /// Fields left over after the last field of the format.
    #[error(
        "{count} unexpected field(s) after `logger_timestamp`, first `{first}` \
         (expected `{format}`)"
    )]
    ExtraFields {
        count: usize,
        first: String,
        format: &'static str,
    },
}
