//! Correspondence between two body shapes of the procedural figure (same connectivity:
//! vertex i of one is vertex i of the other), thin fingers included: the default validity
//! test keeps at least 95% of the vertices with a mean error of at most 1% of the
//! diagonal, and few of the images it keeps are wrong.

use std::sync::{Arc, OnceLock};

use wavg_apps::{CorrespondOptions, correspond_vertices};
use wavg_embed::{NoProgress, PrecomputeOptions, precompute};
use wavg_mesh::ValidMesh;
use wavg_mesh::procedural::{FigureShape, body, figure};
use wavg_mesh::subdivide::loop_subdivide;
use wavg_solve::sampling::{FpsMetric, farthest_point_vertices};
use wavg_solve::{Anchor, EmbeddedMesh, Projector, Solver, Vec8};

/// The slim and heavy bodies (`procedural::body`) with their embeddings: precomputed once
/// for the two tests that use them.
fn bodies() -> &'static [(ValidMesh, Vec<Vec8>); 2] {
    static BODIES: OnceLock<[(ValidMesh, Vec<Vec8>); 2]> = OnceLock::new();
    BODIES.get_or_init(|| {
        [FigureShape::SLIM, FigureShape::HEAVY].map(|s| embedded(ValidMesh::new(body(&s)).unwrap()))
    })
}

#[test]
fn body_shapes_correspond_with_a_mask_that_keeps_what_is_right() {
    let [slim, heavy] = [FigureShape::SLIM, FigureShape::HEAVY]
        .map(|s| embedded(ValidMesh::new(figure(&s)).unwrap()));
    correspond_shapes(slim, heavy, 40);
}

/// The same with ears and toes (`procedural::body`): more thin parts, close to others,
/// where more of the kept images are wrong (at most 1 in 20 vertices).
#[test]
fn bodies_with_ears_and_toes_correspond() {
    let [slim, heavy] = bodies().clone();
    correspond_shapes(slim, heavy, 20);
}

/// Corresponds a slim and a heavy shape (meshes of the same connectivity, with their
/// embeddings) both ways and checks the default mask keeps at least 95% of the vertices,
/// with a mean error of at most 1% of the diagonal, rejects at most 1 right image in 20
/// vertices and keeps at most 1 wrong one in `wrong_kept_per` vertices.
fn correspond_shapes(
    (slim, slim_e): (ValidMesh, Vec<Vec8>),
    (heavy, heavy_e): (ValidMesh, Vec<Vec8>),
    wrong_kept_per: usize,
) {
    let anchors = farthest_point_vertices(&slim, 93, 1, FpsMetric::EdgeGraph).unwrap();
    let (a, b) = (
        solver_on(slim, slim_e, &anchors),
        solver_on(heavy, heavy_e, &anchors),
    );
    for (src, tgt, name) in [(&a, &b, "slim -> heavy"), (&b, &a, "heavy -> slim")] {
        let t0 = std::time::Instant::now();
        let c = correspond_vertices(src, tgt, &CorrespondOptions::default()).unwrap();
        let secs = t0.elapsed().as_secs_f64();
        let t = c.ground_truth_errors(src.mesh(), tgt.mesh()).unwrap();
        let n = src.mesh().n_vertices();
        let wrong = t.answered.count - t.rejected_correct - c.valid() + t.accepted_wrong;
        eprintln!(
            "{name}: valid {:.4}, mean {:.5}, p95 {:.5}, max {:.5}; answered mean {:.5}; \
             rejected correct {}, accepted wrong {} of {wrong} wrong; {:?}; {:.0} vertices/s",
            c.valid_fraction(),
            t.valid.mean,
            t.valid.p95,
            t.valid.max,
            t.answered.mean,
            t.rejected_correct,
            t.accepted_wrong,
            c.reason_counts(),
            n as f64 / secs
        );
        assert!(
            c.valid_fraction() >= 0.95,
            "{name}: valid {}",
            c.valid_fraction()
        );
        assert!(t.valid.mean <= 0.01, "{name}: mean error {}", t.valid.mean);
        // Few right images are rejected and few wrong ones kept (the wrong ones left are
        // smooth displacements of whole finger tips, invisible to a local test).
        assert!(t.rejected_correct * 20 <= n, "{name}: {t:?}");
        assert!(t.accepted_wrong * wrong_kept_per <= n, "{name}: {t:?}");
    }
}

