//! The software renderer: a surface coloured by a scalar per vertex, with a curve drawn
//! over it, written as a PNG to the temporary directory.
//! `cargo run --release -p wavg --example render`

use wavg::apps::{Colouring, Overlays, RenderOptions, render};
use wavg::{Surface, mesh::procedural};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let surface = Surface::from_mesh(procedural::torus(64, 24, 1.0, 0.35))?;
    let mesh = surface.mesh();
    let height: Vec<f64> = mesh.positions.iter().map(|p| p.z).collect();
    // A weighted average drawn as a dot: the midpoint of two vertices.
    let mid = wavg::weighted_average(&surface, [0u32, 40], &[0.5, 0.5])?;
    let overlays = Overlays {
        points: vec![mid.position],
        ..Default::default()
    };
    let opts = RenderOptions {
        width: 320,
        height: 240,
        ..Default::default()
    };
    let image = render(mesh, &Colouring::Scalars(&height), &overlays, &opts)?;

    let covered = image
        .pixels
        .iter()
        .filter(|p| p[..3] != [255, 255, 255])
        .count();
    let path = std::env::temp_dir().join(format!("wavg-example-{}.png", std::process::id()));
    image.encode_png(std::fs::File::create(&path)?)?;
    let bytes = std::fs::metadata(&path)?.len();
    println!(
        "{}x{} picture, {:.1}% of the pixels covered, {bytes} bytes -> {}",
        image.width,
        image.height,
        100.0 * covered as f64 / image.pixels.len() as f64,
        path.display()
    );
    assert!(
        covered > image.pixels.len() / 10,
        "the surface is not in the picture"
    );
    std::fs::remove_file(&path)?;
    Ok(())
}
