//! Every command that writes a mesh writes glTF when its output ends in `.glb` or `.gltf`,
//! read back here with the `gltf` crate (and kept for the Khronos validator when
//! `$WAVG_GLTF_DIR` is set, as `cargo xtask test` does).

use crate::common;

use std::path::Path;

use common::{s, sphere_anchors, wavg, wavg_ok};

/// The document and its buffer (a `.glb`, or a `.gltf` with the `.bin` beside it).
fn read(path: &Path) -> (gltf::Document, Vec<u8>) {
    let g = gltf::Gltf::from_slice(&std::fs::read(path).unwrap()).unwrap();
    let blob = g
        .blob
        .clone()
        .unwrap_or_else(|| std::fs::read(path.with_extension("bin")).unwrap());
    (g.document, blob)
}

/// Vertices and triangles over every triangle primitive of the first mesh.
fn counts(doc: &gltf::Document, blob: &[u8]) -> (usize, usize) {
    let mesh = doc.meshes().next().unwrap();
    let (mut v, mut t) = (0, 0);
    for p in mesh.primitives() {
        assert_eq!(p.mode(), gltf::mesh::Mode::Triangles);
        let r = p.reader(|_| Some(blob));
        v += r.read_positions().unwrap().count();
        t += r.read_indices().unwrap().into_u32().count() / 3;
    }
    (v, t)
}

#[test]
fn repair_and_subdivide_write_glb_and_gltf() {
    let dir = tempfile::tempdir().unwrap();
    let glb = dir.path().join("repaired.glb");
    wavg_ok(&["repair", "builtin:icosphere", "-o", &s(&glb)]);
    wavg_testdata::keep_gltf(&glb, "cli_repair_glb");
    let (doc, blob) = read(&glb);
    assert_eq!(counts(&doc, &blob), (2562, 5120));
    let gltf = dir.path().join("finer.gltf");
    wavg_ok(&["subdivide", "builtin:icosphere", "-o", &s(&gltf)]);
    wavg_testdata::keep_gltf(&gltf, "cli_subdivide_gltf");
    assert!(dir.path().join("finer.bin").is_file());
    let (doc, blob) = read(&gltf);
    assert_eq!(counts(&doc, &blob).1, 4 * 5120);
}

/// `wavg morph` / `correspond` arguments on the icosphere onto itself.
fn pair(cmd: &str, a: &str, out: &Path) -> Vec<String> {
    let m = "builtin:icosphere";
    let mut v: Vec<String> = [
        cmd,
        "--source",
        m,
        "--target",
        m,
        "--source-anchors",
        a,
        "--target-anchors",
        a,
        "-o",
    ]
    .map(String::from)
    .to_vec();
    v.push(s(out));
    v
}

fn run_ok(args: &[String]) {
    wavg_ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
}

#[test]
fn morph_writes_its_frames_as_morph_targets() {
    let dir = tempfile::tempdir().unwrap();
    let a = s(&sphere_anchors(dir.path()));
    let out = dir.path().join("morph.glb");
    let mut args = pair("morph", &a, &out);
    args.extend(["--frames".into(), "3".into()]);
    run_ok(&args);
    wavg_testdata::keep_gltf(&out, "cli_morph");
    let (doc, blob) = read(&out);
    let m = doc.meshes().next().unwrap();
    assert_eq!(m.weights().map(<[f32]>::len), Some(3));
    let p = m.primitives().next().unwrap();
    assert_eq!(p.morph_targets().count(), 3);
    assert_eq!(counts(&doc, &blob), (2562, 5120));
    assert!(m.extras().as_ref().unwrap().get().contains("frame_002"));
}

