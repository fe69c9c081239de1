//! Why points climb the verified inverse's penalty ladder: for each point of the bench
//! roundtrip protocol (93 fps anchors, seed 0; points seed 1) whose paper weights do not
//! round-trip, which search modes (the paper's first hit, the certified closest, the
//! exhaustive) bring the average back to the point, rung by rung.
//!
//! `cargo xtask lab ladder_diagnosis MESH EMB.wavg QUERIES`

use wavg_solve::internal::penalized_weights;
use wavg_solve::sampling::{FpsMetric, farthest_point_vertices, uniform_surface_points};
use wavg_solve::{Anchor, ForwardOptions, PENALTY_LADDER, SearchMode, Solver};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (mesh, proj) = wavg_lab::mesh_and_projector(&args[1], &args[2]);
    let nq: usize = args[3].parse().unwrap();
    let anchors = farthest_point_vertices(&mesh, 93, 0, FpsMetric::EdgeGraph).unwrap();
    let solver = Solver::new(proj, anchors.iter().map(|&v| Anchor::Vertex(v))).unwrap();
    let points = uniform_surface_points(&mesh, nq, 1).unwrap();
    let tol = 1e-3 * solver.mean_edge_length();
    let mode = |m| ForwardOptions {
        mode: m,
        ..Default::default()
    };
    let modes = [SearchMode::Fast, SearchMode::Certified, SearchMode::Exact];
    let back = |w: &[f64], m, target: nalgebra::Vector3<f64>| {
        solver
            .forward(w, &mode(m))
            .is_ok_and(|r| (r.position - target).norm() <= tol)
    };
    // [rung][mode] counts of points brought back; rung 0 = the paper's weights.
    let mut counts = [[0usize; 3]; 5];
    let mut first_fast = [0usize; 6];
    let mut first_cert = [0usize; 6];
    let mut ladder = 0;
    for p in &points {
        let target = p.position(&mesh);
        let paper = solver.inverse(p).unwrap();
        if back(&paper, SearchMode::Fast, target) {
            continue;
        }
        ladder += 1;
        let psi = solver.projector().psi(p);
        let yhat = solver.projector().embedded().point(p);
        let mut ff = 5;
        let mut fc = 5;
        for (r, lambda) in std::iter::once(0.0).chain(PENALTY_LADDER).enumerate() {
            let w = if r == 0 {
                paper.clone()
            } else {
                penalized_weights(&psi, &yhat, solver.anchors().coords(), 10.0, lambda).unwrap()
            };
            for (k, m) in modes.iter().enumerate() {
                if back(&w, *m, target) {
                    counts[r][k] += 1;
                    if k == 0 && ff == 5 {
                        ff = r;
                    }
                    if k == 1 && fc == 5 {
                        fc = r;
                    }
                }
            }
        }
        first_fast[ff] += 1;
        first_cert[fc] += 1;
    }
    println!("{} points, {} climb the ladder", points.len(), ladder);
    for (r, c) in counts.iter().enumerate() {
        println!(
            "rung {r}: back with fast {} certified {} exact {}",
            c[0], c[1], c[2]
        );
    }
    println!("first fast rung (0..4, 5 = none): {first_fast:?}");
    println!("first certified rung (0..4, 5 = none): {first_cert:?}");
}
