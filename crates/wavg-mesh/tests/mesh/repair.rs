//! Repairs: each fixes its problem, keeps everything else, and its index maps are right.

use nalgebra::Vector3;
use proptest::prelude::*;
use wavg_mesh::{DefectKind, NONE, TexCoords, TriMesh, ValidMesh, analyze, procedural};
use wavg_mesh::{RepairOptions, Repaired, repair};

/// Every position is the original's, the two vertex maps are consistent, and every face
/// is the mapped original face (up to a flip, which swaps its last two corners and their
/// texture coordinates).
fn check_maps(orig: &TriMesh, r: &Repaired) {
    assert_eq!(r.vertex_map.len(), r.mesh.n_vertices());
    assert_eq!(r.face_map.len(), r.mesh.n_faces());
    assert_eq!(r.original_to_new.len(), orig.n_vertices());
    for (new, &o) in r.vertex_map.iter().enumerate() {
        assert_eq!(r.mesh.positions[new], orig.positions[o as usize]);
        // A copy made by splitting names its original, which keeps one new index.
        let kept = r.original_to_new[o as usize];
        assert_eq!(r.vertex_map[kept as usize], o);
    }
    for (o, &new) in r.original_to_new.iter().enumerate() {
        if new != NONE {
            let p = orig.positions[o];
            let q = r.mesh.positions[new as usize];
            assert!((p - q).norm() <= 1e-6 || (p == q), "vertex {o} moved");
        }
    }
    for (f, &of) in r.face_map.iter().enumerate() {
        let ot = orig.triangles[of as usize].map(|v| r.original_to_new[v as usize]);
        let nt = r.mesh.triangles[f].map(|v| r.original_to_new[r.vertex_map[v as usize] as usize]);
        let flipped = [nt[0], nt[2], nt[1]];
        assert!(nt == ot || flipped == ot, "face {f}: {nt:?} vs {ot:?}");
        if let (Some(ou), Some(nu)) = (&orig.uv, &r.mesh.uv) {
            let (n, o) = (nu.faces[f], ou.faces[of as usize]);
            assert!(
                if nt == ot {
                    n == o
                } else {
                    [n[0], n[2], n[1]] == o
                },
                "uv of face {f}"
            );
        }
    }
}

/// Each triangle gets its own three vertices (as an STL export would).
fn soup(m: &TriMesh) -> TriMesh {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for f in 0..m.n_faces() {
        let base = positions.len() as u32;
        positions.extend(m.corners(f));
        triangles.push([base, base + 1, base + 2]);
    }
    TriMesh::new(positions, triangles)
}

#[test]
fn weld_exact_restores_a_soup() {
    let m = procedural::icosphere(2);
    let s = soup(&m);
    assert!(analyze(&s).stats.components > 1);
    let r = repair::weld_vertices(&s, 0.0);
    check_maps(&s, &r);
    assert_eq!(r.mesh.n_vertices(), m.n_vertices());
    assert_eq!(r.removed_vertices(), s.n_vertices() - m.n_vertices());
    let v = ValidMesh::new(r.mesh).expect("welded soup is valid");
    assert_eq!(v.topology().genus(), 0);
    assert_eq!(v.topology().n_components(), 1);
}

#[test]
fn weld_with_tolerance_merges_near_points_only() {
    let m = procedural::torus(16, 8, 1.0, 0.3);
    let mut s = soup(&m);
    // Jitter every soup vertex by < 1e-9.
    for (i, p) in s.positions.iter_mut().enumerate() {
        p.x += ((i % 7) as f64) * 1e-10;
    }
    assert_eq!(
        repair::weld_vertices(&s, 0.0).mesh.n_vertices(),
        s.n_vertices() - count_exact_dups(&s)
    );
    let r = repair::weld_vertices(&s, 1e-6);
    check_maps(&s, &r);
    assert_eq!(r.mesh.n_vertices(), m.n_vertices());
    let v = ValidMesh::new(r.mesh).unwrap();
    assert_eq!(v.topology().genus(), 1);
}

