//! The load protocol: counts of the file read, stage times against the whole run, bad
//! files, the serialised keys.

use wavg::mesh::{io, procedural};
use wavg_bench::load_bench;
use wavg_testdata::json_keys::{BENCH_LOAD, sorted};

/// Counts are those of the mesh written; each stage's best time is at most the best run's.
#[test]
fn reports_the_file_and_its_stages() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("torus.off");
    let mesh = procedural::torus(24, 8, 1.0, 0.3);
    io::save(&path, &mesh).unwrap();
    let r = load_bench(&path, 3).unwrap();
    assert_eq!((r.vertices, r.faces), (mesh.n_vertices(), mesh.n_faces()));
    assert_eq!(r.bytes, std::fs::metadata(&path).unwrap().len() as usize);
    assert_eq!(r.repeat, 3);
    assert!(r.valid && r.topology_built, "{r:?}");
    for t in [r.read_s, r.parse_s, r.validate_topology_s] {
        assert!(t.is_finite() && t >= 0.0 && t <= r.total_s, "{r:?}");
    }
    // The stages' best times add up to no more than the best whole run.
    assert!(
        r.read_s + r.parse_s + r.validate_topology_s <= r.total_s + 1e-9,
        "{r:?}"
    );
    // 0 runs counts as one.
    assert_eq!(load_bench(&path, 0).unwrap().repeat, 1);
}

/// A mesh that is not valid is still measured; a missing or unreadable file is an error.
#[test]
fn invalid_meshes_are_measured_and_bad_files_refused() {
    let dir = tempfile::tempdir().unwrap();
    // Three triangles on one edge: not a manifold.
    let fan = dir.path().join("fan.obj");
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n";
    std::fs::write(&fan, text).unwrap();
    let r = load_bench(&fan, 1).unwrap();
    assert_eq!((r.vertices, r.faces), (5, 3));
    assert!(!r.valid, "{r:?}");
    assert!(load_bench(&dir.path().join("missing.obj"), 1).is_err());
    let junk = dir.path().join("junk.off");
    std::fs::write(&junk, "OFF\nnot numbers\n").unwrap();
    assert!(load_bench(&junk, 1).is_err());
}

/// The JSON keys are those of `wavg bench load --json` less `mesh`.
#[test]
fn serialises_to_the_documented_keys() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("ico.obj");
    io::save(&path, &procedural::icosphere(1)).unwrap();
    let v = serde_json::to_value(load_bench(&path, 1).unwrap()).unwrap();
    let mut keys: Vec<&str> = v.as_object().unwrap().keys().map(String::as_str).collect();
    keys.sort();
    assert_eq!(keys, sorted(BENCH_LOAD, &[]));
}
