//! The front door: opening, embedding, saving and loading, solvers, one-off functions and
//! the error kinds callers branch on.

use std::sync::atomic::{AtomicUsize, Ordering};

use wavg::mesh::procedural;
use wavg::{
    Error, ErrorKind, ForwardOptions, NoProgress, PrecomputeOptions, Progress, Stage, Surface,
    SurfacePoint,
};

fn small_opts() -> PrecomputeOptions {
    PrecomputeOptions {
        landmarks: 40,
        quality_pairs: 64,
        ..Default::default()
    }
}

fn torus() -> Surface {
    Surface::from_mesh(procedural::torus(32, 12, 1.0, 0.35)).unwrap()
}

#[test]
fn builtin_meshes_open_wherever_a_mesh_path_is_taken() {
    let s = Surface::open("builtin:torus").unwrap();
    assert_eq!(s.mesh().n_vertices(), 1536);
    let e = Surface::open_with_embedding("builtin:torus", None).unwrap();
    assert_eq!(e.mesh().triangles, s.mesh().triangles);
    let bad = Surface::open("builtin:teapot").unwrap_err();
    assert_eq!(bad.kind(), ErrorKind::InvalidArgument);
    assert!(bad.to_string().contains("available: icosphere"), "{bad}");
    // Anything else is a file name.
    let dir = tempfile::tempdir().unwrap();
    let missing = Surface::open(dir.path().join("builtin:torus")).unwrap_err();
    assert_eq!(missing.kind(), ErrorKind::Io);
}

#[test]
fn surface_is_send_sync_and_cheap_to_clone() {
    fn check<T: Send + Sync + Clone>() {}
    check::<Surface>();
    let s = torus();
    let c = s.clone();
    assert!(std::sync::Arc::ptr_eq(s.mesh(), c.mesh()));
    assert!(std::sync::Arc::ptr_eq(s.projector(), c.projector()));
}

#[test]
fn fresh_surface_embeds_positions() {
    let s = torus();
    assert!(s.embedding().is_none());
    assert!(s.landmarks().is_empty());
    for (v, c) in s.embedded_coords().iter().enumerate().step_by(37) {
        let p = s.mesh().positions[v];
        assert_eq!(&c.as_slice()[..3], p.as_slice());
        assert!(c.as_slice()[3..].iter().all(|&x| x == 0.0));
    }
    // Vertex points sit on their vertex.
    for v in [0u32, 5, 100] {
        let p = s.vertex_point(v).unwrap();
        assert_eq!(s.position(&p).unwrap(), s.mesh().positions[v as usize]);
    }
    let e = s.vertex_point(s.n_vertices() as u32).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::InvalidArgument);
    let e = s
        .position(&SurfacePoint::new(0, [0.5, 0.5, 0.5]))
        .unwrap_err();
    assert_eq!(e.kind(), ErrorKind::InvalidArgument);
}

#[test]
fn precompute_save_load_round_trip() {
    let mut s = torus();
    let before = s.clone();
    let report = s.precompute(&small_opts(), &NoProgress).unwrap();
    assert_eq!(report.landmarks, 40);
    assert_eq!(s.landmarks().len(), 40);
    assert_eq!(s.embedding().unwrap().coords.len(), s.n_vertices());
    // The clone taken before keeps its own (positional) embedding.
    assert!(before.embedding().is_none());
    assert!(!std::sync::Arc::ptr_eq(s.projector(), before.projector()));

    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.wavg");
    s.save_embedding(&path).unwrap();
    let mut t = torus();
    t.load_embedding(&path).unwrap();
    assert_eq!(t.embedding(), s.embedding());
    assert_eq!(t.embedded_coords(), s.embedded_coords());
    // Built once on the file's embedding: the same surface as loading it afterwards.
    let mesh = wavg::ValidMesh::new(procedural::torus(32, 12, 1.0, 0.35)).unwrap();
    let once = Surface::from_valid_and_file(mesh.clone(), Some(&path)).unwrap();
    assert_eq!(once.embedding(), s.embedding());
    assert_eq!(once.embedded_coords(), s.embedded_coords());
    assert!(
        Surface::from_valid_and_file(mesh, None)
            .unwrap()
            .embedding()
            .is_none()
    );
    // In one call from the mesh file (binary PLY keeps every coordinate's bits).
    let mesh_path = dir.path().join("t.ply");
    wavg::mesh::io::save(&mesh_path, &procedural::torus(32, 12, 1.0, 0.35)).unwrap();
    let opened = Surface::open_with_embedding(&mesh_path, Some(&path)).unwrap();
    assert_eq!(opened.embedding(), s.embedding());
    assert_eq!(opened.embedded_coords(), s.embedded_coords());
    let plain = Surface::open_with_embedding(&mesh_path, None).unwrap();
    assert!(plain.embedding().is_none());
    let e =
        Surface::open_with_embedding(&mesh_path, Some(&dir.path().join("none.wavg"))).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::Io, "{e}");

    // Loading onto another mesh fails and leaves the surface as it was.
    let mut other = Surface::from_mesh(procedural::icosphere(2)).unwrap();
    let e = other.load_embedding(&path).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::Io, "{e}");
    assert!(other.embedding().is_none());
    // A truncated file is an I/O error too.
    let bytes = std::fs::read(&path).unwrap();
    std::fs::write(&path, &bytes[..bytes.len() / 2]).unwrap();
    assert_eq!(t.load_embedding(&path).unwrap_err().kind(), ErrorKind::Io);
    assert_eq!(
        t.load_embedding(dir.path().join("missing.wavg"))
            .unwrap_err()
            .kind(),
        ErrorKind::Io
    );
}