fn count_exact_dups(m: &TriMesh) -> usize {
    let mut seen = std::collections::HashSet::new();
    m.positions
        .iter()
        .filter(|p| !seen.insert([p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]))
        .count()
}

#[test]
fn weld_never_merges_non_finite_points() {
    let m = TriMesh::new(
        vec![
            Vector3::new(f64::NAN, 0.0, 0.0),
            Vector3::new(f64::NAN, 0.0, 0.0),
        ],
        vec![],
    );
    assert_eq!(repair::weld_vertices(&m, 0.0).mesh.n_vertices(), 2);
    assert_eq!(repair::weld_vertices(&m, 1.0).mesh.n_vertices(), 2);
}

#[test]
fn degenerate_duplicate_and_unreferenced_are_removed() {
    let mut m = procedural::icosphere(1);
    let nf = m.n_faces() as u32;
    let nv = m.n_vertices() as u32;
    let mut t0 = m.triangles[0];
    m.triangles.push([0, 0, 1]); // repeated index
    m.triangles.push([0, 1, nv + 10]); // out of range
    t0.reverse();
    m.triangles.push(t0); // duplicate of face 0 (flipped)
    m.triangles.push(m.triangles[5]); // duplicate of face 5
    // Collinear face on a new vertex at the midpoint of an edge.
    let [a, b] = [m.triangles[3][0], m.triangles[3][1]];
    let mid = (m.positions[a as usize] + m.positions[b as usize]) / 2.0;
    m.positions.push(mid);
    m.triangles.push([a, b, nv]);
    m.positions.push(Vector3::new(5.0, 5.0, 5.0)); // unreferenced
    let a0 = analyze(&m);
    for k in [
        DefectKind::RepeatedIndex,
        DefectKind::IndexOutOfRange,
        DefectKind::DuplicateFace,
        DefectKind::ZeroAreaFace,
        DefectKind::UnreferencedVertex,
    ] {
        assert!(a0.report.count(k) > 0, "{k:?} not detected");
    }

    let d = repair::drop_degenerate_faces(&m);
    check_maps(&m, &d);
    assert_eq!(d.face_map.len(), m.n_faces() - 3);
    let dd = repair::drop_duplicate_faces(&d.mesh);
    check_maps(&d.mesh, &dd);
    assert_eq!(dd.mesh.n_faces(), nf as usize);
    let u = repair::drop_unreferenced_vertices(&dd.mesh);
    check_maps(&dd.mesh, &u);
    assert_eq!(u.mesh.n_vertices(), nv as usize);
    assert!(ValidMesh::new(u.mesh.clone()).is_ok());

    let all = repair::repair_all(&m, &RepairOptions::default());
    check_maps(&m, &all);
    assert_eq!(all.mesh.triangles, u.mesh.triangles);
    assert_eq!(all.new_vertex(nv + 1), None);
    assert!(ValidMesh::new(all.mesh).is_ok());
}

#[test]
fn unreferenced_drop_keeps_out_of_range_indices_out_of_range() {
    let mut m = procedural::icosphere(0);
    m.positions.insert(0, Vector3::new(9.0, 9.0, 9.0));
    for t in &mut m.triangles {
        *t = t.map(|i| i + 1);
    }
    m.triangles.push([1, 2, 13]); // 13 == n_vertices: out of range
    let r = repair::drop_unreferenced_vertices(&m);
    assert_eq!(r.mesh.n_vertices(), 12);
    assert!(r.mesh.triangles.last().unwrap()[2] >= 12);
    assert_eq!(
        analyze(&r.mesh).report.count(DefectKind::IndexOutOfRange),
        1
    );
}

