//! Instructions of the verified inverse against the inverse and forward problems, for
//! callgrind, on the `wavg bench roundtrip` protocol (93 fps anchors, seed 0; points
//! uniform by area, seed 1; one thread): `verified_instructions MESH EMB [QUERIES]` (MESH a
//! file or `builtin:NAME`). The mean edge length is computed before, so no pass pays it.
//! Each batch runs once to warm up, then once in its `measured_*` function:
//!
//! ```sh
//! valgrind --tool=callgrind --collect-atstart=no '--toggle-collect=*measured_*' \
//!   --callgrind-out-file=cg.out target/release/verified_instructions M M.wavg 10000
//! callgrind_annotate --inclusive=yes cg.out | grep -E 'measured_|ladder|PenaltySystem|weights_into|Solver::forward'
//! ```
//!
//! Prints the ladder's counts: points that climb it, rungs tried, points not reached.

use wavg_mesh::SurfacePoint;
use wavg_solve::sampling::{FpsMetric, farthest_point_vertices, uniform_surface_points};
use wavg_solve::{
    Anchor, BatchWeights, ForwardOptions, ForwardResult, ForwardScratch, PENALTY_LADDER, Par,
    RoundTrip, SearchMode, SolveError, Solver,
};

#[inline(never)]
fn measured_inverse(s: &Solver, points: &[SurfacePoint], w: &mut BatchWeights) {
    std::hint::black_box(1u8);
    s.inverse_batch_into(points, w, Par::Seq).unwrap();
}

#[inline(never)]
fn measured_forward(
    s: &Solver,
    rows: &[&[f64]],
    opts: &ForwardOptions,
    out: &mut Vec<Result<ForwardResult, SolveError>>,
) {
    std::hint::black_box(2u8);
    let mut scratch = ForwardScratch::default();
    s.forward_batch_into(rows, opts, &mut scratch, out, Par::Seq)
        .unwrap();
}

#[inline(never)]
fn measured_forward_certified(
    s: &Solver,
    rows: &[&[f64]],
    opts: &ForwardOptions,
    out: &mut Vec<Result<ForwardResult, SolveError>>,
) {
    std::hint::black_box(3u8);
    let mut scratch = ForwardScratch::default();
    s.forward_batch_into(rows, opts, &mut scratch, out, Par::Seq)
        .unwrap();
}

#[inline(never)]
fn measured_verified(
    s: &Solver,
    points: &[SurfacePoint],
    w: &mut BatchWeights,
    trips: &mut Vec<Result<RoundTrip, SolveError>>,
) {
    std::hint::black_box(4u8);
    s.inverse_verified_batch_into(points, 1e-3, w, trips, Par::Seq)
        .unwrap();
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (mesh, proj) = wavg_lab::mesh_and_projector(&args[1], &args[2]);
    let nq: usize = args.get(3).map_or(10_000, |q| q.parse().unwrap());
    let anchors = farthest_point_vertices(&mesh, 93, 0, FpsMetric::EdgeGraph).unwrap();
    let solver = Solver::new(proj, anchors.iter().map(|&v| Anchor::Vertex(v))).unwrap();
    let points = uniform_surface_points(&mesh, nq, 1).unwrap();
    let tol = 1e-3 * solver.mean_edge_length();
    let opts = ForwardOptions::default();
    let cert = ForwardOptions {
        mode: SearchMode::Certified,
        ..Default::default()
    };
    let (mut w, mut wv, mut trips, mut fwd, mut fwd_c) = (
        BatchWeights::default(),
        BatchWeights::default(),
        Vec::new(),
        Vec::new(),
        Vec::new(),
    );
    for measured in [false, true] {
        if measured {
            measured_inverse(&solver, &points, &mut w);
        } else {
            solver
                .inverse_batch_into(&points, &mut w, Par::Seq)
                .unwrap();
        }
        let rows: Vec<&[f64]> = w.iter().map(|r| r.unwrap_or(&[])).collect();
        let mut scratch = ForwardScratch::default();
        if measured {
            measured_forward(&solver, &rows, &opts, &mut fwd);
            measured_forward_certified(&solver, &rows, &cert, &mut fwd_c);
            measured_verified(&solver, &points, &mut wv, &mut trips);
        } else {
            solver
                .forward_batch_into(&rows, &opts, &mut scratch, &mut fwd, Par::Seq)
                .unwrap();
            solver
                .forward_batch_into(&rows, &cert, &mut scratch, &mut fwd_c, Par::Seq)
                .unwrap();
            solver
                .inverse_verified_batch_into(&points, 1e-3, &mut wv, &mut trips, Par::Seq)
                .unwrap();
        }
    }
    let back = |r: &Result<ForwardResult, SolveError>, p: &SurfacePoint| {
        r.as_ref()
            .is_ok_and(|f| (f.position - p.position(&mesh)).norm() <= tol)
    };
    let ok = |f: &[Result<ForwardResult, SolveError>]| {
        f.iter().zip(&points).filter(|(r, p)| back(r, p)).count()
    };
    let (mut climb, mut rungs, mut not_reached) = (0, 0, 0);
    for t in &trips {
        match t {
            Ok(RoundTrip::Penalized(l)) => {
                climb += 1;
                rungs += 1 + PENALTY_LADDER.iter().position(|x| x == l).unwrap();
            }
            Ok(RoundTrip::NotReached) => {
                climb += 1;
                not_reached += 1;
                rungs += PENALTY_LADDER.len();
            }
            _ => {}
        }
    }
    println!(
        "{}: {} vertices, {nq} queries; paper round trips fast {} certified {}; ladder points {climb} rungs {rungs} not reached {not_reached}",
        args[1],
        mesh.n_vertices(),
        ok(&fwd),
        ok(&fwd_c),
    );
}