#[test]
fn embedding_distances_are_zero_at_the_source_and_checked() {
    let s = torus();
    let d = s.embedding_distances(5u32).unwrap();
    assert_eq!(d.len(), s.n_vertices());
    assert_eq!(d[5], 0.0);
    // Without an embedding the distance is the 3-D one.
    let (a, b) = (s.mesh().positions[5], s.mesh().positions[77]);
    assert!((d[77] - (a - b).norm()).abs() < 1e-12);
    // A point between a face's corners is nearer to each corner than the corners' spread.
    let tri = s.mesh().triangles[3];
    let mid = s
        .embedding_distances(SurfacePoint::new(3, [1.0 / 3.0; 3]))
        .unwrap();
    assert!(tri.iter().all(|&v| mid[v as usize] > 0.0));
    let e = s.embedding_distances(s.n_vertices() as u32).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::InvalidArgument);
    let e = s
        .embedding_distances(SurfacePoint::new(3, [0.5, 0.5, 0.5]))
        .unwrap_err();
    assert_eq!(e.kind(), ErrorKind::InvalidArgument);
}

#[test]
fn saving_without_an_embedding_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("none.wavg");
    let e = torus().save_embedding(&path).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::InvalidArgument);
    assert!(!path.exists());
}

struct CancelAfter {
    calls: AtomicUsize,
    limit: usize,
}

impl Progress for CancelAfter {
    fn report(&self, _stage: Stage, _fraction: f64) {
        self.calls.fetch_add(1, Ordering::Relaxed);
    }
    fn cancelled(&self) -> bool {
        self.calls.load(Ordering::Relaxed) >= self.limit
    }
}

#[test]
fn cancelled_precompute_leaves_the_surface_unchanged() {
    let mut s = torus();
    let p = CancelAfter {
        calls: AtomicUsize::new(0),
        limit: 1,
    };
    let e = s.precompute(&small_opts(), &p).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::Cancelled);
    assert!(matches!(e, Error::Embed(_)));
    assert!(s.embedding().is_none());
}

#[test]
fn bad_meshes_are_invalid_mesh_errors() {
    let tri = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ];
    let faces = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
    assert!(Surface::from_arrays(&tri, &faces).is_ok());
    let out_of_range = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 7]];
    let e = Surface::from_arrays(&tri, &out_of_range).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::InvalidMesh);
    let mut nan = tri;
    nan[2][1] = f64::NAN;
    assert_eq!(
        Surface::from_arrays(&nan, &faces).unwrap_err().kind(),
        ErrorKind::InvalidMesh
    );
    // Non-manifold: a fifth triangle on an existing edge.
    let mut five = tri.to_vec();
    five.push([1.0, 1.0, 1.0]);
    let nm = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2], [0, 1, 4]];
    assert_eq!(
        Surface::from_arrays(&five, &nm).unwrap_err().kind(),
        ErrorKind::InvalidMesh
    );
    let dir = tempfile::tempdir().unwrap();
    let e = Surface::open(dir.path().join("missing.obj")).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::Io);
    let junk = dir.path().join("junk.obj");
    std::fs::write(&junk, "v 0 0 0\nf 1 2 x\n").unwrap();
    assert_eq!(Surface::open(&junk).unwrap_err().kind(), ErrorKind::Io);
}

