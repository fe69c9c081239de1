//! Every file under `bad/` of the shared data set gives a typed parse error or a report
//! naming its problems (figures from `shared/data/README.md`), the repairs make the
//! repairable ones valid, and nothing panics or hangs, even on the 438k-vertex dragon.

use std::path::Path;

use wavg_mesh::DefectKind::{self, *};
use wavg_mesh::{MeshError, ValidMesh, analyze, io};
use wavg_mesh::{RepairOptions, repair};
use wavg_testdata as data;

enum Expect {
    /// Unparseable: a parse error at this line.
    Parse(usize),
    /// Parses; these exact problem kinds (with a count where the README gives one).
    Report {
        v: usize,
        tris: usize,
        loops: usize,
        chi: Option<i64>,
        problems: &'static [(DefectKind, Option<usize>)],
        /// `repair_all` with default options yields a valid mesh.
        repairable: bool,
    },
    /// Listed under bad/ but a valid mesh (an OBJ parser corner case read correctly).
    Valid {
        v: usize,
        tris: usize,
        loops: usize,
        components: usize,
        genus: i64,
    },
}
use Expect::*;

const fn report(
    v: usize,
    tris: usize,
    loops: usize,
    chi: Option<i64>,
    problems: &'static [(DefectKind, Option<usize>)],
    repairable: bool,
) -> Expect {
    Report {
        v,
        tris,
        loops,
        chi,
        problems,
        repairable,
    }
}

#[rustfmt::skip]
const TABLE: &[(&str, Expect)] = &[
    ("beetle.obj", report(1148, 2053, 23, Some(-3), &[(NonManifoldEdge, Some(47)), (NonManifoldVertex, None)], true)),
    ("camel-reference.obj.gz", report(21887, 43814, 2, Some(3), &[(DuplicateFace, Some(14)), (NonManifoldEdge, Some(26)), (NonManifoldVertex, None)], true)),
    ("cow.obj", report(2903, 5804, 0, Some(1), &[(NonManifoldVertex, Some(1))], true)),
    // 108 zero-area faces; welding its 2100 duplicate positions joins the 151 components.
    ("dragon_vrip.off.gz", report(437645, 871414, 407, Some(-197), &[(ZeroAreaFace, Some(108))], true)),
    ("dragon_vrip_res4.off", report(5205, 11102, 0, Some(509), &[(DuplicateFace, Some(502)), (NonManifoldEdge, Some(803)), (NonManifoldVertex, None), (UnreferencedVertex, Some(2))], true)),
    ("ogre.obj.gz", report(62194, 124008, 12, Some(72), &[(ZeroAreaFace, Some(4)), (NonManifoldVertex, Some(3))], true)),
    ("stanford-bunny.obj.gz", report(35947, 69451, 5, None, &[(UnreferencedVertex, Some(1113))], true)),
    ("suzanne.obj", report(507, 32 + 468 * 2, 4, Some(3), &[(DuplicateFace, Some(1)), (NonManifoldEdge, Some(1)), (NonManifoldVertex, None)], true)),
    ("teapot.obj", report(3644, 6320, 10, Some(-34), &[(NonManifoldVertex, Some(38))], true)),
    // Face lines lack the vertex count and are 1-based: strict OFF rejects the first one.
    ("tosca_cat0_malformed.off", Parse(3403)),
    ("trimesh_joined_tetrahedra.obj", report(5, 8, 0, Some(4), &[(DuplicateFace, Some(1)), (NonManifoldEdge, Some(3)), (NonManifoldVertex, None)], true)),
    ("trimesh_nancolor.obj", Valid { v: 8, tris: 12, loops: 0, components: 1, genus: 0 }),
    ("trimesh_negative_indices.obj", Valid { v: 8, tris: 12, loops: 0, components: 1, genus: 0 }),
    // The 2-index face is skipped (fan triangulation of a 2-gon is empty).
    ("trimesh_notenoughindices.obj", Valid { v: 3, tris: 1, loops: 1, components: 1, genus: 0 }),
    ("synthetic/duplicate_faces.obj", report(4, 5, 0, Some(3), &[(DuplicateFace, Some(1)), (NonManifoldEdge, Some(3)), (NonManifoldVertex, None)], true)),
    // A valid mesh of six separate squares until welded (checked below).
    ("synthetic/duplicate_vertices_soup.obj", Valid { v: 24, tris: 12, loops: 6, components: 6, genus: 0 }),
    ("synthetic/empty.obj", report(0, 0, 0, Some(0), &[(Empty, Some(1))], false)),
    ("synthetic/empty.off", report(0, 0, 0, Some(0), &[(Empty, Some(1))], false)),
    ("synthetic/flipped_face.obj", report(4, 4, 0, Some(2), &[(InconsistentOrientation, Some(3))], true)),
    ("synthetic/index_out_of_range.obj", report(4, 2, 1, None, &[(IndexOutOfRange, Some(1)), (UnreferencedVertex, Some(1))], true)),
    ("synthetic/inf_vertex.off", report(4, 4, 0, Some(2), &[(NonFiniteCoordinate, Some(1))], true)),
    ("synthetic/isolated_vertices.off", report(6, 4, 0, Some(2), &[(UnreferencedVertex, Some(2))], true)),
    ("synthetic/mixed_polygons.obj", Valid { v: 10, tris: 5 * 2 + 2 * 3, loops: 0, components: 1, genus: 0 }),
    ("synthetic/moebius.obj", report(48, 48, 1, Some(0), &[(InconsistentOrientation, Some(1))], false)),
    ("synthetic/nan_vertex.obj", report(4, 4, 0, Some(2), &[(NonFiniteCoordinate, Some(1))], true)),
    ("synthetic/nonmanifold_edge_fin.obj", report(5, 3, 1, Some(1), &[(NonManifoldEdge, Some(1)), (NonManifoldVertex, None)], true)),
    ("synthetic/nonmanifold_vertex_bowtie.obj", report(5, 2, 1, Some(1), &[(NonManifoldVertex, Some(1))], true)),
    ("synthetic/nonmanifold_vertex_two_cones.obj", report(9, 12, 0, Some(3), &[(NonManifoldVertex, Some(1))], true)),
    ("synthetic/sliver_faces.obj", report(5, 6, 0, Some(2), &[(ZeroAreaFace, Some(1))], true)),
    // The header promises 4 vertices and 4 faces; the face line is read as a 4th vertex.
    ("synthetic/truncated.off", Parse(7)),
    ("synthetic/zero_area_faces.obj", report(5, 4, 1, None, &[(RepeatedIndex, Some(1)), (ZeroAreaFace, Some(1))], true)),
];

