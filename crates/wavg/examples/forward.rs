//! The forward problem: the weighted average of anchor points on a surface.
//! `cargo run --release -p wavg --example forward`
//!
//! The midpoint of two vertices of a sphere, weighted 1/2 each, lies on the sphere on the
//! great circle through them, halfway along it, not on the chord.

use wavg::{ForwardOptions, Surface, mesh::procedural};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // The 3-D positions serve as the embedding until one is precomputed (exact on a sphere).
    let surface = Surface::from_mesh(procedural::icosphere(4))?;
    let (a, b) = (0u32, 1000u32);
    let mid = wavg::weighted_average(&surface, [a, b], &[0.5, 0.5])?;
    let (pa, pb) = (surface.mesh().positions[0], surface.mesh().positions[1000]);
    let angle = |p: &wavg::Vector3<f64>, q: &wavg::Vector3<f64>| p.angle(q);
    println!(
        "midpoint of vertices {a} and {b}: face {}, |p| = {:.4}, angles to the ends {:.4} and {:.4} rad",
        mid.point.face,
        mid.position.norm(),
        angle(&mid.position, &pa),
        angle(&mid.position, &pb)
    );
    assert!(
        (mid.position.norm() - 1.0).abs() < 0.01,
        "not on the sphere"
    );
    assert!((angle(&mid.position, &pa) - angle(&mid.position, &pb)).abs() < 0.01);

    // Many averages over one anchor set: make a solver once.
    let solver = surface.solver(surface.spread_anchors(8, 0)?)?;
    let weights = [vec![1.0 / 8.0; 8], {
        let mut w = vec![0.0; 8];
        w[3] = 1.0;
        w
    }];
    for w in &weights {
        let r = solver.forward(w, &ForwardOptions::default())?;
        println!(
            "weights {w:?} -> face {} at {:?}",
            r.point.face,
            r.position.as_slice()
        );
    }
    let at_anchor = solver.forward(&weights[1], &ForwardOptions::default())?;
    let anchor3 = surface.position(&solver.anchors().point(3)?)?;
    assert!(
        (at_anchor.position - anchor3).norm() < 1e-9,
        "weight 1 is the anchor"
    );
    Ok(())
}
