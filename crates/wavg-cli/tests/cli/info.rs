//! `wavg info` run as a process: exit codes, JSON keys, one-line errors, no panics.

use crate::common;

use common::{wavg, wavg_ok};

use std::path::Path;

use serde_json::Value;
use wavg::mesh::{io, procedural};
use wavg_testdata as data;

fn info_json(path: &Path) -> Value {
    let out = wavg_ok(&["info", "--json", path.to_str().unwrap()]);
    serde_json::from_slice(&out.stdout).expect("one JSON object")
}

const KEYS: [&str; 7] = [
    "vertices",
    "faces",
    "components",
    "boundary_loops",
    "genus",
    "manifold",
    "problems",
];

#[test]
fn valid_file_reports_counts_and_genus() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("torus.obj");
    io::save(&path, &procedural::torus(12, 6, 1.0, 0.3)).unwrap();
    let j = info_json(&path);
    for k in KEYS {
        assert!(j.get(k).is_some(), "missing key {k}");
    }
    assert_eq!(j["vertices"], 72);
    assert_eq!(j["faces"], 144);
    assert_eq!(j["components"], 1);
    assert_eq!(j["boundary_loops"], 0);
    assert_eq!(j["genus"], 1);
    assert_eq!(j["manifold"], true);
    assert_eq!(j["valid"], true);
    assert_eq!(j["problems"].as_array().unwrap().len(), 0);
}

#[test]
fn text_output_names_every_figure() {
    let out = wavg(&["info", "--builtin", "grid"]);
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8(out.stdout).unwrap();
    for word in [
        "vertices:",
        "faces:",
        "components:",
        "boundary loops:       1",
        "genus:                0",
        "manifold:             yes",
    ] {
        assert!(text.contains(word), "{word:?} missing in\n{text}");
    }
}

#[test]
fn builtin_json_and_unknown_builtin() {
    let out = wavg(&["info", "--builtin", "torus", "--json"]);
    assert_eq!(out.status.code(), Some(0));
    let j: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(j["genus"], 1);
    let out = wavg(&["info", "--builtin", "teapot"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("teapot"));
    // `builtin:NAME`, as the other commands (and their hints) spell it, works too.
    let out = wavg(&["info", "builtin:torus", "--json"]);
    assert_eq!(out.status.code(), Some(0));
    let j: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        (j["genus"].clone(), j["mesh"].clone()),
        (1.into(), "builtin:torus".into())
    );
}

/// An invalid mesh whose faces form an oriented manifold (a triangle and an unused
/// vertex) has no genus to report: null, and "undefined" in the text.
#[test]
fn an_invalid_mesh_has_no_genus() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("stray.off");
    std::fs::write(&path, "OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n9 9 9\n3 0 1 2\n").unwrap();
    let j = info_json(&path);
    assert_eq!(
        (j["manifold"].clone(), j["valid"].clone()),
        (true.into(), false.into())
    );
    assert!(j["genus"].is_null(), "{j}");
    let out = wavg(&["info", path.to_str().unwrap()]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("genus:                undefined"), "{text}");
}

#[test]
fn invalid_but_parseable_file_exits_zero_and_lists_problems() {
    let dir = tempfile::tempdir().unwrap();
    // A fin: three triangles on edge (0, 1), plus an unreferenced vertex.
    let path = dir.path().join("fin.off");
    std::fs::write(
        &path,
        "OFF\n6 3 0\n0 0 0\n1 0 0\n0 1 0\n0 -1 0\n0 0 1\n9 9 9\n3 0 1 2\n3 1 0 3\n3 0 1 4\n",
    )
    .unwrap();
    let j = info_json(&path);
    assert_eq!(j["manifold"], false);
    assert_eq!(j["valid"], false);
    assert!(j["genus"].is_null());
    let problems: Vec<String> = j["problems"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p.as_str().unwrap().to_string())
        .collect();
    assert!(
        problems
            .iter()
            .any(|p| p.contains("non-manifold edges") && p.contains("(0, 1)")),
        "{problems:?}"
    );
    assert!(
        problems
            .iter()
            .any(|p| p.contains("unreferenced") && p.contains("vertex 5")),
        "{problems:?}"
    );
    let out = wavg(&["info", path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("valid:                no"), "{text}");
    // The fin comes apart into three sheets.
    assert!(text.contains("`wavg repair` fixes every problem"), "{text}");
    assert_eq!(j["repair"]["fixes_all"], true);
    assert_eq!(j["repair"]["removed_vertices"], 1);
    assert_eq!(j["repair"]["added_vertices"], 4);
    assert!(text.contains("splits off 4 vertex copies"), "{text}");
    // A problem no repair fixes: a Moebius strip has no consistent orientation.
    let mut positions = Vec::new();
    let n = 12;
    for i in 0..n {
        let t = std::f64::consts::TAU * i as f64 / n as f64;
        for s in [-0.3, 0.3] {
            let (r, h) = (1.0 + s * (t / 2.0).cos(), s * (t / 2.0).sin());
            positions.push(nalgebra::Vector3::new(r * t.cos(), r * t.sin(), h));
        }
    }
    let triangles = (0..n as u32)
        .flat_map(|i| {
            let (a, b) = (2 * i, 2 * i + 1);
            let (c, d) = if i + 1 == n as u32 {
                (1, 0)
            } else {
                (a + 2, a + 3)
            };
            [[a, c, b], [b, c, d]]
        })
        .collect();
    let mpath = dir.path().join("moebius.obj");
    io::save(&mpath, &wavg::mesh::TriMesh::new(positions, triangles)).unwrap();
    let j = info_json(&mpath);
    assert_eq!(j["repair"]["fixes_all"], false);
    let out = wavg(&["info", mpath.to_str().unwrap()]);
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.contains("`wavg repair` leaves: 1 edges with inconsistent orientation\n"),
        "{text}"
    );
    // A problem the repairs do fix: an unreferenced vertex on a valid torus.
    let mut torus = procedural::torus(8, 5, 1.0, 0.3);
    torus.positions.push(torus.positions[0] * 5.0);
    let tpath = dir.path().join("t.obj");
    io::save(&tpath, &torus).unwrap();
    let j = info_json(&tpath);
    assert_eq!(j["valid"], false);
    assert_eq!(j["repair"]["fixes_all"], true);
    let out = wavg(&["info", tpath.to_str().unwrap()]);
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.contains("fixes every problem (removes 1 vertices, 0 faces)"),
        "{text}"
    );
}

