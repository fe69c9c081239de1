//! Tangent frames: convergence to the true tangent planes under refinement (closed and
//! open surfaces), orthonormality, and the degenerate fallbacks.

use crate::common;

use std::sync::Arc;

use common::*;
use nalgebra::Vector3;
use wavg_mesh::{TriMesh, ValidMesh, procedural};
use wavg_project::{EmbeddedMesh, Mat2x8, Projector, Vec8};
use wavg_project::{FrameKind, vertex_frames};

/// Largest angle between a frame plane (padded 3-D) and the plane with normal `n`.
fn tilt(f: &Mat2x8, n: &Vector3<f64>) -> f64 {
    let mut n8 = Vec8::zeros();
    n8.fixed_rows_mut::<3>(0).copy_from(&n.normalize());
    (f * n8).norm().clamp(0.0, 1.0).asin()
}

/// Max tilt over interior and over boundary vertices.
fn max_tilts(mesh: TriMesh, normal: impl Fn(&Vector3<f64>) -> Vector3<f64>) -> (f64, f64) {
    let m = Arc::new(ValidMesh::new(mesh).unwrap());
    let emb = EmbeddedMesh::from_positions(m.clone());
    let frames = vertex_frames(&m, emb.coords());
    let (mut inner, mut bnd) = (0.0f64, 0.0f64);
    for (v, (f, kind)) in frames.iter().enumerate() {
        let t = tilt(f, &normal(&m.positions[v]));
        if m.topology().is_boundary_vertex(v as u32) {
            assert_eq!(*kind, FrameKind::Boundary);
            bnd = bnd.max(t);
        } else {
            assert_eq!(*kind, FrameKind::Interior);
            inner = inner.max(t);
        }
    }
    (inner, bnd)
}

#[test]
fn icosphere_frames_converge_to_the_sphere_tangent_planes() {
    // Level 1 is exact by symmetry; from level 2 on the irregular vertices converge
    // linearly in the edge length.
    let tilts: Vec<f64> = (1..=5)
        .map(|l| max_tilts(procedural::icosphere(l), |p| *p).0)
        .collect();
    eprintln!("icosphere max tilt by level: {tilts:?}");
    assert!(tilts[0] < 1e-12, "{tilts:?}");
    for w in tilts[1..].windows(2) {
        assert!(w[1] < w[0] * 0.6, "{tilts:?}");
    }
    assert!(tilts[4] < 4e-3, "{tilts:?}");
}

#[test]
fn torus_frames_converge_to_the_torus_tangent_planes() {
    let (big, small) = (1.0, 0.35);
    let normal = |p: &Vector3<f64>| {
        let c = Vector3::new(p.x, p.y, 0.0).normalize() * big;
        p - c
    };
    let tilts: Vec<f64> = [8u32, 16, 32, 64]
        .iter()
        .map(|&n| max_tilts(procedural::torus(2 * n, n, big, small), normal).0)
        .collect();
    eprintln!("torus max tilt by resolution: {tilts:?}");
    for w in tilts.windows(2) {
        assert!(w[1] < w[0] * 0.7, "{tilts:?}");
    }
    assert!(tilts[3] < 2e-3, "{tilts:?}");
}

#[test]
fn open_surface_frames_converge_at_interior_and_boundary_vertices() {
    let normal = |p: &Vector3<f64>| {
        let (x, y) = (p.x, p.y);
        let fx = 0.6 * (2.0 * x).cos() * (2.0 * y).cos();
        let fy = -0.6 * (2.0 * x).sin() * (2.0 * y).sin();
        Vector3::new(-fx, -fy, 1.0)
    };
    let tilts: Vec<(f64, f64)> = [8u32, 16, 32, 64]
        .iter()
        .map(|&n| max_tilts(heightfield(n), normal))
        .collect();
    eprintln!("heightfield max tilt (interior, boundary) by resolution: {tilts:?}");
    // Interior: quadratic convergence; boundary (one-sided stencil): linear.
    for w in tilts.windows(2) {
        assert!(w[1].0 < w[0].0 * 0.35, "{tilts:?}");
        assert!(w[1].1 < w[0].1 * 0.65, "{tilts:?}");
    }
    assert!(tilts[3].0 < 1e-3 && tilts[3].1 < 0.04, "{tilts:?}");
}

#[test]
fn frames_are_orthonormal_and_finite_on_every_fixture() {
    for fx in fixtures() {
        for v in 0..fx.mesh().n_vertices() as u32 {
            let f = fx.proj.frame(v);
            assert!(f.iter().all(|x| x.is_finite()));
            assert!(
                (f * f.transpose() - nalgebra::Matrix2::identity()).norm() < 1e-6,
                "{}",
                fx.name
            );
        }
    }
}

/// Flat valence-3 and valence-4 vertices, a collapsed and a collinear embedding: frames
/// fall back, stay orthonormal, and projection never produces NaN.
#[test]
fn degenerate_rings_and_embeddings_fall_back_without_nan() {
    // Collapsed: every vertex at the same point. Collinear: all on a line.
    let mesh = Arc::new(ValidMesh::new(procedural::icosphere(2)).unwrap());
    let n = mesh.n_vertices();
    let collapsed = vec![Vec8::repeat(1.5); n];
    let collinear: Vec<Vec8> = mesh
        .positions
        .iter()
        .map(|p| {
            let mut v = Vec8::zeros();
            v[2] = p.x + 2.0 * p.y;
            v
        })
        .collect();
    for coords in [collapsed, collinear] {
        let emb = Arc::new(EmbeddedMesh::new(mesh.clone(), coords).unwrap());
        let proj = Projector::new(emb.clone()).unwrap();
        let kinds = proj.frame_kind_counts();
        assert!(kinds[3] + kinds[2] > 0, "{kinds:?}");
        for v in 0..n as u32 {
            let f = proj.frame(v);
            assert!((f * f.transpose() - nalgebra::Matrix2::identity()).norm() < 1e-6);
        }
        for k in 0..50 {
            let y = Vec8::from_fn(|i, _| ((k * 7 + i * 3) % 11) as f64 * 0.1);
            for r in [
                proj.project(&y, (k % n) as u32),
                proj.project_exhaustive(&y),
                proj.project_brute_force(&y),
            ]
            .into_iter()
            .flatten()
            {
                assert!(
                    r.distance.is_finite()
                        && r.point.bary.iter().all(|b| b.is_finite() && *b >= 0.0)
                );
            }
            let e = proj.project_euclidean(&y);
            assert!(e.distance.is_finite() && e.point.bary.iter().all(|b| b.is_finite()));
            for f in 0..mesh.n_faces() as u32 {
                let psi = proj.psi(&wavg_mesh::SurfacePoint::new(f, [0.2, 0.3, 0.5]));
                assert!(psi.iter().all(|x| x.is_finite()));
            }
        }
    }
}

/// A flat fan around a valence-3 vertex: the Loop stencil is fine there, and a planar
/// fan with a degenerate stencil (valence 4 with opposite edges folded) uses the fit.
#[test]
fn planar_fans_give_the_plane() {
    let grid = procedural::grid(3, 3, 1.0, 1.0);
    let m = Arc::new(ValidMesh::new(grid).unwrap());
    let emb = EmbeddedMesh::from_positions(m.clone());
    for (f, _) in vertex_frames(&m, emb.coords()) {
        assert!(f.column(2).norm() < 1e-12, "frame leaves the plane: {f}");
    }
}
