//! The facade's error type: every failure the library reports (the layers', the
//! applications' and the remesher's), with a coarse kind that every front end maps to its
//! own form in one table (exit code, C status, Python exception class, HTTP status).

use wavg_apps::{AppError, RemeshError};
use wavg_embed::EmbedError;
use wavg_io::npy::NpyError;
use wavg_mesh::MeshError;
use wavg_project::ProjectError;
use wavg_solve::SolveError;

/// Anything [`crate::Surface`], the one-off functions and the applications can fail with.
///
/// Its `Debug` form is the message and the kind, so a `main` that returns
/// `Result<(), wavg::Error>` and fails through `?` prints a readable line:
///
/// ```
/// let e = wavg::Surface::open("missing.obj").unwrap_err();
/// let shown = format!("{e:?}");
/// assert!(shown.contains("missing.obj") && shown.ends_with("(Io)"), "{shown}");
/// ```
#[derive(thiserror::Error)]
pub enum Error {
    /// Loading, validating, repairing or writing a mesh failed.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// Computing, reading or writing an embedding failed.
    #[error(transparent)]
    Embed(#[from] EmbedError),
    /// Building the projector or projecting failed.
    #[error(transparent)]
    Project(#[from] ProjectError),
    /// A forward or inverse problem was refused or has no answer.
    #[error(transparent)]
    Solve(#[from] SolveError),
    /// A valid mesh that this operation cannot use (for example a disconnected mesh for
    /// the embedding); the message says how to fix it.
    #[error("{0}")]
    Unsuitable(String),
    /// A picture application (renderer, texture transfer, decals, maps) refused its inputs
    /// or an image could not be read or written.
    #[error(transparent)]
    App(#[from] AppError),
    /// Semiregular remeshing refused its base mesh or parameters, or an average failed.
    #[error(transparent)]
    Remesh(#[from] RemeshError),
    /// A NumPy `.npy` array could not be read.
    #[error(transparent)]
    Npy(#[from] NpyError),
    /// A precomputation refused before it started: the mesh needs more memory than the
    /// machine has available (the estimate and the available bytes).
    #[error("{0}")]
    OutOfMemory(Box<crate::memory::MemoryShortfall>),
    /// A line of an input file (an anchors file) is malformed or names what the mesh does
    /// not have, or the file as a whole is unusable (line 0: for example no anchors).
    #[error("{}{}: {message}", path.display(), at_line(*line))]
    Input {
        /// The file.
        path: std::path::PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        message: String,
    },
}

/// `:LINE` after a file name, or nothing for line 0 (the whole file).
fn at_line(line: usize) -> String {
    if line == 0 {
        String::new()
    } else {
        format!(":{line}")
    }
}

impl std::fmt::Debug for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} ({:?})", self.message(), self.kind())
    }
}

/// Coarse classes of [`Error`], stable enough to map to exit codes, C statuses, Python
/// exception classes and HTTP statuses. Each kind is either the caller's fault (bad input:
/// exit status 2, HTTP 4xx) or not (exit status 1, HTTP 5xx): see
/// [`ErrorKind::is_callers_fault`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ErrorKind {
    /// A parameter or input value is out of range or malformed. The caller's fault.
    InvalidArgument,
    /// The mesh is not a valid oriented manifold, or not suitable for the operation (e.g.
    /// disconnected, or beyond what the numerics handle). The caller's fault.
    InvalidMesh,
    /// A file the caller named could not be read or parsed (missing, unreadable, corrupt,
    /// an unsupported format, made for another mesh). The caller's fault.
    Io,
    /// The question is well-formed but has no answer (no valid projection). The caller's:
    /// asking a question without an answer is the input's property, not a failure of ours.
    NoSolution,
    /// The caller cancelled the computation. The caller's (its own choice).
    Cancelled,
    /// A file could not be written (a missing folder, no permission, a full disk). Not the
    /// caller's input: the environment failed the library.
    Write,
    /// The library failed on valid input (threads could not start, a bug). Not the
    /// caller's fault.
    Internal,
    /// The computation would need more memory than the machine has available, so it was
    /// refused before it started. Not the caller's input: the machine is too small for it.
    OutOfMemory,
}

impl ErrorKind {
    /// Every kind, for front ends and tests that go through all of them.
    pub const ALL: [ErrorKind; 8] = [
        ErrorKind::InvalidArgument,
        ErrorKind::InvalidMesh,
        ErrorKind::Io,
        ErrorKind::NoSolution,
        ErrorKind::Cancelled,
        ErrorKind::Write,
        ErrorKind::Internal,
        ErrorKind::OutOfMemory,
    ];

    /// True when the caller's input or choice caused the error (a front end answers with
    /// its "bad input" form: exit status 2, HTTP 4xx); false when the environment or the
    /// library failed (exit status 1, HTTP 5xx).
    pub fn is_callers_fault(self) -> bool {
        match self {
            ErrorKind::InvalidArgument
            | ErrorKind::InvalidMesh
            | ErrorKind::Io
            | ErrorKind::NoSolution
            | ErrorKind::Cancelled => true,
            ErrorKind::Write | ErrorKind::Internal | ErrorKind::OutOfMemory => false,
        }
    }
}

impl Error {
    /// The class of this error.
    pub fn kind(&self) -> ErrorKind {
        match self {
            Error::Mesh(e) => mesh_kind(e),
            Error::Embed(e) => embed_kind(e),
            Error::Project(e) => project_kind(e),
            Error::Solve(e) => solve_kind(e),
            Error::Unsuitable(_) => ErrorKind::InvalidMesh,
            Error::App(AppError::Image(_)) => ErrorKind::Io,
            Error::App(AppError::Input(_)) => ErrorKind::InvalidArgument,
            Error::App(AppError::Solve(e)) => solve_kind(e),
            Error::Remesh(e) => remesh_kind(e),
            Error::Npy(_) => ErrorKind::Io,
            Error::Input { .. } => ErrorKind::InvalidArgument,
            Error::OutOfMemory(_) => ErrorKind::OutOfMemory,
        }
    }

    /// The message on one line: the error, then each cause its text does not already
    /// contain, newlines replaced by `"; "` (for a terminal line, a C string, an HTTP
    /// body).
    pub fn message(&self) -> String {
        use std::error::Error as _;
        let mut s = self.to_string();
        let mut cause = self.source();
        while let Some(c) = cause {
            let text = c.to_string();
            if !s.contains(&text) {
                s.push_str(": ");
                s.push_str(&text);
            }
            cause = c.source();
        }
        s.trim_end().replace('\n', "; ")
    }
}

fn mesh_kind(e: &MeshError) -> ErrorKind {
    match e {
        MeshError::Invalid(_) | MeshError::Repair(_) => ErrorKind::InvalidMesh,
        MeshError::InvalidArgument(_) => ErrorKind::InvalidArgument,
        MeshError::Io { .. } | MeshError::Parse { .. } | MeshError::Unsupported { .. } => {
            ErrorKind::Io
        }
        MeshError::Write { .. } => ErrorKind::Write,
    }
}

fn embed_kind(e: &EmbedError) -> ErrorKind {
    match e {
        EmbedError::Cancelled => ErrorKind::Cancelled,
        EmbedError::InvalidArgument(_) => ErrorKind::InvalidArgument,
        // A valid mesh whose geometry defeats a factorisation or an eigen-solver.
        EmbedError::Numerical(_) => ErrorKind::InvalidMesh,
        EmbedError::Io { .. }
        | EmbedError::BadFile { .. }
        | EmbedError::UnsupportedVersion { .. }
        | EmbedError::MeshMismatch { .. } => ErrorKind::Io,
        EmbedError::Write { .. } => ErrorKind::Write,
    }
}

fn project_kind(e: &ProjectError) -> ErrorKind {
    match e {
        ProjectError::NoProjection => ErrorKind::NoSolution,
        ProjectError::EmptyMesh => ErrorKind::InvalidMesh,
        ProjectError::ThreadPool(_) => ErrorKind::Internal,
        ProjectError::CoordinateCount { .. }
        | ProjectError::NonFinite { .. }
        | ProjectError::OutOfRange { .. }
        | ProjectError::TooSmall { .. }
        | ProjectError::NonFiniteQuery
        | ProjectError::StartOutOfRange { .. }
        | ProjectError::FaceOutOfRange { .. }
        | ProjectError::InvalidThreads => ErrorKind::InvalidArgument,
    }
}

fn solve_kind(e: &SolveError) -> ErrorKind {
    match e {
        SolveError::Project(p) => project_kind(p),
        e if e.is_no_solution() => ErrorKind::NoSolution,
        _ => ErrorKind::InvalidArgument,
    }
}

fn remesh_kind(e: &RemeshError) -> ErrorKind {
    match e {
        RemeshError::Solve { source, .. } => solve_kind(source),
        e if e.is_invalid_mesh() => ErrorKind::InvalidMesh,
        _ => ErrorKind::InvalidArgument,
    }
}

/// `Result` with the facade's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Implements `From<E>` for a front end's error type, through [`Error`], for every layer and
/// application error that [`Error`] wraps, so each front end converts with `?` and the
/// list of wrapped errors is kept here only. The front end's type must implement
/// `From<wavg::Error>` (its mapping of [`ErrorKind`] to exit codes, statuses or exceptions).
///
/// ```
/// struct Failure(wavg::ErrorKind);
/// impl From<wavg::Error> for Failure {
///     fn from(e: wavg::Error) -> Self {
///         Failure(e.kind())
///     }
/// }
/// wavg::from_layer_errors!(Failure);
///
/// let Failure(kind) = wavg::MeshError::Repair("no faces left".into()).into();
/// assert_eq!(kind, wavg::ErrorKind::InvalidMesh);
/// ```
#[macro_export]
macro_rules! from_layer_errors {
    ($target:ty) => {
        $crate::from_layer_errors!(
            @each $target;
            $crate::MeshError,
            $crate::EmbedError,
            $crate::project::ProjectError,
            $crate::SolveError,
            $crate::apps::AppError,
            $crate::apps::RemeshError,
            $crate::npy::NpyError
        );
    };
    (@each $target:ty; $($t:ty),*) => {$(
        impl ::core::convert::From<$t> for $target {
            fn from(e: $t) -> Self {
                $crate::Error::from(e).into()
            }
        }
    )*};
}
