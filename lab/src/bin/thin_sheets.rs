//! How close another sheet of the surface comes to each vertex in the embedding:
//! `thin_sheets MESH EMB [...]` (MESH may be builtin:NAME). For every vertex, the nearest
//! vertex more than `RINGS` rings away, in units of the vertex's mean edge; a
//! histogram. Brute force (quadratic): meshes up to about 50k vertices.
use std::path::Path;

use rayon::prelude::*;
use wavg_mesh::{RingSearch, ValidMesh};

const RINGS: usize = 2;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    for pair in args[1..].chunks(2) {
        let mesh = match pair[0].strip_prefix("builtin:") {
            Some(n) => wavg_mesh::procedural::builtin(n).unwrap(),
            None => wavg_mesh::io::load(Path::new(&pair[0])).expect("mesh"),
        };
        let emb = wavg_embed::file::load(Path::new(&pair[1]), &mesh).expect("embedding");
        let x: Vec<[f64; 8]> = emb.coords.clone();
        let m = ValidMesh::new(mesh).unwrap();
        let topo = m.topology();
        let d = |a: &[f64; 8], b: &[f64; 8]| -> f64 {
            a.iter()
                .zip(b)
                .map(|(p, q)| (p - q) * (p - q))
                .sum::<f64>()
                .sqrt()
        };
        let n = m.n_vertices();
        let ratios: Vec<f64> = (0..n)
            .into_par_iter()
            .map_init(RingSearch::default, |rings, v| {
                let mut near = vec![v as u32];
                for k in 1..=RINGS {
                    near.extend_from_slice(rings.ring_or_farthest(topo, v as u32, k));
                }
                let ring = topo.ring(v as u32);
                let edge = (ring.iter())
                    .map(|&u| d(&x[v], &x[u as usize]))
                    .sum::<f64>()
                    / ring.len() as f64;
                let best = (0..n)
                    .filter(|u| !near.contains(&(*u as u32)))
                    .map(|u| d(&x[v], &x[u]))
                    .fold(f64::INFINITY, f64::min);
                best / edge
            })
            .collect();
        let mut line = format!("{}: {n} vertices;", pair[0]);
        for t in [0.25, 0.5, 0.75, 1.0, 1.5, 2.0] {
            let c = ratios.iter().filter(|&&r| r < t).count();
            line += &format!(" <{t}: {c}");
        }
        println!("{line}");
    }
}