#[test]
fn correspond_writes_the_map_as_custom_attributes() {
    let dir = tempfile::tempdir().unwrap();
    let a = s(&sphere_anchors(dir.path()));
    let out = dir.path().join("map.glb");
    run_ok(&pair("correspond", &a, &out));
    wavg_testdata::keep_gltf(&out, "cli_correspond");
    let (doc, blob) = read(&out);
    let p = doc.meshes().next().unwrap().primitives().next().unwrap();
    for name in ["TARGET_FACE", "TARGET_BARY", "TARGET_POSITION", "VALIDITY"] {
        let acc = p
            .get(&gltf::Semantic::Extras(name.into()))
            .unwrap_or_else(|| panic!("_{name}"));
        assert_eq!(acc.data_type(), gltf::accessor::DataType::F32);
        assert_eq!(acc.count(), 2562);
    }
    // The icosphere onto itself: every valid vertex lands where it is.
    let r = p.reader(|_| Some(&blob[..]));
    let pos: Vec<[f32; 3]> = r.read_positions().unwrap().collect();
    let acc = p
        .get(&gltf::Semantic::Extras("TARGET_POSITION".into()))
        .unwrap();
    let view = acc.view().unwrap();
    let vals: Vec<f32> = blob[view.offset()..view.offset() + view.length()]
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
        .collect();
    let close = pos
        .iter()
        .zip(vals.chunks_exact(3))
        .filter(|(p, q)| (0..3).all(|k| (p[k] - q[k]).abs() < 1e-3))
        .count();
    assert!(close > 2400, "{close} of 2562 vertices map onto themselves");
}

#[test]
fn spline_writes_a_polyline() {
    let dir = tempfile::tempdir().unwrap();
    let control = dir.path().join("c.txt");
    std::fs::write(&control, "v 0\nv 500\nv 1000\nv 1500\n").unwrap();
    let out = dir.path().join("curve.glb");
    wavg_ok(&[
        "spline",
        "builtin:icosphere",
        "--control",
        &s(&control),
        "--closed",
        "--samples",
        "50",
        "-o",
        &s(&out),
    ]);
    wavg_testdata::keep_gltf(&out, "cli_spline");
    let (doc, blob) = read(&out);
    let p = doc.meshes().next().unwrap().primitives().next().unwrap();
    assert_eq!(p.mode(), gltf::mesh::Mode::LineLoop);
    let n = p
        .reader(|_| Some(&blob[..]))
        .read_positions()
        .unwrap()
        .count();
    assert_eq!(n, 50);
}

#[test]
fn decal_writes_its_uvs_and_texture() {
    let dir = tempfile::tempdir().unwrap();
    let out = common::decal_glb(dir.path());
    wavg_testdata::keep_gltf(&out, "cli_decal");
    assert!(!dir.path().join("decal.mtl").exists());
    let (doc, blob) = read(&out);
    let m = doc.meshes().next().unwrap();
    let first = m.primitives().next().unwrap();
    assert!(first.get(&gltf::Semantic::TexCoords(0)).is_some());
    let tex = first
        .material()
        .pbr_metallic_roughness()
        .base_color_texture();
    assert!(tex.is_some(), "the checkerboard is embedded");
    assert_eq!(counts(&doc, &blob).1, 5120);
}

