//! Times metric MDS on great-circle distances between random sphere points.
use rand::{Rng, SeedableRng};
use wavg_embed::NoProgress;
use wavg_embed::{MdsOptions, internal::metric_mds};

fn main() {
    let n: usize = std::env::args().nth(1).map_or(1000, |s| s.parse().unwrap());
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    let p: Vec<[f64; 3]> = (0..n)
        .map(|_| {
            loop {
                let v = [
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0f64..1.0),
                ];
                let r = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                if r > 0.1 && r < 1.0 {
                    break [v[0] / r, v[1] / r, v[2] / r];
                }
            }
        })
        .collect();
    let q: Vec<f64> = (0..n * n)
        .map(|k| {
            let (a, b) = (p[k / n], p[k % n]);
            (a[0] * b[0] + a[1] * b[1] + a[2] * b[2])
                .clamp(-1.0, 1.0)
                .acos()
        })
        .collect();
    let t = std::time::Instant::now();
    let c = wavg_embed::internal::classical_mds(&q, n, 8).unwrap();
    println!("classical {:.3}s", t.elapsed().as_secs_f64());
    let s0 = wavg_embed::internal::relative_stress(&q, n, &c).unwrap();
    let t = std::time::Instant::now();
    let r = metric_mds(&q, n, &MdsOptions::default(), &NoProgress).unwrap();
    println!(
        "metric_mds {:.3}s iterations {} stress {:.5} (classical {:.5}) converged {}",
        t.elapsed().as_secs_f64(),
        r.iterations,
        r.stress,
        s0,
        r.converged
    );
    for (i, s) in r.history.iter().enumerate() {
        if i % 20 == 0 {
            print!("{i}:{s:.5} ");
        }
    }
    println!();
}
