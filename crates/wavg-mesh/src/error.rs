//! The crate's error type.

use std::path::PathBuf;

use crate::defect::ValidationReport;

/// Everything that can go wrong loading, validating or repairing a mesh.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// The mesh failed validation; the report lists every defect.
    #[error("{0}")]
    Invalid(Box<ValidationReport>),
    /// Reading a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// Writing a file failed (a missing folder, no permission, a full disk).
    #[error("{path}: {source}")]
    Write {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// A file could not be parsed.
    #[error("{}{}: {message}", path.display(), LineNo(*line))]
    Parse {
        /// The file.
        path: PathBuf,
        /// 1-based line number (0 when the format has no lines, e.g. binary PLY).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// The file extension or format is not supported.
    #[error("{path}: unsupported format: {message}")]
    Unsupported {
        /// The file.
        path: PathBuf,
        /// What is not supported.
        message: String,
    },
    /// A repair could not produce a usable mesh (for example: nothing left).
    #[error("repair failed: {0}")]
    Repair(String),
    /// An argument was out of range (for example an unknown builtin mesh name).
    #[error("{0}")]
    InvalidArgument(String),
}

/// `:LINE` after a file name, or nothing for line 0 (no lines: binary data, compression).
struct LineNo(usize);

impl std::fmt::Display for LineNo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.0 {
            0 => Ok(()),
            n => write!(f, ":{n}"),
        }
    }
}
