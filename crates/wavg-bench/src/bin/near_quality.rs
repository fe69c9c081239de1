//! Relative embedding-vs-geodesic error on *near* vertex pairs (geodesic distance below a
//! fraction of the bounding-box diagonal), for comparing embeddings of one mesh.
//!
//! `cargo run --release -p wavg-bench --bin near_quality -- MESH FRACTION A.wavg [B.wavg ...]`
use std::path::Path;
use wavg_embed::FastMarching;
use wavg_embed::internal::percentile;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mesh =
        wavg_mesh::ValidMesh::new(wavg_mesh::io::load(Path::new(&args[0])).unwrap()).unwrap();
    let frac: f64 = args[1].parse().unwrap();
    let radius = frac * mesh.bounding_box_diagonal();
    let fm = FastMarching::new(&mesh);
    let mut ws = fm.workspace();
    let n = mesh.n_vertices();
    let sources: Vec<u32> = (0..40).map(|i| ((i * 7919 + 13) % n) as u32).collect();
    let mut pairs = Vec::new();
    for &s in &sources {
        let d = fm.run(&mut ws, &[s]);
        for (v, &g) in d.iter().enumerate() {
            if g > 0.0 && g < radius && v % 3 == 0 {
                pairs.push((s as usize, v, g));
            }
        }
    }
    for f in &args[2..] {
        let e = wavg_embed::file::load(Path::new(f), &mesh).unwrap();
        let mut errs: Vec<f64> = pairs
            .iter()
            .map(|&(a, b, g)| {
                let d = e.coords[a]
                    .iter()
                    .zip(&e.coords[b])
                    .map(|(x, y)| (x - y) * (x - y))
                    .sum::<f64>()
                    .sqrt();
                (d - g).abs() / g
            })
            .collect();
        errs.sort_by(f64::total_cmp);
        println!(
            "{f}: {} near pairs (< {frac} diag): p50 {:.4} p90 {:.4}",
            errs.len(),
            percentile(&errs, 0.5),
            percentile(&errs, 0.9)
        );
    }
}
