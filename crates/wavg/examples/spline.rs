//! A closed cubic B-spline on a surface: every sample is a weighted average of the control
//! points. `cargo run --release -p wavg --example spline`

use wavg::apps::{SplineKind, evaluate_spline};
use wavg::{Surface, mesh::procedural};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let surface = Surface::from_mesh(procedural::icosphere(4))?;
    // Six control points around the equator of the unit sphere.
    let controls: Vec<u32> = (0..6)
        .map(|k| {
            let a = k as f64 * std::f64::consts::TAU / 6.0;
            let target = wavg::Vector3::new(a.cos(), a.sin(), 0.0);
            let d = |v: &u32| (surface.mesh().positions[*v as usize] - target).norm();
            (0..surface.n_vertices() as u32)
                .min_by(|a, b| d(a).total_cmp(&d(b)))
                .unwrap()
        })
        .collect();
    let solver = surface.solver(controls)?;
    let kind = SplineKind::BSpline {
        degree: 3,
        closed: true,
    };
    let curve = evaluate_spline(&solver, kind, 200, 50)?;
    let radius = curve
        .samples
        .iter()
        .flatten()
        .map(|s| s.position.norm())
        .fold(0.0f64, f64::max);
    println!(
        "{} of 200 samples on the surface, length {:.4}, largest |p| {radius:.4}",
        curve.ok_samples(),
        curve.length()
    );
    assert_eq!(curve.ok_samples(), 200);
    // A smooth loop near the equator: shorter than the great circle (2 pi), not much.
    assert!(curve.length() > 5.0 && curve.length() < std::f64::consts::TAU + 0.05);
    Ok(())
}
