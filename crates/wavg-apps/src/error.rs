//! The error of the picture applications (renderer, texture transfer).

use std::fmt;

/// What went wrong in a picture application; every variant is about the caller's input
/// or files, so a command can refuse before writing anything.
#[derive(Debug, Clone, PartialEq)]
pub enum AppError {
    /// A PNG image could not be read, decoded or encoded (the message says which and why).
    Image(String),
    /// Inputs that do not fit together: a mesh without UVs, counts that differ, indices
    /// out of range, non-finite values, an empty picture size.
    Input(String),
    /// A solver failed on the whole problem (not a single sample).
    Solve(wavg_solve::SolveError),
}

impl fmt::Display for AppError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Image(m) | Self::Input(m) => f.write_str(m),
            Self::Solve(e) => write!(f, "{e}"),
        }
    }
}

impl std::error::Error for AppError {}

impl From<wavg_solve::SolveError> for AppError {
    fn from(e: wavg_solve::SolveError) -> Self {
        Self::Solve(e)
    }
}
