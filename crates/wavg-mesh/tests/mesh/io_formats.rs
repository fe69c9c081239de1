//! Format corner cases of the readers, with line numbers, and fuzzing: no input panics.

use std::path::Path;

use proptest::prelude::*;
use wavg_mesh::{DefectKind, MeshError, TriMesh, analyze};
use wavg_mesh::{Format, LoadNotes, io};

fn parse(text: &str, format: Format) -> Result<(TriMesh, LoadNotes), MeshError> {
    io::parse_bytes(text.as_bytes(), format, Path::new("t"))
}

fn parse_err_line(text: &str, format: Format) -> (usize, String) {
    match parse(text, format) {
        Err(MeshError::Parse { line, message, .. }) => (line, message),
        other => panic!("expected a parse error for {text:?}, got {other:?}"),
    }
}

const SQUARE: &str = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n";

#[test]
fn obj_index_forms() {
    let (m, n) = parse(&format!("{SQUARE}f 1 2 3 4\n"), Format::Obj).unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!((n.polygons, n.non_triangles), (1, 1));
    // Both triangles came from polygon 0; a triangle after it is polygon 1.
    assert_eq!(n.polygon_of, vec![0, 0]);
    let (_, n) = parse(
        &format!(
            "{SQUARE}f 1 2 3 4
f 1 2 4
"
        ),
        Format::Obj,
    )
    .unwrap();
    assert_eq!(n.polygon_of, vec![0, 0, 1]);
    let (_, n) = parse(
        &format!(
            "{SQUARE}f 1 2 3
f 1 3 4
"
        ),
        Format::Obj,
    )
    .unwrap();
    assert!(n.polygon_of.is_empty(), "all triangles: {:?}", n.polygon_of);
    let (m, _) = parse(&format!("{SQUARE}f -4 -3 -2\n"), Format::Obj).unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2]]);
    let (m, _) = parse(
        &format!("{SQUARE}vn 0 0 1\nf 1//1 2//1 3//1\nf 1// 3// 4//\n"),
        Format::Obj,
    )
    .unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert!(m.uv.is_none());
    // Colours after the position (here NaN) are ignored.
    let (m, _) = parse(
        "v 0 0 0 nan nan nan\nv 1 0 0 1 1 1\nv 0 1 0 0 0 0\nf 1 2 3\n",
        Format::Obj,
    )
    .unwrap();
    assert!(m.positions.iter().all(|p| p.iter().all(|c| c.is_finite())));
    // A 2-index face is skipped and counted; a face with a vertex defined later is kept.
    let (m, n) = parse(&format!("{SQUARE}f 1 2\nf 1 2 5\nv 0 0 1\n"), Format::Obj).unwrap();
    assert_eq!((n.skipped_faces, m.n_faces(), m.n_vertices()), (1, 1, 5));
    assert_eq!(m.triangles, vec![[0, 1, 4]]);
    assert_eq!(analyze(&m).report.count(DefectKind::IndexOutOfRange), 0);
}

#[test]
fn obj_errors_name_the_line() {
    assert_eq!(
        parse_err_line(&format!("{SQUARE}f 0 1 2\n"), Format::Obj).0,
        5
    );
    assert_eq!(
        parse_err_line(&format!("{SQUARE}\n\nf -5 1 2\n"), Format::Obj).0,
        7
    );
    assert_eq!(parse_err_line("v 1 2\n", Format::Obj).0, 1);
    assert_eq!(parse_err_line("# c\nv 1 2 three\n", Format::Obj).0, 2);
    assert_eq!(
        parse_err_line(&format!("{SQUARE}f 1 2 x\n"), Format::Obj).0,
        5
    );
    assert_eq!(
        parse_err_line(&format!("{SQUARE}f 99999999999 1 2\n"), Format::Obj).0,
        5
    );
    assert_eq!(parse_err_line(&format!("{SQUARE}f\n"), Format::Obj).0, 5);
    let mut bytes = SQUARE.as_bytes().to_vec();
    bytes.extend_from_slice(b"f 1 2 \xff\n");
    match io::parse_bytes(&bytes, Format::Obj, Path::new("t")) {
        Err(MeshError::Parse { line, .. }) => assert_eq!(line, 5),
        other => panic!("{other:?}"),
    }
}

#[test]
fn byte_order_mark_and_crlf_are_accepted() {
    let (m, _) = parse(
        &format!("\u{feff}{}f 1 2 3\r\n", SQUARE.replace('\n', "\r\n")),
        Format::Obj,
    )
    .unwrap();
    assert_eq!((m.n_vertices(), m.n_faces()), (4, 1));
    let (m, _) = parse(
        "\u{feff}OFF\r\n3 1 0\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n3 0 1 2\r\n",
        Format::Off,
    )
    .unwrap();
    assert_eq!(m.n_faces(), 1);
}

#[test]
fn obj_out_of_range_is_kept_for_validation() {
    let (m, _) = parse(&format!("{SQUARE}f 1 2 9\n"), Format::Obj).unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 8]]);
    assert_eq!(analyze(&m).report.count(DefectKind::IndexOutOfRange), 1);
}

