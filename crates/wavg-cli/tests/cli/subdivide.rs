//! `wavg subdivide` run as a process: counts, a valid output keeping the input's vertex ids
//! first, JSON keys, and errors for invalid input.

use crate::common;

use common::{json_object, wavg, wavg_ok};
use wavg::mesh::{ValidMesh, io, procedural};

#[test]
fn two_levels_of_a_torus() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("t.obj");
    let mesh = procedural::torus(16, 8, 1.0, 0.3);
    io::save(&input, &mesh).unwrap();
    let out = dir.path().join("t2.ply");
    let run = wavg_ok(&[
        "subdivide",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--levels",
        "2",
        "--json",
    ]);
    let (o, keys) = json_object(&run);
    assert_eq!(
        keys,
        [
            "faces",
            "input_faces",
            "input_vertices",
            "levels",
            "seconds",
            "vertices"
        ]
    );
    let sub = ValidMesh::new(io::load(&out).unwrap()).unwrap();
    assert_eq!(sub.n_faces(), 16 * mesh.n_faces());
    assert_eq!(o["faces"].as_u64().unwrap() as usize, sub.n_faces());
    assert_eq!(o["vertices"].as_u64().unwrap() as usize, sub.n_vertices());
    // A closed genus-1 mesh: V - E + F = 0 at every level, with E = 3F/2.
    assert_eq!(2 * sub.n_vertices(), sub.n_faces());
    assert_eq!(sub.topology().genus(), 1);
}

#[test]
fn invalid_input_is_refused_and_nothing_written() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("bad.obj");
    // Two triangles sharing an edge with the same orientation: not oriented.
    std::fs::write(
        &input,
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 3 4\n",
    )
    .unwrap();
    let out = dir.path().join("out.obj");
    let run = wavg(&[
        "subdivide",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(run.status.code(), Some(2));
    assert!(!out.exists());
    let run = wavg(&[
        "subdivide",
        "builtin:torus",
        "-o",
        out.to_str().unwrap(),
        "--levels",
        "9",
    ]);
    assert_eq!(run.status.code(), Some(2));
}
