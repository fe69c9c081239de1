//! The glTF writer, read back with the `gltf` crate: vertices, triangles, texture
//! coordinates split at seams, the texture, morph targets, polylines, custom attributes,
//! `.gltf` with its `.bin`, and refusals that leave nothing behind. Each file written is
//! kept for the Khronos validator when `$WAVG_GLTF_DIR` is set (`cargo xtask test`).

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use nalgebra::{Vector2, Vector3};
use wavg_mesh::io::gltf::{GltfMesh, GltfPolyline, GltfScene, VertexAttribute};
use wavg_mesh::{TexCoords, TriMesh, io, procedural};

/// The document and its buffer, from a `.glb` or a `.gltf` with its `.bin`.
fn read(path: &Path) -> (gltf::Document, Vec<u8>) {
    let bytes = std::fs::read(path).unwrap();
    let g = gltf::Gltf::from_slice(&bytes).unwrap();
    let blob = match g.blob.clone() {
        Some(b) => b,
        None => {
            let buffer = g.document.buffers().next().unwrap();
            let gltf::buffer::Source::Uri(uri) = buffer.source() else {
                panic!("a .gltf names its buffer")
            };
            std::fs::read(path.with_file_name(uri.replace("%20", " "))).unwrap()
        }
    };
    (g.document, blob)
}

/// Positions (as f64) and triangles of every triangle primitive of the first mesh.
fn triangles_of(doc: &gltf::Document, blob: &[u8]) -> (Vec<[f32; 3]>, Vec<[u32; 3]>) {
    let mesh = doc.meshes().next().unwrap();
    let (mut pos, mut tri) = (Vec::new(), Vec::new());
    for p in mesh.primitives() {
        assert_eq!(p.mode(), gltf::mesh::Mode::Triangles);
        let r = p.reader(|_| Some(blob));
        let base = pos.len() as u32;
        pos.extend(r.read_positions().unwrap());
        let idx: Vec<u32> = r.read_indices().unwrap().into_u32().collect();
        tri.extend(
            idx.chunks(3)
                .map(|c| [c[0] + base, c[1] + base, c[2] + base]),
        );
    }
    (pos, tri)
}

fn dir() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

fn keep(path: &Path, name: &str) {
    wavg_testdata::keep_gltf(path, name);
}

/// A torus whose texture coordinates have seams: every other face takes its corners'
/// coordinates from a second set, so most vertices carry two.
fn seamed_torus() -> TriMesh {
    let mut m = procedural::torus(12, 8, 2.0, 0.5);
    let n = m.positions.len() as u32;
    let mut coords: Vec<Vector2<f64>> = m
        .positions
        .iter()
        .map(|p| Vector2::new(0.25 * (p.x + 2.5), 0.25 * (p.y + 2.5)))
        .collect();
    coords.extend(coords.clone().iter().map(|c| c * 0.5));
    let faces = (0..m.triangles.len())
        .map(|f| m.triangles[f].map(|v| if f % 2 == 0 { v } else { v + n }))
        .collect();
    m.uv = Some(TexCoords { coords, faces });
    m
}

#[test]
fn a_mesh_round_trips_through_glb_in_f32() {
    let d = dir();
    let path = d.path().join("sphere.glb");
    let mesh = procedural::icosphere(2);
    io::save(&path, &mesh).unwrap();
    keep(&path, "a_mesh_round_trips_through_glb_in_f32");
    let (doc, blob) = read(&path);
    let (pos, tri) = triangles_of(&doc, &blob);
    assert_eq!(pos.len(), mesh.positions.len());
    assert_eq!(tri.len(), mesh.triangles.len());
    for (t, u) in tri.iter().zip(&mesh.triangles) {
        for c in 0..3 {
            let p = mesh.positions[u[c] as usize].map(|x| x as f32);
            assert_eq!(pos[t[c] as usize], [p.x, p.y, p.z]);
        }
    }
    assert!(
        doc.meshes()
            .next()
            .unwrap()
            .primitives()
            .all(|p| p.material().index().is_none())
    );
}