#[test]
fn obj_uvs_are_per_corner_and_positions_are_not_split() {
    let text =
        format!("{SQUARE}vt 0 0\nvt 1 0\nvt 1 1\nvt 0.5 0.5\nf 1/1 2/2 3/3\nf 1/4 3/3 4/-1\n");
    let (m, _) = parse(&text, Format::Obj).unwrap();
    assert_eq!(m.n_vertices(), 4);
    let uv = m.uv.unwrap();
    assert_eq!(uv.faces, vec![[0, 1, 2], [3, 2, 3]]);
    // Vertex 0 carries two different UVs (a seam) without being duplicated.
    assert_ne!(
        uv.coords[uv.faces[0][0] as usize],
        uv.coords[uv.faces[1][0] as usize]
    );
    // UVs on only some faces are dropped (and noted).
    let text = format!("{SQUARE}vt 0 0\nf 1/1 2/1 3/1\nf 1 3 4\n");
    let (m, n) = parse(&text, Format::Obj).unwrap();
    assert!(m.uv.is_none() && n.uv_dropped);
    // The notes keep them, the face without any marked by NONE corners.
    let partial = n.partial_uv.unwrap();
    assert_eq!(partial.faces, vec![[0, 0, 0], [wavg_mesh::NONE; 3]]);
    assert_eq!(partial.coords.len(), 1);
}

#[test]
fn off_variants() {
    let (m, n) = parse(
        "# comment\nOFF\n# counts\n4 1 0\n0 0 0\n1 0 0 # x\n\n1 1 0\n0 1 0\n4 0 1 2 3 255 0 0\n",
        Format::Off,
    )
    .unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(n.non_triangles, 1);
    assert_eq!(n.polygon_of, vec![0, 0]);
    let (m, _) = parse("OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", Format::Off).unwrap();
    assert_eq!(m.n_faces(), 1);
    let (m, _) = parse(
        "COFF\n3 1 0\n0 0 0 1 0 0 1\n1 0 0 1 0 0 1\n0 1 0 1 0 0 1\n3 0 1 2\n",
        Format::Off,
    )
    .unwrap();
    assert_eq!(m.n_vertices(), 3);
    let (m, _) = parse("OFF\n0 0 0\n", Format::Off).unwrap();
    assert_eq!(analyze(&m).report.count(DefectKind::Empty), 1);
}

#[test]
fn off_errors_name_the_line() {
    let cases: &[(&str, usize)] = &[
        ("", 1),
        ("PLY\n", 1),
        ("4OFF\n", 1),
        ("OFF BINARY\n", 1),
        ("OFF\n", 2),
        ("OFF\n3 x 0\n", 2),
        ("OFF\n3 1 0\n0 0 0\n1 0\n", 4),
        ("OFF\n3 1 0\n0 0 0\n1 0 0\n", 5),
        ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n", 6),
        ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1\n", 6),
        ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n", 6),
        ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 -2\n", 6),
        // The line after the last one is reported when the file ends early.
        ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n\n# x\n", 8),
        ("OFF\n99999999999 1 0\n", 2),
    ];
    for (text, line) in cases {
        let (l, msg) = parse_err_line(text, Format::Off);
        assert_eq!(l, *line, "{text:?}: {msg}");
    }
    // A huge announced count in a tiny file is an error, not an allocation failure.
    assert_eq!(
        parse_err_line("OFF\n4000000000 4000000000 0\n0 0 0\n", Format::Off).0,
        4
    );
}

#[test]
fn ply_ascii_with_quads_and_vertex_uvs() {
    let text = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
                property double z\nproperty float u\nproperty float v\n\
                element face 1\nproperty list uchar int vertex_indices\nend_header\n\
                0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n4 0 1 2 3\n";
    let (m, n) = parse(text, Format::Ply).unwrap();
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(n.non_triangles, 1);
    let uv = m.uv.unwrap();
    assert_eq!(
        uv.coords[uv.faces[1][2] as usize],
        nalgebra::Vector2::new(0.0, 1.0)
    );
    let bad = "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n0\n";
    assert!(matches!(
        parse(bad, Format::Ply),
        Err(MeshError::Parse { .. })
    ));
    let neg = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
               property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
               end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 -1\n";
    assert!(matches!(
        parse(neg, Format::Ply),
        Err(MeshError::Parse { .. })
    ));
    let trunc = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                 property float z\nend_header\n0 0 0\n1 0 0\n";
    assert!(matches!(
        parse(trunc, Format::Ply),
        Err(MeshError::Parse { .. })
    ));
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// Arbitrary bytes never panic any reader.
    #[test]
    fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400), f in 0usize..3) {
        let format = [Format::Obj, Format::Off, Format::Ply][f];
        if let Ok((m, _)) = io::parse_bytes(&bytes, format, Path::new("r")) {
            let _ = analyze(&m);
        }
    }

    /// Random tokens in the right shape of a file (headers, numbers, indices) never panic.
    #[test]
    fn random_token_files_never_panic(
        toks in proptest::collection::vec(
            prop_oneof![
                Just("v".to_string()), Just("f".to_string()), Just("vt".to_string()),
                Just("\n".to_string()), Just("OFF".to_string()), Just("-1".to_string()),
                Just("0".to_string()), Just("nan".to_string()), Just("1//".to_string()),
                Just("ply\nformat ascii 1.0\n".to_string()), Just("end_header\n".to_string()),
                Just("element vertex 2\n".to_string()), Just("property float x\n".to_string()),
                (0u32..10).prop_map(|i| i.to_string()),
                (-1e3f64..1e3).prop_map(|x| x.to_string()),
            ],
            0..80,
        ),
        f in 0usize..3,
    ) {
        let text = toks.join(" ");
        let format = [Format::Obj, Format::Off, Format::Ply][f];
        if let Ok((m, _)) = io::parse_bytes(text.as_bytes(), format, Path::new("r")) {
            let _ = analyze(&m);
            let _ = wavg_mesh::repair::repair_all(&m, &Default::default());
        }
    }
}
