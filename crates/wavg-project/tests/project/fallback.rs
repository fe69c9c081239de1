//! The global search (the fast path's fallback and `project_exhaustive`: best-first branch
//! and bound over the hierarchy) returns the brute-force scan's answer: the same face and
//! point, ties to the lowest face index. Queries on the surface (embedded surface points)
//! and off it (offsets along random directions of R^8, near and far), on generated meshes
//! and on real meshes from the shared data folder (skipped with a message when missing).

use crate::common;

use std::sync::Arc;

use common::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use wavg_mesh::{ValidMesh, io};
use wavg_project::{ProjectionPath, Vec8};
use wavg_testdata as data;

/// Offsets off the surface, in mean edge lengths: on it, near, a few rings, far away, very
/// far (where the exclusion tests prune most of the hierarchy).
const OFFSETS: [f64; 6] = [0.0, 0.05, 0.5, 5.0, 50.0, 500.0];

/// Compares the global search with the brute force on `queries` surface points per
/// offset; returns how many answers differed only by a tie in distance (equal up to
/// rounding, the two searches' lower bounds pruning differently).
fn compare(fx: &Fixture, queries: usize, seed: u64) -> usize {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut ties = 0;
    for _ in 0..queries {
        let p = fx.point(rng.random(), rng.random(), rng.random());
        let base = fx.emb.point(&p);
        let start = fx.vertex(rng.random());
        let dir = normal_to(&wavg_project::Mat2x8::zeros(), rng.random());
        for off in OFFSETS {
            let y: Vec8 = base + dir * (off * fx.mean_edge * rng.random_range(0.5..1.0));
            let exh = fx.proj.project_exhaustive(&y);
            let brute = fx.proj.project_brute_force(&y);
            match (&exh, &brute) {
                (Ok(e), Ok(b)) => {
                    assert_eq!(e.path, ProjectionPath::Exhaustive);
                    if e.point != b.point || e.distance != b.distance {
                        let tie =
                            (e.distance - b.distance).abs() <= 1e-12 * (b.distance + fx.mean_edge);
                        assert!(tie, "{} offset {off}: {e:?} vs brute force {b:?}", fx.name);
                        ties += 1;
                    }
                }
                (Err(a), Err(b)) => assert_eq!(a, b, "{}", fx.name),
                _ => panic!("{} offset {off}: {exh:?} vs brute force {brute:?}", fx.name),
            }
            // The fast path agrees too (its fallback is this search).
            let fast = fx.proj.project(&y, start);
            match (&fast, &brute) {
                (Ok(a), Ok(b)) => {
                    let same = (fx.emb.point(&a.point) - fx.emb.point(&b.point)).norm()
                        <= 1e-6 * fx.mean_edge;
                    let tie = (a.distance - b.distance).abs() <= 1e-9 * (b.distance + fx.mean_edge);
                    assert!(same || tie, "{} offset {off}: fast {a:?} vs {b:?}", fx.name);
                }
                (Err(a), Err(b)) => assert_eq!(a, b, "{}", fx.name),
                _ => panic!(
                    "{} offset {off}: fast {fast:?} vs brute force {brute:?}",
                    fx.name
                ),
            }
        }
    }
    ties
}

#[test]
fn generated_meshes_match_the_brute_force() {
    let mut total = 0;
    let mut ties = 0;
    for (i, (name, mesh)) in synthetic_meshes().into_iter().enumerate() {
        for e in EMBEDDINGS {
            let fx = Fixture::new(name, mesh.clone(), e);
            ties += compare(&fx, 150, i as u64);
            total += 150 * OFFSETS.len();
        }
    }
    // Distance ties broken differently are rounding-level coincidences, not a pattern.
    assert!(ties * 1000 <= total, "{ties} ties of {total}");
}