#[test]
fn largest_component_is_kept_with_uvs() {
    let big = procedural::icosphere(2);
    let small =
        procedural::torus(8, 4, 1.0, 0.3).map_positions(|p| p + Vector3::new(5.0, 0.0, 0.0));
    let mut m = small.clone();
    let off = m.n_vertices() as u32;
    m.positions.extend(&big.positions);
    m.triangles
        .extend(big.triangles.iter().map(|t| t.map(|i| i + off)));
    let n = m.n_faces() as u32;
    m.uv = Some(TexCoords {
        coords: vec![nalgebra::Vector2::new(0.0, 0.0); n as usize * 3],
        faces: (0..n).map(|f| [3 * f, 3 * f + 1, 3 * f + 2]).collect(),
    });
    let r = repair::keep_largest_component(&m);
    check_maps(&m, &r);
    assert_eq!(r.mesh.n_vertices(), big.n_vertices());
    assert_eq!(r.mesh.n_faces(), big.n_faces());
    assert_eq!(r.vertex_map[0], off);
    assert_eq!(r.mesh.uv.as_ref().unwrap().faces.len(), big.n_faces());
    let v = ValidMesh::new(r.mesh).unwrap();
    assert_eq!(v.topology().n_components(), 1);
}

#[test]
fn repairs_of_an_empty_mesh_do_not_panic() {
    let m = TriMesh::default();
    let r = repair::repair_all(
        &m,
        &RepairOptions {
            weld: Some(1e-3),
            keep_largest_component: true,
            ..RepairOptions::default()
        },
    );
    assert_eq!(r.mesh.n_vertices(), 0);
}

fn damaged(level: u32, seed: u64, dup: usize, deg: usize, extra: usize, split: bool) -> TriMesh {
    let mut m = procedural::with_noise(procedural::icosphere(level), 0.1, seed);
    if split {
        m = soup(&m);
    }
    let nf = m.n_faces();
    let nv = m.n_vertices() as u32;
    for k in 0..dup {
        let t = m.triangles[(k * 7919 + seed as usize) % nf];
        m.triangles.push([t[2], t[1], t[0]]);
    }
    for k in 0..deg {
        let v = (k as u32 * 31 + seed as u32) % nv;
        m.triangles.push([v, v, (v + 1) % nv]);
    }
    for k in 0..extra {
        m.positions.push(Vector3::new(10.0 + k as f64, 0.0, 0.0));
    }
    m
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    #[test]
    fn repair_all_makes_damaged_spheres_valid(
        level in 0u32..3, seed in 0u64..1000, dup in 0usize..5, deg in 0usize..5,
        extra in 0usize..4, split: bool,
    ) {
        let m = damaged(level, seed, dup, deg, extra, split);
        let r = repair::repair_all(&m, &RepairOptions::default());
        check_maps(&m, &r);
        let v = ValidMesh::new(r.mesh.clone());
        prop_assert!(v.is_ok(), "{:?}", v.err());
        let v = v.unwrap();
        prop_assert_eq!(v.topology().genus(), 0);
        prop_assert_eq!(v.n_faces(), 20 * 4usize.pow(level));
    }
}

