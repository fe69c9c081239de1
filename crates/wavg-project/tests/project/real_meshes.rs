//! Projection on real meshes from the shared data folder (skipped with a message when the
//! folder is missing): self-projection and agreement with the brute force.

use crate::common;

use std::sync::Arc;

use common::*;
use wavg_mesh::{ValidMesh, io};
use wavg_project::{EmbeddedMesh, Projector};
use wavg_testdata as data;

fn check(rel: &str, queries: usize, brute: usize) {
    let Some(path) = data::require_data_file("wavg-project real meshes", rel) else {
        return;
    };
    let mesh = Arc::new(ValidMesh::new(io::load(&path).unwrap()).unwrap());
    for e in EMBEDDINGS {
        let emb = embed(mesh.clone(), e);
        let proj = Projector::new(emb.clone()).unwrap();
        let mean = emb.mean_edge_length();
        let fx = Fixture {
            name: format!("{rel}/{e:?}"),
            embedding: e,
            emb: emb.clone(),
            proj,
            mean_edge: mean,
        };
        let mut back = 0;
        for k in 0..queries {
            let u = |m: f64| (k as f64 * m).fract();
            let p = fx.point(u(0.6180339887), u(0.7548776662), u(0.5698402910));
            let y = fx.emb.point(&p);
            let r = fx.proj.project(&y, fx.vertex(u(0.3819660113))).unwrap();
            if (fx.emb.point(&r.point) - y).norm() <= 1e-9 * fx.face_scale(p.face) {
                back += 1;
            } else {
                eprintln!(
                    "{}: {p:?} -> {r:?}; own face: {:?}",
                    fx.name,
                    fx.proj.project_onto_face(&y, p.face)
                );
            }
        }
        assert_eq!(
            back, queries,
            "{}: {back} of {queries} returned to themselves",
            fx.name
        );
        for k in 0..brute {
            let u = |m: f64| (k as f64 * m).fract();
            let p = fx.point(u(0.1234567), u(0.7548776662), u(0.5698402910));
            let dir = normal_to(&wavg_project::Mat2x8::zeros(), k as u64);
            let y = fx.emb.point(&p) + dir * (0.5 * mean * u(0.31));
            let fast = fx.proj.project(&y, fx.vertex(u(0.71)));
            let bf = fx.proj.project_brute_force(&y);
            match (fast, bf) {
                (Ok(a), Ok(b)) => {
                    let same = (emb.point(&a.point) - emb.point(&b.point)).norm() <= 1e-6 * mean;
                    let tie = (a.distance - b.distance).abs() <= 1e-9 * (b.distance + mean);
                    assert!(same || tie, "{}: {a:?} vs {b:?}", fx.name);
                }
                (Err(a), Err(b)) => assert_eq!(a, b),
                (a, b) => panic!("{}: {a:?} vs {b:?}", fx.name),
            }
        }
    }
}

/// `project_batch` (and `project_batch_into` for any parallelism) gives exactly `project`'s
/// answers, on- and off-surface, including
/// per-query errors (a NaN query, a start out of range) inside a group.
fn batch_equals_single(rel: &str, queries: usize) {
    let Some(path) = data::require_data_file("wavg-project batches", rel) else {
        return;
    };
    let mesh = Arc::new(ValidMesh::new(io::load(&path).unwrap()).unwrap());
    let emb = Arc::new(EmbeddedMesh::from_positions(mesh.clone()));
    let proj = Projector::new(emb.clone()).unwrap();
    let mean = emb.mean_edge_length();
    let nv = mesh.n_vertices() as u32;
    let mut ys = Vec::new();
    let mut starts = Vec::new();
    for k in 0..queries {
        let u = |m: f64| (k as f64 * m).fract();
        let f = (u(0.6180339887) * mesh.n_faces() as f64) as u32;
        let (a, b) = (u(0.7548776662), u(0.5698402910));
        let (a, b) = if a + b > 1.0 {
            (1.0 - a, 1.0 - b)
        } else {
            (a, b)
        };
        let p = wavg_mesh::SurfacePoint::new(f, [a, b, 1.0 - a - b]);
        let off = normal_to(&wavg_project::Mat2x8::zeros(), k as u64) * (0.3 * mean * u(0.31));
        ys.push(emb.point(&p) + if k % 3 == 0 { off } else { off * 0.0 });
        starts.push((u(0.3819660113) * nv as f64) as u32 % nv);
    }
    ys[5][2] = f64::NAN;
    starts[13] = nv + 4;
    let batch = proj.project_batch(&ys, &starts);
    assert_eq!(batch.len(), queries);
    for (k, ((y, &s), b)) in ys.iter().zip(&starts).zip(&batch).enumerate() {
        assert_eq!(b, &proj.project(y, s), "{rel}: query {k}");
    }
    assert!(batch[5].is_err() && batch[13].is_err());
    // The explicit layer, for every parallelism, with its buffers reused.
    let mut scratch = wavg_project::ProjectScratch::default();
    let mut out = Vec::new();
    let three = wavg_project::Par::Threads(std::num::NonZeroUsize::new(3).unwrap());
    for par in [wavg_project::Par::Seq, three, wavg_project::Par::Rayon] {
        proj.project_batch_into(&ys, &starts, &mut scratch, &mut out, par)
            .unwrap();
        assert_eq!(out, batch, "{rel}: {par:?}");
    }
}

