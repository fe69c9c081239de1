//! The renderer frames a mesh whatever its scale: its floors are relative to the mesh's
//! size, so a mesh scaled by 1e-18 or 1e18 covers the same pixels as at scale 1.

use wavg_apps::{Colouring, Image, Overlays, RenderOptions, render};
use wavg_mesh::procedural;

/// Pixels that differ from the top-left corner's (the background).
fn covered(img: &Image) -> usize {
    let bg = img.get(0, 0);
    (0..img.height)
        .flat_map(|y| (0..img.width).map(move |x| (x, y)))
        .filter(|&(x, y)| img.get(x, y) != bg)
        .count()
}

#[test]
fn a_tiny_and_a_huge_mesh_render_the_same_coverage() {
    let opts = RenderOptions {
        width: 120,
        height: 90,
        supersample: 1,
        ..Default::default()
    };
    let draw = |scale: f64| {
        let mut mesh = procedural::torus(24, 12, 1.0, 0.4);
        for p in &mut mesh.positions {
            *p *= scale;
        }
        covered(&render(&mesh, &Colouring::Plain, &Overlays::default(), &opts).unwrap())
    };
    let unit = draw(1.0);
    assert!(unit > 120 * 90 / 4, "{unit}");
    for scale in [1e-18, 1e18] {
        let n = draw(scale);
        assert!(
            n.abs_diff(unit) <= unit / 100,
            "scale {scale:e}: {n} pixels, {unit} at 1"
        );
    }
}
