//! The CLI's error: a message and an exit status, and the one table from the library's
//! error kinds to exit statuses.

use std::fmt::Display;

use wavg::ErrorKind;

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

/// The exit status of a library error's kind: 2 for the caller's input (unreadable or
/// malformed), 130 for a cancellation (only Ctrl-C cancels), 1 for any other failure.
pub fn exit_code(kind: ErrorKind) -> u8 {
    match kind {
        ErrorKind::InvalidArgument | ErrorKind::InvalidMesh | ErrorKind::Io => 2,
        ErrorKind::Cancelled => 130,
        ErrorKind::NoSolution | ErrorKind::Write | ErrorKind::Internal => 1,
        ErrorKind::OutOfMemory => 1,
    }
}

impl From<wavg::Error> for CliError {
    fn from(e: wavg::Error) -> Self {
        Self {
            code: exit_code(e.kind()),
            message: e.message(),
        }
    }
}

// Layer and application errors convert through `wavg::Error`.
wavg::from_layer_errors!(CliError);

impl CliError {
    /// The same exit status with another message (one that says more than the library's).
    pub fn with_message(self, message: impl Display) -> Self {
        Self {
            code: self.code,
            message: message.to_string(),
        }
    }

    /// The same error with `context` (a file name, an option) before its message.
    pub fn context(self, context: impl Display) -> Self {
        Self {
            code: self.code,
            message: format!("{context}: {}", self.message),
        }
    }
}

/// `.context(...)` on a library result: the error as a [`CliError`] with the context
/// before its message.
pub trait Context<T> {
    /// Converts the error through the exit-status table and prefixes `context`.
    fn context(self, context: impl Display) -> Result<T, CliError>;
}

impl<T, E: Into<CliError>> Context<T> for Result<T, E> {
    fn context(self, context: impl Display) -> Result<T, CliError> {
        self.map_err(|e| e.into().context(context))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_the_callers_errors_exit_2() {
        for kind in ErrorKind::ALL {
            let code = exit_code(kind);
            assert!(matches!(code, 1 | 2 | 130), "{kind:?}: {code}");
            if !kind.is_callers_fault() {
                assert_eq!(code, 1, "{kind:?}");
            }
        }
        assert_eq!(exit_code(ErrorKind::Io), 2);
        assert_eq!(exit_code(ErrorKind::Write), 1);
    }
}