#[test]
fn texture_coordinates_split_vertices_at_seams_only() {
    let d = dir();
    let path = d.path().join("torus.glb");
    let mesh = seamed_torus();
    io::save(&path, &mesh).unwrap();
    keep(&path, "texture_coordinates_split_vertices_at_seams_only");
    let (doc, blob) = read(&path);
    let (pos, tri) = triangles_of(&doc, &blob);
    let uv = mesh.uv.as_ref().unwrap();
    let pairs: HashSet<(u32, u32)> = (0..mesh.triangles.len())
        .flat_map(|f| (0..3).map(move |c| (f, c)))
        .map(|(f, c)| (mesh.triangles[f][c], uv.faces[f][c]))
        .collect();
    assert_eq!(pos.len(), pairs.len());
    assert!(pos.len() > mesh.positions.len());
    let p = doc.meshes().next().unwrap().primitives().next().unwrap();
    let st: Vec<[f32; 2]> = p
        .reader(|_| Some(&blob[..]))
        .read_tex_coords(0)
        .unwrap()
        .into_f32()
        .collect();
    for (f, t) in tri.iter().enumerate() {
        for c in 0..3 {
            let want = uv.coords[uv.faces[f][c] as usize];
            assert_eq!(st[t[c] as usize], [want.x as f32, (1.0 - want.y) as f32]);
        }
    }
}

#[test]
fn gltf_names_its_bin_beside_it() {
    let d = dir();
    let path = d.path().join("my torus.gltf");
    io::save(&path, &seamed_torus()).unwrap();
    keep(&path, "gltf_names_its_bin_beside_it");
    assert!(d.path().join("my torus.bin").is_file());
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("\"uri\": \"my%20torus.bin\""), "{text}");
    let (doc, blob) = read(&path);
    let (_, tri) = triangles_of(&doc, &blob);
    assert_eq!(tri.len(), seamed_torus().triangles.len());
}

/// A 2x2 PNG.
fn png() -> Vec<u8> {
    let mut out = Vec::new();
    {
        let mut e = png::Encoder::new(&mut out, 2, 2);
        e.set_color(png::ColorType::Rgb);
        let mut w = e.write_header().unwrap();
        w.write_image_data(&[255, 0, 0, 0, 255, 0, 0, 0, 255, 255, 255, 255])
            .unwrap();
    }
    out
}

#[test]
fn the_texture_is_embedded_as_base_colour_and_uvless_faces_go_apart() {
    let d = dir();
    let path = d.path().join("decal.glb");
    let mut mesh = seamed_torus();
    // The first ten faces have no texture coordinates.
    if let Some(uv) = &mut mesh.uv {
        for f in 0..10 {
            uv.faces[f] = [wavg_mesh::NONE; 3];
        }
    }
    let scene = GltfScene {
        meshes: vec![GltfMesh {
            name: "decal".into(),
            mesh: mesh.clone(),
            texture_png: Some(png()),
            ..Default::default()
        }],
        polylines: vec![],
    };
    scene.save(&path).unwrap();
    keep(
        &path,
        "the_texture_is_embedded_as_base_colour_and_uvless_faces_go_apart",
    );
    let (doc, blob) = read(&path);
    let m = doc.meshes().next().unwrap();
    let prims: Vec<_> = m.primitives().collect();
    assert_eq!(prims.len(), 2);
    let info = prims[0]
        .material()
        .pbr_metallic_roughness()
        .base_color_texture()
        .expect("a base colour texture");
    let gltf::image::Source::View { view, mime_type } = info.texture().source().source() else {
        panic!("embedded")
    };
    assert_eq!(mime_type, "image/png");
    let start = view.offset();
    assert_eq!(&blob[start..start + view.length()], &png()[..]);
    assert!(prims[1].get(&gltf::Semantic::TexCoords(0)).is_none());
    assert!(
        prims[1]
            .material()
            .pbr_metallic_roughness()
            .base_color_texture()
            .is_none()
    );
    let (_, tri) = triangles_of(&doc, &blob);
    assert_eq!(tri.len(), mesh.triangles.len());
}