/// A mesh and its embedding.
fn embedded(mesh: ValidMesh) -> (ValidMesh, Vec<Vec8>) {
    let opts = PrecomputeOptions {
        quality_pairs: 0,
        ..Default::default()
    };
    let (emb, _) = precompute(&mesh, &opts, &NoProgress).unwrap();
    let coords = emb.coords.iter().map(|c| Vec8::from(*c)).collect();
    (mesh, coords)
}

fn solver_on(mesh: ValidMesh, coords: Vec<Vec8>, anchors: &[u32]) -> Solver {
    let e = Arc::new(EmbeddedMesh::new(Arc::new(mesh), coords).unwrap());
    let proj = Arc::new(Projector::new(e).unwrap());
    Solver::new(proj, anchors.iter().map(|&v| Anchor::Vertex(v))).unwrap()
}

/// A mesh and its embedding one Loop level finer: old vertices keep their coordinates
/// and each new one (on an edge) takes the midpoint of its edge's, so the finer
/// embedding is the same surface in 8-D and a map onto it the same map; only the 3-D
/// mesh (smoothed by Loop) and its edges are finer.
fn subdivided(coarse: &ValidMesh, coords: &[Vec8]) -> (ValidMesh, Vec<Vec8>) {
    let fine = ValidMesh::new(loop_subdivide(coarse).unwrap()).unwrap();
    let n0 = coarse.n_vertices();
    let mut out = coords.to_vec();
    out.resize(fine.n_vertices(), Vec8::zeros());
    // Children of face f are faces 4f..4f+4, the three corner children first: each holds
    // one old corner and the new vertices on its two edges.
    let mut ends = vec![Vec::new(); fine.n_vertices()];
    for t in fine.triangles.iter() {
        if let Some(&old) = t.iter().find(|&&c| (c as usize) < n0) {
            for &c in t.iter().filter(|&&c| c as usize >= n0) {
                if !ends[c as usize].contains(&old) {
                    ends[c as usize].push(old);
                }
            }
        }
    }
    for (v, e) in ends.iter().enumerate().skip(n0) {
        assert_eq!(e.len(), 2, "new vertex {v}");
        out[v] = (coords[e[0] as usize] + coords[e[1] as usize]) / 2.0;
    }
    (fine, out)
}

/// The same map judged on a mesh and on its Loop subdivision keeps about the same
/// fraction of the vertices: the local test judges each image at a scale of the
/// diagonal, not of the edges (a one-ring test rejects more as the mesh gets finer,
/// where an image a fraction of a coarse edge off flips and stretches fine edges).
#[test]
fn a_body_and_its_subdivision_keep_the_same_share() {
    let [(slim, slim_e), (heavy, heavy_e)] = bodies().clone();
    let anchors = farthest_point_vertices(&slim, 93, 1, FpsMetric::EdgeGraph).unwrap();
    let (fine_slim, fine_slim_e) = subdivided(&slim, &slim_e);
    let (fine_heavy, fine_heavy_e) = subdivided(&heavy, &heavy_e);
    let (a, b) = (
        solver_on(slim, slim_e, &anchors),
        solver_on(heavy, heavy_e, &anchors),
    );
    let (fa, fb) = (
        solver_on(fine_slim, fine_slim_e, &anchors),
        solver_on(fine_heavy, fine_heavy_e, &anchors),
    );
    let opts = CorrespondOptions::default();
    let coarse = correspond_vertices(&a, &b, &opts).unwrap();
    let fine = correspond_vertices(&fa, &fb, &opts).unwrap();
    let (c, f) = (coarse.valid_fraction(), fine.valid_fraction());
    eprintln!(
        "valid {c:.4} ({:?}) -> {f:.4} ({:?})",
        coarse.reason_counts(),
        fine.reason_counts()
    );
    assert!((c - f).abs() <= 0.03, "coarse {c}, fine {f}");
    let t = fine.ground_truth_errors(fa.mesh(), fb.mesh()).unwrap();
    assert!(t.valid.mean <= 0.01, "mean error {}", t.valid.mean);
}
