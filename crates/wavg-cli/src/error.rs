//! The CLI's error: a message and an exit status.

use std::fmt::Display;

/// A failure reported to the user as `wavg: MESSAGE` with exit status `code`.
#[derive(Debug)]
pub struct CliError {
    /// Exit status: 2 for unreadable or malformed input, 1 for other failures, 0 for a
    /// [`CliError::quiet`] stop.
    pub code: u8,
    /// One-line message.
    pub message: String,
}

impl CliError {
    /// Malformed or unreadable input (exit status 2).
    pub fn input(msg: impl Display) -> Self {
        Self {
            code: 2,
            message: msg.to_string(),
        }
    }

    /// A stop that is no failure (standard output closed by its reader): exit status 0,
    /// nothing printed.
    pub fn quiet() -> Self {
        Self {
            code: 0,
            message: String::new(),
        }
    }

    /// Any other failure (exit status 1).
    pub fn failure(msg: impl Display) -> Self {
        Self {
            code: 1,
            message: msg.to_string(),
        }
    }
}
