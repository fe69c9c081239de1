//! `wavg demo` runs the method end to end on a generated mesh and writes what it says.

use crate::common;

use common::{json_object, wavg, wavg_ok};

#[test]
fn demo_reports_and_writes_its_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("demo");
    let out = wavg_ok(&[
        "demo",
        "--json",
        "--queries",
        "300",
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    let (o, keys) = json_object(&out);
    assert_eq!(
        keys,
        [
            "anchor_gap",
            "anchors",
            "curve_ok",
            "curve_points",
            "curve_us",
            "faces",
            "forward_us",
            "geodesic_rel_err_p50",
            "geodesic_rel_err_p90",
            "inverse_us",
            "landmarks",
            "mesh",
            "pictures",
            "precompute_s",
            "roundtrip_ok_fraction",
            "roundtrip_queries",
            "skipped_pictures",
            "spline_controls",
            "stress",
            "verified_roundtrip_ok_fraction",
            "vertices",
        ]
    );
    assert_eq!(o["vertices"], 2562);
    // The anchor count follows from the gap between anchors; the spline uses the first 8.
    let anchors = o["anchors"].as_u64().unwrap() as usize;
    assert!(anchors > 8, "{anchors}");
    assert!(o["anchor_gap"].as_f64().unwrap() <= 0.08);
    assert_eq!(o["spline_controls"], 8);
    assert_eq!(o["pictures"].as_array().unwrap().len(), 6);
    assert_eq!(o["skipped_pictures"], serde_json::json!([]));
    assert_eq!(o["curve_ok"], o["curve_points"]);
    assert!(o["verified_roundtrip_ok_fraction"].as_f64().unwrap() >= 0.99);
    // The outputs: a mesh that loads, an embedding that matches it, a curve on it.
    let mesh = wavg::mesh::io::load(&out_dir.join("mesh.obj")).unwrap();
    assert_eq!(mesh.n_vertices(), 2562);
    let emb = wavg::embed::file::load(&out_dir.join("mesh.wavg"), &mesh).unwrap();
    assert_eq!(emb.coords.len(), 2562);
    let curve = std::fs::read_to_string(out_dir.join("curve.txt")).unwrap();
    assert_eq!(curve.lines().count(), 400);
    for line in curve.lines() {
        let t: Vec<f64> = line
            .split_whitespace()
            .map(|x| x.parse().unwrap())
            .collect();
        assert_eq!(t.len(), 7);
        assert!((t[1] + t[2] + t[3] - 1.0).abs() < 1e-9);
        let p = wavg::mesh::SurfacePoint::new(t[0] as u32, [t[1], t[2], t[3]]).position(&mesh);
        assert!((p.x - t[4]).abs() + (p.y - t[5]).abs() + (p.z - t[6]).abs() < 1e-6);
    }
    let obj = std::fs::read_to_string(out_dir.join("curve.obj")).unwrap();
    assert_eq!(obj.lines().filter(|l| l.starts_with("v ")).count(), 400);
    assert_eq!(
        std::fs::read_to_string(out_dir.join("anchors.txt"))
            .unwrap()
            .lines()
            .count(),
        anchors
    );
    for png in [
        "spline.png",
        "distance.png",
        "texture_source.png",
        "texture_target.png",
        "remesh.png",
        "decal.png",
    ] {
        let bytes = std::fs::read(out_dir.join(png)).unwrap();
        assert_eq!(&bytes[1..4], b"PNG", "{png}");
    }
}

#[test]
fn demo_rejects_bad_arguments() {
    let out = wavg(&["demo", "--anchors", "2"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--anchors"));
    let out = wavg(&["demo", "--mesh", "builtin:teapot"]);
    assert_eq!(out.status.code(), Some(2));
    // A mesh the embedding cannot take (two components) is an input error too.
    let dir = tempfile::tempdir().unwrap();
    let two = dir.path().join("two.obj");
    let mut mesh = wavg::mesh::procedural::icosphere(1);
    let n = mesh.positions.len() as u32;
    let far: Vec<_> = mesh.positions.iter().map(|p| p.add_scalar(5.0)).collect();
    let tris: Vec<_> = mesh.triangles.iter().map(|t| t.map(|v| v + n)).collect();
    mesh.positions.extend(far);
    mesh.triangles.extend(tris);
    std::fs::write(
        &two,
        wavg::mesh::io::to_bytes(&mesh, wavg::mesh::Format::Obj).unwrap(),
    )
    .unwrap();
    let out = wavg(&["demo", "--mesh", two.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("components"));
}

/// A picture whose application does not apply to the user's surface (here remeshing a cube
/// onto a thin torus, which may fail) is reported as not drawn, and the demo goes on.
#[test]
fn demo_pictures_that_do_not_apply_are_skipped_with_a_reason() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join("thin.obj");
    let torus = wavg::mesh::procedural::torus(64, 8, 1.0, 0.01);
    let valid = wavg::mesh::ValidMesh::new(torus).unwrap();
    wavg::mesh::io::save(&mesh, &valid).unwrap();
    let out_dir = dir.path().join("demo");
    let out = wavg_ok(&[
        "demo",
        "--mesh",
        mesh.to_str().unwrap(),
        "--json",
        "--queries",
        "50",
        "--out",
        out_dir.to_str().unwrap(),
    ]);
    let (o, _) = json_object(&out);
    let written = o["pictures"].as_array().unwrap();
    let skipped = o["skipped_pictures"].as_array().unwrap();
    assert_eq!(written.len() + skipped.len(), 6, "{o:?}");
    for p in written {
        let bytes = std::fs::read(p.as_str().unwrap()).unwrap();
        assert_eq!(&bytes[1..4], b"PNG");
    }
    for s in skipped {
        let (name, why) = s.as_str().unwrap().split_once(": ").unwrap();
        assert!(name.ends_with(".png") && !why.is_empty(), "{s}");
        assert!(!out_dir.join(name).exists());
    }
}

/// Too few anchors for the mesh: the demo says so on stderr and names the remedy.
#[test]
fn demo_warns_when_round_trips_fail() {
    let out = wavg_ok(&[
        "demo",
        "--mesh",
        "builtin:torus",
        "--anchors",
        "4",
        "--queries",
        "300",
        "--json",
    ]);
    let (o, _) = json_object(&out);
    let ok = o["roundtrip_ok_fraction"].as_f64().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(ok < 0.9, "{ok}");
    assert!(err.contains("warning") && err.contains("--count"), "{err}");
}