#[test]
fn transfer_texture_writes_the_target_with_its_texture() {
    let Some(obj) =
        wavg_testdata::require_data_file("transfer_glb", "textured/spot/spot_triangulated.obj")
    else {
        return;
    };
    let png = obj.with_file_name("spot_texture.png");
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.txt");
    let text: String = (0..2900).step_by(100).map(|v| format!("v {v}\n")).collect();
    std::fs::write(&a, text).unwrap();
    let out = dir.path().join("spot.glb");
    let r = wavg(&[
        "transfer-texture",
        "--source",
        &s(&obj),
        "--source-texture",
        &s(&png),
        "--target",
        &s(&obj),
        "--source-anchors",
        &s(&a),
        "--target-anchors",
        &s(&a),
        "--size",
        "64",
        "-o",
        &s(&out),
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    wavg_testdata::keep_gltf(&out, "cli_transfer_texture");
    let (doc, blob) = read(&out);
    let p = doc.meshes().next().unwrap().primitives().next().unwrap();
    let info = p
        .material()
        .pbr_metallic_roughness()
        .base_color_texture()
        .unwrap();
    let gltf::image::Source::View { view, mime_type } = info.texture().source().source() else {
        panic!("the texture is embedded")
    };
    assert_eq!(mime_type, "image/png");
    let bytes = &blob[view.offset()..view.offset() + view.length()];
    let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
    let reader = decoder.read_info().unwrap();
    assert_eq!((reader.info().width, reader.info().height), (64, 64));
    assert!(p.get(&gltf::Semantic::TexCoords(0)).is_some());
}

#[test]
fn a_failed_gltf_write_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("missing-folder").join("x.glb");
    let r = wavg(&["repair", "builtin:icosphere", "-o", &s(&out)]);
    assert!(!r.status.success());
    assert!(!out.exists());
}

#[test]
fn remesh_writes_its_polygons_as_triangles() {
    let dir = tempfile::tempdir().unwrap();
    let base = dir.path().join("cube.obj");
    let c = 0.5773502691896258;
    let mut text = String::new();
    for k in 0..8 {
        let sign = |b: i32| if k & b != 0 { c } else { -c };
        text += &format!("v {} {} {}\n", sign(1), sign(2), sign(4));
    }
    text += "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
    std::fs::write(&base, text).unwrap();
    let out = dir.path().join("fine.glb");
    wavg_ok(&[
        "remesh",
        "builtin:icosphere",
        "--base",
        &s(&base),
        "--levels",
        "2",
        "-o",
        &s(&out),
    ]);
    wavg_testdata::keep_gltf(&out, "cli_remesh");
    let (doc, blob) = read(&out);
    // 6 quads, each split into 16 at two levels, two triangles each.
    assert_eq!(counts(&doc, &blob), (98, 6 * 16 * 2));
}

#[test]
fn render_writes_the_mesh_and_its_curves() {
    let dir = tempfile::tempdir().unwrap();
    let control = dir.path().join("c.txt");
    std::fs::write(&control, "v 0\nv 500\nv 1000\nv 1500\n").unwrap();
    let curve = dir.path().join("curve.txt");
    wavg_ok(&[
        "spline",
        "builtin:icosphere",
        "--control",
        &s(&control),
        "--samples",
        "40",
        "-o",
        &s(&curve),
    ]);
    let out = dir.path().join("scene.glb");
    wavg_ok(&[
        "render",
        "builtin:icosphere",
        "--curve",
        &s(&curve),
        "-o",
        &s(&out),
    ]);
    wavg_testdata::keep_gltf(&out, "cli_render");
    let (doc, blob) = read(&out);
    assert_eq!(counts(&doc, &blob), (2562, 5120));
    let lines: Vec<_> = doc
        .meshes()
        .skip(1)
        .map(|m| m.primitives().next().unwrap())
        .collect();
    assert_eq!(lines.len(), 1);
    assert_eq!(lines[0].mode(), gltf::mesh::Mode::LineStrip);
    let n = lines[0]
        .reader(|_| Some(&blob[..]))
        .read_positions()
        .unwrap()
        .count();
    assert_eq!(n, 40);
}

/// glTF rounds positions to 32-bit floats: a repaired mesh saved so would not be the mesh
/// the embedding belongs to.
#[test]
fn precompute_refuses_a_gltf_repaired_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let (emb, fixed) = (dir.path().join("m.wavg"), dir.path().join("fixed.glb"));
    let r = wavg(&[
        "precompute",
        "builtin:icosphere",
        "-o",
        &s(&emb),
        "--repaired-mesh",
        &s(&fixed),
    ]);
    assert_eq!(r.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&r.stderr).contains("32-bit floats"));
    assert!(!emb.exists() && !fixed.exists());
}
