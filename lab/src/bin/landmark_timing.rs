//! Times landmark selection (decimation) and the landmark geodesics on real meshes.
//!
//! `cargo xtask lab landmark_timing [MESH...] [--landmarks N]
//! [--coarse N,M,...] [--snapshot] [--decimate-only] [--runs-only]` (default meshes: pig, armadillo,
//! horse, igea from the shared data folder).
//!
//! Columns: decimation wall time (and process CPU time), `FastMarching` build, one
//! single-threaded run, all landmark runs in parallel, and the asymmetry of the raw
//! distance rows. `--coarse N` adds the two-level landmark distances on an N-vertex
//! intermediate mesh with their relative difference to full resolution (with `--snapshot`
//! the intermediate mesh is a snapshot of the landmark decimation, as a pipeline would do
//! it, and the two steps are timed separately); `--runs-only`
//! prints the on-CPU time per run (best of 5 batches); `--decimate-only` only decimates.
//! The machine is shared, so CPU times are the more reliable numbers. Set `BFS=1` to
//! reorder the mesh breadth-first first (a locality experiment), `WORST=1` to list the
//! pairs with the largest coarse-vs-full differences.

use std::time::Instant;

use wavg_embed::NoProgress;
use wavg_embed::internal::decimate_with_snapshots;
use wavg_embed::{DecimateOptions, FastMarching, GeodesicOptions, landmark_distances};
use wavg_mesh::ValidMesh;

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut n_landmarks = 1000usize;
    if let Some(i) = args.iter().position(|a| a == "--landmarks") {
        n_landmarks = args[i + 1].parse().expect("--landmarks N");
        args.drain(i..i + 2);
    }
    let mut coarse_sizes: Vec<usize> = Vec::new();
    if let Some(i) = args.iter().position(|a| a == "--coarse") {
        coarse_sizes = args[i + 1]
            .split(',')
            .map(|x| x.parse().expect("--coarse N,M"))
            .collect();
        args.drain(i..i + 2);
    }
    let snapshot = args.iter().any(|a| a == "--snapshot");
    args.retain(|a| a != "--snapshot");
    let runs_only = args.iter().any(|a| a == "--runs-only");
    args.retain(|a| a != "--runs-only");
    let decimate_only = args.iter().any(|a| a == "--decimate-only");
    args.retain(|a| a != "--decimate-only");
    let Some(paths) = wavg_lab::mesh_paths(
        &args,
        &["pig.off", "armadillo.obj.gz", "horse.off.gz", "igea.off.gz"],
        "landmark_timing",
    ) else {
        return;
    };
    println!(
        "| mesh | vertices | decimate (s) | fm build (s) | one run (ms) | {n_landmarks} runs, {} threads (s) | asymmetry % |",
        rayon::current_num_threads()
    );
    println!("|---|---:|---:|---:|---:|---:|---:|");
    for p in paths {
        let mut mesh = ValidMesh::new(wavg_mesh::io::load(&p).expect("load")).expect("valid");
        if std::env::var_os("BFS").is_some() {
            mesh = bfs(&mesh);
        }
        let name = p.file_name().unwrap().to_string_lossy().to_string();
        let (t, c) = (Instant::now(), cpu_seconds());
        let landmarks = landmarks(&mesh, n_landmarks);
        let t_dec = t.elapsed().as_secs_f64();
        let c_dec = cpu_seconds() - c;
        if decimate_only {
            println!(
                "| {name} | {} | {t_dec:.3} (cpu {c_dec:.2}) |",
                mesh.n_vertices()
            );
            continue;
        }
        let t = Instant::now();
        let fm = FastMarching::new(&mesh);
        let t_build = t.elapsed().as_secs_f64();
        let mut ws = fm.workspace();
        if runs_only {
            let per_run = |fm: &FastMarching, ws: &mut wavg_embed::Workspace| {
                // Best on-CPU time of 5 batches of 10 runs (the machine is shared).
                let mut best = f64::INFINITY;
                for b in 0..5 {
                    let t = thread_cpu_ns();
                    for i in 0..10 {
                        std::hint::black_box(fm.run(ws, &landmarks[b * 10 + i..b * 10 + i + 1]));
                    }
                    best = best.min((thread_cpu_ns() - t) as f64 / 10.0 * 1e-6);
                }
                best
            };
            print!(
                "| {name} | {} | {:.2} ms/run",
                mesh.n_vertices(),
                per_run(&fm, &mut ws)
            );
            for &m in coarse_sizes.iter().filter(|&&m| m < mesh.n_vertices()) {
                let opts = DecimateOptions {
                    target: m,
                    locked: landmarks.clone(),
                    ..Default::default()
                };
                let d = wavg_embed::decimate(&mesh, &opts, &NoProgress).unwrap();
                let cm = ValidMesh::new(d.mesh).unwrap();
                let cfm = FastMarching::new(&cm);
                let mut cws = cfm.workspace();
                print!(
                    " | coarse {m}: {:.2} ms/run, obtuse corners/split {:?} of {}",
                    per_run(&cfm, &mut cws),
                    cfm.obtuse_corners(),
                    3 * cm.n_faces()
                );
            }
            println!();
            continue;
        }
        let t = Instant::now();
        let reps = 5;
        for i in 0..reps {
            std::hint::black_box(fm.run(&mut ws, &landmarks[i..i + 1]));
        }
        let t_run = t.elapsed().as_secs_f64() / reps as f64;
        let (t, c) = (Instant::now(), cpu_seconds());
        let geo = GeodesicOptions::new().fast_marching(&fm);
        let q = landmark_distances(&mesh, &landmarks, &geo, &NoProgress).expect("distances");
        let t_all = t.elapsed().as_secs_f64();
        let c_all = cpu_seconds() - c;
        // Asymmetry |d_ij - d_ji| / q_ij of the raw rows of 30 landmarks against all others.
        let n = landmarks.len();
        let h = wavg_mesh::geometry::mean_edge_length(&mesh);
        let (mut asym, mut asym_far, mut over, mut count) = (0.0f64, 0.0f64, 0usize, 0usize);
        for i in 0..30.min(n) {
            let row: Vec<f64> = {
                let d = fm.run(&mut ws, &landmarks[i..i + 1]);
                landmarks.iter().map(|&l| d[l as usize]).collect()
            };
            for j in 0..n {
                if j != i {
                    // q = (d_ij + d_ji)/2, so |d_ij - d_ji| / q = 2 |d_ij - q| / q.
                    let qq = q[i * n + j];
                    let a = 2.0 * (row[j] - qq).abs() / qq;
                    asym = asym.max(a);
                    if qq > 10.0 * h {
                        asym_far = asym_far.max(a);
                    }
                    over += usize::from(a > 0.02);
                    count += 1;
                }
            }
        }
        println!(
            "| {name} | {} | {t_dec:.3} (cpu {c_dec:.2}) | {t_build:.3} | {:.1} | {t_all:.2} (cpu {c_all:.2}) | max {:.2}, beyond 10 h {:.2}, pairs > 2%: {:.2}% |",
            mesh.n_vertices(),
            t_run * 1e3,
            asym * 100.0,
            asym_far * 100.0,
            100.0 * over as f64 / count as f64
        );
        for &m in &coarse_sizes {
            if m >= mesh.n_vertices() {
                continue;
            }
            let (t, c) = (Instant::now(), cpu_seconds());
            let mut label = format!("coarse {m}");
            let qc = if snapshot {
                // The recommended pipeline: one decimation with a snapshot, two-level distances.
                let opts = DecimateOptions {
                    target: n_landmarks,
                    ..Default::default()
                };
                let (fin, snaps) =
                    decimate_with_snapshots(&mesh, &opts, &[m], &NoProgress).expect("decimation");
                assert_eq!(fin.landmarks, landmarks);
                let (td, cd) = (t.elapsed().as_secs_f64(), cpu_seconds() - c);
                label = format!("snapshot {m} (decimate+snapshot {td:.2} s, cpu {cd:.2}; then)");
                let (t, c) = (Instant::now(), cpu_seconds());
                let geo = GeodesicOptions::new()
                    .fast_marching(&fm)
                    .coarse_mesh(&snaps[0]);
                let q =
                    landmark_distances(&mesh, &landmarks, &geo, &NoProgress).expect("two-level");
                let (tc, cc) = (t.elapsed().as_secs_f64(), cpu_seconds() - c);
                label = format!("{label} geodesics {tc:.2} s (cpu {cc:.2})");
                q
            } else {
                let geo = GeodesicOptions::new().coarse_vertices(m);
                landmark_distances(&mesh, &landmarks, &geo, &NoProgress).expect("coarse")
            };
            let (tc, cc) = (t.elapsed().as_secs_f64(), cpu_seconds() - c);
            let mut rel: Vec<f64> = (0..n * n)
                .filter(|k| k / n != k % n)
                .map(|k| (qc[k] - q[k]) / q[k])
                .collect();
            let mean = rel.iter().sum::<f64>() / rel.len() as f64;
            if std::env::var_os("WORST").is_some() {
                let h = wavg_mesh::geometry::mean_edge_length(&mesh);
                let mut idx: Vec<usize> = (0..n * n).filter(|k| k / n < k % n).collect();
                idx.sort_by(|&a, &b| {
                    ((qc[b] - q[b]) / q[b])
                        .abs()
                        .total_cmp(&((qc[a] - q[a]) / q[a]).abs())
                });
                for &k in idx.iter().take(8) {
                    eprintln!(
                        "pair {} {}: full {:.4} ({:.1} h) coarse {:.4}",
                        landmarks[k / n],
                        landmarks[k % n],
                        q[k],
                        q[k] / h,
                        qc[k]
                    );
                }
            }
            rel.iter_mut().for_each(|r| *r = r.abs());
            rel.sort_by(f64::total_cmp);
            println!(
                "|   {label} | | | | | {tc:.2} (cpu {cc:.2}) | rel. diff to full: mean {:+.2}%, |.| p50 {:.2}% p90 {:.2}% max {:.2}% |",
                mean * 100.0,
                rel[rel.len() / 2] * 100.0,
                rel[rel.len() * 9 / 10] * 100.0,
                rel[rel.len() - 1] * 100.0
            );
        }
    }
}

