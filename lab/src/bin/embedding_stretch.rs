//! How evenly an embedding stretches the mesh's edges: `embedding_stretch MESH EMB [...]`.
//!
//! Each edge's embedded length over its length in space. A smooth embedding close to an
//! isometry keeps the ratio near one everywhere; plateaus (whole patches mapped to nearly
//! one point, as an unconverged least-squares mesh leaves) show as a low tail, and the
//! forward walk crawls across them.
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    for pair in args[1..].chunks(2) {
        let mesh = wavg_mesh::io::load(Path::new(&pair[0])).expect("mesh");
        let emb = wavg_embed::file::load(Path::new(&pair[1]), &mesh).expect("embedding");
        let x = &mesh.positions;
        let e = &emb.coords;
        let mut ratios = Vec::with_capacity(mesh.triangles.len() * 3 / 2);
        for t in &mesh.triangles {
            for k in 0..3 {
                let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
                if a < b {
                    let space = (x[a] - x[b]).norm();
                    let embedded = e[a]
                        .iter()
                        .zip(&e[b])
                        .map(|(p, q)| (p - q) * (p - q))
                        .sum::<f64>()
                        .sqrt();
                    if space > 0.0 {
                        ratios.push(embedded / space);
                    }
                }
            }
        }
        ratios.sort_by(f64::total_cmp);
        let at = |f: f64| ratios[((ratios.len() - 1) as f64 * f) as usize];
        let below = |r: f64| ratios.partition_point(|&v| v < r) as f64 / ratios.len() as f64;
        println!(
            "{}: {} edges; ratio p1 {:.3} p5 {:.3} p25 {:.3} p50 {:.3} p75 {:.3} p95 {:.3} p99 {:.3}; below 0.25: {:.4}, below 0.5: {:.4}",
            pair[1],
            ratios.len(),
            at(0.01),
            at(0.05),
            at(0.25),
            at(0.5),
            at(0.75),
            at(0.95),
            at(0.99),
            below(0.25),
            below(0.5)
        );
    }
}
