//! Landmark decimation side by side: today's quadric decimator from the full mesh, against
//! a first pass by meshoptimizer's simplifier (the `meshopt` crate, edge collapses onto
//! existing vertices, so survivors are original vertices too) down to a tenth of the
//! vertices, then today's decimator to the landmark count.
//!
//! `cargo run -p wavg-lab --bin decimate_options MESH [--landmarks N] [--ratio R]`
//!
//! Prints the wall time of each way and two proxies of landmark quality: how far the
//! farthest vertex is from its nearest landmark (max and p99 over 20,000 sampled vertices,
//! over the bounding-box diagonal), and how many landmarks the two ways share.

use std::time::Instant;

use wavg_embed::{DecimateOptions, LANDMARK_ASPECT_RATIO, NoProgress, decimate};
use wavg_mesh::{TriMesh, ValidMesh};

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut take = |flag: &str, default: f64| -> f64 {
        match args.iter().position(|a| a == flag) {
            Some(i) => {
                let v = args[i + 1].parse().expect("a number");
                args.drain(i..i + 2);
                v
            }
            None => default,
        }
    };
    let landmarks = take("--landmarks", 1000.0) as usize;
    let ratio = take("--ratio", 0.1);
    let path = args.first().expect("MESH");
    let mesh = ValidMesh::new(wavg_mesh::io::load(path.as_ref()).expect("load")).expect("valid");
    let n = mesh.n_vertices();
    let opts = DecimateOptions {
        target: landmarks,
        max_aspect_ratio: Some(LANDMARK_ASPECT_RATIO),
        ..Default::default()
    };

    let t = Instant::now();
    let today = decimate(&mesh, &opts, &NoProgress).expect("decimate");
    let t_today = t.elapsed().as_secs_f64();

    let t = Instant::now();
    let (reduced, ids) = meshopt_pass(&mesh, ratio);
    let t_meshopt = t.elapsed().as_secs_f64();
    let nr = reduced.n_vertices();
    println!("meshopt pass: {n} -> {nr} vertices in {t_meshopt:.2} s");
    // meshoptimizer does not keep the surface manifold: repair what it broke (duplicate
    // faces, non-manifold edges and vertices split), timed with the second pass.
    let t2 = Instant::now();
    let (reduced, ids) = match ValidMesh::new(reduced.clone()) {
        Ok(r) => (r, ids),
        Err(e) => {
            println!("meshopt's reduced mesh is not valid: {e}");
            let r = wavg_mesh::repair::repair_all(&reduced, &Default::default());
            let back: Vec<u32> = r.vertex_map.iter().map(|&v| ids[v as usize]).collect();
            match ValidMesh::new(r.mesh) {
                Ok(m) => (m, back),
                Err(e) => {
                    println!("and not after repair: {e}");
                    return;
                }
            }
        }
    };
    let d = decimate(&reduced, &opts, &NoProgress).expect("decimate the reduced mesh");
    let mut lm: Vec<u32> = d.landmarks.iter().map(|&i| ids[i as usize]).collect();
    lm.dedup();
    let (two, t_second) = (Some(lm), t2.elapsed().as_secs_f64());
    let (max_a, p99_a) = coverage(&mesh, &today.landmarks);
    println!("mesh {path}: {n} vertices, {landmarks} landmarks");
    println!("today: decimate {t_today:.2} s; coverage max {max_a:.4} p99 {p99_a:.4}");
    if let Some(lm) = two {
        let (max_b, p99_b) = coverage(&mesh, &lm);
        let mut sorted = lm.clone();
        sorted.sort_unstable();
        let shared = today
            .landmarks
            .iter()
            .filter(|v| sorted.binary_search(v).is_ok())
            .count();
        println!(
            "meshopt to {nr} vertices {t_meshopt:.2} s, then decimate {t_second:.2} s = {:.2} s \
             ({:.2}x faster); coverage max {max_b:.4} p99 {p99_b:.4}; shared landmarks {shared}",
            t_meshopt + t_second,
            t_today / (t_meshopt + t_second)
        );
    }
}

/// meshoptimizer's simplifier down to `ratio` of the faces (borders locked): the reduced
/// mesh on its surviving vertices, and their original ids.
fn meshopt_pass(mesh: &ValidMesh, ratio: f64) -> (TriMesh, Vec<u32>) {
    let pos: Vec<[f32; 3]> = mesh
        .positions
        .iter()
        .map(|p| [p.x as f32, p.y as f32, p.z as f32])
        .collect();
    let indices: Vec<u32> = mesh.mesh().triangles.iter().flatten().copied().collect();
    let bytes: Vec<u8> = pos.iter().flatten().flat_map(|c| c.to_le_bytes()).collect();
    let adapter = meshopt::VertexDataAdapter::new(&bytes, 12, 0).expect("adapter");
    let target = ((indices.len() as f64 * ratio) as usize / 3) * 3;
    let out = meshopt::simplify(
        &indices,
        &adapter,
        target,
        1.0,
        meshopt::SimplifyOptions::LockBorder,
        None,
    );
    let mut new_id = vec![u32::MAX; mesh.n_vertices()];
    let mut ids = Vec::new();
    for &v in &out {
        if new_id[v as usize] == u32::MAX {
            new_id[v as usize] = ids.len() as u32;
            ids.push(v);
        }
    }
    // Ascending original ids, so the result's order does not depend on the face order.
    let mut order: Vec<u32> = ids.clone();
    order.sort_unstable();
    for (i, &v) in order.iter().enumerate() {
        new_id[v as usize] = i as u32;
    }
    let positions = order
        .iter()
        .map(|&v| mesh.mesh().positions[v as usize])
        .collect();
    let triangles = out
        .chunks_exact(3)
        .map(|t| {
            [
                new_id[t[0] as usize],
                new_id[t[1] as usize],
                new_id[t[2] as usize],
            ]
        })
        .collect();
    (TriMesh::new(positions, triangles), order)
}

/// The largest and 99th-percentile distance from a vertex to its nearest landmark, over
/// the bounding-box diagonal, on 20,000 vertices sampled evenly by index.
fn coverage(mesh: &ValidMesh, landmarks: &[u32]) -> (f64, f64) {
    let p = &mesh.mesh().positions;
    let (lo, hi) = p
        .iter()
        .fold((p[0], p[0]), |(lo, hi), q| (lo.inf(q), hi.sup(q)));
    let diag = (hi - lo).norm();
    let step = (p.len() / 20_000).max(1);
    let mut d: Vec<f64> = (0..p.len())
        .step_by(step)
        .map(|v| {
            (landmarks.iter())
                .map(|&l| (p[v] - p[l as usize]).norm_squared())
                .fold(f64::INFINITY, f64::min)
                .sqrt()
                / diag
        })
        .collect();
    d.sort_by(f64::total_cmp);
    (d[d.len() - 1], d[d.len() * 99 / 100])
}