/// Two copies of a 4 x 4 grid in one mesh (two components), the first's positions moved
/// by `first`, the second's by `second`; the first copy's faces come first.
fn two_grids(
    first: impl Fn(&mut nalgebra::Vector3<f64>),
    second: impl Fn(&mut nalgebra::Vector3<f64>),
) -> wavg_mesh::TriMesh {
    let mut mesh = wavg_mesh::procedural::grid(4, 4, 1.0, 1.0);
    let n = mesh.positions.len() as u32;
    let mut copy = mesh.positions.clone();
    copy.iter_mut().for_each(second);
    mesh.positions.iter_mut().for_each(first);
    mesh.positions.extend(copy);
    let tris = mesh.triangles.clone();
    mesh.triangles
        .extend(tris.iter().map(|t| [t[0] + n, t[1] + n, t[2] + n]));
    mesh
}

/// An exact tie (a query equidistant from two mirror-image triangles) goes to the lowest
/// face index, as in the brute force.
#[test]
fn exact_ties_go_to_the_lowest_face() {
    // Two sheets, at z = 1 and z = -1 (same corner order, so the same arithmetic up to
    // the sign of z): the plane z = 0 between them is equidistant, to the last bit.
    let mesh = two_grids(|p| p.z = 1.0, |p| p.z = -1.0);
    let fx = Fixture::new("two sheets", mesh, Embedding::Padded);
    for k in 0..50 {
        let u = |m: f64| (k as f64 * m).fract();
        let mut y = fx.emb.point(&fx.point(u(0.618) * 0.5, u(0.755), u(0.57)));
        y[2] = 0.0;
        let e = fx.proj.project_exhaustive(&y).unwrap();
        let b = fx.proj.project_brute_force(&y).unwrap();
        assert_eq!(e.point, b.point);
        assert!(e.point.face < fx.mesh().n_faces() as u32 / 2, "{e:?}");
    }
}

fn real(rel: &str, queries: usize) {
    let Some(path) = data::require_data_file("wavg-project fallback", rel) else {
        return;
    };
    let mesh = Arc::new(ValidMesh::new(io::load(&path).unwrap()).unwrap());
    let mut total = 0;
    let mut ties = 0;
    for e in [Embedding::Padded, Embedding::Nonlinear] {
        let emb = embed(mesh.clone(), e);
        let fx = Fixture {
            name: format!("{rel}/{e:?}"),
            embedding: e,
            proj: wavg_project::Projector::new(emb.clone()).unwrap(),
            mean_edge: emb.mean_edge_length(),
            emb,
        };
        ties += compare(&fx, queries, 11);
        total += queries * OFFSETS.len();
    }
    assert!(ties * 100 <= total, "{rel}: {ties} ties of {total}");
}

#[test]
fn horse_matches_the_brute_force() {
    real("meshes/horse.off.gz", 40);
}

#[test]
fn fertility_matches_the_brute_force() {
    real("meshes/fertility.off", 100);
}

#[test]
fn armadillo_matches_the_brute_force() {
    real("meshes/armadillo.obj.gz", 40);
}

/// A walk that ends where no face holds a projection (here on another component, beside
/// the query) searches once more from the vertex nearest to the query and certifies what
/// it finds there, instead of going to the global search.
#[test]
fn a_stranded_walk_searches_again_from_the_nearest_vertex() {
    // Two flat sheets side by side in the plane z = 0: B on [0, 1]^2, A on [3, 4] x [0, 1].
    let mesh = two_grids(|_| {}, |p| p.x += 3.0);
    let n = mesh.positions.len() as u32 / 2;
    let fx = Fixture::new("side by side", mesh, Embedding::Padded);
    let faces_b = fx.mesh().n_faces() as u32 / 2;
    for k in 0..40 {
        let u = |m: f64| (k as f64 * m).fract();
        // A point of sheet A, and a start on sheet B.
        let p = fx.point(0.5 + u(0.618) * 0.5, u(0.755), u(0.57));
        assert!(p.face >= faces_b);
        let y = fx.emb.point(&p);
        let start = fx.vertex(u(0.377) * 0.5);
        assert!(start < n);
        let fast = fx.proj.project(&y, start).unwrap();
        let brute = fx.proj.project_brute_force(&y).unwrap();
        assert_eq!(fast.path, ProjectionPath::Certified, "{fast:?}");
        assert!(fast.point.face >= faces_b, "{fast:?}");
        assert!(fast.distance <= 1e-12, "{fast:?}");
        assert!((fx.emb.point(&fast.point) - fx.emb.point(&brute.point)).norm() <= 1e-12);
    }
}
