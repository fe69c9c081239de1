//! The exact key sets of the `--json` reports (nested objects included), on small
//! generated meshes: the reports are serialised from library types, and these keys are a
//! contract that must not change when those types do.

use crate::common;

use std::path::Path;

use common::{
    assert_keys, json_object, key_paths, pair_args, s, sphere_anchors, wavg_ok, wavg_ok_with,
};
use serde_json::Value;
use wavg_testdata::json_keys::{BENCH_LOAD, BENCH_PROJECT, BENCH_SPLINE};

#[test]
fn precompute_json_keys() {
    let dir = tempfile::tempdir().unwrap();
    let out = s(&dir.path().join("t.wavg"));
    let keys = [
        "mesh",
        "output",
        "seconds",
        "stages",
        "stages.decimate",
        "stages.geodesics",
        "stages.mds",
        "stages.lsmesh",
        "stages.quality",
        "load_seconds",
        "save_seconds",
        "landmarks",
        "geodesic_mesh_vertices",
        "dim",
        "stress",
        "initial_stress",
        "mds_iterations",
        "mds_converged",
        "geodesic_rel_err_p50",
        "geodesic_rel_err_p90",
        "quality_pairs",
        "vertices",
        "faces",
        "removed_by_largest_component",
    ];
    let base = [
        "precompute",
        "builtin:torus",
        "-o",
        &out,
        "--landmarks",
        "60",
        "--json",
    ];
    assert_keys(&base, &keys);
    let mut with_removed = keys.to_vec();
    with_removed.extend([
        "removed_by_largest_component.vertices",
        "removed_by_largest_component.faces",
    ]);
    assert_keys(
        &[&base[..], &["--largest-component"]].concat(),
        &with_removed,
    );
}

#[test]
fn correspond_json_keys() {
    let dir = tempfile::tempdir().unwrap();
    let a = s(&sphere_anchors(dir.path()));
    let out = s(&dir.path().join("map.txt"));
    let m = "builtin:icosphere";
    let args = pair_args("correspond", [m, m], [&a, &a], &out);
    let keys = [
        "source",
        "target",
        "anchors",
        "source_vertices",
        "valid",
        "valid_fraction",
        "validity",
        "verified",
        "reasons",
        "flipped_faces",
        "flipped_area_fraction",
        "measured_faces",
        "stretch",
        "stretch_best95",
        "seconds",
        "setup_seconds",
        "weights_seconds",
        "forward_seconds",
        "validity_seconds",
        "vertices_per_s",
        "cpu_seconds",
        "vertices_per_cpu_s",
        "ground_truth",
    ];
    let (o, _) = json_object(&wavg_ok_with(&args, &["--json"]));
    let mut want: Vec<String> = keys.iter().map(|k| k.to_string()).collect();
    // `reasons` counts by reason: its keys depend on the map, not on the format.
    want.extend(
        o["reasons"]
            .as_object()
            .unwrap()
            .keys()
            .map(|k| format!("reasons.{k}")),
    );
    want.sort();
    assert_eq!(key_paths(&Value::Object(o)), want);
    let (o, _) = json_object(&wavg_ok_with(&args, &["--json", "--ground-truth"]));
    let truth = key_paths(&o["ground_truth"]);
    let stats = ["count", "max", "mean", "p95"];
    let mut want: Vec<String> = ["answered", "valid"]
        .iter()
        .flat_map(|g| {
            std::iter::once(g.to_string()).chain(stats.iter().map(move |k| format!("{g}.{k}")))
        })
        .chain(["accepted_wrong".to_string(), "rejected_correct".to_string()])
        .collect();
    want.sort();
    assert_eq!(truth, want);
}

