//! Hostile glTF files: every declared size is checked against the bytes present before
//! anything is allocated, and each broken part gives a typed error, never a panic.

use std::path::Path;

use wavg_mesh::io::gltf::read_limits::{ELEMENTS_PER_BYTE, MAX_DEPTH, MIN_ELEMENTS};
use wavg_mesh::{DefectKind, Format, LoadNotes, MeshError, TriMesh, ValidMesh, analyze, io};
use wavg_testdata::gltf::{Gltf, glb, prim, torus_glb};

fn read(bytes: &[u8]) -> Result<(TriMesh, LoadNotes), MeshError> {
    io::parse_bytes(bytes, Format::Glb, Path::new("hostile.glb"))
}

#[track_caller]
fn refused(bytes: &[u8], expect: &str) {
    match read(bytes) {
        Err(MeshError::Parse { message, .. }) => {
            assert!(message.contains(expect), "{message:?} lacks {expect:?}")
        }
        other => panic!("expected a parse error with {expect:?}, got {other:?}"),
    }
}

/// A torus file whose JSON is edited by `f`.
fn edited(f: impl Fn(&mut Gltf)) -> Vec<u8> {
    let (mut g, _) = torus_glb(6, 4, "Torus");
    f(&mut g);
    g.glb()
}

#[test]
fn declared_counts_beyond_the_buffer_are_refused_before_allocating() {
    let huge = edited(|g| {
        g.accessors[0] = g.accessors[0].replace(r#""count":35"#, r#""count":1099511627776"#)
    });
    refused(&huge, "do not fit in buffer view");
    let past =
        edited(|g| g.views[0] = g.views[0].replace("\"byteLength\":420", "\"byteLength\":4200000"));
    refused(&past, "lies past the end of buffer 0");
    let long_buffer = {
        let (g, _) = torus_glb(6, 4, "Torus");
        let json = g.json(None).replacen(
            &format!(r#""byteLength":{}"#, g.bin.len()),
            r#""byteLength":1000000000"#,
            1,
        );
        glb(&json, &g.bin)
    };
    refused(&long_buffer, "declares 1000000000 bytes but holds");
    let stride = edited(|g| g.views[0] = g.views[0].replace('}', r#","byteStride":8}"#));
    refused(&stride, "smaller than its element");
    let offset = edited(|g| {
        g.accessors[0] = g.accessors[0].replace(
            r#""bufferView":0"#,
            r#""bufferView":0,"byteOffset":4000000000"#,
        )
    });
    refused(&offset, "do not fit");
}

#[test]
fn indices_out_of_range_are_refused() {
    let (g, _) = torus_glb(6, 4, "Torus");
    let mut g2 = g.clone();
    // Rewrite the index buffer's first index to 35 (there are 35 vertices).
    let view: &str = &g2.views[2].clone();
    let at: usize = view
        .split("\"byteOffset\":")
        .nth(1)
        .unwrap()
        .split(',')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    g2.bin[at..at + 4].copy_from_slice(&35u32.to_le_bytes());
    refused(&g2.glb(), "index 35 is out of range (35 vertices)");
    g2.bin[at..at + 4].copy_from_slice(&u32::MAX.to_le_bytes());
    refused(&g2.glb(), "out of range");
}

#[test]
fn sparse_accessors_are_applied_and_their_indices_checked() {
    let mut g = Gltf::default();
    let base = g.floats(&[0., 0., 0., 1., 0., 0., 0., 1., 0.], "VEC3");
    let idx = g.view(&2u32.to_le_bytes());
    let val = g.view(&[0f32, 5., 0.].map(f32::to_le_bytes).concat());
    let sparse = |g: &mut Gltf, index: u32, count: u64| {
        g.bin.truncate(g.bin.len() - 16);
        g.bin.extend(index.to_le_bytes());
        g.bin.extend([0f32, 5., 0.].map(f32::to_le_bytes).concat());
        g.accessors[base] = format!(
            r#"{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","sparse":{{"count":{count},"indices":{{"bufferView":{idx},"componentType":5125}},"values":{{"bufferView":{val}}}}}}}"#
        );
    };
    g.mesh("m", &[prim(base, None, None, 4)]);
    sparse(&mut g, 2, 1);
    let (mesh, _) = read(&g.glb()).unwrap();
    assert_eq!(mesh.positions[2].y, 5.0);
    sparse(&mut g, 3, 1);
    refused(&g.glb(), "index 3 is out of range");
    sparse(&mut g, 0, 1 << 40);
    refused(&g.glb(), "do not fit");
    // Without a buffer view or sparse values there is nothing to read.
    let mut bare = Gltf::default();
    let a = bare.floats(&[0.; 9], "VEC3");
    bare.accessors[a] = r#"{"componentType":5126,"count":1000000000000,"type":"VEC3"}"#.into();
    bare.mesh("m", &[prim(a, None, None, 4)]);
    refused(&bare.glb(), "bufferView");
}

#[test]
fn nan_positions_are_read_and_named_by_validation() {
    let mut g = Gltf::default();
    let a = g.floats(&[0., 0., 0., f32::NAN, 0., 0., 0., 1., 0.], "VEC3");
    // Without `min` (many writers omit it), the file is still read.
    g.accessors[a] = g.accessors[a].replace(r#","min":"#, r#","x":"#);
    g.mesh("m", &[prim(a, None, None, 4)]);
    let (mesh, _) = read(&g.glb()).unwrap();
    let a = analyze(&mesh);
    assert_eq!(a.report.count(DefectKind::NonFiniteCoordinate), 1);
    assert!(matches!(ValidMesh::new(mesh), Err(MeshError::Invalid(_))));
}

#[test]
fn node_graphs_that_are_not_trees_are_refused() {
    let cycle = edited(|g| {
        g.nodes.clear();
        g.node(r#"{"mesh":0,"children":[1]}"#);
        g.node(r#"{"children":[0]}"#);
        g.roots = Some(vec![0]);
    });
    refused(&cycle, "reached twice");
    let shared = edited(|g| {
        g.nodes.clear();
        g.node(r#"{"children":[2]}"#);
        g.node(r#"{"children":[2]}"#);
        g.node(r#"{"mesh":0}"#);
        g.roots = Some(vec![0, 1]);
    });
    refused(&shared, "reached twice");
    let deep = edited(|g| {
        g.nodes.clear();
        for i in 0..MAX_DEPTH + 5 {
            g.node(&format!(r#"{{"children":[{}]}}"#, i + 1));
        }
        g.node(r#"{"mesh":0}"#);
        g.roots = Some(vec![0]);
    });
    refused(&deep, "nested deeper than");
}

#[test]
fn instancing_beyond_the_budget_is_refused() {
    // Each node costs about ten bytes of JSON and reads 35 positions, 35 texture
    // coordinates and 144 indices: far more than ELEMENTS_PER_BYTE per byte.
    let n = (MIN_ELEMENTS / (214 - 10 * ELEMENTS_PER_BYTE)) as usize + 1000;
    let many = edited(|g| {
        g.nodes.clear();
        for _ in 0..n {
            g.node(r#"{"mesh":0}"#);
        }
    });
    refused(&many, "exceed");
    // A handful of instances is fine.
    let few = edited(|g| {
        for _ in 0..4 {
            g.node(r#"{"mesh":0}"#);
        }
    });
    assert_eq!(read(&few).unwrap().0.n_faces(), 5 * 48);
}

#[test]
fn unsupported_content_gets_a_clear_message() {
    let draco = edited(|g| {
        g.extra.push(r#""extensionsRequired":["KHR_draco_mesh_compression"],"extensionsUsed":["KHR_draco_mesh_compression"]"#.into())
    });
    refused(&draco, "required extension");
    let ints = edited(|g| g.accessors[0] = g.accessors[0].replace("5126", "5123"));
    refused(&ints, "positions must be VEC3 of FLOAT");
    let uv_count =
        edited(|g| g.accessors[1] = g.accessors[1].replace(r#""count":35"#, r#""count":34"#));
    refused(&uv_count, "TEXCOORD_0 has 34 elements, POSITION 35");
    let no_position = edited(|g| g.meshes[0] = g.meshes[0].replace("POSITION", "NORMAL"));
    refused(&no_position, "POSITION");
    refused(b"{not json", "glTF");
    refused(
        br#"{"asset":{"version":"2.0"},"meshes":[{"primitives":[{"attributes":{"POSITION":7}}]}]}"#,
        "invalid glTF",
    );
    refused(b"glTF\x01\0\0\0", "");
    let outside = edited(|g| g.images.push(r#"{"uri":"/etc/passwd"}"#.into()));
    assert!(
        read(&outside).is_ok(),
        "an image no material uses is never opened"
    );
}

#[test]
fn every_truncation_and_byte_flip_gives_a_result_or_an_error() {
    let (_, bytes) = torus_glb(4, 3, "Torus");
    for cut in 0..bytes.len() {
        let _ = read(&bytes[..cut]);
    }
    let mut state = 0x2545_f491_4f6c_dd1du64;
    for _ in 0..3000 {
        let mut b = bytes.clone();
        for _ in 0..3 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let at = (state % b.len() as u64) as usize;
            b[at] = (state >> 32) as u8;
        }
        if let Ok((m, _)) = read(&b) {
            let _ = ValidMesh::new(m);
        }
    }
}
