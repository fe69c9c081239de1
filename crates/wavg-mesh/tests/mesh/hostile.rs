//! Hostile inputs get a typed error (or a result) with work bounded by the bytes present:
//! headers that declare 10^12 elements, a PLY list of 2^32 - 1 indices, a gzip bomb, a
//! single huge line, and meshes made only of degenerate faces.

use std::io::Write;
use std::path::Path;

use wavg_mesh::Format;
use wavg_mesh::io::parse_bytes;
use wavg_mesh::{MeshError, TriMesh, ValidMesh, io};

fn parse(bytes: &[u8], format: Format) -> Result<TriMesh, MeshError> {
    parse_bytes(bytes, format, Path::new("hostile")).map(|(m, _)| m)
}

fn assert_parse_error(bytes: &[u8], format: Format) {
    match parse(bytes, format) {
        Err(MeshError::Parse { .. }) => {}
        other => panic!("expected a parse error, got {other:?}"),
    }
}

#[test]
fn declared_counts_beyond_the_bytes_are_parse_errors() {
    assert_parse_error(b"OFF\n1000000000000 1000000000000 0\n0 0 0\n", Format::Off);
    let ascii = "ply\nformat ascii 1.0\nelement vertex 1000000000000\nproperty float x\n\
                 property float y\nproperty float z\nelement face 1000000000000\n\
                 property list uchar int vertex_indices\nend_header\n0 0 0\n";
    assert_parse_error(ascii.as_bytes(), Format::Ply);
    let header = |nv: &str| {
        format!(
            "ply\nformat binary_little_endian 1.0\nelement vertex {nv}\nproperty float x\n\
             property float y\nproperty float z\nelement face 1\n\
             property list uint int vertex_indices\nend_header\n"
        )
        .into_bytes()
    };
    let mut big = header("1000000000000");
    big.extend(0f32.to_le_bytes().repeat(3));
    assert_parse_error(&big, Format::Ply);
    // Three vertices, then a face whose list claims 2^32 - 1 indices.
    let mut list = header("3");
    for c in [0f32, 0., 0., 1., 0., 0., 0., 1., 0.] {
        list.extend(c.to_le_bytes());
    }
    list.extend(u32::MAX.to_le_bytes());
    list.extend([0u8; 64]);
    assert_parse_error(&list, Format::Ply);
}

#[test]
fn a_huge_line_is_an_error_not_a_hang() {
    let mut obj = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 ".to_vec();
    obj.extend(b"3 ".repeat(4_000_000)); // one 8 MB face line
    obj.push(b'\n');
    // A polygon with millions of corners repeating one index: fan-triangulated into
    // degenerate triangles, which validation then names.
    match parse(&obj, Format::Obj) {
        Ok(m) => assert!(ValidMesh::new(m).is_err()),
        Err(MeshError::Parse { .. }) => {}
        Err(e) => panic!("unexpected error {e}"),
    }
    let mut junk = b"v ".to_vec();
    junk.extend(b"9".repeat(10_000_000));
    assert_parse_error(&junk, Format::Obj);
}

#[test]
fn gzip_bomb_file_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bomb.obj.gz");
    let mut enc = flate2::write::GzEncoder::new(
        std::fs::File::create(&path).unwrap(),
        flate2::Compression::best(),
    );
    let zeros = vec![0u8; 1 << 20];
    for _ in 0..256 {
        enc.write_all(&zeros).unwrap(); // 256 MB of zeros, about 250 KB compressed
    }
    enc.finish().unwrap();
    match io::load(&path) {
        Err(MeshError::Parse { message, .. }) => {
            assert!(message.contains("decompression bomb"), "{message}")
        }
        other => panic!("expected a refusal, got {other:?}"),
    }
}

#[test]
fn degenerate_meshes_are_invalid() {
    // Every vertex at one point.
    let sphere = wavg_mesh::procedural::icosphere(4);
    let n = sphere.n_vertices();
    let collapsed = TriMesh::new(
        vec![nalgebra::Vector3::new(1.0, 2.0, 3.0); n],
        sphere.triangles,
    );
    assert!(matches!(
        ValidMesh::new(collapsed),
        Err(MeshError::Invalid(_))
    ));
    // A million faces that all repeat an index.
    let pos = vec![nalgebra::Vector3::zeros(); 3];
    let tris = vec![[0, 0, 1]; 1_000_000];
    match ValidMesh::new(TriMesh::new(pos, tris)) {
        Err(MeshError::Invalid(report)) => assert!(!report.problems.is_empty()),
        other => panic!("expected invalid, got {other:?}"),
    }
}

/// Faces are judged by their shape whatever the mesh's scale: a sphere scaled by 1e±200
/// (whose squared lengths overflow or underflow; at 1e-305 even the reciprocal of an
/// edge overflows) is valid, a needle among them is caught
/// at every scale, and the computations' range check names the remedy.
#[test]
fn validity_does_not_depend_on_scale() {
    use wavg_mesh::{DefectKind, analyze, coordinates_out_of_range};
    let sphere = wavg_mesh::procedural::icosphere(3);
    for (scale, remedy) in [
        (1e200, Some("down")),
        (1e-200, Some("up")),
        (1e-305, Some("up")),
        (1e30, None),
        (1e-50, None),
    ] {
        let mut m = sphere.clone();
        for p in &mut m.positions {
            *p *= scale;
        }
        assert!(analyze(&m).report.is_valid(), "scale {scale:e}");
        let why = coordinates_out_of_range(&m);
        match remedy {
            Some(r) => assert!(
                why.as_deref()
                    .unwrap()
                    .contains(&format!("scale the mesh {r}"))
            ),
            None => assert!(why.is_none(), "scale {scale:e}: {why:?}"),
        }
        // Corner 0 of face 0 moved onto the middle of its opposite edge: a needle.
        let [a, b, c] = m.triangles[0].map(|i| i as usize);
        m.positions[a] = (m.positions[b] + m.positions[c]) / 2.0;
        let report = analyze(&m).report;
        assert!(
            report.count(DefectKind::ZeroAreaFace) >= 1,
            "scale {scale:e}: {report:?}"
        );
        let repaired = wavg_mesh::repair::drop_degenerate_faces(&m);
        assert!(repaired.mesh.n_faces() < m.n_faces(), "scale {scale:e}");
    }
}