#[test]
fn decal_json_keys() {
    let dir = tempfile::tempdir().unwrap();
    let a = dir.path().join("a.txt");
    std::fs::write(&a, "v 0\nv 1\nv 2\nv 3\n").unwrap();
    let uv = dir.path().join("uv.txt");
    std::fs::write(&uv, "0 0\n1 0\n0 1\n1 1\n").unwrap();
    let out = s(&dir.path().join("d.obj"));
    let args = [
        "decal",
        "--mesh",
        "builtin:icosphere",
        "--anchors",
        &s(&a),
        "--uv",
        &s(&uv),
        "-o",
        &out,
        "--json",
    ];
    let keys = [
        "mesh",
        "anchors",
        "vertices",
        "valid_fraction",
        "stretch",
        "stretch_best95",
        "flipped_faces",
        "flipped_area_fraction",
        "seconds",
        "marked",
        "untextured_faces",
        "mtl",
        "texture",
    ];
    assert_keys(&args, &keys);
}

/// A flat 12 x 12 grid in the unit square with its own (x, y) as texture coordinates.
fn textured_grid(path: &Path) {
    let n = 12;
    let mut obj = String::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (i as f64 / n as f64, j as f64 / n as f64);
            obj += &format!("v {x} {y} 0\nvt {x} {y}\n");
        }
    }
    for j in 0..n {
        for i in 0..n {
            let v = |a: usize, b: usize| (j + b) * (n + 1) + i + a + 1;
            let (p, q, r, s) = (v(0, 0), v(1, 0), v(1, 1), v(0, 1));
            obj += &format!("f {p}/{p} {q}/{q} {r}/{r}\nf {p}/{p} {r}/{r} {s}/{s}\n");
        }
    }
    std::fs::write(path, obj).unwrap();
}

#[test]
fn transfer_texture_json_keys() {
    let dir = tempfile::tempdir().unwrap();
    let grid = dir.path().join("grid.obj");
    textured_grid(&grid);
    let texture = s(&dir.path().join("texture.png"));
    wavg_ok(&[
        "render",
        "builtin:icosphere",
        "-o",
        &texture,
        "--size",
        "32",
    ]);
    let a = dir.path().join("a.txt");
    std::fs::write(&a, "v 0\nv 12\nv 84\nv 156\nv 168\n").unwrap();
    let (grid, a) = (s(&grid), s(&a));
    let out = s(&dir.path().join("out.png"));
    let args = [
        "transfer-texture",
        "--source",
        &grid,
        "--source-texture",
        &texture,
        "--target",
        &grid,
        "--source-anchors",
        &a,
        "--target-anchors",
        &a,
        "-o",
        &out,
        "--size",
        "16",
        "--json",
    ];
    let keys = [
        "texels",
        "valid_fraction",
        "seconds",
        "texels_per_s",
        "width",
        "height",
        "atlas_texels",
        "valid_texels",
        "not_reached",
        "dilated_texels",
        "precompute_s",
        "verified",
        "stride",
        "interpolated_texels",
    ];
    assert_keys(&args, &keys);
}

/// A curve's five control points on `builtin:icosphere`, in `dir`: `--mesh builtin:icosphere
/// --control FILE --samples 50`.
fn icosphere_curve(dir: &Path) -> Vec<String> {
    let control = dir.join("c.txt");
    std::fs::write(&control, "v 0\nv 500\nv 1000\nv 1500\nv 2000\n").unwrap();
    [
        "--mesh",
        "builtin:icosphere",
        "--control",
        &s(&control),
        "--samples",
        "50",
    ]
    .map(String::from)
    .to_vec()
}

#[test]
fn bench_spline_json_keys() {
    let dir = tempfile::tempdir().unwrap();
    let keys = [BENCH_SPLINE, &["mesh", "load"]].concat();
    let mut args = ["bench", "spline"].map(String::from).to_vec();
    args.extend(icosphere_curve(dir.path()));
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    assert_keys(&[&args[..], &["--repeat", "2", "--json"]].concat(), &keys);
}

