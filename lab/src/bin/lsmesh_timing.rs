//! Times the least-squares mesh on a mesh file with 1000 evenly spread landmarks.
use std::path::Path;
use std::time::Instant;
use wavg_embed::NoProgress;

fn main() {
    let path = std::env::args().nth(1).expect("mesh path");
    let mesh = wavg_mesh::ValidMesh::new(wavg_mesh::io::load(Path::new(&path)).unwrap()).unwrap();
    let n = mesh.n_vertices();
    let lm: Vec<u32> = (0..1000).map(|i| (i * n / 1000) as u32).collect();
    let vals: Vec<[f64; 8]> = lm
        .iter()
        .map(|&v| {
            let p = mesh.positions[v as usize];
            [
                p.x,
                p.y,
                p.z,
                p.x * p.y,
                p.y * p.z,
                p.z * p.x,
                p.x * p.x,
                p.y * p.y,
            ]
        })
        .collect();
    let t = Instant::now();
    let a = wavg_embed::internal::bilaplacian(&mesh).unwrap();
    println!(
        "bilaplacian {:.3}s nnz {}",
        t.elapsed().as_secs_f64(),
        a.val().len()
    );
    let t = Instant::now();
    let x = wavg_embed::internal::least_squares_mesh(&mesh, &lm, &vals, 8, &NoProgress).unwrap();
    println!(
        "least_squares_mesh {:.3}s ({} vertices) {}",
        t.elapsed().as_secs_f64(),
        n,
        x[5][0]
    );
}
