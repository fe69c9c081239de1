//! Refusals: [`ApiError`] and the one table from the library's [`ErrorKind`] to an HTTP
//! status (4xx for the caller's input, 5xx for ours).

use wavg::ErrorKind;

/// A request the server refuses: its HTTP status and a one-line message (sent as
/// `{"error": MESSAGE}`).
#[derive(Clone, Debug, PartialEq)]
pub struct ApiError {
    /// HTTP status (400, 404, 405, 413, 503, 500, 507).
    pub status: u16,
    /// What is wrong, on one line.
    pub message: String,
}

/// The HTTP status of a library failure of `kind`: 400 for what the caller sent (values,
/// meshes, questions without an answer), 500 for failures of the server's own work, 507
/// Insufficient Storage for a precomputation the machine's memory cannot hold.
pub fn status_of(kind: ErrorKind) -> u16 {
    match kind {
        ErrorKind::InvalidArgument | ErrorKind::InvalidMesh | ErrorKind::NoSolution => 400,
        // No request names a file, and nothing cancels a request.
        ErrorKind::Io | ErrorKind::Cancelled => 500,
        ErrorKind::Write | ErrorKind::Internal => 500,
        ErrorKind::OutOfMemory => 507,
    }
}

impl ApiError {
    /// 400 Bad Request.
    pub(crate) fn bad(message: impl Into<String>) -> Self {
        Self::status(400, message)
    }

    /// Any status.
    pub(crate) fn status(status: u16, message: impl Into<String>) -> Self {
        Self {
            status,
            message: message.into(),
        }
    }

    /// A library failure, with the status [`status_of`] its kind.
    pub(crate) fn lib(e: impl Into<wavg::Error>) -> Self {
        let e = e.into();
        Self::status(status_of(e.kind()), e.message())
    }

    /// The same refusal with `what` (the field it is about) before its message.
    pub(crate) fn within(self, what: &str) -> Self {
        Self {
            message: format!("{what}: {}", self.message),
            ..self
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn caller_input_is_4xx_and_our_failures_are_5xx() {
        for kind in [
            ErrorKind::InvalidArgument,
            ErrorKind::InvalidMesh,
            ErrorKind::NoSolution,
        ] {
            assert_eq!(status_of(kind), 400, "{kind:?}");
        }
        for kind in [ErrorKind::Io, ErrorKind::Cancelled] {
            assert_eq!(status_of(kind), 500, "{kind:?}");
        }
        assert_eq!(status_of(ErrorKind::OutOfMemory), 507);
    }

    #[test]
    fn a_library_error_keeps_its_message_on_one_line_and_gets_its_kinds_status() {
        let e = wavg::Surface::open("/nonexistent/dir/mesh.obj").unwrap_err();
        assert_eq!(e.kind(), ErrorKind::Io);
        let a = ApiError::lib(e);
        assert_eq!(a.status, 500);
        assert!(a.message.contains("mesh.obj") && !a.message.contains('\n'));
        let a = ApiError::lib(wavg::SolveError::NoAnchors);
        assert_eq!(a.status, 400, "{}", a.message);
        assert_eq!(
            ApiError::bad("x").within("weights[2]").message,
            "weights[2]: x"
        );
    }
}
