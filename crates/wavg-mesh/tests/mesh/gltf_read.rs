//! The glTF reader on files built in code: welding at UV seams (genus and per-corner UVs
//! kept), node transforms, strips and fans, mesh names, `.gltf` with its buffer and image
//! beside it or in `data:` URIs.

use std::path::Path;

use wavg_mesh::io::gltf::TextureSource;
use wavg_mesh::{Format, LoadNotes, MeshError, TriMesh, ValidMesh, analyze, io};
use wavg_testdata::gltf::{Gltf, prim, seamed_torus, split_at_seams, torus_glb};

fn read(bytes: &[u8], name: &str) -> Result<(TriMesh, LoadNotes), MeshError> {
    let format = Format::from_path(Path::new(name)).unwrap().0;
    io::parse_bytes(bytes, format, Path::new(name))
}

fn message(r: Result<(TriMesh, LoadNotes), MeshError>) -> String {
    match r {
        Err(MeshError::Parse {
            message, line: 0, ..
        }) => message,
        other => panic!("expected a parse error, got {other:?}"),
    }
}

#[test]
fn a_seamed_torus_is_welded_closed_with_genus_one_and_its_uvs_kept() {
    let (nu, nv) = (12, 8);
    let (_, bytes) = torus_glb(nu, nv, "Torus");
    let (mesh, notes) = read(&bytes, "t.glb").unwrap();
    let split = ((nu + 1) * (nv + 1)) as usize;
    assert_eq!(mesh.n_vertices(), (nu * nv) as usize);
    assert_eq!(notes.welded_vertices, split - (nu * nv) as usize);
    assert_eq!(notes.format, Some(Format::Glb));
    let a = analyze(&mesh);
    assert_eq!((a.stats.genus, a.stats.watertight), (Some(1), true));
    ValidMesh::new(mesh.clone()).unwrap();
    // Every corner keeps its own (u, v), v flipped to wavg's upward convention.
    let (pos, tris, uvs) = seamed_torus(nu, nv);
    let uv = mesh.uv.as_ref().unwrap();
    assert_eq!(uv.faces.len(), tris.len());
    for (f, (t, corner)) in tris.iter().zip(&uvs).enumerate() {
        for k in 0..3 {
            let c = uv.coords[uv.faces[f][k] as usize];
            assert_eq!((c.x, c.y), (corner[k][0] as f64, 1.0 - corner[k][1] as f64));
            let p = mesh.positions[mesh.triangles[f][k] as usize];
            let q = pos[t[k] as usize].map(|x| x as f64);
            assert_eq!([p.x, p.y, p.z], q);
        }
    }
}

