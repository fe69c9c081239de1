//! From a mesh to weights and back: `cargo run --release -p wavg --example quickstart [MESH]`.
//!
//! Opens MESH (`.obj`, `.off`, `.ply`, optionally `.gz`) or, without an argument, a torus
//! generated in code; precomputes the 8-D embedding; spreads 24 anchors; finds the weights
//! of a surface point (inverse problem) and the weighted average of those weights (forward
//! problem), which leads back to the point.

use wavg::{ForwardOptions, NoProgress, PrecomputeOptions, Surface, SurfacePoint};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut surface = match std::env::args().nth(1) {
        Some(path) => Surface::open(path)?,
        None => Surface::from_mesh(wavg::mesh::procedural::torus(64, 24, 1.0, 0.35))?,
    };
    println!(
        "mesh: {} vertices, {} faces",
        surface.n_vertices(),
        surface.n_faces()
    );

    let landmarks = (surface.n_vertices() / 10).clamp(50, 1000);
    let opts = PrecomputeOptions {
        landmarks,
        ..Default::default()
    };
    let report = surface.precompute(&opts, &NoProgress)?;
    println!(
        "embedding: {} landmarks in {:.2} s",
        report.landmarks, report.seconds
    );

    let solver = surface.solver(surface.spread_anchors(24, 0)?)?;
    let x = SurfacePoint::new(surface.n_faces() as u32 / 2, [0.2, 0.3, 0.5]);
    let weights = solver.inverse(&x)?;
    let largest = weights.iter().cloned().fold(f64::MIN, f64::max);
    println!(
        "inverse: {} weights, sum {:.6}, largest {largest:.3}",
        weights.len(),
        weights.iter().sum::<f64>()
    );

    let back = solver.forward(&weights, &ForwardOptions::default())?;
    let error = (back.position - surface.position(&x)?).norm();
    println!(
        "forward: face {} at {:?}, {error:.2e} from the start point",
        back.point.face,
        back.position.as_slice()
    );
    Ok(())
}
