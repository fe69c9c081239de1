//! `wavg repair` run as a process: repaired output is valid, the vertex map points back to
//! the input, remaining problems give exit 1, unreadable input exit 2.

use crate::common;

use common::{wavg, wavg_ok};

use std::path::Path;

use serde_json::Value;
use wavg::mesh::{ValidMesh, io, procedural};

/// `wavg repair IN -o OUT --map MAP --json`, which must succeed; its JSON.
fn repair_with_map(input: &Path, output: &Path, map: &Path) -> Value {
    let args = [
        "repair",
        input.to_str().unwrap(),
        "-o",
        output.to_str().unwrap(),
    ];
    let out = wavg_ok(&[&args[..], &["--map", map.to_str().unwrap(), "--json"]].concat());
    serde_json::from_slice(&out.stdout).unwrap()
}

/// The vertex map file: one input vertex per output vertex.
fn read_map(map: &Path) -> Vec<u32> {
    let text = std::fs::read_to_string(map).unwrap();
    text.lines().map(|l| l.parse().unwrap()).collect()
}

#[test]
fn repairs_unwelded_mesh_and_writes_vertex_map() {
    let dir = tempfile::tempdir().unwrap();
    // A torus whose faces are split into a soup: every face gets its own three vertices.
    let torus = procedural::torus(10, 6, 1.0, 0.3);
    let mut soup = torus.clone();
    soup.positions.clear();
    soup.triangles.clear();
    for t in &torus.triangles {
        let base = soup.positions.len() as u32;
        soup.positions
            .extend(t.iter().map(|&v| torus.positions[v as usize]));
        soup.triangles.push([base, base + 1, base + 2]);
    }
    let input = dir.path().join("soup.obj");
    io::save(&input, &soup).unwrap();
    let output = dir.path().join("fixed.off");
    let map = dir.path().join("map.txt");
    let j = repair_with_map(&input, &output, &map);
    assert_eq!(j["valid"], true);
    assert_eq!(j["vertices"], torus.n_vertices());
    assert_eq!(j["faces"], torus.n_faces());
    let fixed = ValidMesh::new(io::load(&output).unwrap()).expect("repaired mesh is valid");
    assert_eq!(fixed.topology().genus(), 1);
    let lines = read_map(&map);
    assert_eq!(lines.len(), fixed.n_vertices());
    for (new, &old) in lines.iter().enumerate() {
        assert_eq!(fixed.positions[new], soup.positions[old as usize]);
    }
    // No temporary files are left beside the outputs.
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 3, "{names:?}");
}

#[test]
fn remaining_problems_exit_1_and_components_need_opt_in() {
    let dir = tempfile::tempdir().unwrap();
    // Two disjoint spheres: --largest-component keeps one.
    let a = procedural::icosphere(1);
    let mut two = a.clone();
    let n = a.n_vertices() as u32;
    two.positions.extend(
        a.positions
            .iter()
            .map(|p| p + nalgebra::Vector3::new(5.0, 0.0, 0.0)),
    );
    two.triangles
        .extend(a.triangles.iter().map(|t| t.map(|v| v + n)));
    let input = dir.path().join("two.obj");
    io::save(&input, &two).unwrap();
    let output = dir.path().join("one.obj");
    wavg_ok(&[
        "repair",
        input.to_str().unwrap(),
        "-o",
        output.to_str().unwrap(),
        "--largest-component",
    ]);
    assert_eq!(io::load(&output).unwrap().n_vertices(), a.n_vertices());

    // A fin (three faces on one edge) comes apart into three sheets; the map names the
    // input vertex of every copy. With --keep-nonmanifold it stays broken: output
    // written, exit 1.
    let fin = wavg::mesh::TriMesh::new(
        vec![
            nalgebra::Vector3::new(0.0, 0.0, 0.0),
            nalgebra::Vector3::new(1.0, 0.0, 0.0),
            nalgebra::Vector3::new(0.5, 1.0, 0.0),
            nalgebra::Vector3::new(0.5, -1.0, 0.0),
            nalgebra::Vector3::new(0.5, 0.0, 1.0),
        ],
        vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]],
    );
    let input = dir.path().join("fin.obj");
    io::save(&input, &fin).unwrap();
    let output = dir.path().join("fin-out.obj");
    let map = dir.path().join("fin-map.txt");
    let j = repair_with_map(&input, &output, &map);
    assert_eq!(
        (j["valid"].as_bool(), j["components"].as_u64()),
        (Some(true), Some(3))
    );
    assert_eq!(
        (j["added_vertices"].as_u64(), j["removed_faces"].as_u64()),
        (Some(4), Some(0))
    );
    let fixed = ValidMesh::new(io::load(&output).unwrap()).expect("split fin is valid");
    let lines = read_map(&map);
    assert_eq!(lines.len(), 9);
    assert_eq!(&lines[..5], &[0, 1, 2, 3, 4]);
    for (new, &old) in lines.iter().enumerate() {
        assert_eq!(fixed.positions[new], fin.positions[old as usize]);
    }
    let out = wavg(&[
        "repair",
        input.to_str().unwrap(),
        "-o",
        output.to_str().unwrap(),
        "--keep-nonmanifold",
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stdout).contains("non-manifold edges"));
    assert!(output.exists());

    let out = wavg(&["repair", "/nonexistent.obj", "-o", output.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
}

/// An output without a mesh extension is refused before the repair, naming the user's path
/// (not a temporary file's).
#[test]
fn an_output_without_a_mesh_extension_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.obj");
    io::save(&input, &ValidMesh::new(procedural::icosphere(1)).unwrap()).unwrap();
    let output = dir.path().join("fixed");
    let out = wavg(&[
        "repair",
        input.to_str().unwrap(),
        "-o",
        output.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains(output.to_str().unwrap()) && !err.contains(".tmp-"),
        "{err}"
    );
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

/// A repair whose result is valid but in several pieces says that the embedding needs one
/// (stderr), and `precompute` on a mesh that `wavg repair` fixes names that command.
#[test]
fn several_components_and_fixable_meshes_point_to_the_next_step() {
    let dir = tempfile::tempdir().unwrap();
    let a = wavg::mesh::procedural::icosphere(1);
    let mut two = a.clone();
    let n = a.n_vertices() as u32;
    two.positions
        .extend(a.positions.iter().map(|p| p.add_scalar(5.0)));
    two.triangles
        .extend(a.triangles.iter().map(|t| t.map(|v| v + n)));
    let input = dir.path().join("two.obj");
    io::save(&input, &two).unwrap();
    let output = dir.path().join("two-out.obj");
    let out = wavg_ok(&[
        "repair",
        input.to_str().unwrap(),
        "-o",
        output.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("2 connected components") && err.contains("--largest-component"),
        "{err}"
    );
    // A duplicated face: invalid, and the default repair fixes it.
    let mut dup = a.clone();
    dup.triangles.push(dup.triangles[0]);
    let input = dir.path().join("dup.obj");
    io::save(&input, &dup).unwrap();
    let wavg_file = dir.path().join("dup.wavg");
    let out = wavg(&[
        "precompute",
        input.to_str().unwrap(),
        "-o",
        wavg_file.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("`wavg repair") && err.contains("fixes it"),
        "{err}"
    );
}