#[test]
fn batches_equal_single_queries() {
    batch_equals_single("meshes/camelhead.off", 3000);
    batch_equals_single("meshes/armadillo.obj.gz", 3000);
}

#[test]
fn knight() {
    check("meshes/decimated-knight.off", 2000, 200);
}

#[test]
fn camelhead_with_boundary() {
    check("meshes/camelhead.off", 2000, 60);
}

#[test]
fn three_holes_genus_3() {
    check("meshes/3holes.off", 2000, 60);
}

#[test]
fn embedding_errors_are_typed() {
    let mesh = Arc::new(ValidMesh::new(wavg_mesh::procedural::icosphere(1)).unwrap());
    let n = mesh.n_vertices();
    let short = EmbeddedMesh::new(mesh.clone(), vec![wavg_project::Vec8::zeros(); n - 1]);
    assert!(matches!(
        short,
        Err(wavg_project::ProjectError::CoordinateCount { .. })
    ));
    let mut bad = vec![wavg_project::Vec8::zeros(); n];
    bad[5][3] = f64::NAN;
    assert_eq!(
        EmbeddedMesh::new(mesh.clone(), bad).unwrap_err(),
        wavg_project::ProjectError::NonFinite { vertex: 5 }
    );
    // Beyond single precision's range (with a margin): refused, not silently wrong.
    let mut huge = vec![wavg_project::Vec8::zeros(); n];
    huge[7][2] = -2e37;
    let emb = Arc::new(EmbeddedMesh::new(mesh.clone(), huge).unwrap());
    assert!(matches!(
        Projector::new(emb),
        Err(wavg_project::ProjectError::OutOfRange { vertex: 7, value }) if value == 2e37
    ));
    // Too small for squared lengths: refused, saying to scale the mesh up.
    let tiny: Vec<_> = (0..n)
        .map(|v| wavg_project::Vec8::from_fn(|k, _| 1e-62 * ((v * 7 + k) % 5) as f64))
        .collect();
    let emb = Arc::new(EmbeddedMesh::new(mesh.clone(), tiny).unwrap());
    match Projector::new(emb) {
        Err(e @ wavg_project::ProjectError::TooSmall { extent }) => {
            assert!(
                extent < 1e-60 && e.to_string().contains("scale the mesh up"),
                "{e}"
            );
        }
        other => panic!("expected TooSmall, got {:?}", other.map(|_| ())),
    }
    let p = Projector::new(Arc::new(EmbeddedMesh::from_positions(mesh))).unwrap();
    let y = wavg_project::Vec8::repeat(f64::INFINITY);
    assert_eq!(
        p.project(&y, 0).unwrap_err(),
        wavg_project::ProjectError::NonFiniteQuery
    );
    assert_eq!(
        p.project_exhaustive(&y).unwrap_err(),
        wavg_project::ProjectError::NonFiniteQuery
    );
    let z = wavg_project::Vec8::zeros();
    assert!(matches!(
        p.project(&z, n as u32),
        Err(wavg_project::ProjectError::StartOutOfRange { .. })
    ));
    let nf = p.embedded().mesh().n_faces() as u32;
    for goal in [
        wavg_project::SearchGoal::Closest,
        wavg_project::SearchGoal::FirstHit,
    ] {
        assert_eq!(
            p.project_with(&z, 0, Some(nf), goal),
            Err(wavg_project::ProjectError::FaceOutOfRange {
                face: nf,
                n_faces: nf as usize
            })
        );
    }
    // The centre of a sphere has no Phong projection only by accident; far away it has one.
    let far = wavg_project::Vec8::from_fn(|i, _| if i == 0 { 10.0 } else { 0.0 });
    let r = p.project(&far, 0).unwrap();
    assert!((r.distance - 9.0).abs() < 0.1);
}
