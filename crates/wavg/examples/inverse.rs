//! The inverse problem: the weights of a surface point with respect to anchors, checked
//! by the forward problem. `cargo run --release -p wavg --example inverse`

use wavg::{ForwardOptions, RoundTrip, Surface, SurfacePoint, mesh::procedural};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let surface = Surface::from_mesh(procedural::torus(64, 24, 1.0, 0.35))?;
    let solver = surface.solver(surface.spread_anchors(24, 0)?)?;
    let x = SurfacePoint::new(700, [0.2, 0.3, 0.5]);

    // The paper's weights: sum to 1, largest on the anchors near the point.
    let w = solver.inverse(&x)?;
    let sum: f64 = w.iter().sum();
    let (nearest, largest) = w
        .iter()
        .enumerate()
        .fold((0, f64::MIN), |b, (i, &v)| if v > b.1 { (i, v) } else { b });
    println!(
        "{} weights, sum {sum:.9}, largest {largest:.3} (anchor {nearest})",
        w.len()
    );
    assert!((sum - 1.0).abs() < 1e-9, "weights must sum to 1");

    // Their weighted average leads back to the point (the round trip).
    let back = solver.forward(&w, &ForwardOptions::default())?;
    let error = (back.position - surface.position(&x)?).norm();
    println!(
        "forward of the weights: face {}, {error:.2e} from the point",
        back.point.face
    );
    assert!(error < 1e-3 * solver.mean_edge_length(), "no round trip");

    // The verified inverse says how the weights were found.
    let v = solver.inverse_verified(&x, wavg::solve::DEFAULT_TOLERANCE)?;
    println!("verified inverse: {:?}", v.round_trip);
    assert_ne!(v.round_trip, RoundTrip::NotReached);
    Ok(())
}
