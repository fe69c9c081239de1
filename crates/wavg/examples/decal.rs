//! A decal: `(u, v)` coordinates over a patch of the surface, each vertex's the weighted
//! average of the anchors' own `(u, v)` with the vertex's weights.
//! `cargo run --release -p wavg --example decal`

use wavg::{Surface, apps::decal_vertices, mesh::procedural};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let surface = Surface::from_mesh(procedural::icosphere(4))?;
    let p = &surface.mesh().positions;
    // Anchors: the vertices of the cap z > 0.8 of the unit sphere, each with its (x, y)
    // as (u, v): near the pole the decal is a nearly orthographic projection.
    let cap: Vec<u32> = (0..p.len() as u32)
        .filter(|&v| p[v as usize].z > 0.8)
        .step_by(7)
        .collect();
    let uv: Vec<[f64; 2]> = cap
        .iter()
        .map(|&v| [p[v as usize].x, p[v as usize].y])
        .collect();
    let solver = surface.solver(cap.iter().copied())?;
    let decal = decal_vertices(&solver, &uv, -0.1)?;
    let marked = decal.uv.marked.iter().filter(|&&m| m).count();
    // Largest (u, v) error over unmarked vertices near the pole.
    let worst = (0..p.len())
        .filter(|&v| p[v].z > 0.9 && !decal.uv.marked[v])
        .map(|v| (decal.uv.uv[v][0] - p[v].x).hypot(decal.uv.uv[v][1] - p[v].y))
        .fold(0.0f64, f64::max);
    println!(
        "{} anchors, {marked} of {} vertices marked, stretch {:.4}, {} flipped faces, \
         largest (u, v) error near the pole {worst:.4}",
        cap.len(),
        p.len(),
        decal.distortion.stretch,
        decal.distortion.flipped_faces
    );
    assert!(
        worst < 0.02,
        "the decal near the pole is not the projection"
    );
    assert!(marked < p.len(), "every vertex marked");
    Ok(())
}
