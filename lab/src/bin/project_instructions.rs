//! Instructions per projection, for callgrind: `project_instructions MESH EMB [QUERIES]`
//! (MESH a file or `builtin:NAME`). The queries of `wavg bench project` (seed 1: random
//! surface points by area, each from a start vertex three rings away, and the same points
//! 0.1 mean edges off the surface in a random direction orthogonal to the embedded face),
//! each kind projected once to warm up (a vertex's reach is computed on its second ask),
//! then once in `measured_onsurface` and once in `measured_offset`:
//!
//! ```sh
//! valgrind --tool=callgrind --collect-atstart=no '--toggle-collect=*measured_*' \
//!   --callgrind-out-file=cg.out target/release/project_instructions M M.wavg 10000
//! callgrind_annotate --inclusive=yes cg.out | grep measured_   # instructions of each pass
//! ```
//!
//! Prints the fallback fractions (queries the global search answered) of both kinds.

use std::path::Path;
use std::sync::Arc;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use wavg_mesh::{RingSearch, ValidMesh};
use wavg_project::{
    EmbeddedMesh, Par, ProjectError, ProjectScratch, Projection, ProjectionPath, Projector, Vec8,
};
use wavg_solve::sampling::uniform_surface_points;

/// One pass over `ys` through the batch call (as `wavg bench project` times it).
#[inline(always)]
fn pass(p: &Projector, ys: &[Vec8], starts: &[u32]) -> Vec<Result<Projection, ProjectError>> {
    let mut out = Vec::with_capacity(ys.len());
    let mut scratch = ProjectScratch::default();
    p.project_batch_into(ys, starts, &mut scratch, &mut out, Par::Seq)
        .expect("sequential batch");
    out
}

#[inline(never)]
fn measured_onsurface(
    p: &Projector,
    ys: &[Vec8],
    starts: &[u32],
) -> Vec<Result<Projection, ProjectError>> {
    // Distinct from `measured_offset`, so the two are not merged into one symbol.
    std::hint::black_box(1u8);
    pass(p, ys, starts)
}

#[inline(never)]
fn measured_offset(
    p: &Projector,
    ys: &[Vec8],
    starts: &[u32],
) -> Vec<Result<Projection, ProjectError>> {
    std::hint::black_box(2u8);
    pass(p, ys, starts)
}

/// A seeded random unit direction of R^8 orthogonal to face `f`'s embedded plane.
fn offset_direction(emb: &EmbeddedMesh, f: u32, rng: &mut ChaCha8Rng) -> Vec8 {
    let [a, b, c] = emb.corners(f as usize);
    let e1 = (b - a).normalize();
    let w = c - a;
    let e2 = (w - e1 * e1.dot(&w)).normalize();
    loop {
        let r = Vec8::from_fn(|_, _| rng.random_range(-1.0..1.0));
        let n = r - e1 * e1.dot(&r) - e2 * e2.dot(&r);
        let len = n.norm();
        if len > 1e-3 && len.is_finite() {
            return n / len;
        }
    }
}

fn fallbacks(r: &[Result<Projection, ProjectError>]) -> f64 {
    let n = r
        .iter()
        .filter(|r| matches!(r, Ok(p) if p.path == ProjectionPath::Fallback))
        .count();
    n as f64 / r.len() as f64
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let queries: usize = args.get(3).map_or(20_000, |q| q.parse().expect("QUERIES"));
    let mesh = match args[1].strip_prefix("builtin:") {
        Some(name) => wavg_mesh::procedural::builtin(name).expect("builtin"),
        None => wavg_mesh::io::load(Path::new(&args[1])).expect("mesh"),
    };
    let file = wavg_embed::file::load(Path::new(&args[2]), &mesh).expect("embedding");
    let coords: Vec<Vec8> = file.coords.iter().map(|c| Vec8::from(*c)).collect();
    let m = Arc::new(ValidMesh::new(mesh).expect("valid mesh"));
    let emb = Arc::new(EmbeddedMesh::new(m.clone(), coords).expect("embedding"));
    let p = Projector::new(emb.clone()).expect("projector");

    let points = uniform_surface_points(&m, queries, 1).expect("points");
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut rings = RingSearch::new(m.n_vertices());
    let starts: Vec<u32> = points
        .iter()
        .map(|pt| {
            let ring = rings.ring_or_farthest(m.topology(), m.triangles[pt.face as usize][0], 3);
            ring[rng.random_range(0..ring.len())]
        })
        .collect();
    let ys: Vec<Vec8> = points.iter().map(|pt| emb.point(pt)).collect();
    let mean_edge = emb.mean_edge_length();
    let offset: Vec<Vec8> = (points.iter().zip(&ys))
        .map(|(pt, y)| y + offset_direction(&emb, pt.face, &mut rng) * (0.1 * mean_edge))
        .collect();

    let warm_on = pass(&p, &ys, &starts);
    let on = measured_onsurface(&p, &ys, &starts);
    assert!(warm_on == on, "passes differ");
    let warm_off = pass(&p, &offset, &starts);
    let off = measured_offset(&p, &offset, &starts);
    assert!(warm_off == off, "passes differ");
    println!(
        "{}: {} vertices, {} queries, fallbacks on / off surface {:.5} / {:.5}",
        args[1],
        m.n_vertices(),
        queries,
        fallbacks(&on),
        fallbacks(&off)
    );
}
