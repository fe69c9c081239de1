//! The error taxonomy: every kind says whether it is the caller's fault, every library error
//! type converts into `wavg::Error` with the expected kind, and messages are one line.

use std::path::PathBuf;

use wavg::apps::{AppError, BaseMesh, RemeshError};
use wavg::mesh::{io, procedural};
use wavg::npy::NpyError;
use wavg::project::ProjectError;
use wavg::{EmbedError, Error, ErrorKind, MeshError, SolveError, TriMesh, ValidMesh};

fn kind(e: impl Into<Error>) -> ErrorKind {
    e.into().kind()
}

#[test]
fn every_kind_is_listed_once_and_classed() {
    // Exhaustive: a new kind fails to compile here until it is classed.
    let expected_callers = |k: ErrorKind| match k {
        ErrorKind::InvalidArgument
        | ErrorKind::InvalidMesh
        | ErrorKind::Io
        | ErrorKind::NoSolution
        | ErrorKind::Cancelled => true,
        ErrorKind::Write | ErrorKind::Internal | ErrorKind::OutOfMemory => false,
    };
    let all: std::collections::HashSet<_> = ErrorKind::ALL.into_iter().collect();
    assert_eq!(all.len(), ErrorKind::ALL.len(), "a kind is listed twice");
    for k in [
        ErrorKind::InvalidArgument,
        ErrorKind::InvalidMesh,
        ErrorKind::Io,
        ErrorKind::NoSolution,
        ErrorKind::Cancelled,
        ErrorKind::Write,
        ErrorKind::Internal,
        ErrorKind::OutOfMemory,
    ] {
        assert!(all.contains(&k), "{k:?} missing from ErrorKind::ALL");
        assert_eq!(k.is_callers_fault(), expected_callers(k), "{k:?}");
    }
    assert_eq!(ErrorKind::ALL.len(), 8);
}

#[test]
fn mesh_errors_are_classed() {
    let dir = tempfile::tempdir().unwrap();
    assert_eq!(
        kind(io::load(&dir.path().join("missing.obj")).unwrap_err()),
        ErrorKind::Io
    );
    let bad = dir.path().join("bad.obj");
    std::fs::write(&bad, "f 1 2 x\n").unwrap();
    assert_eq!(kind(io::load(&bad).unwrap_err()), ErrorKind::Io);
    assert_eq!(
        kind(io::save(&dir.path().join("a.stl"), &procedural::icosphere(0)).unwrap_err()),
        ErrorKind::Io
    );
    let nowhere = dir.path().join("no/such/folder/m.obj");
    let e = io::save(&nowhere, &procedural::icosphere(0)).unwrap_err();
    assert!(matches!(e, MeshError::Write { .. }), "{e:?}");
    assert_eq!(kind(e), ErrorKind::Write);
    let mut m: TriMesh = procedural::icosphere(0);
    m.triangles[0] = [0, 0, 1];
    assert_eq!(kind(ValidMesh::new(m).unwrap_err()), ErrorKind::InvalidMesh);
    assert_eq!(
        kind(procedural::builtin("nope").unwrap_err()),
        ErrorKind::InvalidArgument
    );
}

#[test]
fn embed_errors_are_classed() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = procedural::icosphere(1);
    let missing = dir.path().join("missing.wavg");
    assert_eq!(
        kind(wavg::embed::file::load(&missing, &mesh).unwrap_err()),
        ErrorKind::Io
    );
    let junk = dir.path().join("junk.wavg");
    std::fs::write(&junk, b"not an embedding").unwrap();
    assert_eq!(
        kind(wavg::embed::file::load(&junk, &mesh).unwrap_err()),
        ErrorKind::Io
    );
    let path = PathBuf::from("x.wavg");
    let io_err = || std::io::Error::other("disk full");
    assert_eq!(
        kind(EmbedError::Write {
            path,
            source: io_err()
        }),
        ErrorKind::Write
    );
    assert_eq!(kind(EmbedError::Cancelled), ErrorKind::Cancelled);
    assert_eq!(
        kind(EmbedError::Numerical("x".into())),
        ErrorKind::InvalidMesh
    );
    assert_eq!(
        kind(EmbedError::InvalidArgument("x".into())),
        ErrorKind::InvalidArgument
    );
}

