//! Compares two embeddings of one mesh: `embedding_diff MESH A.wavg B.wavg` prints the
//! largest and the 99th-percentile distance between a vertex's two embedded points,
//! relative to the largest point norm of A.
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let mesh = wavg_mesh::io::load(Path::new(&args[1])).expect("mesh");
    let a = wavg_embed::file::load(Path::new(&args[2]), &mesh).expect("first embedding");
    let b = wavg_embed::file::load(Path::new(&args[3]), &mesh).expect("second embedding");
    let norm = |p: &[f64]| p.iter().map(|c| c * c).sum::<f64>().sqrt();
    let scale = a.coords.iter().map(|p| norm(p)).fold(0.0f64, f64::max);
    let mut d: Vec<f64> = a
        .coords
        .iter()
        .zip(&b.coords)
        .map(|(p, q)| {
            let diff: Vec<f64> = p.iter().zip(q).map(|(x, y)| x - y).collect();
            norm(&diff) / scale
        })
        .collect();
    d.sort_by(f64::total_cmp);
    let p99 = d[(d.len() - 1) * 99 / 100];
    println!(
        "vertices {} max relative difference {:.3e} p99 {:.3e} (scale {scale:.4})",
        d.len(),
        d[d.len() - 1],
        p99
    );
}