/// Every kind that names a remedy is actually fixed by `repair_all`'s default options.
#[test]
fn remedies_named_by_problem_kinds_are_real() {
    let base = procedural::icosphere(1);
    let n = base.n_vertices() as u32;
    let mut cases: Vec<(TriMesh, DefectKind)> = Vec::new();
    let mut m = base.clone();
    m.triangles.push([0, 0, 1]);
    cases.push((m, DefectKind::RepeatedIndex));
    let mut m = base.clone();
    m.triangles.push([0, 1, n + 3]);
    cases.push((m, DefectKind::IndexOutOfRange));
    let mut m = base.clone();
    m.positions[5] = Vector3::new(f64::NAN, 0.0, 0.0);
    cases.push((m, DefectKind::NonFiniteCoordinate));
    let mut m = base.clone();
    m.triangles.push(m.triangles[4]); // also makes 3 non-manifold edges
    cases.push((m, DefectKind::DuplicateFace));
    let mut m = base.clone();
    m.positions.push(Vector3::zeros());
    cases.push((m, DefectKind::UnreferencedVertex));
    let mut m = base.clone();
    let mid = (m.positions[0] + m.positions[11]) / 2.0;
    m.positions.push(mid);
    m.triangles.push([0, 11, n]);
    cases.push((m, DefectKind::ZeroAreaFace));
    let mut m = base.clone();
    m.triangles[3].swap(0, 1);
    cases.push((m, DefectKind::InconsistentOrientation));
    // Two spheres glued at one vertex, and along one edge.
    let (mut pinch, mut fin) = (base.clone(), base.clone());
    for (m, shared) in [(&mut pinch, 1), (&mut fin, 2)] {
        let t0 = base.triangles[0];
        let shift = Vector3::new(3.0, 0.0, 0.0);
        let new: Vec<u32> = (0..n).map(|v| n + v).collect();
        m.positions.extend(base.positions.iter().map(|p| p + shift));
        // Move the copy so that its first `shared` corners of face 0 coincide.
        for &v in &t0[..shared] {
            m.positions[(n + v) as usize] = base.positions[v as usize];
        }
        let glue = |v: u32| {
            if t0[..shared].contains(&v) {
                v
            } else {
                new[v as usize]
            }
        };
        m.triangles
            .extend(base.triangles.iter().map(|t| t.map(glue)));
    }
    cases.push((pinch, DefectKind::NonManifoldVertex));
    cases.push((fin, DefectKind::NonManifoldEdge));
    for (m, kind) in cases {
        let a = analyze(&m);
        assert!(a.report.count(kind) > 0, "{kind:?}: {}", a.report);
        assert!(kind.remedy().is_some(), "{kind:?}");
        let r = repair::repair_all(&m, &RepairOptions::default());
        assert!(ValidMesh::new(r.mesh).is_ok(), "{}", a.report);
    }
}

/// A fin (three triangles on one edge), a bowtie (two triangles on one vertex) and two
/// tetrahedra sharing an edge come apart into valid sheets; original indices still name
/// the same positions, and the texture coordinates follow their faces.
#[test]
fn non_manifold_vertices_and_edges_are_split() {
    let p = |x: f64, y: f64, z: f64| Vector3::new(x, y, z);
    let fin = TriMesh::new(
        vec![
            p(0., 0., 0.),
            p(1., 0., 0.),
            p(0., 1., 0.),
            p(0., -1., 0.),
            p(0., 0., 1.),
        ],
        vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]],
    );
    let bowtie = TriMesh::new(
        vec![
            p(0., 0., 0.),
            p(1., 0., 0.),
            p(1., 1., 0.),
            p(-1., 0., 0.),
            p(-1., -1., 0.),
        ],
        vec![[0, 1, 2], [0, 3, 4]],
    );
    let tet = |o: u32| {
        [
            [o, o + 1, o + 2],
            [o, o + 3, o + 1],
            [o + 1, o + 3, o + 2],
            [o + 2, o + 3, o],
        ]
    };
    let mut tets = TriMesh::new(
        vec![p(0., 0., 0.), p(1., 0., 0.), p(0., 1., 0.), p(0., 0., 1.)],
        tet(0).to_vec(),
    );
    // A second tetrahedron on the first one's edge (0, 1).
    tets.positions.extend([p(0., -1., 0.), p(0., 0., -1.)]);
    tets.triangles
        .extend([[1, 0, 4], [0, 5, 4], [4, 5, 1], [1, 5, 0]]);
    for (name, mut m, sheets) in [("fin", fin, 3), ("bowtie", bowtie, 2), ("tets", tets, 2)] {
        m.uv = Some(TexCoords {
            coords: vec![nalgebra::Vector2::zeros(); 3 * m.n_faces()],
            faces: (0..m.n_faces() as u32)
                .map(|f| [3 * f, 3 * f + 1, 3 * f + 2])
                .collect(),
        });
        assert!(ValidMesh::new(m.clone()).is_err(), "{name}");
        let r = repair::make_manifold(&m);
        check_maps(&m, &r);
        assert_eq!(r.mesh.n_faces(), m.n_faces(), "{name}: no face lost");
        assert_eq!(r.removed_vertices(), 0, "{name}");
        let v = ValidMesh::new(r.mesh.clone()).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(v.topology().n_components(), sheets, "{name}");
        assert_eq!(
            r.added_vertices(),
            r.mesh.n_vertices() - m.n_vertices(),
            "{name}"
        );
        assert_eq!(r.mesh.uv, m.uv, "{name}: texture coordinates unchanged");
    }
}

