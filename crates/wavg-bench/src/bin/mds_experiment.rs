//! Dev experiment: landmark distances of a mesh cached in /tmp, then MDS variants.
use std::path::Path;
use wavg_embed::NoProgress;
use wavg_embed::{MdsOptions, internal::metric_mds};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = &args[1];
    let tol: f64 = args.get(2).map_or(1e-6, |s| s.parse().unwrap());
    let iters: usize = args.get(3).map_or(300, |s| s.parse().unwrap());
    let name = Path::new(path)
        .file_name()
        .unwrap()
        .to_string_lossy()
        .to_string();
    let cache = format!("/tmp/wavg-emb/q-{name}.bin");
    let mesh = wavg_mesh::ValidMesh::new(wavg_mesh::io::load(Path::new(path)).unwrap()).unwrap();
    let (lm, q): (Vec<u32>, Vec<f64>) = if let Ok(b) = std::fs::read(&cache) {
        let k = u64::from_le_bytes(b[..8].try_into().unwrap()) as usize;
        let lm = (0..k)
            .map(|i| u32::from_le_bytes(b[8 + 4 * i..12 + 4 * i].try_into().unwrap()))
            .collect();
        let o = 8 + 4 * k;
        let q = (0..k * k)
            .map(|i| f64::from_le_bytes(b[o + 8 * i..o + 8 * i + 8].try_into().unwrap()))
            .collect();
        (lm, q)
    } else {
        let lm = wavg_embed::select_landmarks(&mesh, &Default::default(), &NoProgress).unwrap();
        let q =
            wavg_embed::landmark_distances(&mesh, &lm, &Default::default(), &NoProgress).unwrap();
        let mut b = (lm.len() as u64).to_le_bytes().to_vec();
        lm.iter().for_each(|l| b.extend(l.to_le_bytes()));
        q.iter().for_each(|x| b.extend(x.to_le_bytes()));
        std::fs::write(&cache, b).unwrap();
        (lm, q)
    };
    let n = lm.len();
    let t = std::time::Instant::now();
    let r = metric_mds(
        &q,
        n,
        &MdsOptions {
            dim: 8,
            max_iterations: iters,
            tolerance: tol,
        },
        &NoProgress,
    )
    .unwrap();
    let t_mds = t.elapsed().as_secs_f64();
    let x =
        wavg_embed::internal::least_squares_mesh(&mesh, &lm, &r.points, 8, &NoProgress).unwrap();
    let fm = wavg_embed::FastMarching::new(&mesh);
    let qq =
        wavg_embed::internal::geodesic_quality(&mesh, &fm, &x, &Default::default(), &NoProgress)
            .unwrap();
    println!(
        "{name} tol {tol:e}: mds {t_mds:.2}s it {} stress {:.5} (init {:.5}) p50 {:.4} p90 {:.4}",
        r.iterations, r.stress, r.initial_stress, qq.rel_err_p50, qq.rel_err_p90
    );
    let h: Vec<String> = r
        .history
        .iter()
        .enumerate()
        .filter(|(i, _)| i % 25 == 0)
        .map(|(i, s)| format!("{i}:{s:.5}"))
        .collect();
    println!("  {}", h.join(" "));
}
