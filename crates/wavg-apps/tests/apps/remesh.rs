//! Semiregular remeshing: closed-form counts, points on the surface, level-1 points equal
//! to the forward problem of their anchors, smoothing evens the mesh out, warm
//! recomputation equals cold, bad bases are typed errors; generated meshes and spot.

use std::sync::Arc;

use nalgebra::Vector3;
use wavg_apps::{BaseMesh, RemeshError, RemeshResult, Remesher};
use wavg_mesh::{SurfacePoint, ValidMesh, io, procedural};
use wavg_project::closest_point_barycentric;
use wavg_solve::{Anchor, EmbeddedMesh, ForwardOptions, Projector, Solver, Vec8};

const R: f64 = 1.0;
const RT: f64 = 0.35;

/// Surface on its 3-D positions, or on a computed geodesic embedding.
fn projector(mesh: wavg_mesh::TriMesh, landmarks: Option<usize>) -> Arc<Projector> {
    let mesh = Arc::new(ValidMesh::new(mesh).unwrap());
    let emb = match landmarks {
        None => EmbeddedMesh::from_positions(mesh),
        Some(l) => {
            let opts = wavg_embed::PrecomputeOptions {
                landmarks: l,
                quality_pairs: 0,
                ..Default::default()
            };
            let (e, _) = wavg_embed::precompute(&mesh, &opts, &wavg_embed::NoProgress).unwrap();
            let coords = e.coords.iter().map(|c| Vec8::from(*c)).collect();
            EmbeddedMesh::new(mesh, coords).unwrap()
        }
    };
    Arc::new(Projector::new(Arc::new(emb)).unwrap())
}

/// A `nu` x `nv` quad grid on the smooth torus (oriented like `procedural::torus`).
fn torus_base(nu: u32, nv: u32) -> BaseMesh {
    let m = procedural::torus(nu, nv, R, RT);
    let id = |i: u32, j: u32| (i % nu) * nv + (j % nv);
    let mut faces = Vec::new();
    for i in 0..nu {
        for j in 0..nv {
            faces.push(vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    BaseMesh {
        positions: m.positions,
        faces,
    }
}

/// Undirected edge count.
fn n_edges(faces: &[Vec<u32>]) -> usize {
    let mut e: Vec<(u32, u32)> = faces
        .iter()
        .flat_map(|f| (0..f.len()).map(move |i| (f[i], f[(i + 1) % f.len()])))
        .map(|(a, b)| (a.min(b), a.max(b)))
        .collect();
    e.sort_unstable();
    e.dedup();
    e.len()
}

/// Brute-force largest 3-D distance of every 7th output vertex from the mesh's triangles,
/// over the diagonal.
fn brute_offsurface(mesh: &ValidMesh, out: &RemeshResult, diag: f64) -> f64 {
    let pad = |p: &Vector3<f64>| {
        let mut y = Vec8::zeros();
        y.fixed_rows_mut::<3>(0).copy_from(p);
        y
    };
    let mut worst: f64 = 0.0;
    for p in out.positions.iter().step_by(7) {
        let y = pad(p);
        let best = mesh
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| pad(&mesh.positions[v as usize]));
                let xi = closest_point_barycentric(&y, &a, &b, &c);
                (a * xi[0] + b * xi[1] + c * xi[2] - y).norm()
            })
            .fold(f64::INFINITY, f64::min);
        worst = worst.max(best);
    }
    worst / diag
}

/// How far apart two answers to the same forward problem may lie: the projector accepts a
/// root up to `BARY_EPS` outside a triangle and clamps it onto the edge, so a point near
/// an edge found from either side differs by up to that fraction of an edge.
fn same_point_tolerance(proj: &Projector) -> f64 {
    wavg_project::BARY_EPS * wavg_mesh::geometry::mean_edge_length(proj.embedded().mesh())
}

fn max_difference(a: &RemeshResult, b: &RemeshResult) -> f64 {
    assert_eq!(a.positions.len(), b.positions.len());
    a.positions
        .iter()
        .zip(&b.positions)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max)
}