#[test]
fn unparseable_files_exit_2_with_one_line_naming_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        ("trunc.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n", ":5:"),
        ("word.obj", "v 0 0 0\nv 1 x 0\n", ":2:"),
        ("zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", ":4:"),
        ("bin.off", "OFF\n1 0 0\n\u{0}\u{1}\n", ":3:"),
        ("bad.ply", "ply\nformat ascii 1.0\nelement vertex 1\n", ":"),
    ];
    for (name, body, line) in cases {
        let path = dir.path().join(name);
        std::fs::write(&path, body).unwrap();
        for json in [false, true] {
            let mut args = vec!["info", path.to_str().unwrap()];
            if json {
                args.push("--json");
            }
            let out = wavg(&args);
            assert_eq!(out.status.code(), Some(2), "{name}");
            assert!(out.stdout.is_empty());
            let err = String::from_utf8(out.stderr).unwrap();
            assert_eq!(err.lines().count(), 1, "{name}: {err}");
            assert!(err.contains(name) && err.contains(line), "{name}: {err}");
            assert!(!err.contains("panicked"));
        }
    }
    let out = wavg(&["info", "/no/such/file.obj"]);
    assert_eq!(out.status.code(), Some(2));
    let out = wavg(&["info", dir.path().join("x.stl").to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn shared_data_good_bad_and_unparseable() {
    let Some(good) = data::require_data_file("info_shared_data", "meshes/torus.obj") else {
        return;
    };
    let j = info_json(&good);
    assert_eq!(
        (j["vertices"].as_u64(), j["genus"].as_i64()),
        (Some(2304), Some(1))
    );
    let bad = data::require_data_file("info_shared_data", "bad/cow.obj").unwrap();
    let j = info_json(&bad);
    assert_eq!(j["manifold"], false);
    assert!(j["problems"][0].as_str().unwrap().contains("pinched"));
    let trunc = data::require_data_file("info_shared_data", "bad/synthetic/truncated.off").unwrap();
    let out = wavg(&["info", trunc.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(err.contains("truncated.off:7:"), "{err}");
}

/// A tetrahedron with its corners `scale` from the origin, as an OBJ file in `dir`.
fn tetrahedron(dir: &std::path::Path, name: &str, scale: &str) -> std::path::PathBuf {
    let path = dir.join(name);
    let s = scale;
    std::fs::write(
        &path,
        format!("v 0 0 0\nv {s} 0 0\nv 0 {s} 0\nv 0 0 {s}\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"),
    )
    .unwrap();
    path
}

/// `info --json` of `path`: valid, and `out_of_range` says `remedy`.
fn assert_valid_but_out_of_range(path: &std::path::Path, remedy: &str) {
    let out = wavg(&["info", "--json", path.to_str().unwrap()]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["valid"], true, "{v}");
    assert!(v["out_of_range"].as_str().unwrap().contains(remedy), "{v}");
}

/// Coordinates too large for the computations print in scientific notation, with a note
/// saying so; the faces are judged by their shape (not zero-area); the JSON says why.
#[test]
fn coordinates_out_of_range_print_short_with_a_note() {
    let dir = tempfile::tempdir().unwrap();
    let path = tetrahedron(dir.path(), "big.obj", "1e200");
    let out = wavg(&["info", path.to_str().unwrap()]);
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("1.000000e200, 1.000000e200"), "{text}");
    assert!(text.contains("beyond the supported magnitude"), "{text}");
    assert!(
        text.contains("valid:                yes (oriented manifold), but out of range"),
        "{text}"
    );
    assert!(text.lines().all(|l| l.len() < 300), "{text}");
    assert_valid_but_out_of_range(&path, "scale the mesh down");
    let out = wavg(&["info", "--json", path.to_str().unwrap()]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let d = v["bounding_box"]["diagonal"].as_f64().unwrap();
    assert!((d / (3f64.sqrt() * 1e200) - 1.0).abs() < 1e-12, "{v}");
    // An unused vertex far away: invalid (repair drops it), so no range verdict yet.
    let far = dir.path().join("far.obj");
    std::fs::write(
        &far,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1e300 0 0\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n",
    )
    .unwrap();
    let out = wavg(&["info", "--json", far.to_str().unwrap()]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["valid"], false, "{v}");
    assert!(v["out_of_range"].is_null(), "{v}");
    let small = tetrahedron(dir.path(), "small.obj", "1e-70");
    assert_valid_but_out_of_range(&small, "scale the mesh up");
    let out = wavg(&[
        "precompute",
        small.to_str().unwrap(),
        "-o",
        dir.path().join("s.wavg").to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        String::from_utf8(out.stderr)
            .unwrap()
            .contains("scale the mesh up")
    );
    let out = wavg(&["info", "--json", "builtin:torus"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["out_of_range"].is_null(), "{v}");
}