fn all_files(dir: &Path, prefix: &str, out: &mut Vec<String>) {
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        let name = e.file_name().to_string_lossy().into_owned();
        if p.is_dir() {
            all_files(&p, &format!("{prefix}{name}/"), out);
        } else {
            out.push(format!("{prefix}{name}"));
        }
    }
}

#[test]
fn every_bad_file_is_diagnosed_and_repairable_ones_are_repaired() {
    let Some(root) = data::require_data_dir("every_bad_file_is_diagnosed") else {
        return;
    };
    let bad = root.join("bad");
    let mut present = Vec::new();
    all_files(&bad, "", &mut present);
    for f in &present {
        assert!(
            TABLE.iter().any(|(n, _)| n == f),
            "bad/{f} has no expectation"
        );
    }
    for (name, expect) in TABLE {
        let path = bad.join(name);
        let loaded = io::load_with_notes(&path);
        match (expect, loaded) {
            (
                Parse(line),
                Err(MeshError::Parse {
                    path: p, line: l, ..
                }),
            ) => {
                assert_eq!(p, path);
                assert_eq!(l, *line, "{name}: parse error line");
            }
            (Parse(_), other) => panic!("{name}: expected a parse error, got {other:?}"),
            (_, Err(e)) => panic!("{name}: {e}"),
            (
                Valid {
                    v,
                    tris,
                    loops,
                    components,
                    genus,
                },
                Ok((mesh, notes)),
            ) => {
                if *name == "trimesh_notenoughindices.obj" {
                    assert_eq!(notes.skipped_faces, 1);
                }
                let m = ValidMesh::new(mesh).unwrap_or_else(|e| panic!("{name}: {e}"));
                let t = m.topology();
                assert_eq!((m.n_vertices(), m.n_faces()), (*v, *tris), "{name}");
                assert_eq!(t.boundary_loops().len(), *loops, "{name}");
                assert_eq!(t.n_components(), *components, "{name}");
                assert_eq!(t.genus(), *genus, "{name}");
            }
            (
                Report {
                    v,
                    tris,
                    loops,
                    chi,
                    problems,
                    repairable,
                },
                Ok((mesh, _)),
            ) => {
                let a = analyze(&mesh);
                assert_eq!((a.stats.vertices, a.stats.faces), (*v, *tris), "{name}");
                assert_eq!(a.stats.boundary_loops, *loops, "{name}: boundary loops");
                if let Some(chi) = chi {
                    assert_eq!(a.stats.euler_characteristic, *chi, "{name}: chi");
                }
                let kinds: Vec<DefectKind> = a.report.summary().iter().map(|s| s.kind).collect();
                let expected: Vec<DefectKind> = problems.iter().map(|p| p.0).collect();
                assert_eq!(kinds, expected, "{name}: {}", a.report);
                for (kind, count) in problems.iter() {
                    if let Some(c) = count {
                        assert_eq!(a.report.count(*kind), *c, "{name}: {kind:?}");
                    }
                }
                assert!(ValidMesh::new(mesh.clone()).is_err(), "{name}");
                let r = repair::repair_all(&mesh, &RepairOptions::default());
                let valid = ValidMesh::new(r.mesh);
                assert_eq!(
                    valid.is_ok(),
                    *repairable,
                    "{name}: after repair {:?}",
                    valid.err()
                );
            }
        }
    }
}

