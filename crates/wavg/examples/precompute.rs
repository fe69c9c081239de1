//! The 8-D embedding: precompute it with progress, save it to a `.wavg` file, load it back.
//! `cargo run --release -p wavg --example precompute`

use std::sync::Mutex;
use wavg::{PrecomputeOptions, Progress, Stage, Surface, mesh::procedural};

/// Prints each stage when it starts and when it ends (some stages run side by side).
struct Stages(Mutex<Vec<Stage>>);

impl Progress for Stages {
    fn report(&self, stage: Stage, fraction: f64) {
        let mut seen = self.0.lock().unwrap();
        if !seen.contains(&stage) {
            seen.push(stage);
            println!("  {stage:?} started");
        }
        if fraction >= 1.0 {
            println!("  {stage:?} done");
        }
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut surface = Surface::from_mesh(procedural::torus(80, 30, 1.0, 0.35))?;
    let opts = PrecomputeOptions {
        landmarks: 100,
        ..Default::default()
    };
    let report = surface.precompute(&opts, &Stages(Mutex::new(Vec::new())))?;
    println!(
        "{} landmarks in {:.2} s, stress {:.4}, geodesic error p50 {:.4}",
        report.landmarks, report.seconds, report.stress, report.geodesic_rel_err_p50
    );
    assert_eq!(report.dim, 8);
    assert!(report.geodesic_rel_err_p50 < 0.1, "poor embedding");

    let path = std::env::temp_dir().join(format!("wavg-example-{}.wavg", std::process::id()));
    surface.save_embedding(&path)?;
    let mut reloaded = Surface::from_mesh(procedural::torus(80, 30, 1.0, 0.35))?;
    reloaded.load_embedding(&path)?;
    std::fs::remove_file(&path)?;
    println!(
        "saved and loaded {} embedded vertices",
        reloaded.embedded_coords().len()
    );
    assert_eq!(reloaded.embedded_coords(), surface.embedded_coords());
    Ok(())
}
