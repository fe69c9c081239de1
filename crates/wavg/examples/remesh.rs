//! Semiregular remeshing: a coarse base mesh refined on the surface, every new vertex a
//! weighted average of base points. `cargo run --release -p wavg --example remesh`

use wavg::apps::{BaseMesh, Remesher};
use wavg::{Surface, Vector3, mesh::procedural};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let surface = Surface::from_mesh(procedural::icosphere(4))?;
    // An octahedron inscribed in the unit sphere.
    let base = BaseMesh {
        positions: vec![
            Vector3::x(),
            -Vector3::x(),
            Vector3::y(),
            -Vector3::y(),
            Vector3::z(),
            -Vector3::z(),
        ],
        faces: [
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ]
        .map(Vec::from)
        .into(),
    };
    let mut remesher = Remesher::new(surface.projector().clone(), &base)?;
    let out = remesher.remesh(3, 2)?;
    let off = out
        .positions
        .iter()
        .map(|p| (p.norm() - 1.0).abs())
        .fold(0.0f64, f64::max);
    println!(
        "{} vertices, {} faces after {} levels and {} smoothing steps ({} forward problems); \
         largest distance from the unit sphere {off:.5}",
        out.positions.len(),
        out.faces.len(),
        out.levels,
        out.smooth_steps,
        out.problems
    );
    assert_eq!(out.faces.len(), 8 * 4usize.pow(3));
    assert!(off < 0.01, "a vertex is off the surface");
    Ok(())
}
