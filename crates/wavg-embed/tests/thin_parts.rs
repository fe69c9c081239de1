//! Thin parts (fingers, tails, tubes) keep their cross-sections: the landmark decimation
//! keeps landmarks all around a thin tube, and the embedding does not fold one side of
//! it onto the other.

use wavg_embed::{DecimateOptions, NoProgress, PrecomputeOptions, decimate, precompute};
use wavg_mesh::{ValidMesh, procedural};

/// A torus whose tube is 50 times thinner than its ring: 400 x 16 vertices.
const AROUND: u32 = 400;
const TUBE: u32 = 16;
const TUBE_RADIUS: f64 = 0.02;

fn thin_torus() -> ValidMesh {
    ValidMesh::new(procedural::torus(AROUND, TUBE, 1.0, TUBE_RADIUS)).unwrap()
}

/// The largest aspect ratio (longest edge squared over twice the area) of a mesh's faces.
fn worst_aspect(mesh: &wavg_mesh::TriMesh) -> f64 {
    mesh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| mesh.positions[v as usize]);
            let longest = (b - a)
                .norm_squared()
                .max((c - b).norm_squared())
                .max((a - c).norm_squared());
            longest / (b - a).cross(&(c - a)).norm()
        })
        .fold(0.0, f64::max)
}

#[test]
fn the_aspect_bound_keeps_coarse_triangles_round() {
    let mesh = thin_torus();
    let quadric_only = DecimateOptions {
        target: 1000,
        ..Default::default()
    };
    let d = decimate(&mesh, &quadric_only, &NoProgress).unwrap();
    let free = worst_aspect(&d.mesh);
    let bounded = DecimateOptions {
        max_aspect_ratio: Some(5.0),
        ..quadric_only
    };
    let d = decimate(&mesh, &bounded, &NoProgress).unwrap();
    assert!(d.relaxations.is_empty(), "{:?}", d.relaxations);
    let worst = worst_aspect(&d.mesh);
    assert!(worst <= 5.0, "worst aspect ratio {worst} with the bound");
    // The premise: quadric errors alone make long triangles on this shape.
    assert!(free > 20.0, "worst aspect ratio {free} without the bound");
}

#[test]
fn no_cross_section_of_a_thin_tube_collapses() {
    let mesh = thin_torus();
    let opts = PrecomputeOptions {
        quality_pairs: 0,
        ..Default::default()
    };
    let (emb, _) = precompute(&mesh, &opts, &NoProgress).unwrap();
    let dist = |a: u32, b: u32| {
        let (p, q) = (emb.coords[a as usize], emb.coords[b as usize]);
        p.iter()
            .zip(&q)
            .map(|(x, y)| (x - y).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let chord = 2.0 * TUBE_RADIUS;
    let mut worst = f64::INFINITY;
    for i in 0..AROUND {
        for j in 0..TUBE / 2 {
            let a = i * TUBE + j;
            worst = worst.min(dist(a, a + TUBE / 2) / chord);
        }
    }
    // Opposite points of a cross-section are `chord` apart in space and farther on the
    // surface; folding the tube brings them much closer.
    assert!(
        worst > 0.5,
        "opposite points embedded {worst} x their distance apart"
    );
}
