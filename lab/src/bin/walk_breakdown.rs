//! Where a forward query's time goes: `walk_breakdown MESH EMB [MESH EMB ...]`.
use std::path::Path;
use std::sync::Arc;
use std::time::Instant;

use wavg_mesh::ValidMesh;
use wavg_project::{EmbeddedMesh, Projector, SearchGoal, Vec8};
use wavg_solve::sampling::{FpsMetric, farthest_point_vertices, uniform_surface_points};
use wavg_solve::{Anchor, ForwardOptions, Solver};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mut setups = Vec::new();
    for pair in args[1..].chunks(2) {
        let mesh = wavg_mesh::io::load(Path::new(&pair[0])).expect("mesh");
        let emb = wavg_embed::file::load(Path::new(&pair[1]), &mesh).expect("embedding");
        let coords: Vec<Vec8> = emb.coords.iter().map(|c| Vec8::from(*c)).collect();
        let m = Arc::new(ValidMesh::new(mesh).unwrap());
        let e = Arc::new(EmbeddedMesh::new(m.clone(), coords.clone()).unwrap());
        let p = Arc::new(Projector::new(e).unwrap());
        let anchors = farthest_point_vertices(&m, 32, 0, FpsMetric::EdgeGraph).unwrap();
        let points = uniform_surface_points(&m, 20000, 1).unwrap();
        let s = Solver::new(p.clone(), anchors.iter().map(|&v| Anchor::Vertex(v))).unwrap();
        let ws: Vec<Vec<f64>> = points.iter().map(|x| s.inverse(x).unwrap()).collect();
        let ys: Vec<(Vec8, u32)> = ws
            .iter()
            .map(|w| {
                let y = w
                    .iter()
                    .zip(&anchors)
                    .map(|(&wi, &a)| coords[a as usize] * wi)
                    .sum::<Vec8>();
                let best = (0..w.len()).max_by(|&i, &j| w[i].total_cmp(&w[j])).unwrap();
                (y, anchors[best])
            })
            .collect();
        setups.push((pair[0].clone(), p, s, ws, ys));
    }
    if let Ok(n) = std::env::var("BATCH_ONLY") {
        eprintln!("setup done");
        for (name, _, s, ws, _) in &setups {
            let rows: Vec<&[f64]> = ws.iter().map(|w| w.as_slice()).collect();
            let t = Instant::now();
            for _ in 0..n.parse::<usize>().unwrap() {
                let r = s.forward_batch(&rows, &ForwardOptions::default());
                assert_eq!(r.len(), rows.len());
            }
            println!("{name}: {:.2} s", t.elapsed().as_secs_f64());
        }
        return;
    }
    let rounds: usize = std::env::var("ROUNDS").map_or(7, |r| r.parse().unwrap());
    let mut best = vec![[f64::INFINITY; 5]; setups.len()];
    for round in 0..rounds {
        for (i, (name, p, s, ws, ys)) in setups.iter().enumerate() {
            let t = Instant::now();
            let mut acc = 0u64;
            for (y, a) in ys {
                acc += u64::from(p.start_near(y, *a));
            }
            let t_start = t.elapsed().as_secs_f64() / ys.len() as f64 * 1e6;
            let t = Instant::now();
            for (y, a) in ys {
                acc += u64::from(p.walk(y, p.start_near(y, *a)));
            }
            let t_walk = t.elapsed().as_secs_f64() / ys.len() as f64 * 1e6;
            let t = Instant::now();
            for (y, a) in ys {
                acc += u64::from(
                    p.project_with(y, p.start_near(y, *a), None, SearchGoal::FirstHit)
                        .unwrap()
                        .point
                        .face,
                );
            }
            let t_proj = t.elapsed().as_secs_f64() / ys.len() as f64 * 1e6;
            let t = Instant::now();
            for w in ws {
                acc += u64::from(s.forward(w, &ForwardOptions::default()).unwrap().point.face);
            }
            let t_fwd = t.elapsed().as_secs_f64() / ys.len() as f64 * 1e6;
            let rows: Vec<&[f64]> = ws.iter().map(|w| w.as_slice()).collect();
            let t = Instant::now();
            let r = s.forward_batch(&rows, &ForwardOptions::default());
            let t_batch = t.elapsed().as_secs_f64() / ys.len() as f64 * 1e6;
            acc += r.len() as u64;
            println!(
                "round {round} {name}: start_near {t_start:.3} +walk {t_walk:.3} project {t_proj:.3} forward {t_fwd:.3} batch {t_batch:.3} us ({acc})"
            );
            for (b, t) in best[i]
                .iter_mut()
                .zip([t_start, t_walk, t_proj, t_fwd, t_batch])
            {
                *b = b.min(t);
            }
        }
    }
    for ((name, ..), b) in setups.iter().zip(&best) {
        println!(
            "best {name}: start_near {:.3} +walk {:.3} project {:.3} forward {:.3} batch {:.3}",
            b[0], b[1], b[2], b[3], b[4]
        );
    }
    if best.len() >= 2 {
        for i in 1..best.len() {
            let r: Vec<String> = (0..5)
                .map(|k| format!("{:.2}", best[i][k] / best[0][k]))
                .collect();
            println!("ratio {i}/first: {}", r.join(" "));
        }
    }
}
