//! The facade's error type: every failure of the lower crates, with a coarse kind that
//! callers (and the C ABI's status codes) can branch on.

use wavg_embed::EmbedError;
use wavg_mesh::MeshError;
use wavg_project::ProjectError;
use wavg_solve::SolveError;

/// Anything [`crate::Surface`] and the one-off functions can fail with.
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
    /// Loading, validating or repairing a mesh failed.
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
        write!(f, "{self} ({:?})", self.kind())
    }
}

/// Coarse classes of [`Error`], stable enough to map to exit codes or C status codes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ErrorKind {
    /// A parameter or input value is out of range or malformed.
    InvalidArgument,
    /// The mesh is not a valid oriented manifold (or not suitable, e.g. disconnected).
    InvalidMesh,
    /// A file could not be read, parsed or written.
    Io,
    /// The question is well-formed but has no answer (no valid projection).
    NoSolution,
    /// The caller cancelled the computation.
    Cancelled,
}

impl Error {
    /// The class of this error.
    pub fn kind(&self) -> ErrorKind {
        match self {
            Error::Mesh(MeshError::Invalid(_) | MeshError::Repair(_)) => ErrorKind::InvalidMesh,
            Error::Mesh(MeshError::InvalidArgument(_)) => ErrorKind::InvalidArgument,
            Error::Mesh(
                MeshError::Io { .. } | MeshError::Parse { .. } | MeshError::Unsupported { .. },
            ) => ErrorKind::Io,
            Error::Embed(EmbedError::Cancelled) => ErrorKind::Cancelled,
            Error::Embed(EmbedError::InvalidArgument(_)) => ErrorKind::InvalidArgument,
            Error::Embed(EmbedError::Numerical(_)) => ErrorKind::InvalidMesh,
            Error::Embed(_) => ErrorKind::Io,
            Error::Project(ProjectError::NoProjection) => ErrorKind::NoSolution,
            Error::Project(ProjectError::EmptyMesh) => ErrorKind::InvalidMesh,
            Error::Project(_) => ErrorKind::InvalidArgument,
            Error::Solve(e) if e.is_no_solution() => ErrorKind::NoSolution,
            Error::Solve(_) => ErrorKind::InvalidArgument,
            Error::Unsuitable(_) => ErrorKind::InvalidMesh,
            Error::Input { .. } => ErrorKind::InvalidArgument,
        }
    }
}

/// `Result` with the facade's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;