#[test]
fn projection_and_solver_errors_are_classed() {
    assert_eq!(kind(ProjectError::NoProjection), ErrorKind::NoSolution);
    assert_eq!(kind(ProjectError::EmptyMesh), ErrorKind::InvalidMesh);
    assert_eq!(
        kind(ProjectError::NonFiniteQuery),
        ErrorKind::InvalidArgument
    );
    assert_eq!(
        kind(ProjectError::ThreadPool("no threads".into())),
        ErrorKind::Internal
    );
    assert_eq!(kind(SolveError::NoWeightedAverage), ErrorKind::NoSolution);
    assert_eq!(kind(SolveError::DegenerateAnchors), ErrorKind::NoSolution);
    assert_eq!(
        kind(SolveError::WeightCount {
            expected: 3,
            got: 2
        }),
        ErrorKind::InvalidArgument
    );
    assert_eq!(
        kind(SolveError::Project(ProjectError::NoProjection)),
        ErrorKind::NoSolution
    );
    assert_eq!(
        kind(SolveError::Project(ProjectError::ThreadPool("x".into()))),
        ErrorKind::Internal
    );
}

#[test]
fn application_and_remesher_errors_are_classed() {
    assert_eq!(
        kind(AppError::Image("x.png: not a PNG".into())),
        ErrorKind::Io
    );
    assert_eq!(
        kind(AppError::Input("no UVs".into())),
        ErrorKind::InvalidArgument
    );
    assert_eq!(
        kind(AppError::Solve(SolveError::NoWeightedAverage)),
        ErrorKind::NoSolution
    );
    assert_eq!(
        kind(wavg::apps::Image::read_png(std::path::Path::new("/no/such.png")).unwrap_err()),
        ErrorKind::Io
    );

    assert_eq!(
        kind(BaseMesh::from_obj_str("v 0 0\n").unwrap_err()),
        ErrorKind::InvalidArgument
    );
    let fin = BaseMesh {
        positions: vec![wavg::Vector3::zeros(); 5],
        faces: vec![vec![0, 1, 2], vec![0, 1, 3], vec![0, 1, 4]],
    };
    let e = fin.validate().unwrap_err();
    assert!(matches!(e, RemeshError::NonManifold { .. }), "{e:?}");
    assert_eq!(kind(e), ErrorKind::InvalidMesh);
    assert_eq!(
        kind(RemeshError::InvalidParameter("x".into())),
        ErrorKind::InvalidArgument
    );
    let solve = |source| RemeshError::Solve {
        stage: "level 1".into(),
        vertex: 0,
        source,
    };
    assert_eq!(
        kind(solve(SolveError::NoWeightedAverage)),
        ErrorKind::NoSolution
    );
    assert_eq!(
        kind(solve(SolveError::FaceOutOfRange { face: 9, count: 1 })),
        ErrorKind::InvalidArgument
    );
}

#[test]
fn npy_errors_are_classed() {
    let e: NpyError = wavg::npy::read_matrix(&b"not npy"[..]).unwrap_err();
    assert_eq!(kind(e), ErrorKind::Io);
}

#[test]
fn messages_are_one_line_with_their_causes() {
    let e = Error::from(MeshError::InvalidArgument("first\nsecond\n".into()));
    assert_eq!(e.message(), "first; second");
    let e = Error::from(EmbedError::Write {
        path: "out.wavg".into(),
        source: std::io::Error::other("no space left"),
    });
    assert_eq!(e.message(), "out.wavg: no space left");
    assert!(format!("{e:?}").ends_with("(Write)"));
}
