//! Collapsed pairs of an embedding: pairs of vertices embedded closer than half their
//! straight-line distance (one part folded onto another), the measure of #41's "no
//! collapsed pair on human-like bodies".
//!
//! `cargo xtask lab collapsed_pairs [--levels 0,2] [--seeds 8] [--no-cover] [--save DIR] MESH...`
//!
//! `body:SEED` is a procedural body (fingers, toes, ears) of a seeded random shape.
//! Each mesh is Loop-subdivided to each level and precomputed with the default options
//! (`--no-cover`: without the landmarks added around thin parts), or, with `MESH=EMB.wavg`,
//! its embedding is read. Reported per mesh and level:
//! * `seconds`: the precomputation's wall time, and the landmarks it used;
//! * `p50 / p90`: the precomputation's own quality check (relative error of embedded
//!   against geodesic distance over 1,024 pairs, the default);
//! * `random`: collapsed pairs among 2,048 seeded random pairs of distinct vertices, per
//!   seed (the exact-geodesic comparison's sample, `lab/tools/exact_geodesics.py`; the
//!   collapse needs no geodesic), and the smallest ratio over them all;
//! * `all`: every pair of vertices (rows of every `stride`-th vertex above 20k vertices):
//!   the fraction collapsed, the expected count among 2,048 random pairs, the vertices in
//!   some collapsed pair, the smallest ratio with its pair's positions.
use std::path::{Path, PathBuf};

use rayon::prelude::*;
use wavg_embed::{Embedding, NoProgress, PrecomputeOptions, precompute};
use wavg_mesh::{ValidMesh, procedural};

/// A pair is collapsed when embedded closer than this times its straight-line distance.
const COLLAPSED: f64 = 0.5;

fn main() {
    let mut levels = vec![0usize];
    let mut seeds = 8u64;
    let mut cover = true;
    let mut save: Option<PathBuf> = None;
    let mut meshes = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--levels" => {
                levels = (args.next().expect("--levels L,L").split(','))
                    .map(|s| s.parse().expect("level"))
                    .collect()
            }
            "--seeds" => seeds = args.next().expect("--seeds N").parse().expect("seeds"),
            "--no-cover" => cover = false,
            "--save" => save = Some(PathBuf::from(args.next().expect("--save DIR"))),
            _ => meshes.push(a),
        }
    }
    println!(
        "| mesh | level | vertices | landmarks | seconds (decimate / geodesics / lsmesh) | p50 / p90 | collapsed of 2,048 random (per seed) | min ratio (random) | all pairs: collapsed fraction | expected of 2,048 | vertices in one | min ratio | worst pair at | min ratio between landmarks |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for spec in &meshes {
        let (mesh_path, emb_path) = match spec.split_once('=') {
            Some((m, e)) => (m, Some(e)),
            None => (spec.as_str(), None),
        };
        let base = match mesh_path.strip_prefix("body:") {
            Some(seed) => {
                let shape = shape(seed.parse().expect("body:SEED"));
                eprintln!("{mesh_path}: {shape:?}");
                procedural::body(&shape)
            }
            None => wavg_mesh::io::load(Path::new(mesh_path)).expect("mesh"),
        };
        for &level in &levels {
            let mut mesh = ValidMesh::new(base.clone()).expect("valid mesh");
            for _ in 0..level {
                mesh =
                    ValidMesh::new(wavg_mesh::subdivide::loop_subdivide(&mesh).unwrap()).unwrap();
            }
            let (emb, seconds, errors) = match emb_path {
                Some(e) if level == 0 => (
                    wavg_embed::file::load(Path::new(e), &mesh).expect("embedding"),
                    "-".to_string(),
                    "-".to_string(),
                ),
                _ => {
                    let opts = PrecomputeOptions {
                        cover_thin_parts: cover,
                        ..Default::default()
                    };
                    let (emb, report) = precompute(&mesh, &opts, &NoProgress).expect("embedding");
                    let st = &report.stages;
                    let parts = format!(
                        "{:.2} ({:.2} / {:.2} / {:.2})",
                        report.seconds, st.decimate, st.geodesics, st.lsmesh
                    );
                    let errors = format!(
                        "{:.4} / {:.4}",
                        report.geodesic_rel_err_p50, report.geodesic_rel_err_p90
                    );
                    (emb, parts, errors)
                }
            };
            let name = Path::new(mesh_path)
                .file_name()
                .unwrap()
                .to_string_lossy()
                .to_string();
            if let Some(dir) = &save {
                let out = dir.join(format!("{name}.L{level}.wavg"));
                wavg_embed::file::save(&out, &emb, &mesh).expect("save");
                wavg_mesh::io::save(&dir.join(format!("{name}.L{level}.obj")), &mesh)
                    .expect("save mesh");
            }
            let random: Vec<(usize, f64)> =
                (0..seeds).map(|s| random_pairs(&mesh, &emb, s)).collect();
            let counts: Vec<String> = random.iter().map(|r| r.0.to_string()).collect();
            let min_random = random.iter().map(|r| r.1).fold(f64::INFINITY, f64::min);
            let all = all_pairs(&mesh, &emb);
            let lm = &emb.landmarks;
            let landmark_min = (lm.par_iter().enumerate())
                .map(|(i, &a)| {
                    (lm[i + 1..].iter())
                        .map(|&b| ratio(&mesh, &emb, a as usize, b as usize))
                        .fold(f64::INFINITY, f64::min)
                })
                .reduce(|| f64::INFINITY, f64::min);
            let [x, y] = [all.worst.1, all.worst.2].map(|v| {
                let p = mesh.positions[v];
                format!("({:.3}, {:.3}, {:.3})", p.x, p.y, p.z)
            });
            println!(
                "| {name} | {level} | {} | {} | {seconds} | {errors} | {} | {min_random:.3} | {:.2e} | {:.3} | {} | {:.3} | {x}-{y} | {landmark_min:.3} |",
                mesh.n_vertices(),
                emb.landmarks.len(),
                counts.join(" "),
                all.fraction,
                all.fraction * 2048.0,
                all.vertices,
                all.worst.0,
            );
        }
    }
}

