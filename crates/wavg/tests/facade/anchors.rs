//! `wavg::anchors`: anchors files read (checked against the mesh, errors naming file and
//! line) and written, and the spread every front end shares.

use wavg::mesh::procedural;
use wavg::sampling::{FpsMetric, farthest_point_vertices};
use wavg::{Anchor, Error, ErrorKind, NoProgress, PrecomputeOptions, Surface, SurfacePoint};

fn torus() -> Surface {
    Surface::from_mesh(procedural::torus(32, 12, 1.0, 0.35)).unwrap()
}

#[test]
fn files_round_trip_and_comments_are_skipped() {
    let s = torus();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("a.txt");
    let anchors = vec![
        Anchor::Vertex(3),
        Anchor::Point(SurfacePoint::new(7, [0.1, 0.2, 0.7])),
        Anchor::Vertex(383),
    ];
    wavg::anchors::write(&path, &anchors).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert_eq!(text, "v 3\nf 7 0.1 0.2 0.7\nv 383\n");
    assert_eq!(wavg::anchors::read(&path, s.mesh()).unwrap(), anchors);
    // A byte order mark, comments and blank lines.
    std::fs::write(&path, "\u{feff}# two\nv 3 # first\n\n  f 7 0.1 0.2 0.7\n").unwrap();
    assert_eq!(
        wavg::anchors::read(&path, s.mesh()).unwrap(),
        anchors[..2].to_vec()
    );
}

#[test]
fn comments_may_hold_any_bytes_and_data_lines_stay_utf8() {
    let s = torus();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("a.txt");
    // A Latin-1 comment (another tool's export), whole-line and after data.
    std::fs::write(&path, b"# caf\xe9 \xa9 2024\nv 3 # \xe9paule\nv 5\n").unwrap();
    assert_eq!(
        wavg::anchors::read(&path, s.mesh()).unwrap(),
        [Anchor::Vertex(3), Anchor::Vertex(5)]
    );
    std::fs::write(&path, b"v 3\nv \xe95\n").unwrap();
    let e = wavg::anchors::read(&path, s.mesh()).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::InvalidArgument);
    let msg = e.to_string();
    assert!(msg.starts_with(&format!("{}:2: ", path.display())), "{msg}");
    assert!(msg.contains("UTF-8"), "{msg}");
}

#[test]
fn only_what_reads_back_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("a.txt");
    let point = |bary| Anchor::Point(SurfacePoint::new(0, bary));
    for (anchors, says) in [
        (vec![], "the anchor set is empty"),
        (
            vec![Anchor::Vertex(1), point([5.0, 0.0, 1.0])],
            "do not sum to 1",
        ),
        (vec![point([-0.5, 0.5, 1.0])], "negative"),
        (vec![point([f64::NAN, 0.5, 0.5])], "not finite"),
    ] {
        let e = wavg::anchors::write(&path, &anchors).unwrap_err();
        assert_eq!(e.kind(), ErrorKind::InvalidArgument, "{anchors:?}");
        assert!(e.to_string().contains(says), "{e}");
        assert!(!path.exists(), "{anchors:?}");
    }
    let ok = [point([0.2, 0.3, 0.5]), Anchor::Vertex(7)];
    wavg::anchors::write(&path, &ok).unwrap();
    assert_eq!(wavg::anchors::read(&path, torus().mesh()).unwrap(), ok);
}

#[test]
fn bad_files_name_the_file_and_line() {
    let s = torus();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("a.txt");
    let shown = path.display().to_string();
    for (text, line, says) in [
        ("v 1\nq 2\n", 2, ""),
        ("v 1\n# c\nv 384\n", 3, "vertex 384 is out of range"),
        ("f 768 0.2 0.3 0.5\n", 1, "face 768 is out of range"),
        ("v 0\nf 1 0.2 0.3 0.9\n", 2, "barycentric"),
        ("v 99999999999\n", 1, "out of range"),
    ] {
        std::fs::write(&path, text).unwrap();
        let e = wavg::anchors::read(&path, s.mesh()).unwrap_err();
        assert_eq!(e.kind(), ErrorKind::InvalidArgument, "{text:?}");
        let msg = e.to_string();
        assert!(msg.starts_with(&format!("{shown}:{line}: ")), "{msg}");
        assert!(msg.contains(says), "{msg}");
        assert!(matches!(e, Error::Input { line: l, .. } if l == line));
    }
    std::fs::write(&path, "# nothing\n\n").unwrap();
    let e = wavg::anchors::read(&path, s.mesh()).unwrap_err();
    assert_eq!(e.to_string(), format!("{shown}: no anchors"));
    let missing = dir.path().join("missing.txt");
    let e = wavg::anchors::read(&missing, s.mesh()).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::Io);
    assert!(e.to_string().contains("missing.txt"), "{e}");
    // A failed write leaves nothing behind.
    let into_missing_dir = dir.path().join("no/such/dir/a.txt");
    let e = wavg::anchors::write(&into_missing_dir, &[Anchor::Vertex(1)]).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::Io);
}

#[test]
fn spread_is_farthest_points_in_the_embedding() {
    let mut s = torus();
    let in_positions = s.spread_anchors(20, 5).unwrap();
    s.precompute(
        &PrecomputeOptions {
            landmarks: 40,
            quality_pairs: 0,
            ..Default::default()
        },
        &NoProgress,
    )
    .unwrap();
    let a = s.spread_anchors(20, 5).unwrap();
    let want = farthest_point_vertices(s.mesh(), 20, 5, FpsMetric::Embedding(s.embedded_coords()))
        .unwrap();
    let ids: Vec<u32> = a
        .iter()
        .map(|a| match a {
            Anchor::Vertex(v) => *v,
            Anchor::Point(_) => panic!("spread anchors are vertices"),
        })
        .collect();
    assert_eq!(ids, want);
    // The embedding decides: the same seed spreads differently in the 3-D positions.
    assert_eq!(in_positions[0], a[0]);
    assert_ne!(in_positions, a);
    // The gap-bounded spread is a prefix of the same order, and its gap is the measured one.
    let (b, gap) = s
        .spread_anchors_to_gap(wavg::anchors::GOOD_GAP, 4, 300, 5)
        .unwrap();
    assert!(gap <= wavg::anchors::GOOD_GAP && b.len() >= 4);
    assert_eq!(b, s.spread_anchors(b.len(), 5).unwrap());
    let bids: Vec<u32> = b
        .iter()
        .map(|a| match a {
            Anchor::Vertex(v) => *v,
            Anchor::Point(_) => unreachable!(),
        })
        .collect();
    assert_eq!(s.largest_gap(&bids), gap);
    assert!(s.largest_gap(&bids[..bids.len() - 1]) > wavg::anchors::GOOD_GAP);
    assert!(s.spread_anchors(s.n_vertices() + 1, 0).is_err());
    assert!(s.spread_anchors(0, 0).unwrap().is_empty());
}