#[test]
fn torus_counts_surface_level_one_and_smoothing() {
    let proj = projector(procedural::torus(96, 40, R, RT), Some(150));
    let base = torus_base(8, 4);
    let mut r = Remesher::new(proj.clone(), &base).unwrap();
    // Counts per level: V' = V + E + F, F' = 4 F, E' = 2 E + 4 F for a closed quad mesh.
    let (mut v, mut f) = (32usize, 32usize);
    let mut e = n_edges(&base.faces);
    for levels in 0..=3 {
        let out = r.remesh(levels, 0).unwrap();
        assert_eq!(out.positions.len(), v, "level {levels}");
        assert_eq!(out.faces.len(), f);
        assert_eq!(n_edges(&out.faces), e);
        assert!(out.faces.iter().all(|q| q.len() == 4));
        (v, f, e) = (v + e + f, 4 * f, 2 * e + 4 * f);
    }
    // Level 1: every edge point and face point is the forward problem of its anchors.
    let out = r.remesh(1, 0).unwrap();
    let bp = r.base_points().to_vec();
    for (j, q) in base.faces.iter().enumerate() {
        for i in 0..4 {
            let sub = &out.faces[4 * j + i];
            assert_eq!(sub[0], q[i]);
            let ends = [q[i], q[(i + 1) % 4]].map(|c| Anchor::Point(bp[c as usize]));
            let edge = Solver::new(proj.clone(), ends).unwrap();
            let want = edge
                .forward(&[0.5, 0.5], &ForwardOptions::default())
                .unwrap();
            assert!((want.position - out.positions[sub[1] as usize]).norm() < 1e-9);
            let corners = q.iter().map(|&c| Anchor::Point(bp[c as usize]));
            let face = Solver::new(proj.clone(), corners).unwrap();
            let want = face
                .forward(&[0.25; 4], &ForwardOptions::default())
                .unwrap();
            assert!((want.position - out.positions[sub[2] as usize]).norm() < 1e-9);
        }
    }
    // On the surface (BVH and brute force agree), and smoothing evens the mesh out.
    let rough = r.remesh(3, 0).unwrap();
    let smooth = r.remesh(3, 5).unwrap();
    for out in [&rough, &smooth] {
        let m = r.max_offsurface(&out.positions);
        assert!(m < 1e-12, "{m}");
        let b = brute_offsurface(proj.embedded().mesh(), out, r.diagonal());
        assert!(b < 1e-12, "{b}");
    }
    let (a, b) = (rough.roughness(), smooth.roughness());
    assert!(b < a, "roughness {a} -> {b}");
    let n = smooth.positions.len();
    assert_eq!(smooth.problems, (n - 32) + 5 * n);
}

#[test]
fn warm_recompute_after_moving_a_vertex_equals_cold() {
    let proj = projector(procedural::torus(96, 40, R, RT), Some(150));
    let base = torus_base(8, 4);
    let mut warm = Remesher::new(proj.clone(), &base).unwrap();
    warm.remesh(2, 3).unwrap();
    // Drag vertex 5 along the torus, in two steps.
    let mut moved = base.clone();
    for step in 1..=2 {
        let p = moved.positions[5];
        let a: f64 = 0.05;
        moved.positions[5] = Vector3::new(
            p.x * a.cos() - p.y * a.sin(),
            p.x * a.sin() + p.y * a.cos(),
            p.z,
        );
        let (target, _) = warm.closest_point(&moved.positions[5]);
        warm.move_base_vertex(5, target).unwrap();
        let w = warm.remesh(2, 3).unwrap();
        let c = Remesher::new(proj.clone(), &moved)
            .unwrap()
            .remesh(2, 3)
            .unwrap();
        let worst = max_difference(&w, &c);
        assert!(worst < same_point_tolerance(&proj), "step {step}: {worst}");
        assert!((w.positions[5] - c.positions[5]).norm() < 1e-12);
    }
    // Bad edits are refused and leave the remesher usable.
    assert!(matches!(
        warm.move_base_vertex(32, SurfacePoint::new(0, [1.0, 0.0, 0.0])),
        Err(RemeshError::VertexOutOfRange { .. })
    ));
    assert!(
        warm.move_base_vertex(0, SurfacePoint::new(0, [0.5, 0.5, 0.5]))
            .is_err()
    );
    assert!(matches!(
        warm.remesh(9, 0),
        Err(RemeshError::InvalidParameter(_))
    ));
    warm.remesh(2, 3).unwrap();
}