#[test]
fn disconnected_meshes_cannot_be_embedded() {
    let mut two = procedural::icosphere(2);
    let other = procedural::icosphere(2).map_positions(|p| p + wavg::Vector3::new(3.0, 0.0, 0.0));
    let n = two.n_vertices() as u32;
    two.positions.extend(other.positions);
    two.triangles
        .extend(other.triangles.iter().map(|t| t.map(|v| v + n)));
    let mut s = Surface::from_mesh(two).unwrap();
    let e = s.precompute(&small_opts(), &NoProgress).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::InvalidMesh, "{e}");
    assert!(e.to_string().contains("2 connected components"));
    assert!(s.embedding().is_none());
}

#[test]
fn open_reads_a_mesh_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("sphere.obj");
    let mesh = procedural::icosphere(2);
    wavg::mesh::io::save(&path, &mesh).unwrap();
    let s = Surface::open(&path).unwrap();
    assert_eq!(
        (s.n_vertices(), s.n_faces()),
        (mesh.n_vertices(), mesh.n_faces())
    );
}

#[test]
fn solvers_and_one_offs_agree() {
    let mut s = torus();
    s.precompute(&small_opts(), &NoProgress).unwrap();
    // The anchor set this test was written for (farthest points along edges): with the
    // embedding's farthest points (`spread_anchors`), face 40's round trip does not lead back.
    let anchors: Vec<wavg::Anchor> = wavg::sampling::farthest_point_vertices(
        s.mesh(),
        12,
        3,
        wavg::sampling::FpsMetric::EdgeGraph,
    )
    .unwrap()
    .into_iter()
    .map(wavg::Anchor::Vertex)
    .collect();
    assert_eq!(anchors.len(), 12);
    assert_eq!(s.spread_anchors(12, 3).unwrap().len(), 12);
    let ids: Vec<u32> = anchors
        .iter()
        .map(|a| match a {
            wavg::Anchor::Vertex(v) => *v,
            wavg::Anchor::Point(_) => panic!("spread anchors are vertices"),
        })
        .collect();
    // The same anchors given as vertex ids, as anchors and as surface points.
    let by_id = s.solver(ids.iter().copied()).unwrap();
    let by_anchor = s.solver(anchors.clone()).unwrap();
    let points: Vec<SurfacePoint> = ids.iter().map(|&v| s.vertex_point(v).unwrap()).collect();
    let by_point = s.solver(points.iter().copied()).unwrap();

    let x = SurfacePoint::new(40, [0.1, 0.6, 0.3]);
    let w = by_id.inverse(&x).unwrap();
    assert_eq!(w, by_anchor.inverse(&x).unwrap());
    let wp = by_point.inverse(&x).unwrap();
    for (a, b) in w.iter().zip(&wp) {
        assert!((a - b).abs() < 1e-9);
    }
    assert_eq!(
        w,
        wavg::barycentric_weights(&s, ids.iter().copied(), &x).unwrap()
    );

    let back = by_id.forward(&w, &ForwardOptions::default()).unwrap();
    let once = wavg::weighted_average(&s, ids.iter().copied(), &w).unwrap();
    assert_eq!(back, once);
    assert!((back.position - s.position(&x).unwrap()).norm() < 1e-6);

    // Bad queries are typed errors, not panics.
    let e = wavg::weighted_average(&s, ids.iter().copied(), &[1.0]).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::InvalidArgument);
    let mut nan = w.clone();
    nan[0] = f64::NAN;
    assert_eq!(
        by_id
            .forward(&nan, &ForwardOptions::default())
            .map_err(Error::from)
            .unwrap_err()
            .kind(),
        ErrorKind::InvalidArgument
    );
    let e = s.solver([s.n_vertices() as u32]).err().unwrap();
    assert_eq!(e.kind(), ErrorKind::InvalidArgument);
}

/// The facade's old name for a defect kind still names the same type (deprecated).
#[test]
#[allow(deprecated)]
fn problem_kind_is_the_deprecated_name_of_defect_kind() {
    let k: wavg::ProblemKind = wavg::DefectKind::ZeroAreaFace;
    assert_eq!(k, wavg::mesh::DefectKind::ZeroAreaFace);
}