/// Landmarks by decimation (prints any relaxation of the normal bounds that was needed).
fn landmarks(mesh: &ValidMesh, n: usize) -> Vec<u32> {
    let opts = DecimateOptions {
        target: n,
        ..Default::default()
    };
    let d = wavg_embed::decimate(mesh, &opts, &NoProgress).expect("decimation");
    if !d.relaxations.is_empty() {
        eprintln!("relaxations: {:?}", d.relaxations);
    }
    d.landmarks
}

/// User + system CPU time of this process so far (Linux; 0 elsewhere). The machine is
/// shared, so wall-clock times alone are noisy.
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    // Fields after the parenthesised command name; utime and stime are fields 14 and 15.
    let rest = &stat[stat.rfind(')').map_or(0, |i| i + 2)..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = f[11].parse::<f64>().unwrap_or(0.0) + f[12].parse::<f64>().unwrap_or(0.0);
    ticks / 100.0
}

fn bfs(mesh: &ValidMesh) -> ValidMesh {
    let n = mesh.n_vertices();
    let mut order = Vec::with_capacity(n);
    let mut seen = vec![false; n];
    for s in 0..n {
        if seen[s] {
            continue;
        }
        seen[s] = true;
        order.push(s as u32);
        let mut i = order.len() - 1;
        while i < order.len() {
            let v = order[i];
            for &w in mesh.topology().ring(v) {
                if !seen[w as usize] {
                    seen[w as usize] = true;
                    order.push(w);
                }
            }
            i += 1;
        }
    }
    let mut new_id = vec![0u32; n];
    for (i, &v) in order.iter().enumerate() {
        new_id[v as usize] = i as u32;
    }
    let pos = order.iter().map(|&v| mesh.positions[v as usize]).collect();
    let mut tris: Vec<[u32; 3]> = mesh
        .triangles
        .iter()
        .map(|t| t.map(|v| new_id[v as usize]))
        .collect();
    tris.sort_by_key(|t| *t.iter().min().unwrap());
    ValidMesh::new(wavg_mesh::TriMesh::new(pos, tris)).unwrap()
}

/// Nanoseconds this thread has spent on a CPU (Linux schedstat; 0 elsewhere).
fn thread_cpu_ns() -> u64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse().ok())
        .unwrap_or(0)
}