/// A body shape drawn with seed `seed` between and a little beyond the slim and heavy
/// figures' (arms, elbows, legs, fingers, girth, height).
fn shape(seed: u64) -> procedural::FigureShape {
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut u = |lo: f64, hi: f64| rng.random_range(lo..hi);
    procedural::FigureShape {
        height: u(0.85, 1.1),
        girth: u(0.9, 1.6),
        arm_spread: u(0.3, 0.8),
        elbow: u(0.0, 0.9),
        leg_spread: u(0.04, 0.2),
        finger_length: u(0.07, 0.1),
        finger_radius: u(0.007, 0.012),
    }
}

/// The ratio of embedded to straight-line distance of vertices `a` and `b`.
fn ratio(mesh: &ValidMesh, emb: &Embedding, a: usize, b: usize) -> f64 {
    let e = (emb.coords[a].iter().zip(&emb.coords[b]))
        .map(|(s, t)| (s - t) * (s - t))
        .sum::<f64>()
        .sqrt();
    e / (mesh.positions[a] - mesh.positions[b]).norm()
}

/// Collapsed pairs among 2,048 random pairs of seed `seed` (32 sources, 64 targets
/// each), and their smallest ratio.
fn random_pairs(mesh: &ValidMesh, emb: &Embedding, seed: u64) -> (usize, f64) {
    use rand::{Rng, SeedableRng};
    let n = mesh.n_vertices();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let (mut count, mut worst) = (0, f64::INFINITY);
    for _ in 0..32 {
        let s = rng.random_range(0..n);
        for _ in 0..64 {
            let t = loop {
                let t = rng.random_range(0..n);
                if t != s {
                    break t;
                }
            };
            let r = ratio(mesh, emb, s, t);
            count += usize::from(r < COLLAPSED);
            worst = worst.min(r);
        }
    }
    (count, worst)
}

/// What [`all_pairs`] measures.
struct AllPairs {
    fraction: f64,
    vertices: usize,
    worst: (f64, usize, usize),
}

/// Every pair of vertices (rows of every `stride`-th vertex on large meshes).
fn all_pairs(mesh: &ValidMesh, emb: &Embedding) -> AllPairs {
    let n = mesh.n_vertices();
    let stride = n.div_ceil(20_000);
    let rows: Vec<usize> = (0..n).step_by(stride).collect();
    let per_row: Vec<(usize, f64, usize, Vec<usize>)> = rows
        .par_iter()
        .map(|&a| {
            let (mut count, mut worst, mut at, mut partners) = (0, f64::INFINITY, a, Vec::new());
            for b in 0..n {
                if b == a {
                    continue;
                }
                let r = ratio(mesh, emb, a, b);
                if r < COLLAPSED {
                    count += 1;
                    partners.push(b);
                }
                if r < worst {
                    (worst, at) = (r, b);
                }
            }
            (count, worst, at, partners)
        })
        .collect();
    let mut involved = vec![false; n];
    let (mut count, mut worst) = (0usize, (f64::INFINITY, 0, 0));
    for (&a, (c, w, at, partners)) in rows.iter().zip(&per_row) {
        count += c;
        if *c > 0 {
            involved[a] = true;
        }
        for &b in partners {
            involved[b] = true;
        }
        if *w < worst.0 {
            worst = (*w, a, *at);
        }
    }
    AllPairs {
        fraction: count as f64 / (rows.len() * (n - 1)) as f64,
        vertices: involved.iter().filter(|&&x| x).count(),
        worst,
    }
}