#[test]
fn spline_json_keys() {
    let dir = tempfile::tempdir().unwrap();
    let curve = icosphere_curve(dir.path());
    let out = s(&dir.path().join("curve.txt"));
    let keys = [
        "mesh",
        "controls",
        "degree",
        "closed",
        "bezier",
        "samples",
        "ok_samples",
        "seconds",
        "us_per_sample",
        "length",
    ];
    let mut args = vec!["spline"];
    args.extend(curve.iter().map(String::as_str));
    args.extend(["-o", &out, "--json"]);
    assert_keys(&args, &keys);
    assert_keys(&[&args[..], &["--bezier"]].concat(), &keys);
}

#[test]
fn remesh_json_keys() {
    let dir = tempfile::tempdir().unwrap();
    let base = dir.path().join("tetra.obj");
    // A tetrahedron inscribed in the unit sphere.
    std::fs::write(
        &base,
        "v 0.5773502691896258 0.5773502691896258 0.5773502691896258\n\
         v 0.5773502691896258 -0.5773502691896258 -0.5773502691896258\n\
         v -0.5773502691896258 0.5773502691896258 -0.5773502691896258\n\
         v -0.5773502691896258 -0.5773502691896258 0.5773502691896258\n\
         f 1 2 3\nf 1 4 2\nf 1 3 4\nf 2 4 3\n",
    )
    .unwrap();
    let out = dir.path().join("fine.obj");
    let run = common::remesh_on_sphere(&base, &out, &["--levels", "1", "--frames", "2", "--json"]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let (o, _) = json_object(&run);
    let mut want = common::REMESH_KEYS.map(String::from);
    want.sort();
    assert_eq!(key_paths(&Value::Object(o)), want);
}

#[test]
fn morph_json_keys() {
    let dir = tempfile::tempdir().unwrap();
    let a = s(&sphere_anchors(dir.path()));
    let out = s(&dir.path().join("frames"));
    let m = "builtin:icosphere";
    let args = pair_args("morph", [m, m], [&a, &a], &out);
    let (o, _) = json_object(&wavg_ok_with(&args, &["--frames", "2", "--json"]));
    let mut want: Vec<String> = [
        "source",
        "target",
        "output",
        "frames",
        "valid_fraction",
        "reasons",
        "seconds",
        "setup_seconds",
    ]
    .iter()
    .map(|k| k.to_string())
    .collect();
    // `reasons` counts by reason: its keys depend on the map, not on the format.
    want.extend(
        o["reasons"]
            .as_object()
            .unwrap()
            .keys()
            .map(|k| format!("reasons.{k}")),
    );
    want.sort();
    assert_eq!(key_paths(&Value::Object(o)), want);
}

/// A fin (three triangles on edge (0, 1)) plus an unreferenced vertex: invalid, and the
/// default repairs fix it.
fn fin(dir: &Path) -> String {
    let p = dir.join("fin.off");
    std::fs::write(
        &p,
        "OFF\n6 3 0\n0 0 0\n1 0 0\n0 1 0\n0 -1 0\n0 0 1\n9 9 9\n3 0 1 2\n3 1 0 3\n3 0 1 4\n",
    )
    .unwrap();
    s(&p)
}

#[test]
fn info_json_keys() {
    let mut keys = vec![
        "mesh",
        "vertices",
        "faces",
        "polygons",
        "skipped_faces",
        "uv_dropped",
        "welded_vertices",
        "skipped_primitives",
        "edges",
        "components",
        "boundary_loops",
        "euler_characteristic",
        "genus",
        "manifold",
        "oriented",
        "watertight",
        "valid",
        "uv",
        "bounding_box",
        "bounding_box.min",
        "bounding_box.max",
        "bounding_box.diagonal",
        "problems",
        "problem_summary",
        "repair",
        "out_of_range",
    ];
    assert_keys(&["info", "--builtin", "torus", "--json"], &keys);
    let dir = tempfile::tempdir().unwrap();
    let fin = fin(dir.path());
    keys.extend([
        "repair.fixes_all",
        "repair.removed_vertices",
        "repair.added_vertices",
        "repair.removed_faces",
        "repair.remaining_problems",
    ]);
    assert_keys(&["info", &fin, "--json"], &keys);
    // `problem_summary` is an array of objects, which `key_paths` does not enter.
    let (o, _) = json_object(&wavg_ok(&["info", &fin, "--json"]));
    let summary = o["problem_summary"].as_array().unwrap();
    assert_eq!(summary.len(), 3);
    for p in summary {
        let want = ["count", "description", "examples", "kind", "remedy"];
        assert_eq!(key_paths(p), want);
    }
}

#[test]
fn repair_json_keys() {
    let dir = tempfile::tempdir().unwrap();
    let fin = fin(dir.path());
    let out = s(&dir.path().join("fixed.obj"));
    let keys = [
        "input",
        "output",
        "vertices_before",
        "faces_before",
        "vertices",
        "faces",
        "removed_vertices",
        "added_vertices",
        "removed_faces",
        "components",
        "valid",
        "problems",
    ];
    assert_keys(&["repair", &fin, "-o", &out, "--json"], &keys);
}

#[test]
fn subdivide_json_keys() {
    let dir = tempfile::tempdir().unwrap();
    let out = s(&dir.path().join("fine.ply"));
    let args = ["subdivide", "builtin:sphere-small", "-o", &out, "--json"];
    let keys = [
        "input_vertices",
        "input_faces",
        "vertices",
        "faces",
        "levels",
        "seconds",
    ];
    assert_keys(&args, &keys);
}

#[test]
fn render_json_keys() {
    let dir = tempfile::tempdir().unwrap();
    let out = s(&dir.path().join("a.png"));
    let args = [
        "render",
        "builtin:sphere-small",
        "-o",
        &out,
        "--size",
        "24x16",
    ];
    let mut keys = vec![
        "output",
        "width",
        "height",
        "vertices",
        "faces",
        "covered_fraction",
        "seconds",
    ];
    assert_keys(&[&args[..], &["--json"]].concat(), &keys);
    let scalars = dir.path().join("s.txt");
    let text: String = (0..162).map(|i| format!("{}\n", i as f64 / 7.0)).collect();
    std::fs::write(&scalars, text).unwrap();
    keys.extend(["scalar_min", "scalar_max"]);
    assert_keys(
        &[&args[..], &["--scalar", &s(&scalars), "--json"]].concat(),
        &keys,
    );
}

#[test]
fn demo_json_keys() {
    let args = [
        "demo",
        "--mesh",
        "builtin:sphere-small",
        "--landmarks",
        "50",
        "--samples",
        "20",
        "--queries",
        "50",
        "--json",
    ];
    let keys = [
        "mesh",
        "vertices",
        "faces",
        "landmarks",
        "precompute_s",
        "stress",
        "geodesic_rel_err_p50",
        "geodesic_rel_err_p90",
        "anchors",
        "anchor_gap",
        "spline_controls",
        "curve_points",
        "curve_ok",
        "curve_us",
        "roundtrip_queries",
        "inverse_us",
        "forward_us",
        "roundtrip_ok_fraction",
        "verified_roundtrip_ok_fraction",
    ];
    assert_keys(&args, &keys);
}

#[test]
fn bench_project_json_keys() {
    let args = [
        "bench",
        "project",
        "--mesh",
        "builtin:sphere-small",
        "--queries",
        "200",
        "--json",
    ];
    assert_keys(&args, &[BENCH_PROJECT, &["mesh"]].concat());
}

#[test]
fn bench_load_json_keys() {
    let dir = tempfile::tempdir().unwrap();
    let fin = fin(dir.path());
    let args = ["bench", "load", "--mesh", &fin, "--repeat", "1", "--json"];
    assert_keys(&args, &[BENCH_LOAD, &["mesh"]].concat());
}