#[test]
fn frames_are_morph_targets_of_one_mesh() {
    let d = dir();
    let path = d.path().join("morph.glb");
    let mesh = procedural::icosphere(1);
    let frames: Vec<(String, Vec<Vector3<f64>>)> = (1..=3)
        .map(|k| {
            let s = 1.0 + 0.25 * k as f64;
            (
                format!("frame_{k:03}"),
                mesh.positions.iter().map(|p| p * s).collect(),
            )
        })
        .collect();
    let scene = GltfScene {
        meshes: vec![GltfMesh {
            name: "morph".into(),
            mesh: mesh.clone(),
            morph_targets: frames.clone(),
            ..Default::default()
        }],
        polylines: vec![],
    };
    scene.save(&path).unwrap();
    keep(&path, "frames_are_morph_targets_of_one_mesh");
    let (doc, blob) = read(&path);
    let m = doc.meshes().next().unwrap();
    assert_eq!(m.weights(), Some(&[0.0, 0.0, 0.0][..]));
    let extras = m.extras().as_ref().unwrap().get();
    assert!(extras.contains("frame_002"), "{extras}");
    let p = m.primitives().next().unwrap();
    let r = p.reader(|_| Some(&blob[..]));
    let base: Vec<[f32; 3]> = r.read_positions().unwrap().collect();
    let targets: Vec<_> = r.read_morph_targets().collect();
    assert_eq!(targets.len(), 3);
    let (_, tri) = triangles_of(&doc, &blob);
    for ((_, frame), (pos, _, _)) in frames.iter().zip(targets) {
        let delta: Vec<[f32; 3]> = pos.unwrap().collect();
        // glTF vertex t[c] is mesh vertex u[c].
        for (t, u) in tri.iter().zip(&mesh.triangles) {
            for c in 0..3 {
                let (g, v) = (t[c] as usize, u[c] as usize);
                for k in 0..3 {
                    let got = base[g][k] + delta[g][k];
                    assert!(
                        (got - frame[v][k] as f32).abs() < 1e-5,
                        "{got} {}",
                        frame[v][k]
                    );
                }
            }
        }
    }
}

#[test]
fn polylines_are_line_strips_and_loops() {
    let d = dir();
    let path = d.path().join("curves.glb");
    let pts: Vec<Vector3<f64>> = (0..10)
        .map(|i| Vector3::new((i as f64).cos(), (i as f64).sin(), 0.1 * i as f64))
        .collect();
    let scene = GltfScene {
        meshes: vec![],
        polylines: vec![
            GltfPolyline {
                name: "open".into(),
                points: pts.clone(),
                closed: false,
            },
            GltfPolyline {
                name: "closed".into(),
                points: pts.clone(),
                closed: true,
            },
        ],
    };
    scene.save(&path).unwrap();
    keep(&path, "polylines_are_line_strips_and_loops");
    let (doc, blob) = read(&path);
    let modes: Vec<_> = doc
        .meshes()
        .map(|m| m.primitives().next().unwrap().mode())
        .collect();
    assert_eq!(
        modes,
        [gltf::mesh::Mode::LineStrip, gltf::mesh::Mode::LineLoop]
    );
    let p = doc.meshes().next().unwrap().primitives().next().unwrap();
    let got: Vec<[f32; 3]> = p
        .reader(|_| Some(&blob[..]))
        .read_positions()
        .unwrap()
        .collect();
    assert_eq!(got.len(), 10);
    assert_eq!(got[3], [3f64.cos() as f32, 3f64.sin() as f32, 0.3f32]);
    assert_eq!(doc.scenes().next().unwrap().nodes().count(), 2);
}

