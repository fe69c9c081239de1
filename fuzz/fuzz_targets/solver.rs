//! A surface from arbitrary arrays, then solvers with arbitrary anchors, weights and
//! points: typed errors or finite answers, never a panic or a NaN.
#![no_main]

use arbitrary::Arbitrary;
use libfuzzer_sys::fuzz_target;
use wavg::{Anchor, ForwardOptions, Normalization, Surface, SurfacePoint};

#[derive(Arbitrary, Debug)]
enum AnchorIn {
    Vertex(u16),
    Point(u16, [f64; 3]),
}

#[derive(Arbitrary, Debug)]
struct Input {
    /// Perturbation of a generated sphere, or free positions.
    noise: Vec<[i8; 3]>,
    extra_triangles: Vec<[u8; 3]>,
    anchors: Vec<AnchorIn>,
    weights: Vec<f64>,
    points: Vec<(u16, [f64; 3])>,
    normalize: bool,
}

fuzz_target!(|input: Input| {
    let base = wavg::mesh::procedural::icosphere(1);
    let mut xyz: Vec<[f64; 3]> = base.positions.iter().map(|p| [p.x, p.y, p.z]).collect();
    for (p, n) in xyz.iter_mut().zip(&input.noise) {
        for k in 0..3 {
            p[k] += f64::from(n[k]) / 64.0;
        }
    }
    let mut tris = base.triangles.clone();
    tris.extend(input.extra_triangles.iter().map(|t| t.map(u32::from)));
    let Ok(surface) = Surface::from_arrays(&xyz, &tris) else {
        return;
    };
    let anchors: Vec<Anchor> = input
        .anchors
        .iter()
        .take(64)
        .map(|a| match *a {
            AnchorIn::Vertex(v) => Anchor::Vertex(u32::from(v)),
            AnchorIn::Point(f, b) => Anchor::Point(SurfacePoint::new(u32::from(f), b)),
        })
        .collect();
    let Ok(solver) = surface.solver(anchors) else {
        return;
    };
    let opts = ForwardOptions {
        normalization: if input.normalize {
            Normalization::Normalize
        } else {
            Normalization::default()
        },
        ..ForwardOptions::default()
    };
    if let Ok(r) = solver.forward(&input.weights, &opts) {
        assert!(r.position.iter().all(|c| c.is_finite()));
        assert!(r.point.bary.iter().all(|b| b.is_finite()));
    }
    for &(f, b) in input.points.iter().take(8) {
        let p = SurfacePoint::new(u32::from(f), b);
        if let Ok(w) = solver.inverse(&p) {
            assert!(w.iter().all(|x| x.is_finite()));
        }
        if let Ok(v) = solver.inverse_verified(&p, 1e-3) {
            assert!(v.weights.iter().all(|x| x.is_finite()));
        }
    }
});
