//! Where the verified inverse's time goes: the paper's inverse batch, the forward batch that
//! checks it, and each rung of the penalty ladder (points tried, forward paths), composed
//! from the public batches one stage at a time, on the Table-1 protocol's anchors and
//! points; then the library's verified batch on the same points. Wall and CPU time of all
//! threads (from `/proc/self/task/*/schedstat`; CPU time is what a loaded machine distorts
//! least).
//!
//! `cargo xtask lab verified_stages MESH EMB.wavg ANCHORS QUERIES [THREADS]` (with
//! `VERIFIED_ONLY` set: only the library's verified batch, five times, for a profiler)

use std::time::Instant;

use rayon::prelude::*;

use wavg_solve::internal::penalized_weights;
use wavg_solve::sampling::{FpsMetric, farthest_point_vertices, uniform_surface_points};
use wavg_solve::{
    Anchor, BatchWeights, ForwardOptions, ForwardScratch, PENALTY_LADDER, Par, ProjectionPath,
    Solver,
};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (mesh, proj) = wavg_lab::mesh_and_projector(&args[1], &args[2]);
    let k: usize = args[3].parse().unwrap();
    let nq: usize = args[4].parse().unwrap();
    let threads: usize = args.get(5).map_or(2, |t| t.parse().unwrap());
    let anchors = farthest_point_vertices(&mesh, k, 0, FpsMetric::EdgeGraph).unwrap();
    let solver = Solver::new(proj, anchors.iter().map(|&v| Anchor::Vertex(v))).unwrap();
    let points = uniform_surface_points(&mesh, nq, 0).unwrap();
    let par = Par::Threads(std::num::NonZeroUsize::new(threads).unwrap());
    let n = nq as f64;
    let tol = 1e-3 * solver.mean_edge_length();
    let opts = ForwardOptions::default();
    let us = |t: Instant| t.elapsed().as_secs_f64() / n * 1e6;
    // On-CPU nanoseconds of every thread of the process (the scheduler's accounting).
    let cpu = || {
        let tasks = std::fs::read_dir("/proc/self/task").into_iter().flatten();
        tasks
            .flatten()
            .filter_map(|t| std::fs::read_to_string(t.path().join("schedstat")).ok())
            .filter_map(|s| s.split_whitespace().next()?.parse::<f64>().ok())
            .sum::<f64>()
            / 1e9
    };
    let cpu_us = |c0: f64| (cpu() - c0) / n * 1e6;
    if std::env::var_os("VERIFIED_ONLY").is_some() {
        // Only the library's verified batch, for a profiler.
        let (mut w2, mut trips) = (BatchWeights::default(), Vec::new());
        for _ in 0..5 {
            let (t, c) = (Instant::now(), cpu());
            solver
                .inverse_verified_batch_into(&points, 1e-3, &mut w2, &mut trips, par)
                .unwrap();
            println!("verified {:.3} us (cpu {:.3})", us(t), cpu_us(c));
        }
        return;
    }
    for rep in 0..3 {
        let (t_all, c_all) = (Instant::now(), cpu());
        let mut w = BatchWeights::default();
        let (t, c) = (Instant::now(), cpu());
        solver.inverse_batch_into(&points, &mut w, par).unwrap();
        let (t_inv, c_inv) = (us(t), cpu_us(c));
        let rows: Vec<&[f64]> = w.iter().map(|r| r.unwrap_or(&[])).collect();
        let (mut scratch, mut fwd) = (ForwardScratch::default(), Vec::new());
        let (t, c) = (Instant::now(), cpu());
        solver
            .forward_batch_into(&rows, &opts, &mut scratch, &mut fwd, par)
            .unwrap();
        let (t_fwd, c_fwd) = (us(t), cpu_us(c));
        let mut pending: Vec<usize> = (0..nq)
            .filter(|&i| {
                !fwd[i]
                    .as_ref()
                    .is_ok_and(|f| (f.position - points[i].position(&mesh)).norm() <= tol)
            })
            .collect();
        let mut line = format!(
            "rep {rep}: inverse {t_inv:.3} us (cpu {c_inv:.3}), forward {t_fwd:.3} us (cpu {c_fwd:.3}), pending {}",
            pending.len()
        );
        let c_ladder = cpu();
        for lambda in PENALTY_LADDER {
            let (t, c) = (Instant::now(), cpu());
            let tried: Vec<Vec<f64>> = pending
                .par_iter()
                .map(|&i| {
                    let p = points[i];
                    let psi = solver.projector().psi(&p);
                    let yhat = solver.projector().embedded().point(&p);
                    penalized_weights(&psi, &yhat, solver.anchors().coords(), 10.0, lambda)
                        .unwrap_or_default()
                })
                .collect();
            let (t_pen, c_pen) = (us(t), cpu_us(c));
            let (t, c) = (Instant::now(), cpu());
            solver
                .forward_batch_into(&tried, &opts, &mut scratch, &mut fwd, par)
                .unwrap();
            let (t_f, c_f) = (us(t), cpu_us(c));
            let fallbacks = fwd
                .iter()
                .filter(|f| f.as_ref().is_ok_and(|f| f.path == ProjectionPath::Fallback))
                .count();
            pending = pending
                .iter()
                .zip(&fwd)
                .filter(|(i, f)| {
                    !f.as_ref()
                        .is_ok_and(|f| (f.position - points[**i].position(&mesh)).norm() <= tol)
                })
                .map(|(i, _)| *i)
                .collect();
            line += &format!(
                " | l{lambda}: weights {t_pen:.3} (cpu {c_pen:.3}) fwd {t_f:.3} (cpu {c_f:.3}) fb {fallbacks} left {}",
                pending.len()
            );
        }
        line += &format!(" | ladder cpu {:.3}", cpu_us(c_ladder));
        line += &format!(" | staged {:.3} us (cpu {:.3})", us(t_all), cpu_us(c_all));
        let (mut w2, mut trips) = (BatchWeights::default(), Vec::new());
        let (t, c) = (Instant::now(), cpu());
        solver
            .inverse_verified_batch_into(&points, 1e-3, &mut w2, &mut trips, par)
            .unwrap();
        line += &format!(" | verified {:.3} us (cpu {:.3})", us(t), cpu_us(c));
        println!("{line}");
    }
}