#[test]
fn sphere_with_a_mixed_base_and_bad_bases() {
    let proj = projector(procedural::icosphere(4), None);
    // A cube on the unit sphere, one face split into two triangles.
    let s = 1.0 / 3f64.sqrt();
    let positions: Vec<Vector3<f64>> = (0..8)
        .map(|i| {
            let c = |bit: i32| if i & bit == 0 { -s } else { s };
            Vector3::new(c(1), c(2), c(4))
        })
        .collect();
    let faces = vec![
        vec![0, 2, 3, 1],
        vec![4, 5, 7, 6],
        vec![0, 1, 5, 4],
        vec![2, 6, 7],
        vec![2, 7, 3],
        vec![0, 4, 6, 2],
        vec![1, 3, 7, 5],
    ];
    let base = BaseMesh { positions, faces };
    let mut r = Remesher::new(proj.clone(), &base).unwrap();
    let out = r.remesh(2, 4).unwrap();
    // Level 1: V = 8 + 13 + 5 = 26, 20 quads and 8 triangles, E = 2*13 + 6 + 20 = 52.
    // Level 2: V = 26 + 52 + 20 = 98, 80 quads and 32 triangles.
    assert_eq!(out.positions.len(), 98);
    assert_eq!(out.faces.iter().filter(|f| f.len() == 4).count(), 80);
    assert_eq!(out.faces.iter().filter(|f| f.len() == 3).count(), 32);
    assert!(r.max_offsurface(&out.positions) < 1e-12);
    for p in &out.positions {
        assert!(p.norm() <= 1.0 + 1e-12 && p.norm() > 0.99);
    }

    let err = |b: &BaseMesh| Remesher::new(proj.clone(), b).unwrap_err();
    assert!(matches!(
        err(&BaseMesh::default()),
        RemeshError::EmptyBase { .. }
    ));
    let mut b = base.clone();
    b.faces[0][2] = 8;
    assert!(matches!(
        err(&b),
        RemeshError::IndexOutOfRange { index: 8, .. }
    ));
    let mut b = base.clone();
    b.faces.push(vec![0, 2, 3, 1]);
    assert!(matches!(err(&b), RemeshError::NonManifold { .. }));
    let mut b = base.clone();
    b.positions[3] *= 3.0;
    match err(&b) {
        RemeshError::FarFromSurface {
            vertex: 3,
            distance,
            ..
        } => assert!(distance > 0.5),
        e => panic!("{e:?}"),
    }
    let mut b = base.clone();
    b.positions[3].y = f64::NAN;
    assert!(matches!(err(&b), RemeshError::NonFinite { vertex: 3 }));
    assert!(Remesher::with_max_distance(proj.clone(), &base, 0.0).is_err());
}

#[test]
fn spot_control_cage_on_the_quadrangulated_spot() {
    let (Some(surface), Some(cage)) = (
        wavg_testdata::require_data_file("remesh spot", "meshes/spot_quadrangulated.obj"),
        wavg_testdata::require_data_file("remesh spot", "meshes/spot_control_mesh.obj"),
    ) else {
        return;
    };
    let proj = projector(io::load(&surface).unwrap(), Some(300));
    let base = BaseMesh::from_obj_str(&std::fs::read_to_string(cage).unwrap()).unwrap();
    let sizes = |n: usize| base.faces.iter().filter(|f| f.len() == n).count();
    assert_eq!((sizes(3), sizes(4), sizes(5)), (4, 160, 16));
    let mut r = Remesher::new(proj.clone(), &base).unwrap();
    // V' = V + E + (polygons with 4 or more corners); F' = 4 F_tri + sum of their corners.
    let (mut v, mut e) = (base.positions.len(), n_edges(&base.faces));
    let mut faces = base.faces.clone();
    for levels in 1..=3 {
        let out = r.remesh(levels, 0).unwrap();
        let tris = faces.iter().filter(|f| f.len() == 3).count();
        let big: Vec<usize> = faces.iter().map(Vec::len).filter(|&n| n > 3).collect();
        v += e + big.len();
        assert_eq!(out.positions.len(), v);
        assert_eq!(out.faces.len(), 4 * tris + big.iter().sum::<usize>());
        e = n_edges(&out.faces);
        faces = out.faces.to_vec();
        assert!(r.max_offsurface(&out.positions) < 1e-12);
    }
    let rough = r.remesh(3, 0).unwrap().roughness();
    let out = r.remesh(3, 5).unwrap();
    assert!(out.roughness() < rough, "{rough} -> {}", out.roughness());
    assert!(r.max_offsurface(&out.positions) < 1e-12);
    // Warm after a drag equals cold.
    let (p, _) = r.closest_point(&(base.positions[10] + Vector3::new(0.0, 0.0, 0.02)));
    r.move_base_vertex(10, p).unwrap();
    let w = r.remesh(3, 5).unwrap();
    let mut moved = base.clone();
    moved.positions[10] = p.position(proj.embedded().mesh());
    let c = Remesher::new(proj.clone(), &moved)
        .unwrap()
        .remesh(3, 5)
        .unwrap();
    let worst = max_difference(&w, &c);
    assert!(worst < same_point_tolerance(&proj), "{worst}");
}