#[test]
fn custom_attributes_are_underscored_floats_per_vertex() {
    let d = dir();
    let path = d.path().join("map.glb");
    let mesh = seamed_torus();
    let n = mesh.positions.len();
    let face: Vec<f32> = (0..n).map(|i| i as f32 - 1.0).collect();
    let bary: Vec<[f32; 3]> = (0..n).map(|i| [i as f32, 0.5, 0.25]).collect();
    let scene = GltfScene {
        meshes: vec![GltfMesh {
            name: "map".into(),
            mesh: mesh.clone(),
            attributes: vec![
                ("target_face".into(), VertexAttribute::Scalar(face)),
                ("TARGET_BARY".into(), VertexAttribute::Vec3(bary)),
            ],
            ..Default::default()
        }],
        polylines: vec![],
    };
    scene.save(&path).unwrap();
    keep(&path, "custom_attributes_are_underscored_floats_per_vertex");
    let (doc, blob) = read(&path);
    let p = doc.meshes().next().unwrap().primitives().next().unwrap();
    let semantics: Vec<String> = p.attributes().map(|(s, _)| s.to_string()).collect();
    assert!(
        semantics.contains(&"_TARGET_FACE".to_string()),
        "{semantics:?}"
    );
    assert!(
        semantics.contains(&"_TARGET_BARY".to_string()),
        "{semantics:?}"
    );
    let acc = p
        .get(&gltf::Semantic::Extras("TARGET_FACE".into()))
        .unwrap();
    assert_eq!(acc.data_type(), gltf::accessor::DataType::F32);
    // Each glTF vertex carries its mesh vertex's value: found by position.
    let view = acc.view().unwrap();
    let vals: Vec<f32> = blob[view.offset()..view.offset() + view.length()]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
        .collect();
    let pos: Vec<[f32; 3]> = p
        .reader(|_| Some(&blob[..]))
        .read_positions()
        .unwrap()
        .collect();
    for (k, x) in pos.iter().enumerate() {
        let v = mesh
            .positions
            .iter()
            .position(|q| [q.x as f32, q.y as f32, q.z as f32] == *x)
            .unwrap();
        assert_eq!(vals[k], v as f32 - 1.0);
    }
}

fn names_in(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    v.sort();
    v
}

#[test]
fn bad_input_is_refused_and_nothing_is_written() {
    let d = dir();
    let mut mesh = procedural::icosphere(0);
    mesh.positions[3].y = f64::NAN;
    for name in ["nan.glb", "nan.gltf"] {
        let e = io::save(&d.path().join(name), &mesh).unwrap_err();
        assert!(e.to_string().contains("32-bit float"), "{e}");
    }
    let mut big = procedural::icosphere(0);
    big.positions[0].x = 1e300;
    assert!(io::save(&d.path().join("big.glb"), &big).is_err());
    let empty = TriMesh::default();
    let e = io::save(&d.path().join("empty.glb"), &empty).unwrap_err();
    assert!(e.to_string().contains("nothing to write"), "{e}");
    let mut bad = procedural::icosphere(0);
    bad.triangles[0][1] = 99;
    assert!(io::save(&d.path().join("bad.glb"), &bad).is_err());
    let short = GltfScene {
        meshes: vec![GltfMesh {
            mesh: procedural::icosphere(0),
            morph_targets: vec![("f".into(), vec![Vector3::zeros(); 3])],
            ..Default::default()
        }],
        polylines: vec![],
    };
    assert!(short.save(&d.path().join("short.glb")).is_err());
    assert!(names_in(d.path()).is_empty(), "{:?}", names_in(d.path()));
}

#[test]
fn a_failed_write_keeps_the_previous_file() {
    let d = dir();
    let path = d.path().join("keep.glb");
    io::save(&path, &procedural::icosphere(0)).unwrap();
    let before = std::fs::read(&path).unwrap();
    let mut bad = procedural::icosphere(1);
    bad.positions[0].z = f64::INFINITY;
    assert!(io::save(&path, &bad).is_err());
    assert_eq!(std::fs::read(&path).unwrap(), before);
    assert_eq!(names_in(d.path()), [path]);
}

/// Coordinates stored once per corner (as Python's per-corner arrays give them) split a
/// vertex only where their values differ.
#[test]
fn equal_coordinates_stored_twice_do_not_split() {
    let d = dir();
    let path = d.path().join("corners.glb");
    let mut mesh = procedural::icosphere(1);
    let coords = mesh
        .triangles
        .iter()
        .flat_map(|t| t.map(|v| Vector2::new(mesh.positions[v as usize].x, 0.5)))
        .collect();
    let faces = (0..mesh.triangles.len() as u32)
        .map(|f| [3 * f, 3 * f + 1, 3 * f + 2])
        .collect();
    mesh.uv = Some(TexCoords { coords, faces });
    io::save(&path, &mesh).unwrap();
    keep(&path, "equal_coordinates_stored_twice_do_not_split");
    let (doc, blob) = read(&path);
    assert_eq!(triangles_of(&doc, &blob).0.len(), mesh.positions.len());
}