/// The data set's file `relative`, loaded; `None` (the test is skipped) without the data
/// folder.
fn load_data_file(test: &str, relative: &str) -> Option<wavg_mesh::TriMesh> {
    data::require_data_file(test, relative).map(|p| io::load(&p).unwrap())
}

#[test]
fn welding_the_soup_closes_the_cube() {
    let Some(m) = load_data_file(
        "welding_the_soup_closes_the_cube",
        "bad/synthetic/duplicate_vertices_soup.obj",
    ) else {
        return;
    };
    let r = repair::weld_vertices(&m, 0.0);
    assert_eq!(r.mesh.n_vertices(), 8);
    let v = ValidMesh::new(r.mesh).unwrap();
    assert_eq!(v.topology().n_components(), 1);
    assert!(v.topology().boundary_loops().is_empty());
    assert_eq!(v.topology().genus(), 0);
}

#[test]
fn large_dirty_dragon_is_diagnosed_and_repaired() {
    let Some(m) = load_data_file(
        "large_dirty_dragon_is_diagnosed_and_repaired",
        "bad/dragon_vrip.off.gz",
    ) else {
        return;
    };
    let a = analyze(&m);
    assert_eq!(a.stats.components, 151);
    assert_eq!(a.stats.genus, Some(46));
    assert!(a.stats.manifold);
    let r = repair::repair_all(
        &m,
        &RepairOptions {
            keep_largest_component: true,
            ..RepairOptions::default()
        },
    );
    assert_eq!(r.removed_faces(m.n_faces()), 108);
    let v = ValidMesh::new(r.mesh).unwrap();
    assert_eq!(v.topology().n_components(), 1);
    // The ids of the original file still reach the repaired vertices.
    for (new, &orig) in r.vertex_map.iter().enumerate().step_by(997) {
        assert_eq!(v.positions[new], m.positions[orig as usize]);
    }
}

/// Cut every small bad file at many places and corrupt bytes: the readers must return a
/// mesh or an error, never panic.
#[test]
fn damaged_bad_files_never_panic() {
    let Some(root) = data::require_data_dir("damaged_bad_files_never_panic") else {
        return;
    };
    for (name, _) in TABLE {
        let path = root.join("bad").join(name);
        if name.ends_with(".gz") {
            continue;
        }
        let bytes = std::fs::read(&path).unwrap();
        let (format, _) = wavg_mesh::Format::from_path(&path).unwrap();
        let n = bytes.len();
        for k in 0..40usize {
            let cut = n * k / 40;
            let _ = io::parse_bytes(&bytes[..cut], format, &path);
            let mut b = bytes[..n.min(4096)].to_vec();
            if !b.is_empty() {
                let i = (k * 7919) % b.len();
                b[i] = [b'-', b'/', b'0', b'#', 0xff, b'\n', b' ', b'9'][k % 8];
                if let Ok((m, _)) = io::parse_bytes(&b, format, &path) {
                    let _ = analyze(&m);
                    let _ = repair::repair_all(&m, &RepairOptions::default());
                }
            }
        }
    }
}
