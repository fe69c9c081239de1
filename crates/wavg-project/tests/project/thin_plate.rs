//! Thin parts: a plate with 4 x 3 holes whose straps are thinner than an edge is long (two
//! sheets close together, joined only around the rims). Queries on the surface, searched
//! from a start three rings away (often across a rim, on the other sheet): every fast
//! answer is the closest valid projection (the exhaustive search's, and on a sample the
//! brute force's), and fewer than one in a thousand needs the global search.

use crate::common;

use common::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use wavg_mesh::{RingSearch, procedural};
use wavg_project::ProjectionPath;

/// Queries per embedding.
const QUERIES: usize = 3000;
/// Of which the first are also checked against the (slow) brute force.
const BRUTE_FORCE: usize = 100;

/// Projects `QUERIES` seeded surface points of the plate from starts three rings away;
/// checks each against the exhaustive search (the first [`BRUTE_FORCE`] against the brute
/// force too). Returns (fallbacks, queries whose walk from the
/// start ends on the other sheet of a top or bottom face).
fn plate(e: Embedding, seed: u64) -> (usize, usize) {
    let fx = Fixture::new("genus-12 plate", procedural::holed_plate(4, 3, 8, 0.05), e);
    let mesh = fx.mesh();
    let (topo, z) = (mesh.topology(), |v: u32| mesh.positions[v as usize].z);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut rings = RingSearch::new(mesh.n_vertices());
    let (mut fallbacks, mut other_sheet) = (0, 0);
    for q in 0..QUERIES {
        let p = fx.point(rng.random(), rng.random(), rng.random());
        let t = mesh.triangles[p.face as usize];
        let ring = rings.ring_or_farthest(topo, t[0], 3);
        let start = ring[rng.random_range(0..ring.len())];
        let y = fx.emb.point(&p);
        let fast = fx.proj.project(&y, start).unwrap();
        let mut exact = vec![fx.proj.project_exhaustive(&y).unwrap()];
        if q < BRUTE_FORCE {
            exact.push(fx.proj.project_brute_force(&y).unwrap());
        }
        for b in exact {
            let same =
                (fx.emb.point(&fast.point) - fx.emb.point(&b.point)).norm() <= 1e-9 * fx.mean_edge;
            assert!(same, "{}: {fast:?} vs {b:?}", fx.name);
        }
        fallbacks += usize::from(fast.path == ProjectionPath::Fallback);
        let sheet = z(t[0]);
        if t.iter().all(|&v| z(v) == sheet) && z(fx.proj.walk(&y, start)) != sheet {
            other_sheet += 1;
        }
    }
    (fallbacks, other_sheet)
}

#[test]
fn a_thin_plate_rarely_needs_the_global_search_and_answers_as_the_brute_force() {
    for (i, e) in EMBEDDINGS.into_iter().enumerate() {
        let (fallbacks, other_sheet) = plate(e, 31 + i as u64);
        eprintln!("{e:?}: {fallbacks} fallbacks, {other_sheet} walks on the other sheet");
        // The case exists: many walks stop on the wrong sheet.
        assert!(other_sheet * 50 >= QUERIES, "{e:?}: {other_sheet} walks");
        assert!(
            fallbacks * 1000 < QUERIES,
            "{e:?}: {fallbacks} of {QUERIES} needed the global search ({other_sheet} walks on the other sheet)"
        );
    }
}