#[test]
fn node_transforms_place_every_instance_and_mirrors_keep_the_orientation() {
    let (mut g, _) = torus_glb(6, 4, "Torus");
    g.nodes.clear();
    g.node(r#"{"mesh":0,"translation":[10,0,0]}"#);
    g.node(r#"{"children":[2],"matrix":[2,0,0,0, 0,2,0,0, 0,0,2,0, 0,0,5,1]}"#);
    g.node(r#"{"mesh":0,"scale":[-1,1,1]}"#);
    g.roots = Some(vec![0, 1]);
    let (mesh, notes) = read(&g.glb(), "t.glb").unwrap();
    assert_eq!(mesh.n_vertices(), 2 * 24);
    assert_eq!(notes.welded_vertices, 2 * (35 - 24));
    let a = analyze(&mesh);
    assert_eq!((a.stats.components, a.stats.genus), (2, Some(2)));
    assert!(
        a.stats.oriented && a.report.is_valid(),
        "{:?}",
        a.report.lines()
    );
    let (lo, hi) = mesh.bounding_box().unwrap();
    // The second instance: mirrored in x, scaled by 2, lifted by 5.
    assert!(
        (lo.x + 2.6).abs() < 1e-6 && (hi.x - 11.3).abs() < 1e-6,
        "{lo} {hi}"
    );
    assert!(
        (lo.z + 0.3).abs() < 1e-6 && (hi.z - 5.6).abs() < 1e-6,
        "{lo} {hi}"
    );
    // The mirrored copy still has outward normals: positive signed volume.
    let vol: f64 = mesh
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            a.dot(&b.cross(&c)) / 6.0
        })
        .sum();
    assert!(vol > 0.0, "{vol}");
}

#[test]
fn a_mesh_is_chosen_by_name_after_a_hash() {
    let (mut g, _) = torus_glb(6, 4, "Torus");
    let a = g.floats(&[0., 0., 0., 1., 0., 0., 0., 1., 0.], "VEC3");
    g.mesh("Tri", &[prim(a, None, None, 4)]);
    g.node(r#"{"mesh":1,"name":"TriNode","translation":[0,0,3]}"#);
    let bytes = g.glb();
    let (all, _) = read(&bytes, "s.glb").unwrap();
    assert_eq!(all.n_faces(), 48 + 1);
    let (tri, _) = read(&bytes, "s.glb#Tri").unwrap();
    assert_eq!(tri.n_faces(), 1);
    assert_eq!(tri.positions[0].z, 3.0, "the node's transform applies");
    let (by_node, _) = read(&bytes, "s.glb#TriNode").unwrap();
    assert_eq!(by_node.positions, tri.positions);
    let (torus, _) = read(&bytes, "s.glb#Torus").unwrap();
    assert_eq!(torus.n_faces(), 48);
    let m = message(read(&bytes, "s.glb#Body"));
    assert!(
        m.contains("no mesh or node named \"Body\"") && m.contains("\"Tri\""),
        "{m}"
    );
    // The file part of the path is what error messages name.
    match read(&bytes, "s.glb#Body") {
        Err(MeshError::Parse { path, .. }) => assert_eq!(path, Path::new("s.glb")),
        other => panic!("{other:?}"),
    }
}

#[test]
fn strips_and_fans_are_triangulated_and_lines_skipped() {
    let mut g = Gltf::default();
    // A square as a strip (0 1 2 3) and the same square as a fan, side by side.
    let a = g.floats(&[0., 0., 0., 1., 0., 0., 0., 1., 0., 1., 1., 0.], "VEC3");
    let b = g.floats(&[3., 0., 0., 4., 0., 0., 4., 1., 0., 3., 1., 0.], "VEC3");
    let line = g.floats(&[0., 0., 5., 1., 0., 5.], "VEC3");
    g.mesh(
        "m",
        &[
            prim(a, None, None, 5),
            prim(b, None, None, 6),
            prim(line, None, None, 1),
        ],
    );
    g.node(r#"{"mesh":0}"#);
    let (mesh, notes) = read(&g.glb(), "s.glb").unwrap();
    assert_eq!(mesh.n_faces(), 4);
    assert_eq!(notes.skipped_primitives, 1);
    let a = analyze(&mesh);
    assert_eq!((a.stats.components, a.stats.boundary_loops), (2, 2));
    assert!(a.stats.oriented);
    // The line adds nothing, not even unreferenced vertices.
    assert_eq!(mesh.n_vertices(), 8);

    let mut lines = Gltf::default();
    let l = lines.floats(&[0., 0., 0., 1., 0., 0.], "VEC3");
    lines.mesh("l", &[prim(l, None, None, 1)]);
    let m = message(read(&lines.glb(), "l.glb"));
    assert!(
        m.contains("no triangles") && m.contains("points or lines"),
        "{m}"
    );
}

#[test]
fn without_a_scene_every_mesh_is_read_once() {
    let (mut g, _) = torus_glb(5, 3, "Torus");
    g.nodes.clear();
    let (mesh, _) = read(&g.glb(), "t.glb").unwrap();
    assert_eq!(mesh.n_faces(), 30);
}

#[test]
fn gltf_with_its_buffer_and_image_beside_it_or_in_data_uris() {
    let dir = tempfile::tempdir().unwrap();
    let (mut g, _) = torus_glb(6, 4, "Torus");
    g.materials
        .push(r#"{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}"#.to_string());
    g.textures.push(r#"{"source":0}"#.to_string());
    g.images.push(r#"{"uri":"my%20tex.png"}"#.to_string());
    g.meshes[0] = g.meshes[0].replace(r#""mode":4"#, r#""mode":4,"material":0"#);
    std::fs::write(dir.path().join("torus data.bin"), &g.bin).unwrap();
    let path = dir.path().join("t.gltf");
    std::fs::write(&path, g.json(Some("torus%20data.bin"))).unwrap();
    let (mesh, notes) = io::load_with_notes(&path).unwrap();
    assert_eq!((mesh.n_vertices(), notes.format), (24, Some(Format::Gltf)));
    assert_eq!(
        notes.texture,
        Some(TextureSource::File(dir.path().join("my tex.png")))
    );
    // The same through `#Name`, and the same again with everything inlined.
    let (named, _) = io::load_with_notes(&dir.path().join("t.gltf#Torus")).unwrap();
    assert_eq!(named, mesh);
    let b64 = base64(&g.bin);
    g.images[0] = r#"{"uri":"data:image/png;base64,iVBORw0K"}"#.to_string();
    let inline = g.json(Some(&format!("data:application/octet-stream;base64,{b64}")));
    let (m2, n2) = read(inline.as_bytes(), "x.gltf").unwrap();
    assert_eq!(m2, mesh);
    assert_eq!(
        n2.texture,
        Some(TextureSource::Embedded {
            media_type: Some("image/png".into()),
            bytes: b"\x89PNG\r\n".to_vec(),
        })
    );
    // In a GLB the image is a buffer view.
    let view = g.view(b"JPEGBYTES");
    g.images[0] = format!(r#"{{"bufferView":{view},"mimeType":"image/jpeg"}}"#);
    let (_, n3) = read(&g.glb(), "x.glb").unwrap();
    assert_eq!(
        n3.texture,
        Some(TextureSource::Embedded {
            media_type: Some("image/jpeg".into()),
            bytes: b"JPEGBYTES".to_vec(),
        })
    );
    // A missing buffer file is an error naming it.
    std::fs::remove_file(dir.path().join("torus data.bin")).unwrap();
    let e = io::load(&path).unwrap_err().to_string();
    assert!(e.contains("torus data.bin"), "{e}");
}

#[test]
fn buffers_and_images_outside_the_gltf_files_folder_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let sub = dir.path().join("scene");
    std::fs::create_dir(&sub).unwrap();
    let (mut g, _) = torus_glb(6, 4, "Torus");
    std::fs::write(dir.path().join("outside.bin"), &g.bin).unwrap();
    std::fs::create_dir(sub.join("bin")).unwrap();
    std::fs::write(sub.join("bin/inside.bin"), &g.bin).unwrap();
    let path = sub.join("t.gltf");
    // A folder below the file's is fine.
    std::fs::write(&path, g.json(Some("bin/inside.bin"))).unwrap();
    assert_eq!(io::load(&path).unwrap().n_vertices(), 24);
    let outside = dir.path().join("outside.bin");
    let absolute = outside.to_string_lossy().into_owned();
    for uri in [
        "../outside.bin",
        "bin/../../outside.bin",
        "%2E%2E/outside.bin",
        absolute.as_str(),
    ] {
        std::fs::write(&path, g.json(Some(uri))).unwrap();
        let e = io::load(&path).unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains(&format!("{uri:?}")), "{msg}");
        assert!(msg.contains("outside the glTF file's folder"), "{msg}");
    }
    // Images follow the same rule (a material's texture is read with the mesh).
    std::fs::write(dir.path().join("tex.png"), b"\x89PNG\r\n").unwrap();
    g.materials
        .push(r#"{"pbrMetallicRoughness":{"baseColorTexture":{"index":0}}}"#.to_string());
    g.textures.push(r#"{"source":0}"#.to_string());
    g.images.push(r#"{"uri":"../tex.png"}"#.to_string());
    g.meshes[0] = g.meshes[0].replace(r#""mode":4"#, r#""mode":4,"material":0"#);
    std::fs::write(&path, g.json(Some("bin/inside.bin"))).unwrap();
    let e = io::load(&path).unwrap_err().to_string();
    assert!(e.contains("\"../tex.png\"") && e.contains("outside"), "{e}");
}

#[test]
fn primitives_without_texture_coordinates_drop_them_like_obj() {
    let (mut g, _) = torus_glb(6, 4, "Torus");
    let a = g.floats(&[0., 0., 3., 1., 0., 3., 0., 1., 3.], "VEC3");
    let m = g.meshes[0].clone();
    g.meshes[0] = m.replace("]}", &format!(",{}]}}", prim(a, None, None, 4)));
    let (mesh, notes) = read(&g.glb(), "t.glb").unwrap();
    assert!(mesh.uv.is_none() && notes.uv_dropped);
    let partial = notes.partial_uv.unwrap();
    assert_eq!(partial.faces.len(), 49);
    assert_eq!(partial.faces[48], [wavg_mesh::NONE; 3]);
}

fn base64(b: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in b.chunks(3) {
        let n = (c[0] as u32) << 16
            | (*c.get(1).unwrap_or(&0) as u32) << 8
            | *c.get(2).unwrap_or(&0) as u32;
        for k in 0..=c.len() {
            s.push(A[(n >> (18 - 6 * k) & 63) as usize] as char);
        }
    }
    s
}

#[test]
fn every_index_layout_gives_the_same_triangles() {
    let (g, bytes) = torus_glb(6, 4, "Torus");
    let (expected, _) = read(&bytes, "t.glb").unwrap();
    let (pos, tris, uvs) = seamed_torus(6, 4);
    let (_, _, idx) = split_at_seams(&pos, &tris, &uvs);
    assert!(idx.len() == 144 && idx.iter().all(|&i| i < 256));
    // Accessor 2 (the indices) replaced by `json` over `bytes`, its view's index as {v}.
    let with = |bytes: &[u8], json: &str| {
        let mut g = g.clone();
        let v = g.view(bytes);
        g.accessors[2] = json.replace("{v}", &v.to_string());
        g
    };
    let le = |size: usize, stride: usize| -> Vec<u8> {
        idx.iter()
            .flat_map(|&i| {
                let mut e = i.to_le_bytes()[..size].to_vec();
                e.resize(stride, 0xAB);
                e
            })
            .collect()
    };
    let u8s = with(
        &le(1, 1),
        r#"{"bufferView":{v},"componentType":5121,"count":144,"type":"SCALAR"}"#,
    );
    let u16s = with(
        &le(2, 2),
        r#"{"bufferView":{v},"componentType":5123,"count":144,"type":"SCALAR"}"#,
    );
    // A trailing index that makes no triangle is ignored.
    let mut extra = le(4, 4);
    extra.extend(7u32.to_le_bytes());
    let trailing = with(
        &extra,
        r#"{"bufferView":{v},"componentType":5125,"count":145,"type":"SCALAR"}"#,
    );
    let mut strided = with(
        &le(4, 8),
        r#"{"bufferView":{v},"componentType":5125,"count":144,"type":"SCALAR"}"#,
    );
    let last = strided.views.len() - 1;
    strided.views[last] = strided.views[last].replace('}', r#","byteStride":8}"#);
    // Every index first written as 0, then set back by sparse values.
    let mut sparse = g.clone();
    let zeros = sparse.view(&vec![0u8; 4 * 144]);
    let at: Vec<u8> = (0..144u32).flat_map(|k| k.to_le_bytes()).collect();
    let (at, values) = (sparse.view(&at), sparse.view(&le(4, 4)));
    sparse.accessors[2] = format!(
        r#"{{"bufferView":{zeros},"componentType":5125,"count":144,"type":"SCALAR","sparse":{{"count":144,"indices":{{"bufferView":{at},"componentType":5125}},"values":{{"bufferView":{values}}}}}}}"#
    );
    for (name, g) in [
        ("u8", u8s),
        ("u16", u16s),
        ("trailing", trailing),
        ("strided", strided),
        ("sparse", sparse),
    ] {
        let (mesh, notes) = read(&g.glb(), "t.glb").unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(mesh, expected, "{name}");
        assert_eq!(notes.welded_vertices, 35 - 24, "{name}");
    }
}