/// Flipped faces are turned back (with their texture coordinates) and the first face of
/// each component keeps its orientation; a Moebius strip cannot be oriented and stays
/// invalid without panicking.
#[test]
fn faces_are_oriented_consistently() {
    let base = procedural::icosphere(2);
    let mut m = base.clone();
    for f in (1..m.n_faces()).step_by(3) {
        m.triangles[f].swap(1, 2);
    }
    m.uv = Some(TexCoords {
        coords: vec![nalgebra::Vector2::zeros(); 3 * m.n_faces()],
        faces: (0..m.n_faces() as u32)
            .map(|f| [3 * f, 3 * f + 1, 3 * f + 2])
            .collect(),
    });
    assert!(ValidMesh::new(m.clone()).is_err());
    let r = repair::orient_faces(&m);
    check_maps(&m, &r);
    assert_eq!(r.mesh.triangles, base.triangles);
    assert!(ValidMesh::new(r.mesh).is_ok());

    let moebius = moebius_strip(24);
    let r = repair::repair_all(&moebius, &RepairOptions::default());
    check_maps(&moebius, &r);
    let a = analyze(&r.mesh);
    assert!(a.report.count(DefectKind::InconsistentOrientation) > 0);
}

/// A Moebius strip of `n` quads (two triangles each), one half twist.
fn moebius_strip(n: u32) -> TriMesh {
    let mut positions = Vec::new();
    for i in 0..n {
        let t = std::f64::consts::TAU * i as f64 / n as f64;
        for s in [-0.3, 0.3] {
            let (r, h) = (1.0 + s * (t / 2.0).cos(), s * (t / 2.0).sin());
            positions.push(Vector3::new(r * t.cos(), r * t.sin(), h));
        }
    }
    let mut triangles = Vec::new();
    for i in 0..n {
        let (a, b) = (2 * i, 2 * i + 1);
        // The last quad closes onto the first with its sides swapped.
        let (c, d) = if i + 1 == n {
            (1, 0)
        } else {
            (2 * i + 2, 2 * i + 3)
        };
        triangles.push([a, c, b]);
        triangles.push([b, c, d]);
    }
    TriMesh::new(positions, triangles)
}

fn scrambled(level: u32, seed: u64, flips: usize, glue: bool) -> TriMesh {
    let mut m = procedural::with_noise(procedural::icosphere(level), 0.1, seed);
    let nf = m.n_faces();
    for k in 0..flips {
        m.triangles[(k * 7919 + seed as usize) % nf].swap(0, 2);
    }
    if glue {
        // A second sphere sharing one vertex with the first.
        let n = m.n_vertices() as u32;
        let first = m.triangles[0][0];
        let shift = Vector3::new(5.0, 0.0, 0.0);
        let copy: Vec<_> = m.positions.iter().map(|p| p + shift).collect();
        m.positions.extend(copy);
        let more: Vec<[u32; 3]> = (m.triangles.iter())
            .map(|t| t.map(|v| if v == first { first } else { v + n }))
            .collect();
        m.triangles.extend(more);
    }
    m
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    /// Random flips and a pinched second sphere: the default repairs give a valid mesh
    /// with every face kept, and every original index still names its position.
    #[test]
    fn repair_all_orients_and_splits(level in 0u32..3, seed in 0u64..1000, flips in 0usize..40, glue: bool) {
        let m = scrambled(level, seed, flips, glue);
        let r = repair::repair_all(&m, &RepairOptions::default());
        check_maps(&m, &r);
        prop_assert_eq!(r.mesh.n_faces(), m.n_faces());
        let v = ValidMesh::new(r.mesh.clone());
        prop_assert!(v.is_ok(), "{:?}", v.err());
        prop_assert_eq!(v.unwrap().topology().n_components(), 1 + glue as usize);
    }
}
