//! A correspondence between two surfaces: each vertex of the source gets its weights from
//! anchors on the source; the same weights on the target's matching anchors place it there.
//! `cargo run --release -p wavg --example correspond`

use wavg::apps::{CorrespondOptions, correspond_vertices};
use wavg::{Surface, mesh::procedural};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let torus = procedural::torus(64, 24, 1.0, 0.35);
    // The target: the same torus stretched along x (same connectivity, so vertex v of the
    // source should land on vertex v of the target).
    let stretched = torus
        .clone()
        .map_positions(|p| wavg::Vector3::new(1.5 * p.x, p.y, p.z));
    let (source, target) = (Surface::from_mesh(torus)?, Surface::from_mesh(stretched)?);
    let anchors = source.spread_anchors(32, 0)?;
    let map = correspond_vertices(
        &source.solver(anchors.clone())?,
        &target.solver(anchors)?,
        &CorrespondOptions::default(),
    )?;
    let t = target.mesh();
    let errors: Vec<f64> = map
        .mapped
        .iter()
        .enumerate()
        .filter_map(|(v, m)| {
            m.target
                .as_ref()
                .ok()
                .map(|r| (r.position - t.positions[v]).norm())
        })
        .collect();
    let mean = errors.iter().sum::<f64>() / errors.len() as f64 / t.bounding_box_diagonal();
    println!(
        "{:.1}% of {} vertices valid, stretch {:.3}, mean error {:.4} bounding-box diagonals",
        100.0 * map.valid_fraction(),
        map.mapped.len(),
        map.distortion.stretch,
        mean
    );
    assert!(map.valid_fraction() > 0.9, "too few valid vertices");
    assert!(mean < 0.01, "vertices land far from their counterparts");
    Ok(())
}
