//! The PLY reader gives the same mesh whatever the layout: ASCII, binary little or big
//! endian, `float` or `double` positions, `int` or `uint` indices, extra properties, and
//! polygons among the triangles (which leave the binary fast path and come back to it),
//! over more than one read block; and a file read from disk streams through it.

use std::path::Path;

use wavg_mesh::{Format, MeshError, TriMesh, io};

/// Positions and polygons (mostly triangles, a quad every 1000th face).
fn polygons(n: usize) -> (Vec<[f64; 3]>, Vec<Vec<u32>>) {
    let pos = (0..n)
        .map(|i| {
            let t = i as f64;
            [t.sin() * 0.5, (t * 0.37).cos(), t / 7.0]
        })
        .collect();
    let faces = (0..2 * n - 4)
        .map(|f| {
            let a = (f / 2) as u32;
            if f % 1000 == 999 {
                vec![a, a + 1, a + 2, a + 3]
            } else {
                vec![a, a + 1, a + 2]
            }
        })
        .collect();
    (pos, faces)
}

#[derive(Clone, Copy)]
struct Layout {
    ascii: bool,
    big: bool,
    float: bool,
    signed: bool,
    /// A `uchar red` between y and z, and a `float quality` after the index list.
    extra: bool,
}

fn file(pos: &[[f64; 3]], faces: &[Vec<u32>], l: Layout) -> Vec<u8> {
    let enc = match (l.ascii, l.big) {
        (true, _) => "ascii",
        (false, true) => "binary_big_endian",
        (false, false) => "binary_little_endian",
    };
    let coord = if l.float { "float" } else { "double" };
    let index = if l.signed { "int" } else { "uint" };
    let red = if l.extra { "property uchar red\n" } else { "" };
    let quality = if l.extra {
        "property float quality\n"
    } else {
        ""
    };
    let mut out = format!(
        "ply\nformat {enc} 1.0\ncomment layout test\nelement vertex {}\nproperty {coord} x\n\
         property {coord} y\n{red}property {coord} z\nelement face {}\n\
         property list uchar {index} vertex_indices\n{quality}end_header\n",
        pos.len(),
        faces.len()
    )
    .into_bytes();
    let num = |out: &mut Vec<u8>, x: f64| match (l.float, l.big) {
        (true, false) => out.extend((x as f32).to_le_bytes()),
        (true, true) => out.extend((x as f32).to_be_bytes()),
        (false, false) => out.extend(x.to_le_bytes()),
        (false, true) => out.extend(x.to_be_bytes()),
    };
    let int = |out: &mut Vec<u8>, i: u32| match l.big {
        false => out.extend(i.to_le_bytes()),
        true => out.extend(i.to_be_bytes()),
    };
    for p in pos {
        if l.ascii {
            let (x, y, z) = if l.float {
                (p[0] as f32 as f64, p[1] as f32 as f64, p[2] as f32 as f64)
            } else {
                (p[0], p[1], p[2])
            };
            let red = if l.extra { " 200" } else { "" };
            out.extend(format!("{x:?} {y:?}{red} {z:?}\n").bytes());
        } else {
            num(&mut out, p[0]);
            num(&mut out, p[1]);
            if l.extra {
                out.push(200);
            }
            num(&mut out, p[2]);
        }
    }
    for f in faces {
        if l.ascii {
            let ids: Vec<String> = f.iter().map(|i| i.to_string()).collect();
            let q = if l.extra { " 0.5" } else { "" };
            out.extend(format!("{} {}{q}\n", f.len(), ids.join(" ")).bytes());
        } else {
            out.push(f.len() as u8);
            for &i in f {
                int(&mut out, i);
            }
            if l.extra {
                let q = 0.5f32;
                out.extend(if l.big {
                    q.to_be_bytes()
                } else {
                    q.to_le_bytes()
                });
            }
        }
    }
    out
}

fn parse(bytes: &[u8]) -> Result<TriMesh, MeshError> {
    io::parse_bytes(bytes, Format::Ply, Path::new("t.ply")).map(|(m, _)| m)
}

#[test]
fn every_layout_reads_the_same_mesh_across_blocks() {
    // 2 x 60,000 faces of 13-17 bytes: more than one 1 MiB block.
    let (pos, faces) = polygons(60_000);
    let mut reference: [Option<TriMesh>; 2] = [None, None];
    for bits in 0..32u32 {
        let l = Layout {
            ascii: bits & 1 != 0,
            big: bits & 2 != 0,
            float: bits & 4 != 0,
            signed: bits & 8 != 0,
            extra: bits & 16 != 0,
        };
        if l.ascii && l.big {
            continue;
        }
        let bytes = file(&pos, &faces, l);
        let (m, notes) = io::parse_bytes(&bytes, Format::Ply, Path::new("t.ply")).unwrap();
        assert_eq!(m.n_vertices(), pos.len());
        assert_eq!(notes.polygons, faces.len());
        assert_eq!(notes.non_triangles, faces.len() / 1000);
        assert_eq!(m.n_faces(), faces.len() + faces.len() / 1000);
        assert_eq!(notes.polygon_of.len(), m.n_faces());
        assert_eq!(m.triangles[998], [499, 500, 501]);
        assert_eq!(&m.triangles[999..1001], &[[499, 500, 501], [499, 501, 502]]);
        assert_eq!(notes.polygon_of[999..1002], [999, 999, 1000]);
        match &reference[l.float as usize] {
            None => reference[l.float as usize] = Some(m),
            Some(r) => {
                assert_eq!(m.positions, r.positions, "layout bits {bits}");
                assert_eq!(m.triangles, r.triangles, "layout bits {bits}");
            }
        }
    }
}

#[test]
fn bad_triangles_in_the_fast_layout_are_errors() {
    let (pos, faces) = polygons(300);
    let l = Layout {
        ascii: false,
        big: false,
        float: true,
        signed: true,
        extra: false,
    };
    let good = file(&pos, &faces, l);
    assert!(parse(&good).is_ok());
    // A negative index in face 5.
    let header = good.len() - 12 * pos.len() - faces.iter().map(|f| 1 + 4 * f.len()).sum::<usize>();
    let at = header + 12 * pos.len() + 13 * 5 + 1;
    let mut neg = good.clone();
    neg[at..at + 4].copy_from_slice(&(-2i32).to_le_bytes());
    match parse(&neg) {
        Err(MeshError::Parse { message, .. }) => assert!(message.contains("face 5"), "{message}"),
        other => panic!("expected a parse error, got {other:?}"),
    }
    // Cut inside a face, inside a vertex, and inside the header.
    for cut in [good.len() - 7, header + 30, header - 5] {
        assert!(
            matches!(parse(&good[..cut]), Err(MeshError::Parse { .. })),
            "cut {cut}"
        );
    }
}

#[test]
fn files_stream_plain_and_gzipped() {
    let (pos, faces) = polygons(20_000);
    let l = Layout {
        ascii: true,
        big: false,
        float: false,
        signed: true,
        extra: true,
    };
    let bytes = file(&pos, &faces, l);
    let expected = parse(&bytes).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let plain = dir.path().join("m.ply");
    std::fs::write(&plain, &bytes).unwrap();
    let gz = dir.path().join("m.ply.gz");
    let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    std::io::Write::write_all(&mut enc, &bytes).unwrap();
    std::fs::write(&gz, enc.finish().unwrap()).unwrap();
    for path in [plain, gz] {
        let m = io::load(&path).unwrap();
        assert_eq!(
            (m.positions, m.triangles),
            (expected.positions.clone(), expected.triangles.clone())
        );
    }
}
